//! [`fuse_routes`]: one answer from several correspondence routes, each trusted on each shape
//! as far as the others agree with it.

use serde::Serialize;
use std::collections::BTreeMap;

/// A correspondence route of the fused propagation (docs/PROPAGATION.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Route {
    /// The band-affinity transport ([`super::propagate_labels`]).
    Affinity,
    /// The collection's own parts, named from the sources ([`super::parts_route`]).
    Parts,
    /// A similarity alignment to a source and the nearest surface point
    /// ([`super::rigid_route`]).
    Rigid,
}

impl Route {
    /// The route's name as the CLI and `summary.json` write it.
    pub fn name(self) -> &'static str {
        match self {
            Route::Affinity => "affinity",
            Route::Parts => "parts",
            Route::Rigid => "rigid",
        }
    }
}

/// One route's labels on every shape of a collection.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RouteLabels {
    /// Per shape (graph order), per vertex: the label (`-1` = the route does not say); an
    /// empty vector where the route did not vote (the sources, a shape it could not run on).
    pub labels: Vec<Vec<i32>>,
    /// Per shape, per vertex: the route's own confidence in the label, in `[0, 1]` (only its
    /// order within a shape matters to [`fuse_routes`]); empty where `labels` is.
    pub confidence: Vec<Vec<f64>>,
    /// Per shape: the route's own confidence on the shape, in `[0, 1]` (reported; the
    /// fusion's trust comes from agreement, [`FusedRoutes::weights`]).
    pub shape_confidence: Vec<f64>,
}

impl RouteLabels {
    /// No vote on any of `n` shapes.
    pub fn empty(n: usize) -> Self {
        RouteLabels {
            labels: vec![Vec::new(); n],
            confidence: vec![Vec::new(); n],
            shape_confidence: vec![0.0; n],
        }
    }

    /// Whether the route voted on shape `i`.
    pub fn votes_on(&self, i: usize) -> bool {
        self.labels.get(i).is_some_and(|l| !l.is_empty())
    }
}

/// The result of [`fuse_routes`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FusedRoutes {
    /// Per shape, per vertex: the fused label (`-1` where no route says anything); empty on
    /// shapes no route voted on.
    pub labels: Vec<Vec<i32>>,
    /// Per shape, per vertex: the fused label's margin, `(best − second) / total` of the
    /// weighted votes, in `[0, 1]`.
    pub confidence: Vec<Vec<f64>>,
    /// Per shape, per route (the order of the `routes` argument): the route's weight in the
    /// vote on the shape, the log-odds of its accuracy estimated from the routes' agreement
    /// (1 each with fewer than three routes; 0 where it did not vote).
    pub weights: Vec<Vec<f64>>,
    /// Per shape, per route: the area share on which the route's labels equal the fused ones
    /// (0 where it did not vote).
    pub agreement: Vec<Vec<f64>>,
}

/// The largest accuracy above chance a route is credited with: its say stays finite when it
/// agrees perfectly with the others (a route equal to another would otherwise silence every
/// third one).
const MAX_KAPPA: f64 = 0.99;

