//! [`auction_assignment`]: a near-bijective assignment of queries to targets over sparse
//! candidate lists (Bertsekas' auction algorithm), used by
//! [`zoomout`](super::zoomout) to read its last point map.

use crate::option_range::non_negative;
use crate::spectral::SpectralError;
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;

/// For every query, its `per_query` best candidate targets and their costs, sorted by cost
/// ascending (the first is the query's nearest target).
///
/// Layout: query `q`'s candidates are `targets[q·per_query .. (q+1)·per_query]`, with costs
/// at the same positions.
#[derive(Debug, Clone, PartialEq)]
pub struct CandidateLists {
    /// Candidates per query (at least 1).
    pub per_query: usize,
    /// Candidate target indices, `queries × per_query`.
    pub targets: Vec<u32>,
    /// Their costs (finite, non-negative; e.g. squared embedding distances), same layout.
    pub costs: Vec<f64>,
}

impl CandidateLists {
    /// Number of queries.
    pub fn queries(&self) -> usize {
        self.targets.len().checked_div(self.per_query).unwrap_or(0)
    }
}

/// Options of [`auction_assignment`]. Costs are measured in units of the *cost scale*: the
/// median over queries of the nearest candidate's cost.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct AuctionOptions {
    /// Extra cost, in cost-scale units, at which a query gives up exclusivity and shares its
    /// nearest target instead (default 20). `0` returns the nearest targets; larger values
    /// approach a true bijection at the price of longer bidding wars.
    pub penalty: f64,
    /// Bid increment ε in cost-scale units (default `0.1`): the assignment's total cost is
    /// within `queries · ε` of the optimum over the candidates, and the bidding takes
    /// `O(1/ε)` rounds where targets are contested. On the TOSCA pairs `1e-3` gives the same
    /// correspondence ratio for a 3× longer auction, and `0.1` the same (95.65 % against
    /// 95.67 % with `0.03`) for a third of the bids (docs/PERFORMANCE.md, "Map step").
    pub epsilon: f64,
    /// Bid in two phases, 5 ε then ε, the second starting from the first one's prices, then
    /// let slots left empty with a price bid back for queries until none is left (ε-scaling
    /// with a reverse auction; default `true`). Same guarantee as one phase; far fewer bids
    /// where queries crowd a region (docs/PERFORMANCE.md, "Third pass").
    pub epsilon_scaling: bool,
}

impl Default for AuctionOptions {
    fn default() -> Self {
        AuctionOptions {
            penalty: 20.0,
            epsilon: 0.1,
            epsilon_scaling: true,
        }
    }
}

/// The result of [`auction_assignment`].
#[derive(Debug, Clone, PartialEq)]
pub struct Assignment {
    /// The target of every query.
    pub map: Vec<u32>,
    /// Queries that hold a target slot of their own (the rest share their nearest target).
    pub exclusive: usize,
    /// Bids made over all phases (a measure of the work done).
    pub bids: usize,
}

