//! [`PartCues`]: the per-shape geometry [`super::geometric_part_tree`] reads (thickness and
//! mean curvature per vertex), computed once per shape and kept in the per-shape cache by
//! [`load_or_compute_part_cues`].
//!
//! Why a cache entry of its own: the thickness is the shape diameter function, 30 ray casts
//! per vertex, about 0.5 s for a 10k-vertex shape on two cores: without the cache, `coseg
//! segment --parts N --parts-from geometry` on 20 such shapes spent three quarters of its warm
//! run on it (docs/PARTS.md). The cues depend on the mesh alone, not on the feature options,
//! so one entry serves every run on that mesh.

use crate::cache::{CacheOutcome, EntryKind, Lookup, entry_key, entry_path, read_entry};
use crate::cache::{encode_entry, write_entry};
use crate::features::{FeatureError, SdfOptions, mean_curvature, shape_diameter};
use crate::graph::GraphError;
use crate::mesh::TriMesh;
use rayon::prelude::*;
use std::path::Path;

/// One shape's geometric cues of part boundaries, per vertex (each #V long).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PartCues {
    /// The local thickness: the shape diameter function smoothed by one round of one-ring
    /// averaging ([`shape_diameter`] with [`PartCues::sdf_options`]), in units of
    /// `√(total area)` (so it does not depend on the shape's scale). Positive.
    pub thickness: Vec<f64>,
    /// The mean curvature ([`mean_curvature`], positive where the surface is convex), in
    /// units of 1 / file length.
    pub mean_curvature: Vec<f64>,
}

impl PartCues {
    /// The SDF options of [`Self::thickness`]: the defaults (30 rays in a 120° cone) with one
    /// smoothing round.
    pub fn sdf_options() -> SdfOptions {
        SdfOptions {
            smoothing_rounds: vec![1],
            ..SdfOptions::default()
        }
    }

    /// The cues of `mesh` (#V vertices), computed.
    ///
    /// Errors: [`FeatureError`] when the SDF cannot be computed.
    ///
    /// ```
    /// use coseg::{parts::PartCues, mesh::TriMesh};
    /// let p = vec![[0.,0.,0.],[1.,0.,0.],[1.,1.,0.],[0.,1.,0.],[0.,0.,1.],[1.,0.,1.],[1.,1.,1.],[0.,1.,1.]];
    /// let f = vec![[0,2,1],[0,3,2],[4,5,6],[4,6,7],[0,1,5],[0,5,4],[1,2,6],[1,6,5],[2,3,7],[2,7,6],[3,0,4],[3,4,7]];
    /// let cues = PartCues::of(&TriMesh::new(p, f).unwrap()).unwrap();
    /// assert_eq!(cues.thickness.len(), 8);
    /// assert!(cues.mean_curvature.iter().all(|&h| h > 0.0)); // a cube's corners are convex
    /// ```
    pub fn of(mesh: &TriMesh) -> Result<Self, FeatureError> {
        let thickness = shape_diameter(mesh, &Self::sdf_options())?
            .column(0)
            .to_vec();
        Ok(PartCues {
            thickness,
            mean_curvature: mean_curvature(mesh),
        })
    }

    fn check(&self, vertices: usize) -> Result<(), String> {
        if self.thickness.len() != vertices || self.mean_curvature.len() != vertices {
            return Err(format!(
                "part cues for {} / {} vertices, the mesh has {vertices}",
                self.thickness.len(),
                self.mean_curvature.len()
            ));
        }
        if self
            .thickness
            .iter()
            .chain(&self.mean_curvature)
            .any(|x| !x.is_finite())
        {
            return Err("part cues hold a non-finite value".into());
        }
        Ok(())
    }
}

/// What [`load_or_compute_part_cues`] returns.
#[derive(Debug, Clone)]
pub struct PartCuesResult {
    /// The cues (identical whether read or computed).
    pub cues: PartCues,
    /// Hit, miss or recomputed (with the reason).
    pub outcome: CacheOutcome,
    /// Set when freshly computed cues could not be written (they are still valid): a
    /// warning for the caller.
    pub write_error: Option<String>,
}

