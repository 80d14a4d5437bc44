//! [`PropagateOptions`]: how labels travel from the labelled shapes to the others.

use super::{PartScore, PropagateError};
use crate::option_range::non_negative;
use serde::{Deserialize, Serialize};

/// Options of [`propagate_labels`](super::propagate_labels).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct PropagateOptions {
    /// Heat-smoothing time of the part scores on every target (unit-area surface, see
    /// [`HeatSmoother`](crate::spectral::HeatSmoother)); default `3e-3`, the boundary
    /// refinement's ([`RefineOptions`](crate::stable::RefineOptions)). `0` = no smoothing.
    pub smoothing_time: f64,
    /// Largest number of Gauss–Seidel sweeps over the unlabelled shapes after the first pass;
    /// default 3 (on the COSEG chairs, 3 sweeps gave 69.6 % where 2 gave 66.0 %, and every
    /// sweep costs a transport per part and graph edge). Sweeps stop when one changes no label.
    pub max_sweeps: usize,
    /// Vote weight of an already-labelled neighbour that is not a source, relative to a
    /// source's 1, before scaling by its confidence; default 1. `0` = sources only (no
    /// network).
    pub network_weight: f64,
    /// How much more a source similar to the target counts than a dissimilar one when several
    /// sources vote: source `j`'s vote on shape `i` weighs `(d_min / d_ij)^p` (`d`: the
    /// graph's [`summary_distance`](crate::graph::ShapeGraph::summary_distance), `d_min` the
    /// nearest source's; floored at 1/16, so every source keeps a say on every part), `p` this
    /// power. `0` = every source counts alike (default). Three sources, 10 seeded triples,
    /// aligned features (docs/PROPAGATION.md): it helps where a collection mixes kinds (COSEG
    /// chairs with two stools 87.67 → 88.62 % with 4, the shipped chairs 76.64 → 77.85 %) and
    /// costs where the shapes are alike and every source is worth hearing (shipped goblets
    /// 75.36 → 72.16 %, humanoids 85.15 → 84.67 %), so it is opt-in. One source: no effect.
    pub similarity_power: f64,
    /// How strongly part sizes on a target follow the sources' area shares, in `[0, 1]`:
    /// `0` = the plain best-score assignment, `1` = the sources' shares exactly, `0.5` the
    /// geometric mean of the two. Default `0.25`, the best compromise measured on two
    /// collections (docs/PROPAGATION.md): COSEG chairs from sources 1, 2, 9 gave 69.6 % with
    /// `0`, 69.8 % with `0.25`, 66.1 % with `0.5`; the shipped goblets from one shape 65.0 %,
    /// 75.0 %, 77.0 % (vertex counts).
    pub size_prior: f64,
    /// How a vertex's histogram values are combined into a part score (see
    /// [`PartScore`]); default [`PartScore::Affinity`], the band affinity's mean transport
    /// ([`PartScore::Geometric`] measured 1.2 points lower on the COSEG chairs, extrinsic).
    pub part_score: PartScore,
    /// Weigh the parts by vertex area rather than vertex count: each part's vote is the
    /// transport of its area density (`areas / part area`) instead of its indicator over its
    /// vertex count, so a densely meshed patch counts for its area. Default `false`: measured
    /// on the COSEG chairs it helps with the extrinsic family (+3.8 points from one source;
    /// spectral + extrinsic +1.5) but costs the spectral default 2.5 points (68.8 → 66.2 %),
    /// and on the shipped goblets 0.8 (docs/PROPAGATION.md); use it with `extrinsic`.
    pub area_weighted: bool,
    /// Rounds of the label-aware refit on every target: after the votes assign it, the
    /// target's own parts (its current labels) score its vertices as a source would, and
    /// the scores `votes + refit_weight · own` are assigned again; default 0 (off: 3 rounds
    /// measured 2.6 points lower on the COSEG chairs from one source, extrinsic — the refit
    /// entrenches what the votes got wrong).
    pub refit_rounds: usize,
    /// Weight of the target's own parts in the refit, relative to the votes' 1.
    pub refit_weight: f64,
    /// Whether [`Propagation::update`](super::Propagation::update) also recomputes the relay
    /// votes of neighbours whose labels changed and sweeps to the fixed point (about a fresh
    /// run's cost); default `false`: the quick update (one pass, relays as cached).
    pub update_relays: bool,
}

impl Default for PropagateOptions {
    fn default() -> Self {
        PropagateOptions {
            smoothing_time: 3e-3,
            max_sweeps: 3,
            network_weight: 1.0,
            similarity_power: 0.0,
            size_prior: 0.25,
            part_score: PartScore::Affinity,
            area_weighted: false,
            refit_rounds: 0,
            refit_weight: 1.0,
            update_relays: false,
        }
    }
}

impl PropagateOptions {
    pub(crate) fn validate(&self) -> Result<(), PropagateError> {
        let bad = |m: String| Err(PropagateError::BadOption(m));
        for (name, value) in [
            ("smoothing_time", self.smoothing_time),
            ("network_weight", self.network_weight),
            ("similarity_power", self.similarity_power),
            ("refit_weight", self.refit_weight),
        ] {
            non_negative(name, value).map_err(PropagateError::BadOption)?;
        }
        if !(0.0..=1.0).contains(&self.size_prior) {
            return bad(format!(
                "size_prior = {} must be in [0, 1]",
                self.size_prior
            ));
        }
        Ok(())
    }
}