/// Assigns every query to one of its candidate targets so that no target takes more than
/// `⌈queries / target_count⌉` queries (one each when there are no more queries than targets:
/// a bijection between shapes of equal vertex count) and the total cost is minimal, up to
/// `queries · ε`; a query whose candidates are all more contested than
/// [`AuctionOptions::penalty`] is worth takes its nearest target without a slot.
///
/// Why: a nearest-neighbour point map sends many vertices to one and leaves others without a
/// preimage wherever an embedding is compressed; a true correspondence between two
/// samplings of one surface is (near) one-to-one, so asking for it moves the crowded matches
/// to their free second-best neighbours. On the TOSCA within-class pairs this lifts the map
/// step by 0.4–1.05 points of correspondence ratio (README).
///
/// Sequential and deterministic (queries bid in index order, first-in first-out; ties go to
/// the earlier candidate). Terminates: every bid raises a price by at least `ε`, and no
/// query bids above its outside option.
///
/// ```
/// use coseg::maps::{auction_assignment, AuctionOptions, CandidateLists};
/// // Two queries whose nearest target is 0; query 1 has target 1 almost as near.
/// let lists = CandidateLists { per_query: 2, targets: vec![0, 1, 0, 1], costs: vec![1.0, 5.0, 1.0, 1.5] };
/// let out = auction_assignment(&lists, 2, &AuctionOptions::default()).unwrap();
/// assert_eq!(out.map, vec![0, 1]);
/// assert_eq!(out.exclusive, 2);
/// ```
pub fn auction_assignment(
    candidates: &CandidateLists,
    target_count: usize,
    options: &AuctionOptions,
) -> Result<Assignment, SpectralError> {
    validate(candidates, target_count, options)?;
    let k = candidates.per_query;
    let queries = candidates.queries();
    if queries == 0 {
        return Ok(Assignment {
            map: Vec::new(),
            exclusive: 0,
            bids: 0,
        });
    }
    let scale = cost_scale(candidates);
    let capacity = queries.div_ceil(target_count);
    let penalty = options.penalty * scale;
    // Slot `t · capacity + s` is the `s`-th place of target `t`.
    let mut price = vec![0.0f64; target_count * capacity];
    let mut owner = vec![u32::MAX; target_count * capacity];
    let mut map = vec![0u32; queries];
    let mut bids = 0usize;
    // The cheapest slot of every target (the first of equal prices) and its price, kept up
    // to date: a bid reads one price per candidate, with no dependent read of the slot.
    let mut cheapest: Vec<u32> = (0..target_count).map(|t| (t * capacity) as u32).collect();
    let mut cheapest_price = vec![0.0f64; target_count];
    // Every query's slot (`u32::MAX`: none) and the cost of its target.
    let mut slot_of = vec![u32::MAX; queries];
    let mut own_cost = vec![0.0f64; queries];
    let schedule = phases(options);
    let epsilon = *schedule.last().expect("at least one phase") * scale;
    for (phase, &phase_epsilon) in schedule.iter().enumerate() {
        let phase_epsilon = phase_epsilon * scale;
        if phase > 0 {
            // A later phase starts from the last one's prices with every query unassigned.
            owner.fill(u32::MAX);
            slot_of.fill(u32::MAX);
        }
        let mut queue: VecDeque<usize> = (0..queries).collect();
        while let Some(q) = queue.pop_front() {
            // The queue is long and a requeued query's lists were last read long ago:
            // fetching the lists of a query a few bids ahead hides part of the memory
            // latency (1.65 → 1.45 s for the 3.6 M bids of victoria0 × david0 in one phase).
            if let Some(&next) = queue.get(PREFETCH_AHEAD) {
                prefetch(&candidates.targets[next * k]);
                prefetch(&candidates.costs[next * k]);
            }
            bids += 1;
            let targets = &candidates.targets[q * k..(q + 1) * k];
            let costs = &candidates.costs[q * k..(q + 1) * k];
            let outside = -(costs[0] + penalty);
            let (mut best, mut second, mut best_target) = (outside, f64::NEG_INFINITY, None);
            for (&t, &cost) in targets.iter().zip(costs) {
                // Prices are never negative and costs ascend, so once `-cost` cannot beat
                // the second best no later candidate can either: the rest of the list is
                // skipped with exactly the result of scanning it.
                if -cost <= second {
                    break;
                }
                let value = -cost - cheapest_price[t as usize];
                if value > best {
                    second = best;
                    best = value;
                    best_target = Some((t as usize, cost));
                } else if value > second {
                    second = value;
                }
            }
            let Some((t, cost)) = best_target else {
                map[q] = targets[0];
                continue;
            };
            let slot = cheapest[t] as usize;
            price[slot] += best - second + phase_epsilon;
            let (low, at) = cheapest_slot(&price, t, capacity);
            (cheapest[t], cheapest_price[t]) = (at as u32, low);
            let previous = std::mem::replace(&mut owner[slot], q as u32);
            map[q] = t as u32;
            (slot_of[q], own_cost[q]) = (slot as u32, cost);
            if previous != u32::MAX {
                slot_of[previous as usize] = u32::MAX;
                queue.push_back(previous as usize);
            }
        }
    }
    if schedule.len() > 1 {
        bids += reverse_phase(
            candidates,
            &Market {
                capacity,
                penalty,
                epsilon,
            },
            &mut price,
            &mut owner,
            &mut slot_of,
            &mut own_cost,
            &mut map,
        );
    }
    let exclusive = owner.iter().filter(|&&o| o != u32::MAX).count();
    Ok(Assignment {
        map,
        exclusive,
        bids,
    })
}