/// The cues of `mesh` from `cache_dir` (file `<key>.coseg-cues`, key: the mesh and
/// [`PartCues::sdf_options`]) if a verified entry exists, otherwise computed and written
/// atomically. A corrupt, stale or foreign entry is recomputed and replaced
/// ([`CacheOutcome::Recomputed`] says why); a cache that cannot be written gives
/// `write_error`, not a failure.
///
/// Errors: [`FeatureError`] when the SDF cannot be computed.
///
/// ```
/// use coseg::{cache::CacheOutcome, parts::{load_or_compute_part_cues, PartCues}, mesh::TriMesh};
/// let dir = std::env::temp_dir().join(format!("coseg-doc-cues-{}", std::process::id()));
/// let p = vec![[0.,0.,0.],[1.,0.,0.],[1.,1.,0.],[0.,1.,0.],[0.,0.,1.],[1.,0.,1.],[1.,1.,1.],[0.,1.,1.]];
/// let f = vec![[0,2,1],[0,3,2],[4,5,6],[4,6,7],[0,1,5],[0,5,4],[1,2,6],[1,6,5],[2,3,7],[2,7,6],[3,0,4],[3,4,7]];
/// let m = TriMesh::new(p, f).unwrap();
/// let first = load_or_compute_part_cues(&m, &dir).unwrap();
/// let second = load_or_compute_part_cues(&m, &dir).unwrap();
/// assert_eq!((first.outcome, second.outcome), (CacheOutcome::Miss, CacheOutcome::Hit));
/// assert_eq!(second.cues, PartCues::of(&m).unwrap());
/// # std::fs::remove_dir_all(&dir).ok();
/// ```
pub fn load_or_compute_part_cues(
    mesh: &TriMesh,
    cache_dir: &Path,
) -> Result<PartCuesResult, FeatureError> {
    let key = entry_key(mesh, &("part cues", PartCues::sdf_options()));
    let path = entry_path(cache_dir, &key, EntryKind::PartCues);
    let vertices = mesh.vertex_count();
    let outcome = match read_entry(&path, EntryKind::PartCues, &key, |c: &PartCues| {
        c.check(vertices)
    }) {
        Lookup::Hit(cues) => {
            return Ok(PartCuesResult {
                cues,
                outcome: CacheOutcome::Hit,
                write_error: None,
            });
        }
        Lookup::Missing => CacheOutcome::Miss,
        Lookup::Untrusted(reason) => CacheOutcome::Recomputed {
            reason: format!("{}: {reason}; recomputed", path.display()),
        },
    };
    let cues = PartCues::of(mesh)?;
    let write_error = std::fs::create_dir_all(cache_dir)
        .and_then(|()| write_entry(&path, &encode_entry(EntryKind::PartCues, &key, &cues)))
        .err()
        .map(|e| format!("{}: cache entry not written: {e}", path.display()));
    Ok(PartCuesResult {
        cues,
        outcome,
        write_error,
    })
}

/// Each shape's cues (in parallel, one task per shape), through the cache in `cache_dir` when
/// given; untrusted or unwritten entries become `warnings`. `name(i)` names shape `i` in the
/// error of a shape whose SDF fails ([`GraphError::Thickness`]).
pub(crate) fn collection_cues(
    meshes: &[TriMesh],
    name: impl Fn(usize) -> String + Sync,
    cache_dir: Option<&Path>,
    warnings: &mut Vec<String>,
) -> Result<Vec<PartCues>, GraphError> {
    let got = meshes
        .par_iter()
        .enumerate()
        .map(|(i, mesh)| {
            let thickness = |source| GraphError::Thickness {
                name: name(i),
                source,
            };
            match cache_dir {
                None => Ok((PartCues::of(mesh).map_err(thickness)?, Vec::new())),
                Some(dir) => {
                    let r = load_or_compute_part_cues(mesh, dir).map_err(thickness)?;
                    let mut w = Vec::new();
                    if let CacheOutcome::Recomputed { reason } = r.outcome {
                        w.push(reason);
                    }
                    w.extend(r.write_error);
                    Ok((r.cues, w))
                }
            }
        })
        .collect::<Result<Vec<_>, GraphError>>()?;
    Ok(got
        .into_iter()
        .map(|(c, w)| {
            warnings.extend(w);
            c
        })
        .collect())
}
