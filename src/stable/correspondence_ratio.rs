//! [`correspondence_ratio`]: the paper's §7.2 quality measure against a ground-truth map.

use super::{StableError, StableRegions};
use std::path::Path;

/// A ground-truth vertex map `L : C_A ⊂ A → B`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum VertexMap {
    /// `L(p) = p` for every vertex (shapes sharing their triangulation); `C_A` is every vertex
    /// of A that is also a vertex index of B.
    Identity,
    /// `map[p] = Some(q)`: `L(p) = q`; `None`: `p ∉ C_A`.
    Explicit(Vec<Option<u32>>),
}

impl VertexMap {
    /// Reads a map file: one integer per line for each vertex of A in order, the index of its
    /// image in B, or a negative number for "no correspondence". Blank lines and lines starting
    /// with `#` are skipped.
    pub fn read(path: impl AsRef<Path>) -> Result<Self, StableError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path)
            .map_err(|e| StableError::BadMap(format!("{}: {e}", path.display())))?;
        let mut map = Vec::new();
        for (i, line) in text.lines().enumerate() {
            let l = line.trim();
            if l.is_empty() || l.starts_with('#') {
                continue;
            }
            let v: i64 = l.parse().map_err(|_| {
                StableError::BadMap(format!(
                    "{}:{}: not an integer: {l:?}",
                    path.display(),
                    i + 1
                ))
            })?;
            map.push(if v < 0 { None } else { Some(v as u32) });
        }
        Ok(VertexMap::Explicit(map))
    }
}

/// `Cor_L = |{p ∈ C_A : ∃ i, p ∈ Ω_A,i and L(p) ∈ Ω_B,i}| / |C_A|` (a fraction in `[0, 1]`).
///
/// ```
/// use coseg::stable::{correspondence_ratio, RegionPair, StableRegions, VertexMap};
/// let pair = |a: Vec<u32>, b: Vec<u32>| RegionPair { region_a: a, region_b: b,
///     area_fraction_a: 0.5, area_fraction_b: 0.5, objective: 0.0, iterations: 1,
///     converged: true, leftover: false, auto: None };
/// let r = StableRegions { vertices_a: 4, vertices_b: 4,
///     pairs: vec![pair(vec![0, 1], vec![0, 2]), pair(vec![2, 3], vec![1, 3])] };
/// assert_eq!(correspondence_ratio(&r, &VertexMap::Identity).unwrap(), 0.5);
/// ```
pub fn correspondence_ratio(regions: &StableRegions, map: &VertexMap) -> Result<f64, StableError> {
    let la = regions.labels_a();
    let lb = regions.labels_b();
    let (mut hit, mut total) = (0usize, 0usize);
    let mut check = |p: usize, q: usize| {
        total += 1;
        if la[p] >= 0 && la[p] == lb[q] {
            hit += 1;
        }
    };
    match map {
        VertexMap::Identity => {
            for p in 0..la.len().min(lb.len()) {
                check(p, p);
            }
        }
        VertexMap::Explicit(m) => {
            if m.len() != la.len() {
                return Err(StableError::BadMap(format!(
                    "map has {} entries, shape A has {} vertices",
                    m.len(),
                    la.len()
                )));
            }
            for (p, q) in m.iter().enumerate() {
                if let Some(q) = q {
                    if *q as usize >= lb.len() {
                        return Err(StableError::BadMap(format!(
                            "vertex {p} maps to {q}, shape B has {} vertices",
                            lb.len()
                        )));
                    }
                    check(p, *q as usize);
                }
            }
        }
    }
    if total == 0 {
        return Err(StableError::BadMap("no corresponding vertices".into()));
    }
    Ok(hit as f64 / total as f64)
}