/// Fuses the labels of several routes on every shape by a vote in which each route counts by
/// its accuracy on that shape, estimated from the routes' agreement alone.
///
/// Accuracy (the one-coin model of Dawid and Skene: each route is right on a share `p_r` of a
/// shape and otherwise wrong at random): on shape `i`, the chance-corrected agreement of two
/// routes (Cohen's κ over the area, `κ_rq = (a_rq − e_rq) / (1 − e_rq)`, `a` the area share
/// with equal labels, `e` the share expected from their label shares alone) is the product
/// of their accuracies above chance, `κ_rq = κ_r κ_q`; with three routes or more each `κ_r` is
/// read off every triangle, `κ_r = √(κ_rq κ_rs / κ_qs)`, and averaged. A route that collapses
/// on a shape (a rigid alignment of a posed body) agrees with no other, and a route that is
/// right where the others are each half right agrees with both more than they agree with each
/// other: it is recognised even when outvoted. `p_r = 1/L + κ_r (1 − 1/L)` (`L` labels in the
/// votes) and the route's weight is its log-odds `ln(p_r (L − 1) / (1 − p_r))`, the optimal
/// weighted vote under the model. With two routes the accuracies cannot be separated: equal
/// weights.
///
/// Vote: vertex `v` gives label `l` the score `Σ_r w_r · (1 + ĉ_r(v)) / 2 · [L_r(v) = l]`,
/// where `ĉ_r(v)` is the area-weighted rank of the route's confidence at `v` among the
/// shape's vertices, in `[0, 1]`. Ranks, not the raw values, because routes state confidence
/// on different scales (a transport's margin, a part's purity); half of each vote is kept
/// everywhere so that a route's least confident vertices still count. Ties: the smallest
/// label. A route label `< 0` casts no vote.
///
/// Inputs: `routes` (each [`RouteLabels`] over the same `#shapes` shapes), `areas` (per shape,
/// per vertex). Output: [`FusedRoutes`] (labels empty on shapes no route voted on, e.g. the
/// sources).
///
/// See also: [`super::parts_route`], [`super::propagate_labels`].
///
/// Known issue: the model assumes the routes fail independently; two routes that share a
/// failure (both read the same features) agree more than their accuracies say, which
/// lowers the estimate of a third. Routes built on different evidence (bands, parts,
/// geometry) keep this small.
pub fn fuse_routes(routes: &[&RouteLabels], areas: &[&[f64]]) -> FusedRoutes {
    let n = areas.len();
    let nr = routes.len();
    let mut out = FusedRoutes {
        labels: vec![Vec::new(); n],
        confidence: vec![Vec::new(); n],
        weights: vec![vec![0.0; nr]; n],
        agreement: vec![vec![0.0; nr]; n],
    };
    for (i, &a) in areas.iter().enumerate() {
        let voting: Vec<usize> = (0..nr).filter(|&r| routes[r].votes_on(i)).collect();
        if voting.is_empty() {
            continue;
        }
        let total: f64 = a.iter().sum::<f64>().max(f64::MIN_POSITIVE);
        let m = voting.len();
        let mut values: Vec<i32> = voting
            .iter()
            .flat_map(|&r| routes[r].labels[i].iter().copied().filter(|&l| l >= 0))
            .collect();
        values.sort_unstable();
        values.dedup();
        let mut trust = route_weights(&voting, &pair_kappa(routes, &voting, i, a), values.len());
        if trust.iter().all(|&w| w <= 0.0) {
            // No route agrees with another above chance: nothing to tell them apart by.
            trust = vec![1.0; m];
        }
        let ranks: Vec<Vec<f64>> = voting
            .iter()
            .map(|&r| area_ranks(&routes[r].confidence[i], a))
            .collect();
        let d = a.len();
        let mut labels = vec![-1i32; d];
        let mut conf = vec![0.0; d];
        let mut scores: Vec<(i32, f64)> = Vec::with_capacity(m);
        for v in 0..d {
            scores.clear();
            for (x, &r) in voting.iter().enumerate() {
                let l = routes[r].labels[i][v];
                if l < 0 {
                    continue;
                }
                let s = trust[x] * (1.0 + ranks[x][v]) / 2.0;
                match scores.iter_mut().find(|(k, _)| *k == l) {
                    Some(e) => e.1 += s,
                    None => scores.push((l, s)),
                }
            }
            scores.sort_by(|p, q| q.1.total_cmp(&p.1).then(p.0.cmp(&q.0)));
            if let Some(&(l, best)) = scores.first() {
                let sum: f64 = scores.iter().map(|s| s.1).sum();
                let second = scores.get(1).map_or(0.0, |s| s.1);
                labels[v] = l;
                conf[v] = if sum > 0.0 {
                    (best - second) / sum
                } else {
                    0.0
                };
            }
        }
        for (x, &r) in voting.iter().enumerate() {
            out.weights[i][r] = trust[x];
            out.agreement[i][r] = routes[r].labels[i]
                .iter()
                .zip(&labels)
                .zip(a)
                .filter(|((p, q), _)| **p >= 0 && p == q)
                .map(|(_, w)| w)
                .sum::<f64>()
                / total;
        }
        out.labels[i] = labels;
        out.confidence[i] = conf;
    }
    out
}

