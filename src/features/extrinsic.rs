//! Extrinsic features: directional heights, distance to the centroid and to the up axis, in a
//! frame that is the same rule on every shape (the user's axes, or PCA axes with a sign rule).

use super::{FeatureColumns, FeatureError};
use crate::mesh::TriMesh;

/// A signed coordinate axis of the input files (`+Y` is `Axis { index: 1, positive: true }`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Axis {
    /// 0 = X, 1 = Y, 2 = Z.
    pub index: usize,
    /// `true` for `+`, `false` for `−`.
    pub positive: bool,
}

impl std::str::FromStr for Axis {
    type Err = FeatureError;
    /// `x`, `+y`, `-z`… (case-insensitive; no sign means `+`).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let t = s.trim().to_ascii_lowercase();
        let (positive, rest) = match t.strip_prefix('-') {
            Some(r) => (false, r),
            None => (true, t.strip_prefix('+').unwrap_or(&t)),
        };
        let index = match rest {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            _ => {
                return Err(FeatureError::BadOption(format!(
                    "axis {s:?}: expected x, y or z with an optional sign"
                )));
            }
        };
        Ok(Axis { index, positive })
    }
}

/// The form `coseg --up` takes: `x`, `-y`, … (`+` unwritten).
impl std::fmt::Display for Axis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let sign = if self.positive { "" } else { "-" };
        let name = ["x", "y", "z"].get(self.index).copied().unwrap_or("?");
        write!(f, "{sign}{name}")
    }
}

/// The form `coseg --up` takes: an axis (`y`, `-z`) or `pca`.
impl std::fmt::Display for Alignment {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Alignment::Up(a) => a.fmt(f),
            Alignment::Pca => f.write_str("pca"),
        }
    }
}

/// How a shape is put in the frame its extrinsic features are measured in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Alignment {
    /// The collection is already aligned and `up` is this axis of the files (the frame is the
    /// file's axes, cyclically permuted so that `up` comes last, its sign applied to it).
    Up(Axis),
    /// Principal axes of the surface (area-weighted second moments about the area centroid),
    /// `up` = the axis of **largest** variance, then the middle one, then the smallest. Sign
    /// rule: each axis points towards the side where the surface's area-weighted third moment
    /// `Σ aᵥ (pᵥ·e)³` is positive (a left-handed frame is allowed: the features are then also
    /// unchanged by a mirror image). Shapes whose moments are nearly equal (a sphere) have no
    /// stable frame; nothing can be done there but say so in the documentation.
    Pca,
}

impl Default for Alignment {
    fn default() -> Self {
        Alignment::Up(Axis {
            index: 1,
            positive: true,
        })
    }
}

/// Options of [`extrinsic_features`]. Every field changes the result.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub struct ExtrinsicOptions {
    /// Number of height directions (default 100).
    pub directions: usize,
    /// Directions on the upper half-sphere only (default `true`): the height along `−d` is the
    /// height along `d` reversed, which gives the same bands in reverse order, so the full
    /// sphere only repeats every column.
    pub hemisphere: bool,
    /// The frame rule (default: already aligned with up = `+Y`).
    pub alignment: Alignment,
    /// Add the distance to the centroid (`ext_centroid`, default `true`).
    pub centroid_distance: bool,
    /// Add the distance to the up axis through the centroid (`ext_axis`, default `true`).
    pub axis_distance: bool,
    /// Number of normal columns `ext_nrm_000…`: `|n · u|` for the vertex normal `n` (the
    /// area-weighted mean of its faces' normals) and `u` along [`height_directions`] on the
    /// upper half-sphere (default 0 = none). The absolute value makes them independent of
    /// the faces' winding, so components wound inwards give the same values; they tell a
    /// horizontal patch (a seat) from a vertical one (a chair back) at the same height.
    #[serde(default)]
    pub normal_directions: usize,
}

impl Default for ExtrinsicOptions {
    fn default() -> Self {
        ExtrinsicOptions {
            directions: 100,
            hemisphere: true,
            alignment: Alignment::default(),
            centroid_distance: true,
            axis_distance: true,
            normal_directions: 0,
        }
    }
}

/// Unit directions of the frame, `z` = up: a Fibonacci spiral on the sphere or on the upper
/// half-sphere (`z > 0`), so the set depends only on `n` and `hemisphere`.
///
/// ```
/// let d = coseg::features::height_directions(10, true);
/// assert_eq!(d.len(), 10);
/// assert!(d.iter().all(|u| u[2] > 0.0 && ((u[0]*u[0] + u[1]*u[1] + u[2]*u[2]) - 1.0).abs() < 1e-12));
/// ```
pub fn height_directions(n: usize, hemisphere: bool) -> Vec<[f64; 3]> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let s = (i as f64 + 0.5) / n as f64;
            // z from 1 (up) to 0 on the hemisphere, to −1 on the sphere.
            let z = if hemisphere { 1.0 - s } else { 1.0 - 2.0 * s };
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * i as f64;
            [r * phi.cos(), r * phi.sin(), z]
        })
        .collect()
}

