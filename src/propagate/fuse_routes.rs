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
    /// Per shape: how far the route's correspondence is from overlaying the shape on its
    /// source, relative to the source's size (the rigid route: the symmetric trimmed chamfer
    /// after registration, in source RMS radii); `NaN` where the route has no such measure.
    pub residual: Vec<f64>,
}

impl RouteLabels {
    /// No vote on any of `n` shapes.
    pub fn empty(n: usize) -> Self {
        RouteLabels {
            labels: vec![Vec::new(); n],
            confidence: vec![Vec::new(); n],
            shape_confidence: vec![0.0; n],
            residual: vec![f64::NAN; n],
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

/// A route whose accuracy the sources measure by a round trip (their labels carried to
/// themselves through it: the parts route, [`super::parts_route`]), and the route that may
/// fail together with it. See [`fuse_routes_with`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoundTrip {
    /// The route measured (an index into the `routes` of [`fuse_routes_with`]).
    pub route: usize,
    /// The route that reads the same evidence and may share its failures (the band affinity
    /// for the parts route: both read the band features).
    pub partner: usize,
    /// The measured accuracy: the area share of the sources' labels the round trip gives back.
    pub accuracy: f64,
}

/// One shape's voting routes, its number of labels and each voting route's κ estimate.
type ShapeVotes = (Vec<usize>, usize, Vec<f64>);

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
/// lowers the estimate of a third: [`fuse_routes_with`] takes such a pair, or the routes'
/// accuracies measured on the sources.
pub fn fuse_routes(routes: &[&RouteLabels], areas: &[&[f64]]) -> FusedRoutes {
    fuse_routes_with(routes, areas, None, None, None)
}

/// [`fuse_routes`] with three kinds of evidence the agreement triangles lack; `None` for all
/// is [`fuse_routes`].
///
/// `shared`: two routes (indices into `routes`) that may fail together, as the band affinity
/// and the parts route do (both read the intrinsic band features, so both confuse a part with
/// its mirror image alike). The triangles take their joint failures for agreement, credit
/// them, and discredit the third route. Where exactly these three routes vote and no
/// held-out accuracy is given, each shape is fused by the shared-failure model instead (the
/// pair fails together on a share of the surface the patterns of agreement measure; with no
/// such share it is the one-coin vote): on FAUST from one source, the pair wrong together on
/// 14–22 % of each body, the fused accuracy goes from 74.7 % to 91.9 % (the rigid route alone
/// 92.1 %; docs/PROPAGATION.md).
///
/// `held_out`: each route's accuracy measured on the sources (per route: the area share of
/// the sources' labels the route gives each source from the other sources,
/// [`super::held_out_accuracy`]).
///
/// The agreement triangles rank the shapes (where a route holds and where it collapses) but
/// their level is biased when two routes fail together; the held-out accuracy is measured
/// against the user's own labels, so it sets the level: each route's per-shape κ is scaled so
/// that its mean over the shapes is the held-out κ (with fewer than three routes voting,
/// where no triangle exists, the held-out κ itself).
///
/// `round_trip` (used where no `held_out` is given, on the shapes where exactly three routes
/// vote, the measured route, its partner and one more): one route's accuracy measured on the
/// sources by a round trip ([`RoundTrip`]; the parts route with one source). A triangle reads
/// each route's accuracy off all three agreements, so a pair that fails together (the band
/// affinity and the parts, which read the same band features) inflates itself and deflates
/// the third route, and the shape's agreements cannot say which pair did it. With one
/// route's accuracy `κ_m` measured, the agreements that pair can bias are not needed: the
/// third route is read off its agreement with the measured one, `κ_z = κ_mz / κ_m`, and the
/// partner off its agreement with the third route, `κ_p = κ_pz / κ_z` (the partner's own
/// triangle where the third route agrees with nothing); the partner's agreement with the
/// measured route is not read. Where the shared-failure vote or a collapse reading takes a
/// shape (below), it still does.
pub fn fuse_routes_with(
    routes: &[&RouteLabels],
    areas: &[&[f64]],
    held_out: Option<&[f64]>,
    shared: Option<(usize, usize)>,
    round_trip: Option<RoundTrip>,
) -> FusedRoutes {
    let n = areas.len();
    let nr = routes.len();
    let mut out = FusedRoutes {
        labels: vec![Vec::new(); n],
        confidence: vec![Vec::new(); n],
        weights: vec![vec![0.0; nr]; n],
        agreement: vec![vec![0.0; nr]; n],
    };
    // First pass: every shape's voting routes, label count and κ estimates.
    let mut shapes: Vec<Option<ShapeVotes>> = vec![None; n];
    let mut matrices: Vec<Vec<Vec<f64>>> = vec![Vec::new(); n];
    for (i, &a) in areas.iter().enumerate() {
        let voting: Vec<usize> = (0..nr).filter(|&r| routes[r].votes_on(i)).collect();
        if voting.is_empty() {
            continue;
        }
        let mut values: Vec<i32> = voting
            .iter()
            .flat_map(|&r| routes[r].labels[i].iter().copied().filter(|&l| l >= 0))
            .collect();
        values.sort_unstable();
        values.dedup();
        let matrix = pair_kappa(routes, &voting, i, a);
        let mut kappas = route_kappas(&matrix);
        if let (None, Some(rt)) = (held_out, round_trip)
            && let Some(k) = anchored_kappas(&matrix, &voting, &kappas, values.len(), rt)
        {
            kappas = k;
        }
        shapes[i] = Some((voting, values.len(), kappas));
        matrices[i] = matrix;
    }
    if let Some(h) = held_out {
        calibrate(&mut shapes, h, nr);
    }
    let pair_in = |voting: &[usize]| {
        shared.and_then(|(x, y)| {
            Some((
                voting.iter().position(|&r| r == x)?,
                voting.iter().position(|&r| r == y)?,
            ))
        })
    };
    // One source, a pair that may fail together: the shapes where one of the pair collapsed
    // with its partner, re-weighted from the collection's levels (`pair_collapse`).
    let mut collapses: Vec<Option<Vec<f64>>> = match held_out {
        None => collapse_weights(routes, areas, &shapes, &matrices, pair_in),
        Some(_) => vec![None; n],
    };
    // One source: the shapes where a route whose own residual says its correspondence failed
    // shares the failure of the route that breaks the one-coin bound (`residual_collapse_weights`);
    // this reading comes first, the pair's is the fallback.
    if held_out.is_none() {
        let read = residual_collapse_weights(routes, areas, &shapes, &matrices, pair_in);
        for (c, r) in collapses.iter_mut().zip(read) {
            if r.is_some() {
                *c = r;
            }
        }
    }
    for (i, &a) in areas.iter().enumerate() {
        let Some((voting, labels, kappas)) = shapes[i].take() else {
            continue;
        };
        let total: f64 = a.iter().sum::<f64>().max(f64::MIN_POSITIVE);
        let m = voting.len();
        let mut trust: Vec<f64> = match kappas.is_empty() {
            true => vec![1.0; m],
            false => kappas.iter().map(|&k| log_odds(k, labels)).collect(),
        };
        let pair = pair_in(&voting);
        if let Some(w) = &collapses[i] {
            trust = w.clone();
        }
        let vote = match pair {
            Some(pair) if m == 3 && held_out.is_none() && collapses[i].is_none() => {
                let ranks: Vec<Vec<f64>> = voting
                    .iter()
                    .map(|&r| area_ranks(&routes[r].confidence[i], a))
                    .collect();
                let lab: Vec<&[i32]> = voting
                    .iter()
                    .map(|&r| routes[r].labels[i].as_slice())
                    .collect();
                shared_failure_vote(&lab, &ranks, a, labels, pair)
            }
            _ => None,
        };
        if let Some(vote) = vote {
            let (fl, fc, acc) = (vote.labels, vote.confidence, vote.accuracy);
            for (x, &r) in voting.iter().enumerate() {
                let l = labels.max(2) as f64;
                out.weights[i][r] =
                    log_odds(((acc[x] - 1.0 / l) / (1.0 - 1.0 / l)).max(0.0), labels);
                out.agreement[i][r] = agreement(&routes[r].labels[i], &fl, a, total);
            }
            out.labels[i] = fl;
            out.confidence[i] = fc;
            continue;
        }
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
                    ((best - second) / sum).clamp(0.0, 1.0)
                } else {
                    0.0
                };
            }
        }
        for (x, &r) in voting.iter().enumerate() {
            out.weights[i][r] = trust[x];
            out.agreement[i][r] = agreement(&routes[r].labels[i], &labels, a, total);
        }
        out.labels[i] = labels;
        out.confidence[i] = conf;
    }
    out
}

