//! Synthetic shape families with ground-truth parts (the repository's own `collections/`).
//!
//! Each shape is a union of smoothly blended primitives (capsules, ellipsoids, rounded boxes, an
//! open spherical shell, a cut torus) given as a signed distance function, polygonised with
//! [`marching_tetrahedra`] (a closed 2-manifold by construction), relaxed onto the surface and
//! rounded to 5 decimals. The part of every vertex is the part whose signed distance is
//! smallest there (lowest part index on ties). Parameters — proportions varying by large
//! factors, joint angles, optional parts, grid resolution — are drawn from ChaCha8 seeded by
//! the user seed and the shape index, with deterministic arithmetic only, so a seed gives the
//! same bytes on every platform.
//!
//! Also seeded synthetic inputs for benchmarks and scaling studies, without any spectrum:
//! smooth pseudo-features ([`smooth_features`], banded by
//! [`crate::bands::synthetic_band_table`]), a bent grid ([`grid_mesh`]) and a finer copy of a
//! mesh ([`refine_mesh`]).
//!
//! ```
//! use coseg::generate::{generate_family, Family, GenerateOptions};
//! let mut options = GenerateOptions::default();
//! options.count = 1;
//! let collection = generate_family(Family::Goblets, &options).unwrap();
//! let shape = &collection.shapes[0];
//! assert_eq!(shape.labels.len(), shape.mesh.vertex_count());
//! assert!(shape.labels.iter().all(|&l| (l as usize) < Family::Goblets.part_names().len()));
//! ```

mod families;
mod generate_family;
mod marching_tetrahedra;
mod polygonise;
mod sdf;
mod synthetic;
mod write_collection;

pub use generate_family::{GenerateOptions, generate_family, shape_name};
pub use marching_tetrahedra::{ScalarGrid, marching_tetrahedra};
pub use synthetic::{SmoothFeatures, SplitMix64, grid_mesh, refine_mesh, smooth_features};
pub use write_collection::{MANIFEST_FORMAT, Manifest, ManifestShape, obj_text, write_collection};

use crate::mesh::TriMesh;
use thiserror::Error;

/// A family of shapes with the same parts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Family {
    /// Four-legged animals: torso, head, four legs, tail.
    Quadrupeds,
    /// Humanoids: torso, head, two arms, two legs.
    Humanoids,
    /// Goblets and cups: bowl, stem, base, optional handle.
    Goblets,
    /// Chairs and stools: seat, four legs, optional back and armrests.
    Chairs,
}

impl Family {
    /// Every family, in a fixed order.
    pub const ALL: [Family; 4] = [
        Family::Quadrupeds,
        Family::Humanoids,
        Family::Goblets,
        Family::Chairs,
    ];

    /// The family's name (also its directory name under `collections/`).
    pub fn name(self) -> &'static str {
        match self {
            Family::Quadrupeds => "quadrupeds",
            Family::Humanoids => "humanoids",
            Family::Goblets => "goblets",
            Family::Chairs => "chairs",
        }
    }

    /// The family with this name, if any.
    pub fn from_name(name: &str) -> Option<Family> {
        Family::ALL.into_iter().find(|f| f.name() == name)
    }

    /// Part names; a vertex label is an index into this list.
    pub fn part_names(self) -> &'static [&'static str] {
        match self {
            Family::Quadrupeds => &[
                "torso",
                "head",
                "leg_front_left",
                "leg_front_right",
                "leg_back_left",
                "leg_back_right",
                "tail",
            ],
            Family::Humanoids => &[
                "torso",
                "head",
                "arm_left",
                "arm_right",
                "leg_left",
                "leg_right",
            ],
            Family::Goblets => &["bowl", "stem", "base", "handle"],
            Family::Chairs => &[
                "seat",
                "leg_front_left",
                "leg_front_right",
                "leg_back_left",
                "leg_back_right",
                "back",
                "armrest_left",
                "armrest_right",
            ],
        }
    }

    /// Groups of parts that are the same kind of part (for example the four legs), by name,
    /// for evaluations that do not distinguish left from right.
    pub fn part_groups(self) -> &'static [(&'static str, &'static [&'static str])] {
        match self {
            Family::Quadrupeds => &[(
                "leg",
                &[
                    "leg_front_left",
                    "leg_front_right",
                    "leg_back_left",
                    "leg_back_right",
                ],
            )],
            Family::Humanoids => &[
                ("arm", &["arm_left", "arm_right"]),
                ("leg", &["leg_left", "leg_right"]),
            ],
            Family::Goblets => &[],
            Family::Chairs => &[
                (
                    "leg",
                    &[
                        "leg_front_left",
                        "leg_front_right",
                        "leg_back_left",
                        "leg_back_right",
                    ],
                ),
                ("armrest", &["armrest_left", "armrest_right"]),
            ],
        }
    }

    /// Range of the grid spacing drawn per shape (model units).
    pub(crate) fn cell_range(self) -> (f64, f64) {
        match self {
            Family::Quadrupeds => (0.045, 0.082),
            Family::Humanoids => (0.044, 0.085),
            Family::Goblets => (0.052, 0.085),
            Family::Chairs => (0.04, 0.064),
        }
    }
}

impl std::fmt::Display for Family {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One generated shape.
#[derive(Debug, Clone)]
pub struct GeneratedShape {
    /// File stem, `<family>_<index:02>`.
    pub name: String,
    /// The closed, manifold, single-component, outward-oriented mesh (coordinates rounded to
    /// 5 decimals).
    pub mesh: TriMesh,
    /// Ground-truth part of every vertex (index into [`Family::part_names`]), vertex order.
    pub labels: Vec<u32>,
    /// Which parts this shape has (optional parts may be absent), indexed like the part names.
    pub parts_present: Vec<bool>,
    /// Grid spacing used (model units).
    pub cell: f64,
    /// Every generator parameter, in draw order (lengths in model units, angles in radians,
    /// yes/no as 1/0).
    pub parameters: Vec<(String, f64)>,
}

/// A generated family.
#[derive(Debug, Clone)]
pub struct Collection {
    /// The family.
    pub family: Family,
    /// The seed it was generated from.
    pub seed: u64,
    /// The shapes, in index order.
    pub shapes: Vec<GeneratedShape>,
}

/// Errors of the generator.
#[derive(Debug, Error)]
pub enum GenerateError {
    /// No valid mesh was obtained for a shape even after refining the grid.
    #[error("{family} shape {index}: {message}")]
    Polygonise {
        /// The family.
        family: Family,
        /// The shape index.
        index: usize,
        /// What went wrong at the finest grid tried.
        message: String,
    },
    /// The options are out of range.
    #[error("invalid options: {0}")]
    Options(String),
    /// Writing a file failed.
    #[error(transparent)]
    Io(#[from] crate::FileError),
}