/// The frame of a shape: area centroid `c` (file units) and three unit axes (rows), the last
/// being up; frame coordinates of `p` are `axesᵢ · (p − c)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Area-weighted centroid of the surface.
    pub centroid: [f64; 3],
    /// Frame axes as rows; `axes[2]` is up.
    pub axes: [[f64; 3]; 3],
}

/// The frame of `mesh` under `alignment` (see [`Alignment`]).
///
/// ```
/// use coseg::{mesh::TriMesh, features::{shape_frame, Alignment}};
/// let m = TriMesh::new(vec![[0.,0.,0.],[4.,0.,0.],[0.,1.,0.]], vec![[0,1,2]]).unwrap();
/// let f = shape_frame(&m, Alignment::Pca);
/// assert!(f.axes[2][0].abs() > 0.9); // up = the long (x) direction
/// ```
pub fn shape_frame(mesh: &TriMesh, alignment: Alignment) -> Frame {
    let (centroid, cov, weights) = surface_moments(mesh);
    let axes = match alignment {
        Alignment::Up(a) => {
            let mut axes = [[0.0; 3]; 3];
            let s = if a.positive { 1.0 } else { -1.0 };
            // Cyclic permutation keeps the frame right-handed: up = e_a, then e_{a+1}, e_{a+2}.
            axes[0][(a.index + 1) % 3] = 1.0;
            axes[1][(a.index + 2) % 3] = s;
            axes[2][a.index] = s;
            axes
        }
        Alignment::Pca => pca_axes(mesh, centroid, cov, &weights),
    };
    Frame { centroid, axes }
}

/// Area centroid, area-weighted covariance (vertex areas) and the vertex areas.
pub(crate) fn surface_moments(mesh: &TriMesh) -> ([f64; 3], [[f64; 3]; 3], Vec<f64>) {
    let w = mesh.vertex_areas();
    let total: f64 = w.iter().sum();
    let mut c = [0.0; 3];
    for (p, &a) in mesh.positions().iter().zip(&w) {
        for k in 0..3 {
            c[k] += a * p[k];
        }
    }
    c.iter_mut().for_each(|x| *x /= total);
    let mut cov = [[0.0; 3]; 3];
    for (p, &a) in mesh.positions().iter().zip(&w) {
        let q = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
        for i in 0..3 {
            for j in 0..3 {
                cov[i][j] += a * q[i] * q[j];
            }
        }
    }
    for row in &mut cov {
        row.iter_mut().for_each(|x| *x /= total);
    }
    (c, cov, w)
}

fn pca_axes(
    mesh: &TriMesh,
    centroid: [f64; 3],
    cov: [[f64; 3]; 3],
    weights: &[f64],
) -> [[f64; 3]; 3] {
    let m = nalgebra::Matrix3::from_fn(|i, j| cov[i][j]);
    let eig = nalgebra::SymmetricEigen::new(m);
    let mut order = [0usize, 1, 2];
    // Ascending variance: smallest, middle, largest = frame x, y, up.
    order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    let mut axes = [[0.0; 3]; 3];
    for (row, &k) in order.iter().enumerate() {
        let e = eig.eigenvectors.column(k);
        let mut axis = [e[0], e[1], e[2]];
        let third: f64 = mesh
            .positions()
            .iter()
            .zip(weights)
            .map(|(p, &a)| {
                let h = (p[0] - centroid[0]) * axis[0]
                    + (p[1] - centroid[1]) * axis[1]
                    + (p[2] - centroid[2]) * axis[2];
                a * h * h * h
            })
            .sum();
        // Ties (a symmetric shape) fall back to the largest |component| being positive, so the
        // rule is a function of the shape alone.
        let flip = if third != 0.0 {
            third < 0.0
        } else {
            let big = (0..3)
                .max_by(|&i, &j| axis[i].abs().total_cmp(&axis[j].abs()))
                .unwrap_or(0);
            axis[big] < 0.0
        };
        if flip {
            axis.iter_mut().for_each(|x| *x = -*x);
        }
        axes[row] = axis;
    }
    axes
}

/// Name prefix of the normal columns `|n·u|` (`ext_nrm_000`…).
const NORMAL_PREFIX: &str = "ext_nrm_";

