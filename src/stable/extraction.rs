//! The extraction engine shared by Algorithms 2 and 3 ([`super::stable_pairs_fixed`],
//! [`super::stable_pairs_auto`]): the remaining vertices, their areas, one Algorithm 1 run on
//! them, removal of a found pair, and the leftovers pair.

use super::region_types::{RegionPair, StableRegions, StableRegionsOptions};
use super::stable_pair::stable_pair_inner;
use super::{Remaining, StableError, StablePair, StablePairOptions, StableWorkspace};
use crate::affinity::BandAffinity;
use crate::vertex_sets::remove_sorted;

/// The frame of Algorithms 2 and 3: after checking `options` and the areas, up to
/// `options.pairs − 1` pairs, each from `next(extraction, i)` on what the earlier ones left
/// (`None`: stop early; so does a shape that runs out of vertices), then the leftovers as the
/// last pair.
pub(crate) fn extract_pairs<'s>(
    w: &BandAffinity<'_>,
    areas_a: &'s [f64],
    areas_b: &'s [f64],
    options: &StableRegionsOptions,
    mut next: impl FnMut(&mut Extraction<'s>, usize) -> Result<Option<RegionPair>, StableError>,
) -> Result<StableRegions, StableError> {
    options.validate()?;
    let mut ex = Extraction::new(w, areas_a, areas_b)?;
    let mut pairs = Vec::with_capacity(options.pairs);
    for i in 0..options.pairs - 1 {
        if ex.rem_a.is_empty() || ex.rem_b.is_empty() {
            break;
        }
        let Some(pair) = next(&mut ex, i)? else {
            break;
        };
        pairs.push(pair);
    }
    if !ex.rem_a.is_empty() || !ex.rem_b.is_empty() {
        pairs.push(ex.leftovers(w)?);
    }
    Ok(StableRegions {
        vertices_a: w.cols(),
        vertices_b: w.rows(),
        pairs,
    })
}

/// Shared state of Algorithms 2 and 3: remaining vertices and areas.
pub(crate) struct Extraction<'s> {
    pub areas_a: &'s [f64],
    pub areas_b: &'s [f64],
    pub total_a: f64,
    pub total_b: f64,
    pub rem_a: Vec<u32>,
    pub rem_b: Vec<u32>,
    pub ws: StableWorkspace,
}

impl<'s> Extraction<'s> {
    pub fn new(
        w: &BandAffinity<'_>,
        areas_a: &'s [f64],
        areas_b: &'s [f64],
    ) -> Result<Self, StableError> {
        if areas_a.len() != w.cols() || areas_b.len() != w.rows() {
            return Err(StableError::AreaLength {
                expected_a: w.cols(),
                expected_b: w.rows(),
                got_a: areas_a.len(),
                got_b: areas_b.len(),
            });
        }
        if areas_a
            .iter()
            .chain(areas_b)
            .any(|x| !x.is_finite() || *x < 0.0)
        {
            return Err(StableError::BadOption(
                "vertex areas must be finite and non-negative".into(),
            ));
        }
        Ok(Self {
            areas_a,
            areas_b,
            total_a: areas_a.iter().sum(),
            total_b: areas_b.iter().sum(),
            rem_a: (0..w.cols() as u32).collect(),
            rem_b: (0..w.rows() as u32).collect(),
            ws: StableWorkspace::default(),
        })
    }

    pub fn remaining_area_a(&self) -> f64 {
        self.rem_a.iter().map(|&v| self.areas_a[v as usize]).sum()
    }

    pub fn remaining_area_b(&self) -> f64 {
        self.rem_b.iter().map(|&v| self.areas_b[v as usize]).sum()
    }

    pub fn area_a(&self, r: &[u32]) -> f64 {
        r.iter().map(|&v| self.areas_a[v as usize]).sum()
    }

    pub fn area_b(&self, r: &[u32]) -> f64 {
        r.iter().map(|&v| self.areas_b[v as usize]).sum()
    }

    /// Algorithm 1 on the remainder with the given reference areas.
    pub fn run(
        &mut self,
        w: &BandAffinity<'_>,
        f0: &[u32],
        opts: &StablePairOptions,
        reference: (f64, f64),
    ) -> Result<StablePair, StableError> {
        let rem = Remaining {
            vertices_a: &self.rem_a,
            vertices_b: &self.rem_b,
            areas_a: self.areas_a,
            areas_b: self.areas_b,
            reference_area_a: reference.0,
            reference_area_b: reference.1,
        };
        stable_pair_inner(w, &rem, f0, opts, &mut self.ws)
    }

    /// Removes a pair from the remainder and records it.
    pub fn take(&mut self, pair: StablePair) -> RegionPair {
        remove_sorted(&mut self.rem_a, &pair.region_a);
        remove_sorted(&mut self.rem_b, &pair.region_b);
        RegionPair {
            area_fraction_a: self.area_a(&pair.region_a) / self.total_a,
            area_fraction_b: self.area_b(&pair.region_b) / self.total_b,
            region_a: pair.region_a,
            region_b: pair.region_b,
            objective: pair.objective,
            iterations: pair.iterations,
            converged: pair.converged,
            leftover: false,
            auto: None,
        }
    }

    /// The leftovers as the last pair (its objective from the operator).
    pub fn leftovers(&mut self, w: &BandAffinity<'_>) -> Result<RegionPair, StableError> {
        let (ra, rb) = (
            std::mem::take(&mut self.rem_a),
            std::mem::take(&mut self.rem_b),
        );
        let mut scores = vec![0.0; rb.len()];
        w.transport_indicator(
            crate::affinity::Direction::AtoB,
            &ra,
            Some(&rb),
            &mut scores,
            &mut self.ws.affinity,
        )?;
        let objective = w.unit() * scores.iter().sum::<f64>();
        Ok(RegionPair {
            area_fraction_a: self.area_a(&ra) / self.total_a,
            area_fraction_b: self.area_b(&rb) / self.total_b,
            region_a: ra,
            region_b: rb,
            objective,
            iterations: 0,
            converged: true,
            leftover: true,
            auto: None,
        })
    }
}