/// Target `t`'s cheapest slot (the first of equal prices): its price and index.
#[inline]
fn cheapest_slot(price: &[f64], t: usize, capacity: usize) -> (f64, usize) {
    (t * capacity..(t + 1) * capacity)
        .map(|x| (price[x], x))
        .min_by(|x, y| x.0.total_cmp(&y.0))
        .expect("capacity is at least 1")
}

/// The bid increments of the phases, in cost-scale units, the requested ε last.
///
/// With [`AuctionOptions::epsilon_scaling`], a first phase bids with 5 ε when that stays below
/// a quarter of the penalty. Why: where more queries crowd a region than it has slots, the
/// prices must climb to the penalty before the losers give up, by about ε per bid (200 bids
/// per slot at the defaults); the coarse phase raises them in larger steps and the last one
/// starts from its prices (docs/PERFORMANCE.md, "Third pass").
fn phases(options: &AuctionOptions) -> Vec<f64> {
    let coarse = options.epsilon * 5.0;
    if options.epsilon_scaling && coarse <= options.penalty / 4.0 {
        vec![coarse, options.epsilon]
    } else {
        vec![options.epsilon]
    }
}

/// The fixed quantities of an assignment problem: slots per target, the outside option's
/// extra cost and the last phase's ε (cost units).
struct Market {
    capacity: usize,
    penalty: f64,
    epsilon: f64,
}

/// Reverse auction (Bertsekas): every slot left empty with a positive price bids for the
/// queries that list its target, lowering its price, until every empty slot is free (price
/// 0). Returns the bids made.
///
/// Why: the single-phase forward auction never prices a slot that ends empty, and that is what
/// makes its result optimal within `queries · ε`. After a coarse phase a crowded region's slots
/// carry prices above what any query will pay at the last ε, and end empty. The reverse bids
/// restore the condition: a slot takes the query that gains most by moving to it (against that
/// query's current profit, its slot or its outside option) at the price that makes the second
/// one indifferent less ε, or drops to price 0 when no query would move.
fn reverse_phase(
    candidates: &CandidateLists,
    market: &Market,
    price: &mut [f64],
    owner: &mut [u32],
    slot_of: &mut [u32],
    own_cost: &mut [f64],
    map: &mut [u32],
) -> usize {
    let k = candidates.per_query;
    let capacity = market.capacity;
    let target_count = price.len() / capacity;
    // The queries listing each target, with their costs (compressed rows).
    let mut start = vec![0usize; target_count + 1];
    for &t in &candidates.targets {
        start[t as usize + 1] += 1;
    }
    for t in 0..target_count {
        start[t + 1] += start[t];
    }
    let mut fill = start.clone();
    // Positions in the candidate lists (query `at / k`, cost `costs[at]`): 4 bytes a listing
    // (lists of over 4·10⁹ candidates, 67 M queries of 64, would need 8).
    let mut listed = vec![0u32; candidates.targets.len()];
    for (at, &t) in candidates.targets.iter().enumerate() {
        let t = t as usize;
        // Repeated candidates (tiny clusters) appear once per listing: harmless, equal values.
        listed[fill[t]] = at as u32;
        fill[t] += 1;
    }
    let profit = |q: usize, price: &[f64], slot_of: &[u32], own_cost: &[f64]| -> f64 {
        match slot_of[q] {
            u32::MAX => -(candidates.costs[q * k] + market.penalty),
            s => -own_cost[q] - price[s as usize],
        }
    };
    let mut queue: VecDeque<usize> = (0..price.len())
        .filter(|&s| owner[s] == u32::MAX && price[s] > 0.0)
        .collect();
    let mut bids = 0;
    while let Some(s) = queue.pop_front() {
        if owner[s] != u32::MAX || price[s] <= 0.0 {
            continue;
        }
        bids += 1;
        let t = s / capacity;
        let (mut best, mut second, mut who) = (f64::NEG_INFINITY, f64::NEG_INFINITY, None);
        for &at in &listed[start[t]..start[t + 1]] {
            let (q, cost) = (at as usize / k, candidates.costs[at as usize]);
            if slot_of[q] != u32::MAX && slot_of[q] as usize / capacity == t {
                // Already at this target: moving to another of its slots gains nothing.
                continue;
            }
            let gain = -cost - profit(q, price, slot_of, own_cost);
            if gain > best {
                second = best;
                best = gain;
                who = Some((q, cost));
            } else if gain > second {
                second = gain;
            }
        }
        match who {
            Some((q, cost)) if best - market.epsilon > 0.0 => {
                price[s] = (second - market.epsilon).max(0.0);
                if slot_of[q] != u32::MAX {
                    let old = slot_of[q] as usize;
                    owner[old] = u32::MAX;
                    if price[old] > 0.0 {
                        queue.push_back(old);
                    }
                }
                owner[s] = q as u32;
                (slot_of[q], own_cost[q], map[q]) = (s as u32, cost, t as u32);
            }
            _ => price[s] = 0.0,
        }
    }
    bids
}

