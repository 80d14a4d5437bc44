//! [`part_coverage`]: how much of each ground-truth part one found region covers.

use super::{EvaluateError, Overlap, ShapeParts};

/// Coverage of the ground-truth parts, in `[0, 1]`: for each part `p` (pooled over all shapes,
/// each scaled to unit area), `max_r area(r ∩ p) / area(p)` over found region ids `r ≥ 0`; the
/// plain mean over the parts that occur. The mean is not area-weighted so that a small part
/// (a head, a tail) counts as much as the torso.
///
/// One region id must cover the part on every shape at once: a part split between ids across
/// shapes scores low even if each shape alone is clean. Vertices in no region (negative id)
/// count in the part's area and are never covered. Since a region holds a fixed share of each
/// shape, a part larger than a region cannot reach 1.
///
/// Errors when `shapes` is empty, a shape's vectors differ in length, or the total area is 0.
///
/// ```
/// use coseg::evaluate::{part_coverage, ShapeParts};
/// // Part 0 (2 vertices) in region 3; part 1 (2 vertices) split between regions 3 and 4.
/// let s = ShapeParts::new(vec![1.0; 4], vec![0, 0, 1, 1], vec![3, 3, 3, 4]).unwrap();
/// assert_eq!(part_coverage(&[s]).unwrap(), 0.75);
/// ```
pub fn part_coverage(shapes: &[ShapeParts]) -> Result<f64, EvaluateError> {
    let overlap = Overlap::pool(shapes)?;
    let mut sum = 0.0;
    let mut count = 0usize;
    for (&p, &area) in &overlap.parts {
        if area <= 0.0 {
            continue;
        }
        let best = overlap
            .cells
            .iter()
            .filter(|((_, q), _)| *q == p)
            .map(|(_, &a)| a)
            .fold(0.0, f64::max);
        sum += best / area;
        count += 1;
    }
    if count == 0 {
        return Err(EvaluateError::Empty("no part has area".into()));
    }
    Ok(sum / count as f64)
}
