//! [`stable_pairs_fixed`]: Algorithm 2, several stable pairs with fixed thresholds.

use super::stable_pair::stable_pair_inner;
use super::stable_regions::{AreaReference, RegionPair, StableRegions, StableRegionsOptions};
use super::{
    Remaining, StableError, StablePair, StablePairOptions, StableWorkspace, initial_indicator,
};
use crate::affinity::BandAffinity;
use crate::vertex_sets::remove_sorted;

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

/// Algorithm 2: `K − 1` stable pairs with the fixed rules `options.p` (on B) and `options.q`
/// (on A), each found by Algorithm 1 on what the previous pairs left and removed; the leftovers
/// form the last pair. Stops early (leftovers last) when a shape runs out of vertices.
///
/// `areas_a`, `areas_b`: per-vertex areas of A (`d_a`) and B (`d_b`).
///
/// ```
/// use coseg::affinity::BandAffinity;
/// use coseg::bands::equal_count_bands;
/// use coseg::stable::{stable_pairs_fixed, StableRegionsOptions};
/// let vals: Vec<f64> = (0..30).map(|v| v as f64).collect();
/// let a = equal_count_bands(&vals, 1, 30, 3).unwrap();
/// let w = BandAffinity::new(&a, &a).unwrap();
/// let areas = vec![1.0; 30];
/// let opts = StableRegionsOptions { pairs: 3, ..Default::default() };
/// let r = stable_pairs_fixed(&w, &areas, &areas, &opts).unwrap();
/// assert_eq!(r.pairs.len(), 3);
/// assert_eq!(r.pairs[0].region_a, r.pairs[0].region_b);
/// ```
pub fn stable_pairs_fixed(
    w: &BandAffinity<'_>,
    areas_a: &[f64],
    areas_b: &[f64],
    options: &StableRegionsOptions,
) -> Result<StableRegions, StableError> {
    options.validate()?;
    let mut ex = Extraction::new(w, areas_a, areas_b)?;
    let opts = StablePairOptions {
        p: options.p,
        q: options.q,
        max_iterations: options.max_iterations,
    };
    let mut pairs = Vec::with_capacity(options.pairs);
    for i in 0..options.pairs - 1 {
        if ex.rem_a.is_empty() || ex.rem_b.is_empty() {
            break;
        }
        let reference = match options.area_reference {
            AreaReference::Total => (ex.total_a, ex.total_b),
            AreaReference::Remaining => (ex.remaining_area_a(), ex.remaining_area_b()),
        };
        let f0 = initial_indicator(w, &ex.rem_a, options.init, options.seed, i);
        let pair = ex.run(w, &f0, &opts, reference)?;
        if pair.region_a.is_empty() || pair.region_b.is_empty() {
            break;
        }
        pairs.push(ex.take(pair));
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
