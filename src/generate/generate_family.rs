//! `generate_family()`: all shapes of one family from a seed.

use super::polygonise::{PolygoniseFailure, polygonise};
use super::sdf::{Params, round_to};
use super::{Collection, Family, GenerateError, GeneratedShape, families};

/// Options of [`generate_family`].
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct GenerateOptions {
    /// Seed of the parameter stream (default 1, the seed of the shipped collections).
    pub seed: u64,
    /// Number of shapes (default 6; 1–100,000). Names are zero-padded to the digits of the
    /// count, at least 2 ([`shape_name`]): `humanoids_0000` … `humanoids_0999` for 1,000.
    pub count: usize,
    /// Gauss–Seidel relaxation sweeps applied to the marching-tetrahedra mesh (default 3;
    /// 0 keeps the raw marching-tetrahedra vertices).
    pub relax_iterations: usize,
}

impl Default for GenerateOptions {
    fn default() -> Self {
        GenerateOptions {
            seed: 1,
            count: 6,
            relax_iterations: 3,
        }
    }
}

/// Largest `count` [`generate_family`] accepts (about 10 GB of meshes for humanoids).
const MAX_COUNT: usize = 100_000;

/// The name of shape `index` of a collection of `count` shapes of `family`: `<family>_<index>`,
/// the index zero-padded to the number of digits of `count`, at least 2, so that the names
/// sort in index order whatever the count and collections of fewer than 100 shapes keep the
/// names `chairs_00` … `chairs_99`.
///
/// ```
/// use coseg::generate::{shape_name, Family};
/// assert_eq!(shape_name(Family::Chairs, 5, 6), "chairs_05");
/// assert_eq!(shape_name(Family::Humanoids, 7, 100), "humanoids_007");
/// assert_eq!(shape_name(Family::Humanoids, 999, 1000), "humanoids_0999");
/// ```
pub fn shape_name(family: Family, index: usize, count: usize) -> String {
    let width = count.to_string().len().max(2);
    format!("{}_{index:0width$}", family.name())
}

/// Generates `options.count` shapes of `family` (shape `i` from ChaCha8 seeded by
/// `(options.seed, i)`, so shapes do not depend on the count).
///
/// If a grid is too coarse to give a single closed manifold component, that shape's grid is
/// refined by 15% (up to 4 times) and the cell actually used is recorded.
///
/// ```
/// use coseg::generate::{generate_family, Family, GenerateOptions};
/// let mut options = GenerateOptions::default();
/// options.count = 1;
/// let c = generate_family(Family::Chairs, &options)
///     .unwrap();
/// assert_eq!(c.shapes[0].name, "chairs_00");
/// ```
pub fn generate_family(
    family: Family,
    options: &GenerateOptions,
) -> Result<Collection, GenerateError> {
    if options.count == 0 || options.count > MAX_COUNT {
        return Err(GenerateError::Options(format!(
            "count must be in 1..={MAX_COUNT}, got {}",
            options.count
        )));
    }
    let mut shapes = Vec::with_capacity(options.count);
    for index in 0..options.count {
        let mut params = Params::new(options.seed, index as u64);
        let (model, mut cell) = families::build(family, index, &mut params);
        let mut attempt = 0;
        let (mesh, labels) = loop {
            match polygonise(&model, cell, options.relax_iterations) {
                Ok(r) => break r,
                Err(_) if attempt < 4 => {
                    attempt += 1;
                    cell = round_to(cell * 0.85, 1e4);
                }
                Err(e) => {
                    let message = match e {
                        PolygoniseFailure::Components(n) => format!("{n} components"),
                        PolygoniseFailure::NotManifold(m) => m,
                    };
                    return Err(GenerateError::Polygonise {
                        family,
                        index,
                        message,
                    });
                }
            }
        };
        if attempt > 0 {
            for entry in params.drawn.iter_mut().filter(|e| e.0 == "cell") {
                entry.1 = cell;
            }
        }
        let parts_present = model.parts.iter().map(Option::is_some).collect();
        shapes.push(GeneratedShape {
            name: shape_name(family, index, options.count),
            mesh,
            labels,
            parts_present,
            cell,
            parameters: params.drawn,
        });
    }
    Ok(Collection {
        family,
        seed: options.seed,
        shapes,
    })
}