/// The area share (of `total`) where `x` labels a vertex and `y` gives it the same label: a
/// route's [`FusedRoutes::agreement`] with the fused labels, and the raw agreement of
/// [`cohen_kappa`].
fn agreement(x: &[i32], y: &[i32], areas: &[f64], total: f64) -> f64 {
    x.iter()
        .zip(y)
        .zip(areas)
        .filter(|((p, q), _)| **p >= 0 && p == q)
        .map(|(_, w)| w)
        .sum::<f64>()
        / total
}

/// The chance-corrected agreement (Cohen's κ, area-weighted) of every pair of the `voting`
/// routes on shape `i`, as an `m × m` matrix (diagonal 1).
fn pair_kappa(routes: &[&RouteLabels], voting: &[usize], i: usize, areas: &[f64]) -> Vec<Vec<f64>> {
    let m = voting.len();
    let mut k = vec![vec![1.0; m]; m];
    for x in 0..m {
        for y in x + 1..m {
            let kappa = cohen_kappa(
                &routes[voting[x]].labels[i],
                &routes[voting[y]].labels[i],
                areas,
            );
            k[x][y] = kappa;
            k[y][x] = kappa;
        }
    }
    k
}

/// Cohen's κ of two labellings of one shape, over its area: `(a − e) / (1 − e)`, `a` the area
/// share where both give the same label (`< 0` is no label and agrees with nothing), `e` the
/// share expected from their label shares alone; 0 where `e = 1`.
pub(crate) fn cohen_kappa(x: &[i32], y: &[i32], areas: &[f64]) -> f64 {
    let total: f64 = areas.iter().sum::<f64>().max(f64::MIN_POSITIVE);
    let shares = |l: &[i32]| {
        let mut s = BTreeMap::new();
        for (&l, &w) in l.iter().zip(areas) {
            if l >= 0 {
                *s.entry(l).or_insert(0.0) += w / total;
            }
        }
        s
    };
    let (sx, sy) = (shares(x), shares(y));
    let agree = agreement(x, y, areas, total);
    let chance: f64 = sx
        .iter()
        .map(|(l, s)| s * sy.get(l).copied().unwrap_or(0.0))
        .sum();
    // `agree` and `chance` are sums of up to `d` area shares: rounding leaves each uncertain
    // by up to `d ε` (ε the machine epsilon; the bound of a plain sum, doubled for the
    // products of `chance`). Within that they are equal and κ is exactly 0 — as it is, in exact
    // arithmetic, against a labelling with one label everywhere. Otherwise the sign of a
    // κ that is 0 was rounding, and the tests that compare κ (the rigid route's outlier test,
    // the triangle estimate that divides by it) followed it (docs/ALIGN.md, "Invariance").
    let resolution = KAPPA_ROUNDING * x.len().max(1) as f64 * f64::EPSILON;
    if chance < 1.0 && (agree - chance).abs() > resolution {
        (agree - chance) / (1.0 - chance)
    } else {
        0.0
    }
}

