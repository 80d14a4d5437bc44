//! [`part_purity`]: how much of each found region lies in one ground-truth part.

use super::{EvaluateError, Overlap, ShapeParts};
use std::collections::BTreeMap;

/// Area-weighted purity of the found regions, in `[0, 1]`:
/// `Σ_r max_p area(r ∩ p) / Σ_r area(r)`, where `r` runs over found region ids `≥ 0` pooled
/// over all shapes (the same id on two shapes is one region tuple, and its majority part is
/// decided over the whole tuple, so a tuple that is the head on one shape and the tail on
/// another is impure), `p` over ground-truth parts, and each shape is scaled to unit area.
///
/// Every region id `≥ 0` counts, the leftover region (the last id) included: it is part of the
/// output. Vertices with a negative id are in no region and do not count.
///
/// Errors when `shapes` is empty, a shape's vectors differ in length, or no vertex is in a
/// region.
///
/// ```
/// use coseg::evaluate::{part_purity, ShapeParts};
/// let a = ShapeParts::new(vec![1.0; 4], vec![0, 0, 1, 1], vec![0, 0, 1, 1]).unwrap();
/// // The same parts with other ids are just as pure …
/// let b = ShapeParts::new(vec![1.0; 4], vec![0, 0, 1, 1], vec![9, 9, 4, 4]).unwrap();
/// assert_eq!(part_purity(&[b]).unwrap(), 1.0);
/// // … but across two shapes id 0 is the first part on one and the second on the other.
/// let c = ShapeParts::new(vec![1.0; 4], vec![0, 0, 1, 1], vec![1, 1, 0, 0]).unwrap();
/// assert_eq!(part_purity(&[a, c]).unwrap(), 0.5);
/// ```
pub fn part_purity(shapes: &[ShapeParts]) -> Result<f64, EvaluateError> {
    let overlap = Overlap::pool(shapes)?;
    // region → (area, area in its best part)
    let mut regions: BTreeMap<i32, (f64, f64)> = BTreeMap::new();
    for (&(r, _), &a) in &overlap.cells {
        let e = regions.entry(r).or_insert((0.0, 0.0));
        e.0 += a;
        e.1 = e.1.max(a);
    }
    let total: f64 = regions.values().map(|e| e.0).sum();
    if total <= 0.0 {
        return Err(EvaluateError::Empty(
            "no vertex is in a found region".into(),
        ));
    }
    Ok(regions.values().map(|e| e.1).sum::<f64>() / total)
}
