//! Operations on ascending vertex lists (`&[u32]`), shared by the pair algorithms
//! ([`crate::stable`]) and the collection stage ([`crate::graph`]). All inputs must be strictly
//! ascending; outputs are too.

/// Sorted intersection of two ascending lists, into `out` (cleared first).
pub(crate) fn intersect_sorted(a: &[u32], b: &[u32], out: &mut Vec<u32>) {
    out.clear();
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        match a[i].cmp(&b[j]) {
            std::cmp::Ordering::Less => i += 1,
            std::cmp::Ordering::Greater => j += 1,
            std::cmp::Ordering::Equal => {
                out.push(a[i]);
                i += 1;
                j += 1;
            }
        }
    }
}

/// Sum of `scores[i]` over the positions `i` whose vertex `vertices[i]` is in `selected`
/// (both lists ascending, `scores` as long as `vertices`).
pub(crate) fn selected_sum(vertices: &[u32], scores: &[f64], selected: &[u32]) -> f64 {
    let mut s = 0.0;
    let mut j = 0;
    for (&v, &sc) in vertices.iter().zip(scores) {
        if j < selected.len() && selected[j] == v {
            s += sc;
            j += 1;
        }
    }
    s
}

/// Removes the ascending `remove` from the ascending `from`, in place.
pub(crate) fn remove_sorted(from: &mut Vec<u32>, remove: &[u32]) {
    let mut j = 0;
    from.retain(|&v| {
        while j < remove.len() && remove[j] < v {
            j += 1;
        }
        !(j < remove.len() && remove[j] == v)
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn helpers_agree_with_set_operations() {
        let a = [1u32, 3, 4, 7, 9];
        let b = [0u32, 3, 7, 8, 9, 12];
        let mut out = Vec::new();
        intersect_sorted(&a, &b, &mut out);
        assert_eq!(out, vec![3, 7, 9]);
        let scores = [1.0, 2.0, 4.0, 8.0, 16.0];
        assert_eq!(selected_sum(&a, &scores, &[3, 9]), 18.0);
        let mut from = a.to_vec();
        remove_sorted(&mut from, &b);
        assert_eq!(from, vec![1, 4]);
    }
}