/// Multiple of `d ε` that bounds the rounding of κ's numerator over `d` vertices: one plain
/// sum for the agreement (`d ε`), two for the label shares whose products make the chance
/// agreement (`2 d ε`), and one more for their differences. A numerical bound, not a level
/// fitted to data.
const KAPPA_ROUNDING: f64 = 4.0;

/// Each voting route's accuracy above chance `κ_r` from the pairwise κ (see
/// [`fuse_routes`]), clamped to `[0, MAX_KAPPA]`; empty for fewer than three routes (no
/// triangle separates two routes' accuracies).
fn route_kappas(kappa: &[Vec<f64>]) -> Vec<f64> {
    let m = kappa.len();
    if m < 3 {
        return Vec::new();
    }
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
            k.clamp(0.0, MAX_KAPPA)
        })
        .collect()
}

/// Each voting route's accuracy above chance on a shape of three voting routes with the
/// pairwise κ `kappa` (voting positions), read from the round trip's measured route
/// ([`RoundTrip`]; see [`fuse_routes_with`]): the measured route at its measured κ, the third
/// route off its agreement with it, the partner off its agreement with the third route
/// (its triangle value in `triangle` where the third route agrees with nothing). `None` where
/// the three are not the measured route, its partner and one more, or the measured accuracy is
/// not above chance among `labels` labels.
fn anchored_kappas(
    kappa: &[Vec<f64>],
    voting: &[usize],
    triangle: &[f64],
    labels: usize,
    rt: RoundTrip,
) -> Option<Vec<f64>> {
    if voting.len() != 3 || triangle.len() != 3 {
        return None;
    }
    let m = voting.iter().position(|&r| r == rt.route)?;
    let p = voting.iter().position(|&r| r == rt.partner)?;
    if m == p {
        return None;
    }
    let z = 3 - m - p;
    let l = labels.max(2) as f64;
    let km = ((rt.accuracy - 1.0 / l) / (1.0 - 1.0 / l)).min(MAX_KAPPA);
    // Read as a ceiling, not a level: targets lacking a part the source has make the round
    // trip overstate the route (COSEG chairs: the parts give their sources back 83–100 %, the
    // other chairs 64–91 %), so it is used only where the shape's triangle credits the route
    // above it, where the triangle has counted shared failures as agreement.
    if !(km > 0.0 && triangle[m] > km) {
        return None;
    }
    let kz = (kappa[m][z].max(0.0) / km).min(MAX_KAPPA);
    let kp = if kz > 0.0 {
        (kappa[p][z].max(0.0) / kz).min(MAX_KAPPA)
    } else {
        triangle[p]
    };
    let mut out = vec![0.0; 3];
    out[m] = km;
    out[z] = kz;
    out[p] = kp;
    Some(out)
}

