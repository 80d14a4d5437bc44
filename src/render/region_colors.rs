//! [`region_colors`]: a fixed, well-separated colour per region id.

/// RGB colour of each vertex from its region id: region `i` gets the `i`-th colour of a fixed
/// 20-colour palette (cycling past 20, each cycle darker); `-1` (no region) is mid grey.
///
/// ```
/// let c = coseg::output::region_colors(&[0, 1, 0, -1]);
/// assert_eq!(c[0], c[2]);
/// assert_ne!(c[0], c[1]);
/// assert_eq!(c[3], [128, 128, 128]);
/// ```
pub fn region_colors(regions: &[i32]) -> Vec<[u8; 3]> {
    const PALETTE: [[u8; 3]; 20] = [
        [230, 25, 75],
        [60, 180, 75],
        [255, 225, 25],
        [0, 130, 200],
        [245, 130, 48],
        [145, 30, 180],
        [70, 240, 240],
        [240, 50, 230],
        [210, 245, 60],
        [250, 190, 212],
        [0, 128, 128],
        [220, 190, 255],
        [170, 110, 40],
        [255, 250, 200],
        [128, 0, 0],
        [170, 255, 195],
        [128, 128, 0],
        [255, 215, 180],
        [0, 0, 128],
        [255, 255, 255],
    ];
    regions
        .iter()
        .map(|&r| {
            if r < 0 {
                return [128, 128, 128];
            }
            let r = r as usize;
            let c = PALETTE[r % PALETTE.len()];
            let dim = 1.0 / (1.0 + (r / PALETTE.len()) as f64 * 0.5);
            c.map(|x| (x as f64 * dim).round() as u8)
        })
        .collect()
}