/// How many bids ahead [`auction_assignment`] fetches a query's candidate lists.
const PREFETCH_AHEAD: usize = 4;

/// Asks the processor to bring the cache line holding `x` closer; no effect on results.
#[inline(always)]
fn prefetch<T>(x: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch is a hint that never faults and reads nothing the program sees; the
    // address comes from a live reference.
    unsafe {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        _mm_prefetch::<_MM_HINT_T0>((x as *const T).cast::<i8>());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = x;
}

/// The median nearest cost, or (when it is 0: exact matches) the mean candidate cost, or 1.
fn cost_scale(candidates: &CandidateLists) -> f64 {
    let mut nearest: Vec<f64> = candidates
        .costs
        .chunks_exact(candidates.per_query)
        .map(|c| c[0])
        .collect();
    let mid = nearest.len() / 2;
    let median = *nearest.select_nth_unstable_by(mid, f64::total_cmp).1;
    if median > 0.0 {
        return median;
    }
    let mean = candidates.costs.iter().sum::<f64>() / candidates.costs.len() as f64;
    if mean > 0.0 { mean } else { 1.0 }
}

fn validate(
    candidates: &CandidateLists,
    target_count: usize,
    options: &AuctionOptions,
) -> Result<(), SpectralError> {
    let bad = |m: String| {
        Err(SpectralError::InvalidOption(format!(
            "auction assignment: {m}"
        )))
    };
    let k = candidates.per_query;
    if k == 0
        || !candidates.targets.len().is_multiple_of(k)
        || candidates.costs.len() != candidates.targets.len()
    {
        return bad(format!(
            "{} targets and {} costs are not whole lists of {k} candidates",
            candidates.targets.len(),
            candidates.costs.len()
        ));
    }
    if !candidates.targets.is_empty() && target_count == 0 {
        return bad("candidates given but there are no targets".into());
    }
    if let Some(&t) = candidates
        .targets
        .iter()
        .find(|&&t| t as usize >= target_count)
    {
        return bad(format!(
            "candidate target {t} but only {target_count} targets"
        ));
    }
    if let Some(c) = candidates
        .costs
        .iter()
        .find(|c| !(c.is_finite() && **c >= 0.0))
    {
        return bad(format!("cost {c} is not finite and non-negative"));
    }
    if let Some(q) = candidates
        .costs
        .chunks_exact(k)
        .position(|c| c.windows(2).any(|w| w[1] < w[0]))
    {
        return bad(format!("the costs of query {q} are not sorted ascending"));
    }
    non_negative("penalty", options.penalty).or_else(bad)?;
    if !(options.epsilon.is_finite() && options.epsilon > 0.0) {
        return bad(format!(
            "epsilon = {} must be finite and positive",
            options.epsilon
        ));
    }
    Ok(())
}