/// The log-odds vote weight `ln(p (L − 1) / (1 − p))` of a route right above chance by `κ`
/// among `labels` labels, `p = 1/L + κ (1 − 1/L)`.
fn log_odds(kappa: f64, labels: usize) -> f64 {
    let l = labels.max(2) as f64;
    let p = 1.0 / l + kappa.clamp(0.0, MAX_KAPPA) * (1.0 - 1.0 / l);
    // At chance (κ = 0) the log-odds is 0 up to rounding; a weight a hair below 0 turned its
    // votes into negative scores and the fused confidence above 1.
    (p * (l - 1.0) / (1.0 - p)).ln().max(0.0)
}

/// Sets the level of each route's per-shape κ to its held-out accuracy (`held_out[r]`, an
/// accuracy in `[0, 1]`): the shapes' κ of route `r` are scaled so that their mean is the
/// held-out κ; shapes with fewer than three voting routes take the held-out κ itself.
fn calibrate(shapes: &mut [Option<ShapeVotes>], held_out: &[f64], nr: usize) {
    // Mean of the triangle κ per route over the shapes it votes on with a triangle.
    let mut sum = vec![0.0; nr];
    let mut count = vec![0usize; nr];
    for (voting, _, kappas) in shapes.iter().flatten() {
        for (x, &r) in voting.iter().enumerate() {
            if let Some(&k) = kappas.get(x) {
                sum[r] += k;
                count[r] += 1;
            }
        }
    }
    for (voting, labels, kappas) in shapes.iter_mut().flatten() {
        let l = (*labels).max(2) as f64;
        let target: Vec<f64> = voting
            .iter()
            .map(|&r| {
                let acc = held_out.get(r).copied().unwrap_or(0.0);
                ((acc - 1.0 / l) / (1.0 - 1.0 / l)).clamp(0.0, MAX_KAPPA)
            })
            .collect();
        if kappas.is_empty() {
            *kappas = target;
            continue;
        }
        for (x, &r) in voting.iter().enumerate() {
            let mean = if count[r] > 0 {
                sum[r] / count[r] as f64
            } else {
                0.0
            };
            kappas[x] = if mean > 0.0 {
                (kappas[x] * target[x] / mean).clamp(0.0, MAX_KAPPA)
            } else {
                target[x]
            };
        }
    }
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

/// The accuracies [`shared_failure_vote`] keeps a route within: a route credited as always
/// right (or always wrong) would decide every vertex alone.
const P_RANGE: (f64, f64) = (0.01, 0.995);

/// What [`shared_failure_vote`] gives on one shape.
struct SharedFailureVote {
    /// Per vertex: the fused label (`-1` where no route votes).
    labels: Vec<i32>,
    /// Per vertex: the posterior margin of the label, `(best − second) / total`.
    confidence: Vec<f64>,
    /// Per route: its accuracy over the surface (a pair route is wrong on the shared share).
    accuracy: Vec<f64>,
}

/// The fused labels of one shape from three routes of which two (`pair`, indices into
/// `labels`) may fail together: on a share `γ` of the surface both give the same wrong label
/// (two routes reading the same intrinsic features confuse a part with its mirror image
/// alike) while the third votes as usual; elsewhere every route is right with its own
/// accuracy `p_r` and otherwise wrong at random (the one-coin model of Dawid and Skene).
///
/// The parameters come from the area shares of the agreement patterns (method of moments, as
/// the κ triangles are for the one-coin model): outside the shared failures the routes are
/// independent, so "the second pair route and the third agree, the first differs" against
/// "all three agree" is `(1 − p_x) / p_x` (likewise for the second), the excess of "the pair
/// agrees, the third differs" over what independence gives is `γ`, and "all agree" is
/// `(1 − γ) p_x p_y p_z`. Each vertex then takes the label of highest posterior, each route's
/// likelihood tempered by `(1 + rank) / 2` of its confidence rank (`ranks`), as the weighted
/// vote does. With `γ = 0` this is the one-coin vote, so a pair that does not fail together
/// changes nothing; where it does, the pair's agreement no longer outvotes a third route that
/// is right. Chance agreements of two wrong routes are left out of the moments (small with
/// more than three labels; with two or three they count a little towards `γ`).
///
/// Inputs: `labels` and `ranks` (per voting route, per vertex; label `< 0` = no vote),
/// `areas`, `classes` (the number of labels). `None` (the caller keeps the one-coin vote)
/// without three routes, without a vertex where all three agree, or when the fit puts a route
/// below chance.
fn shared_failure_vote(
    labels: &[&[i32]],
    ranks: &[Vec<f64>],
    areas: &[f64],
    classes: usize,
    pair: (usize, usize),
) -> Option<SharedFailureVote> {
    let fit = shared_failure_fit(labels, areas, classes, pair)?;
    let (p, gamma, accuracy) = (fit.p, fit.gamma, fit.accuracy);
    let m = labels.len();
    let d = areas.len();
    let l = classes.max(2) as f64;
    let c = 1.0 / (l - 1.0);
    let mut out = vec![-1i32; d];
    let mut conf = vec![0.0; d];
    let mut candidates: Vec<i32> = Vec::with_capacity(m);
    for v in 0..d {
        candidates.clear();
        candidates.extend((0..m).map(|x| labels[x][v]).filter(|&x| x >= 0));
        candidates.sort_unstable();
        candidates.dedup();
        let (a, b) = (labels[pair.0][v], labels[pair.1][v]);
        let (mut best, mut second, mut total) = (None::<(i32, f64)>, 0.0, 0.0);
        // Ascending labels and a strict comparison: ties go to the smallest label.
        for &truth in &candidates {
            let mut indep = 1.0;
            let mut shared = if a >= 0 && a == b && a != truth {
                c
            } else {
                0.0
            };
            for x in 0..m {
                let lab = labels[x][v];
                if lab < 0 {
                    continue;
                }
                let f = if lab == truth { p[x] } else { (1.0 - p[x]) * c };
                let f = f.powf((1.0 + ranks[x][v]) / 2.0);
                indep *= f;
                if x != pair.0 && x != pair.1 {
                    shared *= f;
                }
            }
            let post = (1.0 - gamma) * indep + gamma * shared;
            total += post;
            match best {
                Some((_, q)) if q >= post => second = f64::max(second, post),
                _ => {
                    if let Some((_, q)) = best {
                        second = f64::max(second, q);
                    }
                    best = Some((truth, post));
                }
            }
        }
        if let Some((k, q)) = best {
            out[v] = k;
            conf[v] = if total > 0.0 {
                ((q - second) / total).clamp(0.0, 1.0)
            } else {
                0.0
            };
        }
    }
    Some(SharedFailureVote {
        labels: out,
        confidence: conf,
        accuracy,
    })
}

/// The parameters [`shared_failure_vote`] reads off one shape's agreement patterns.
struct SharedFailureFit {
    /// Per route: its accuracy outside the shared failures.
    p: [f64; 3],
    /// The share of the surface on which the pair gives the same wrong label.
    gamma: f64,
    /// Per route: its accuracy over the surface (a pair route is wrong on the shared share).
    accuracy: Vec<f64>,
}

/// The shared-failure model of [`shared_failure_vote`] fitted to one shape by the method of
/// moments; `None` without three routes, without a vertex where all three agree, or when
/// the fit puts a route below chance.
fn shared_failure_fit(
    labels: &[&[i32]],
    areas: &[f64],
    classes: usize,
    pair: (usize, usize),
) -> Option<SharedFailureFit> {
    let m = labels.len();
    let d = areas.len();
    if m != 3 {
        return None;
    }
    let l = classes.max(2) as f64;
    let c = 1.0 / (l - 1.0);
    let z = 3 - pair.0 - pair.1;
    // Area shares of: all agree, the pair agrees alone, x with z alone, y with z alone.
    let mut f = [0.0; 4];
    let mut tot = 0.0;
    for v in 0..d {
        let (a, b, t) = (labels[pair.0][v], labels[pair.1][v], labels[z][v]);
        if a < 0 || b < 0 || t < 0 {
            continue;
        }
        tot += areas[v];
        let k = match (a == b, a == t, b == t) {
            (true, true, _) => 0,
            (true, false, _) => 1,
            (false, true, _) => 2,
            (false, false, true) => 3,
            _ => continue,
        };
        f[k] += areas[v];
    }
    if !(tot > 0.0 && f[0] > 0.0) {
        return None;
    }
    let f: Vec<f64> = f.iter().map(|x| x / tot).collect();
    let px = (f[0] / (f[0] + f[3])).clamp(P_RANGE.0, P_RANGE.1);
    let py = (f[0] / (f[0] + f[2])).clamp(P_RANGE.0, P_RANGE.1);
    let both = px * py;
    // Independent routes agree where both are right, and by chance where both are wrong:
    // with few labels two wrong routes often agree without a shared cause.
    let agree = both + (1.0 - px) * (1.0 - py) * c;
    let gamma = if agree < 1.0 {
        ((f[1] + f[0] - agree) / (1.0 - agree)).clamp(0.0, 1.0 - P_RANGE.0)
    } else {
        0.0
    };
    let mut p = [0.0; 3];
    p[pair.0] = px;
    p[pair.1] = py;
    p[z] = (f[0] / ((1.0 - gamma) * both)).clamp(P_RANGE.0, P_RANGE.1);
    let accuracy: Vec<f64> = (0..m)
        .map(|x| {
            if x == pair.0 || x == pair.1 {
                p[x] * (1.0 - gamma)
            } else {
                p[x]
            }
        })
        .collect();
    // Every route carries labels from the sources, so none is worse than chance. A fit that
    // says otherwise has read a third route that collapsed (agreeing with neither, a rigid
    // alignment upside down) as a pair failing together: the patterns cannot tell those
    // apart, and the one-coin vote, which silences the collapsed route, is kept.
    if accuracy.iter().any(|&a| a < 1.0 / l) {
        return None;
    }
    Some(SharedFailureFit { p, gamma, accuracy })
}

/// Which member of the shared `pair` (voting positions) collapsed with its partner on a shape
/// with the pairwise κ `kappa` and the independent route `third`: `(collapsed, kept, third)`,
/// or `None`.
///
/// Under the one-coin model a route cannot agree with both others more than they agree with
/// each other allows (`κ_xy κ_xz ≤ κ_yz`: its accuracy read off the triangle would exceed 1).
/// Where a pair member `x` does, while its partner `y` agrees with the independent route less
/// than `x` does, the pair's agreement is not two opinions: `y` has failed *with* `x` (an
/// intrinsic co-segmentation that swapped arms and legs on a generated humanoid, agreeing
/// with the band affinity on 30–36 % of the body and with the rigid route at chance), and
/// what it shares with `x` is their common error. The test needs no threshold: the bound is
/// the model's own.
fn pair_collapse(
    kappa: &[Vec<f64>],
    pair: (usize, usize),
    third: usize,
) -> Option<(usize, usize, usize)> {
    let z = third;
    [(pair.0, pair.1), (pair.1, pair.0)]
        .into_iter()
        .find(|&(x, y)| {
            kappa[x][y] > 0.0
                && kappa[x][z] > 0.0
                && kappa[x][y] * kappa[x][z] > kappa[y][z].max(0.0)
                && kappa[y][z] < kappa[x][z]
        })
        .map(|(x, y)| (y, x, z))
}

/// Per shape, the vote weights (voting positions) where a member of the shared pair collapsed
/// with its partner ([`pair_collapse`]); `None` on the other shapes, which keep the
/// shared-failure vote.
///
/// The collapsed member gets no vote. The other two, its partner `x` and the independent
/// route `z`, are two routes whose accuracies one shape cannot separate (their agreement
/// `κ_xz = κ_x κ_z` gives only the product); the evidence that separates them comes from
/// outside the shape: each route's level over the collection, the median of its accuracy
/// above chance under the shared-failure fit on the shapes where no member collapsed (`ℓ`).
/// The product comes from this shape and the ratio from the collection: `κ_x = √(κ_xz ℓ_x /
/// ℓ_z)`, `κ_z = √(κ_xz ℓ_z / ℓ_x)`, each weighted by its log-odds. Where `κ_xz` is nearer 0
/// than `ℓ_x ℓ_z`, both pair members failing together and the independent route collapsing
/// look alike on the shape (its agreement with both near chance): the independent route is
/// then believed only if the collection finds it the most accurate (`ℓ_z` above both pair
/// members' levels), else the shape keeps the shared-failure vote. Without a shape to read
/// the levels on, nothing changes.
fn collapse_weights(
    routes: &[&RouteLabels],
    areas: &[&[f64]],
    shapes: &[Option<ShapeVotes>],
    matrices: &[Vec<Vec<f64>>],
    pair_in: impl Fn(&[usize]) -> Option<(usize, usize)>,
) -> Vec<Option<Vec<f64>>> {
    let n = shapes.len();
    let mut out = vec![None; n];
    let mut collapsed = vec![None; n];
    let mut levels: BTreeMap<usize, Vec<f64>> = BTreeMap::new();
    for (i, s) in shapes.iter().enumerate() {
        let Some((voting, classes, _)) = s else {
            continue;
        };
        let Some(pair) = pair_in(voting).filter(|_| voting.len() == 3) else {
            continue;
        };
        let third = 3 - pair.0 - pair.1;
        if let Some(c) = pair_collapse(&matrices[i], pair, third) {
            collapsed[i] = Some(c);
            continue;
        }
        let lab: Vec<&[i32]> = voting
            .iter()
            .map(|&r| routes[r].labels[i].as_slice())
            .collect();
        if let Some(fit) = shared_failure_fit(&lab, areas[i], *classes, pair) {
            let l = (*classes).max(2) as f64;
            for (x, &r) in voting.iter().enumerate() {
                let k = ((fit.accuracy[x] - 1.0 / l) / (1.0 - 1.0 / l)).clamp(0.0, MAX_KAPPA);
                levels.entry(r).or_default().push(k);
            }
        }
    }
    let level = route_levels(levels);
    for (i, c) in collapsed.into_iter().enumerate() {
        let (Some((y, x, z)), Some((voting, classes, _))) = (c, &shapes[i]) else {
            continue;
        };
        let (Some(&lx), Some(&lz)) = (level.get(&voting[x]), level.get(&voting[z])) else {
            continue;
        };
        let kxz = matrices[i][x][z];
        // "y failed with x" is read directly where x and z agree as two sound routes do: their
        // κ nearer the product of their levels (both sound) than chance (one of them failed
        // too). Nearer chance, the shape cannot tell the rigid route collapsing from both pair
        // members failing together (on generated humanoids both intrinsic routes swapped the
        // limbs, 1–8 % above chance, while the rigid route was right on 88–95 %; on fresh
        // goblets and chairs rigid alignments right on 5–45 % of a shape agreed with parts
        // right on 82–93 % as little); there the collection decides: the independent route is
        // believed only if its level is above both pair members' levels, else the shape keeps
        // the shared-failure vote.
        let ly = level.get(&voting[y]).copied().unwrap_or(0.0);
        let sound = kxz > lx * lz / 2.0;
        if !(lx > 0.0 && lz > 0.0 && (sound || (lz > lx && lz > ly))) {
            continue;
        }
        let mut w = vec![0.0; voting.len()];
        w[x] = log_odds((kxz * lx / lz).sqrt(), *classes);
        w[z] = log_odds((kxz * lz / lx).sqrt(), *classes);
        out[i] = Some(w);
    }
    out
}

/// The voting position that breaks the one-coin model's bound on a shape with the pairwise κ
/// `kappa` (three routes): the route `x` that agrees with both others more than they agree
/// with each other allows, `κ_xy κ_xz > κ_yz` (its accuracy read off the triangle would
/// exceed 1); `None` where the three are consistent with independent failures. At most one
/// route can break it while every κ is at most 1.
fn bound_breaker(kappa: &[Vec<f64>]) -> Option<usize> {
    if kappa.len() != 3 {
        return None;
    }
    (0..3).find(|&x| {
        let (y, z) = ((x + 1) % 3, (x + 2) % 3);
        kappa[x][y] > 0.0 && kappa[x][z] > 0.0 && kappa[x][y] * kappa[x][z] > kappa[y][z].max(0.0)
    })
}

/// Per shape, the vote weights (voting positions) where a route's own residual says that it
/// is the one that failed with the route breaking the one-coin bound; `None` elsewhere.
///
/// Where a route `x` breaks the bound ([`bound_breaker`]), the other two disagree with each
/// other more than independent failures allow: one of them, `z`, failed *with* `x` (their
/// joint errors read as agreement), and the agreement statistics of the shape cannot say
/// which (the patterns are symmetric in `y` and `z`). That was read as the affinity being
/// right on generated chairs from one source (the affinity 37.7 %, the parts 89.3 %, a rigid
/// alignment right on 19.4 % agreeing with the affinity on a wrong label over a third of the
/// chair: fused 37.7 %). Evidence from outside the agreements separates them where a route
/// measures its own correspondence: the rigid route's registration residual. A residual above
/// every residual the route has on the shapes where the three routes are consistent (no route
/// breaks the bound) says its correspondence failed there: `z` is that route, it gets no
/// vote, and `x` and `y` share the product `κ_xy = κ_x κ_y` by the ratio of their levels over
/// the collection (`ℓ`, the median of their κ on the consistent shapes — the triangles, or
/// the shared-failure fit where the fusion models a pair), `κ_x = √(κ_xy ℓ_x / ℓ_y)`, each
/// weighted by its log-odds. No threshold: the residual is compared with the collection's
/// own; without a consistent shape to compare with, or where no route or both report a
/// residual above it, nothing changes.
fn residual_collapse_weights(
    routes: &[&RouteLabels],
    areas: &[&[f64]],
    shapes: &[Option<ShapeVotes>],
    matrices: &[Vec<Vec<f64>>],
    pair_in: impl Fn(&[usize]) -> Option<(usize, usize)>,
) -> Vec<Option<Vec<f64>>> {
    let n = shapes.len();
    let mut out = vec![None; n];
    let residual =
        |r: usize, i: usize| routes[r].residual.get(i).copied().filter(|x| x.is_finite());
    // The largest residual of each route, and each route's κ, on the consistent shapes.
    let mut reference: BTreeMap<usize, f64> = BTreeMap::new();
    let mut levels: BTreeMap<usize, Vec<f64>> = BTreeMap::new();
    let mut breaking = vec![None; n];
    for (i, s) in shapes.iter().enumerate() {
        let Some((voting, classes, kappas)) = s else {
            continue;
        };
        if voting.len() != 3 {
            continue;
        }
        if let Some(x) = bound_breaker(&matrices[i]) {
            breaking[i] = Some(x);
            continue;
        }
        for &r in voting {
            if let Some(res) = residual(r, i) {
                let e = reference.entry(r).or_insert(res);
                *e = e.max(res);
            }
        }
        let kappa: Vec<f64> = match pair_in(voting) {
            Some(pair) => {
                let lab: Vec<&[i32]> = voting
                    .iter()
                    .map(|&r| routes[r].labels[i].as_slice())
                    .collect();
                let Some(fit) = shared_failure_fit(&lab, areas[i], *classes, pair) else {
                    continue;
                };
                let l = (*classes).max(2) as f64;
                fit.accuracy
                    .iter()
                    .map(|&a| ((a - 1.0 / l) / (1.0 - 1.0 / l)).clamp(0.0, MAX_KAPPA))
                    .collect()
            }
            None => kappas.clone(),
        };
        for (x, &r) in voting.iter().enumerate() {
            if let Some(&k) = kappa.get(x) {
                levels.entry(r).or_default().push(k);
            }
        }
    }
    let level = route_levels(levels);
    for (i, b) in breaking.into_iter().enumerate() {
        let (Some(x), Some((voting, classes, _))) = (b, &shapes[i]) else {
            continue;
        };
        let failed: Vec<usize> = (0..3)
            .filter(|&z| z != x)
            .filter(|&z| {
                let r = voting[z];
                residual(r, i)
                    .zip(reference.get(&r))
                    .is_some_and(|(res, &m)| res > m)
            })
            .collect();
        let [z] = failed[..] else {
            continue;
        };
        let y = 3 - x - z;
        let (Some(&lx), Some(&ly)) = (level.get(&voting[x]), level.get(&voting[y])) else {
            continue;
        };
        if !(lx > 0.0 && ly > 0.0) {
            continue;
        }
        let kxy = matrices[i][x][y].max(0.0);
        let mut w = vec![0.0; 3];
        w[x] = log_odds((kxy * lx / ly).sqrt(), *classes);
        w[y] = log_odds((kxy * ly / lx).sqrt(), *classes);
        out[i] = Some(w);
    }
    out
}

/// Each route's level over the collection: the median of the accuracies above chance it was
/// read at on the shapes that give one (routes with none are left out).
fn route_levels(levels: BTreeMap<usize, Vec<f64>>) -> BTreeMap<usize, f64> {
    levels
        .into_iter()
        .filter(|(_, v)| !v.is_empty())
        .map(|(r, v)| (r, crate::parts::median(&v)))
        .collect()
}