/// The fixed value range of an extrinsic column, if its values mean the same on every shape:
/// `[0, 1]` for the normal columns `|n·u|` (1 = the surface faces along `u`), `None` for the
/// heights and distances, whose scale is the shape's. The band stage cuts fixed-range columns
/// by value ([`fixed_range_bands`](crate::bands::fixed_range_bands)), not by rank, so a
/// horizontal patch is in the top band of the vertical direction on every shape, whatever
/// share of the surface it is (measured on the aligned sets in docs/FEATURES.md).
pub fn fixed_value_range(name: &str) -> Option<[f64; 2]> {
    name.starts_with(NORMAL_PREFIX).then_some([0.0, 1.0])
}

/// Extrinsic per-vertex features of `mesh`: heights along [`height_directions`] in the shape's
/// [`Frame`] (`ext_dir_000`…), then the distance to the centroid (`ext_centroid`) and to the
/// up axis through it (`ext_axis`), as enabled.
///
/// Collection-consistent scale: every column is measured in the shape's frame on the mesh
/// scaled to unit total area, so values mean the same on every shape (and only ranks matter
/// downstream). Invariant to translation and uniform scaling; with [`Alignment::Pca`] also to
/// rotations (up to the sign rule's ties); a vertex permutation permutes the columns.
///
/// ```
/// use coseg::{mesh::TriMesh, features::{extrinsic_features, ExtrinsicOptions}};
/// let m = TriMesh::new(vec![[0.,0.,0.],[1.,0.,0.],[0.,1.,0.]], vec![[0,1,2]]).unwrap();
/// let mut o = ExtrinsicOptions::default();
/// o.directions = 4;
/// let c = extrinsic_features(&m, &o).unwrap();
/// assert_eq!(c.names, ["ext_dir_000", "ext_dir_001", "ext_dir_002", "ext_dir_003", "ext_centroid", "ext_axis"]);
/// assert_eq!(c.values.len(), 6 * 3);
/// ```
pub fn extrinsic_features(
    mesh: &TriMesh,
    options: &ExtrinsicOptions,
) -> Result<FeatureColumns, FeatureError> {
    if options.directions == 0
        && !options.centroid_distance
        && !options.axis_distance
        && options.normal_directions == 0
    {
        return Err(FeatureError::BadOption(
            "the extrinsic family has no column (0 directions and both distances off)".into(),
        ));
    }
    let frame = shape_frame(mesh, options.alignment);
    let scale = 1.0 / mesh.total_area().sqrt();
    let local: Vec<[f64; 3]> = mesh
        .positions()
        .iter()
        .map(|p| {
            let q = [
                p[0] - frame.centroid[0],
                p[1] - frame.centroid[1],
                p[2] - frame.centroid[2],
            ];
            let mut r = [0.0; 3];
            for (k, axis) in frame.axes.iter().enumerate() {
                r[k] = scale * (axis[0] * q[0] + axis[1] * q[1] + axis[2] * q[2]);
            }
            r
        })
        .collect();
    let d = local.len();
    let dirs = height_directions(options.directions, options.hemisphere);
    let mut names = Vec::new();
    let mut values = Vec::with_capacity((dirs.len() + 2) * d);
    for (i, u) in dirs.iter().enumerate() {
        names.push(format!("ext_dir_{i:03}"));
        values.extend(
            local
                .iter()
                .map(|p| u[0] * p[0] + u[1] * p[1] + u[2] * p[2]),
        );
    }
    if options.centroid_distance {
        names.push("ext_centroid".into());
        values.extend(
            local
                .iter()
                .map(|p| (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt()),
        );
    }
    if options.axis_distance {
        names.push("ext_axis".into());
        values.extend(local.iter().map(|p| (p[0] * p[0] + p[1] * p[1]).sqrt()));
    }
    if options.normal_directions > 0 {
        let normals: Vec<[f64; 3]> = mesh
            .vertex_normals()
            .iter()
            .map(|n| {
                let mut r = [0.0; 3];
                for (k, axis) in frame.axes.iter().enumerate() {
                    r[k] = axis[0] * n[0] + axis[1] * n[1] + axis[2] * n[2];
                }
                r
            })
            .collect();
        for (i, u) in height_directions(options.normal_directions, true)
            .iter()
            .enumerate()
        {
            names.push(format!("{NORMAL_PREFIX}{i:03}"));
            values.extend(
                normals
                    .iter()
                    .map(|n| (u[0] * n[0] + u[1] * n[1] + u[2] * n[2]).abs()),
            );
        }
    }
    FeatureColumns::new(d, names, values)
}