/// The chance-corrected agreement (Cohen's κ, area-weighted) of every pair of the `voting`
/// routes on shape `i`, as an `m × m` matrix (diagonal 1).
fn pair_kappa(routes: &[&RouteLabels], voting: &[usize], i: usize, areas: &[f64]) -> Vec<Vec<f64>> {
    let m = voting.len();
    let total: f64 = areas.iter().sum::<f64>().max(f64::MIN_POSITIVE);
    let shares: Vec<BTreeMap<i32, f64>> = voting
        .iter()
        .map(|&r| {
            let mut s = BTreeMap::new();
            for (&l, &w) in routes[r].labels[i].iter().zip(areas) {
                if l >= 0 {
                    *s.entry(l).or_insert(0.0) += w / total;
                }
            }
            s
        })
        .collect();
    let mut k = vec![vec![1.0; m]; m];
    for x in 0..m {
        for y in x + 1..m {
            let (lx, ly) = (&routes[voting[x]].labels[i], &routes[voting[y]].labels[i]);
            let agree: f64 = lx
                .iter()
                .zip(ly)
                .zip(areas)
                .filter(|((p, q), _)| **p >= 0 && p == q)
                .map(|(_, w)| w)
                .sum::<f64>()
                / total;
            let chance: f64 = shares[x]
                .iter()
                .map(|(l, s)| s * shares[y].get(l).copied().unwrap_or(0.0))
                .sum();
            let kappa = if chance < 1.0 {
                (agree - chance) / (1.0 - chance)
            } else {
                0.0
            };
            k[x][y] = kappa;
            k[y][x] = kappa;
        }
    }
    k
}

/// Each voting route's log-odds weight from the pairwise κ (see [`fuse_routes`]); equal
/// weights for fewer than three routes.
fn route_weights(voting: &[usize], kappa: &[Vec<f64>], labels: usize) -> Vec<f64> {
    let m = voting.len();
    if m < 3 {
        return vec![1.0; m];
    }
    let l = labels.max(2) as f64;
    (0..m)
        .map(|x| {
            let mut sum = 0.0;
            let mut count = 0usize;
            for y in (0..m).filter(|&y| y != x) {
                for z in (y + 1..m).filter(|&z| z != x) {
                    let (kxy, kxz, kyz) = (kappa[x][y], kappa[x][z], kappa[y][z]);
                    let est = if kyz > 0.0 {
                        (kxy.max(0.0) * kxz.max(0.0) / kyz).sqrt()
                    } else {
                        // The other two do not agree above chance: they say nothing of x.
                        continue;
                    };
                    sum += est;
                    count += 1;
                }
            }
            let k = if count > 0 {
                sum / count as f64
            } else {
                // No triangle informs on x (every pair of the others agrees at chance: one
                // of them collapsed). Read x off the routes it agrees with as if each pair
                // were equally accurate, `κ_x = √κ_xy` (the two-route case), so that a
                // collapsed route, agreeing with none, keeps no say.
                let pairs: Vec<f64> = (0..m)
                    .filter(|&y| y != x && kappa[x][y] > 0.0)
                    .map(|y| kappa[x][y].sqrt())
                    .collect();
                if pairs.is_empty() {
                    0.0
                } else {
                    pairs.iter().sum::<f64>() / pairs.len() as f64
                }
            };
            let k = k.clamp(0.0, MAX_KAPPA);
            let p = 1.0 / l + k * (1.0 - 1.0 / l);
            (p * (l - 1.0) / (1.0 - p)).ln()
        })
        .collect()
}

/// Area-weighted mid-ranks of `values` in `[0, 1]`: the area of the vertices with a smaller
/// value plus half the area of those with an equal one, over the total (equal values share a
/// rank). Missing values (a shorter vector) rank 0.
fn area_ranks(values: &[f64], areas: &[f64]) -> Vec<f64> {
    let d = areas.len();
    if values.len() != d {
        return vec![0.0; d];
    }
    let total: f64 = areas.iter().sum();
    if total <= 0.0 {
        return vec![0.0; d];
    }
    let mut order: Vec<usize> = (0..d).collect();
    order.sort_by(|&x, &y| values[x].total_cmp(&values[y]).then(x.cmp(&y)));
    let mut ranks = vec![0.0; d];
    let (mut below, mut k) = (0.0, 0);
    while k < d {
        let mut e = k;
        let mut tie = 0.0;
        while e < d && values[order[e]] == values[order[k]] {
            tie += areas[order[e]];
            e += 1;
        }
        let r = (below + tie / 2.0) / total;
        for &v in &order[k..e] {
            ranks[v] = r;
        }
        below += tie;
        k = e;
    }
    ranks
}
