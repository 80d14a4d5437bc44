//! [`classifier_route`]: the labelled shapes as training data — a per-vertex classifier on the
//! band features that settles the vertices where the routes disagree.

use super::{FusedRoutes, RouteLabels};
use crate::graph::ShapeGraph;
use crate::spectral::HeatSmoother;
use rayon::prelude::*;
use serde::Serialize;

/// What [`classifier_route`] did on one unlabelled shape (`summary.json`: `classifier`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ClassifierShape {
    /// Area share of the shape on which the voting routes do not all give the fused label
    /// (the vertices the classifier may settle).
    pub disputed: f64,
    /// Area share whose label the classifier changed.
    pub changed: f64,
}

/// The result of [`classifier_route`].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ClassifierReport {
    /// The classifier's accuracy on the sources' labelled vertices (area-weighted) when trained
    /// on the unlabelled shapes' undisputed vertices alone; `None` where it did not run.
    pub held_out: Option<f64>,
    /// The classifier's weight in the vote on disputed vertices: the log-odds of `held_out`
    /// (0: it changed nothing).
    pub weight: f64,
    /// Per shape (graph order): what it did; `None` for the sources and where it did not run.
    pub shapes: Vec<Option<ClassifierShape>>,
    /// Per shape: the fused labels before the classifier (empty for sources; the fused labels
    /// themselves where it did not run).
    pub before: Vec<Vec<i32>>,
}

/// Training vertices taken per shape at most (every `k`-th of the eligible ones, so no random
/// draw): the classifier's parameters number `features × bands × labels` (a few thousand), so
/// a thousand vertices per shape over a collection are far more samples than parameters, and
/// training stays well under a second on a 22-shape collection.
const PER_SHAPE: usize = 1000;

/// Gradient steps of the logistic fit (Nesterov-accelerated, step `1/Lipschitz`): the loss is
/// smooth and convex, and the accuracy on held-out vertices no longer changes after about a
/// hundred steps on the synthetic tests; fixed so that the result is the same bytes on every
/// machine.
const STEPS: usize = 150;

/// The ridge on the weights: a weak prior (a hundredth of one sample's loss per unit weight)
/// so that a band no training vertex has keeps weight 0 and the optimum is finite when the
/// classes separate.
const RIDGE: f64 = 1e-3;

/// Self-training rounds: the first fit reads the sources and the undisputed vertices; each
/// further round also reads the disputed vertices the classifier and the vote then agree on.
/// Two rounds: a third changed no label on the synthetic tests.
const ROUNDS: usize = 2;

/// Settles the vertices where the routes disagree with a classifier trained on the labelled
/// shapes (transductive: the sources' own labels and, on every unlabelled shape, the vertices
/// where all the voting routes give the fused label).
///
/// Features: each vertex's band labels (the band table every route already reads: per feature,
/// the vertex's equal-count band on its own shape, so comparable across shapes), one-hot — an
/// additive per-feature, per-band log-odds model. Model: multinomial logistic regression with
/// a weak ridge, fitted deterministically (fixed steps, training vertices taken by stride).
/// Trust, from the data: the classifier is first fitted on the unlabelled shapes' undisputed
/// vertices alone and scored on the sources' labelled vertices, which it never saw; that
/// accuracy `p` gives it the one-coin weight `ln(p (L − 1) / (1 − p))` of [`super::fuse_routes`]
/// (`L` labels). It is then refitted with the sources, its per-label probabilities are
/// heat-smoothed on each mesh (`smoothers`, the propagation's), and on each disputed vertex the
/// label with the highest `Σ_r w_r [L_r(v) = l] + w_c P_c(l | v)` among the fused label and the
/// classifier's is taken (`w_r` the routes' weights of the fusion on the shape). A few rounds:
/// the disputed vertices where classifier and vote agree join the training set.
///
/// Inputs: `graph` (band tables and areas), `annotations` (per shape, `None` for unlabelled;
/// `< 0` = unlabelled vertex), `routes` (the fusion's routes, in the order of
/// `fused.weights`), `fused` (refined in place on the unlabelled shapes), `smoothers` (one per
/// shape, or `None`: the probabilities are not smoothed). Output: [`ClassifierReport`]. With
/// fewer than two labels on the sources, no unlabelled shape with two voting routes, or a
/// held-out accuracy no better than chance, nothing changes.
///
/// See also: [`super::fuse_routes`], [`super::fuse_propagation`] (calls it).
///
/// Known issue: the undisputed vertices are easier than the disputed ones (away from the
/// parts' boundaries), so the held-out accuracy on whole source shapes overstates the
/// classifier a little where it matters.
pub fn classifier_route(
    graph: &ShapeGraph,
    annotations: &[Option<Vec<i32>>],
    routes: &[&RouteLabels],
    fused: &mut FusedRoutes,
    smoothers: Option<&[HeatSmoother]>,
) -> ClassifierReport {
    let n = graph.node_count();
    let mut report = ClassifierReport {
        held_out: None,
        weight: 0.0,
        shapes: vec![None; n],
        before: fused.labels.clone(),
    };
    let mut classes: Vec<i32> = annotations
        .iter()
        .flatten()
        .flat_map(|a| a.iter().copied().filter(|&l| l >= 0))
        .collect();
    classes.sort_unstable();
    classes.dedup();
    let l = classes.len();
    if l < 2 || n == 0 || fused.labels.len() != n {
        return report;
    }
    let class_of = |label: i32| classes.binary_search(&label).ok();
    let bands = &graph.node(0).bands;
    let (nf, nb) = (bands.features, bands.bands.max(1));
    if (0..n).any(|i| graph.node(i).bands.features != nf || graph.node(i).bands.bands > nb) {
        return report;
    }
    // Per target: the voting routes and the undisputed vertices.
    let targets: Vec<usize> = (0..n)
        .filter(|&i| annotations[i].is_none() && !fused.labels[i].is_empty())
        .filter(|&i| routes.iter().filter(|r| r.votes_on(i)).count() >= 2)
        .collect();
    if targets.is_empty() {
        return report;
    }
    let undisputed: Vec<Vec<bool>> = (0..n)
        .map(|i| {
            if !targets.contains(&i) {
                return Vec::new();
            }
            let f = &fused.labels[i];
            (0..f.len())
                .map(|v| {
                    f[v] >= 0
                        && routes
                            .iter()
                            .filter(|r| r.votes_on(i))
                            .all(|r| r.labels[i][v] == f[v])
                })
                .collect()
        })
        .collect();
    let mut target_samples = Vec::new();
    for &i in &targets {
        let eligible: Vec<usize> = (0..undisputed[i].len())
            .filter(|&v| undisputed[i][v])
            .collect();
        for v in stride(&eligible) {
            if let Some(c) = class_of(fused.labels[i][v]) {
                target_samples.push(Sample {
                    shape: i,
                    vertex: v,
                    class: c,
                });
            }
        }
    }
    let mut source_samples = Vec::new();
    for (i, a) in annotations.iter().enumerate() {
        let Some(a) = a else { continue };
        let eligible: Vec<usize> = (0..a.len()).filter(|&v| a[v] >= 0).collect();
        for v in stride(&eligible) {
            if let Some(c) = class_of(a[v]) {
                source_samples.push(Sample {
                    shape: i,
                    vertex: v,
                    class: c,
                });
            }
        }
    }
    if target_samples.is_empty() {
        return report;
    }
    let model = Model::fit(graph, &target_samples, nf, nb, l);
    // Held out: the sources' labelled vertices, all of them, area-weighted.
    let (mut right, mut total) = (0.0, 0.0);
    for (i, a) in annotations.iter().enumerate() {
        let Some(a) = a else { continue };
        let areas = &graph.node(i).areas;
        for (v, &label) in a.iter().enumerate() {
            let Some(c) = class_of(label) else { continue };
            total += areas[v];
            if model.predict(graph, i, v) == c {
                right += areas[v];
            }
        }
    }
    if total <= 0.0 {
        return report;
    }
    let p = (right / total).clamp(1e-6, 1.0 - 1e-6);
    report.held_out = Some(p);
    let weight = (p * (l - 1) as f64 / (1.0 - p)).ln();
    if weight <= 0.0 {
        return report;
    }
    report.weight = weight;
    let before = fused.labels.clone();
    let mut training: Vec<Sample> = source_samples
        .iter()
        .chain(&target_samples)
        .copied()
        .collect();
    let mut refined = before.clone();
    for round in 0..ROUNDS {
        let model = Model::fit(graph, &training, nf, nb, l);
        let probs: Vec<(usize, Vec<f64>)> = targets
            .par_iter()
            .map(|&i| (i, model.smoothed(graph, i, smoothers.map(|s| &s[i]))))
            .collect();
        let mut agreed: Vec<Vec<usize>> = vec![Vec::new(); n];
        let mut agreed_class = vec![Vec::new(); n];
        for (i, prob) in &probs {
            let i = *i;
            let d = before[i].len();
            let w = &fused.weights[i];
            for v in 0..d {
                if undisputed[i][v] {
                    continue;
                }
                let mut score = vec![0.0; l];
                for (r, route) in routes.iter().enumerate() {
                    if !route.votes_on(i) {
                        continue;
                    }
                    if let Some(c) = class_of(route.labels[i][v]) {
                        score[c] += w[r].max(0.0);
                    }
                }
                let mut best_c = 0;
                for c in 0..l {
                    score[c] += weight * prob[c * d + v];
                    if prob[c * d + v] > prob[best_c * d + v] {
                        best_c = c;
                    }
                }
                let fused_c = class_of(before[i][v]);
                let take = match fused_c {
                    Some(f) => score[best_c] > score[f],
                    None => true,
                };
                refined[i][v] = if take { classes[best_c] } else { before[i][v] };
                if round + 1 < ROUNDS && class_of(refined[i][v]) == Some(best_c) {
                    agreed[i].push(v);
                    agreed_class[i].push(best_c);
                }
            }
        }
        if round + 1 < ROUNDS {
            for &i in &targets {
                let k = agreed[i].len().div_ceil(PER_SHAPE).max(1);
                training.extend(agreed[i].iter().zip(&agreed_class[i]).step_by(k).map(
                    |(&vertex, &class)| Sample {
                        shape: i,
                        vertex,
                        class,
                    },
                ));
            }
        }
    }
    for &i in &targets {
        let areas = &graph.node(i).areas;
        let tot: f64 = areas.iter().sum::<f64>().max(f64::MIN_POSITIVE);
        let share = |f: &dyn Fn(usize) -> bool| {
            // A fold from +0: an empty `sum` of floats is −0, which summary.json would print.
            (0..areas.len())
                .filter(|&v| f(v))
                .fold(0.0, |acc, v| acc + areas[v])
                / tot
        };
        report.shapes[i] = Some(ClassifierShape {
            disputed: share(&|v| !undisputed[i][v]),
            changed: share(&|v| refined[i][v] != before[i][v]),
        });
        fused.labels[i] = std::mem::take(&mut refined[i]);
    }
    report
}

/// At most [`PER_SHAPE`] of `eligible`, every `k`-th.
fn stride(eligible: &[usize]) -> Vec<usize> {
    let k = eligible.len().div_ceil(PER_SHAPE).max(1);
    eligible.iter().copied().step_by(k).collect()
}

/// One training vertex.
#[derive(Debug, Clone, Copy)]
struct Sample {
    shape: usize,
    vertex: usize,
    class: usize,
}

/// Multinomial logistic regression on one-hot band labels: `features × bands` indicator
/// columns (one active per feature) and a bias, `classes` outputs.
struct Model {
    features: usize,
    bands: usize,
    classes: usize,
    /// `(features · bands + 1) × classes`, row-major; the last row is the bias.
    w: Vec<f64>,
}

impl Model {
    fn fit(
        graph: &ShapeGraph,
        samples: &[Sample],
        features: usize,
        bands: usize,
        classes: usize,
    ) -> Model {
        let rows = features * bands + 1;
        let mut m = Model {
            features,
            bands,
            classes,
            w: vec![0.0; rows * classes],
        };
        if samples.is_empty() {
            return m;
        }
        // Each sample has `features + 1` active columns of value 1: the Hessian of the mean
        // softmax loss is at most `½ (features + 1)` in norm.
        let step = 1.0 / (0.5 * (features + 1) as f64 + RIDGE);
        let ns = samples.len() as f64;
        let mut prev = m.w.clone();
        let mut y = m.w.clone();
        // Fixed chunks summed in order: the same bytes whatever the thread count.
        const CHUNK: usize = 2048;
        for t in 0..STEPS {
            let probe = Model {
                features,
                bands,
                classes,
                w: y.clone(),
            };
            let parts: Vec<Vec<f64>> = samples
                .par_chunks(CHUNK)
                .map(|chunk| {
                    let mut g = vec![0.0; rows * classes];
                    let mut p = vec![0.0; classes];
                    for s in chunk {
                        let row = graph.node(s.shape).bands.row(s.vertex);
                        probe.probabilities(row, &mut p);
                        p[s.class] -= 1.0;
                        for (k, &b) in row.iter().enumerate() {
                            let base = (k * bands + b as usize) * classes;
                            for c in 0..classes {
                                g[base + c] += p[c];
                            }
                        }
                        let base = (rows - 1) * classes;
                        for c in 0..classes {
                            g[base + c] += p[c];
                        }
                    }
                    g
                })
                .collect();
            let mut grad = vec![0.0; rows * classes];
            for g in parts {
                for (a, b) in grad.iter_mut().zip(g) {
                    *a += b;
                }
            }
            let next: Vec<f64> = y
                .iter()
                .zip(&grad)
                .map(|(&yj, &gj)| yj - step * (gj / ns + RIDGE * yj))
                .collect();
            let momentum = t as f64 / (t as f64 + 3.0);
            y = next
                .iter()
                .zip(&prev)
                .map(|(&a, &b)| a + momentum * (a - b))
                .collect();
            prev = next;
        }
        m.w = prev;
        m
    }

    /// The class probabilities of one vertex's band `row`, into `p`.
    fn probabilities(&self, row: &[u8], p: &mut [f64]) {
        let c = self.classes;
        p.copy_from_slice(&self.w[self.features * self.bands * c..]);
        for (k, &b) in row.iter().enumerate() {
            let base = (k * self.bands + b as usize) * c;
            for (pc, w) in p.iter_mut().zip(&self.w[base..base + c]) {
                *pc += w;
            }
        }
        let max = p.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let mut sum = 0.0;
        for x in p.iter_mut() {
            *x = (*x - max).exp();
            sum += *x;
        }
        for x in p.iter_mut() {
            *x /= sum;
        }
    }

    fn predict(&self, graph: &ShapeGraph, shape: usize, vertex: usize) -> usize {
        let mut p = vec![0.0; self.classes];
        self.probabilities(graph.node(shape).bands.row(vertex), &mut p);
        argmax(&p)
    }

    /// Shape `i`'s class probabilities, column-major (`classes` columns of its vertex count),
    /// heat-smoothed by `smoother` when given (and renormalised per vertex).
    fn smoothed(&self, graph: &ShapeGraph, i: usize, smoother: Option<&HeatSmoother>) -> Vec<f64> {
        let bands = &graph.node(i).bands;
        let (d, c) = (bands.vertices, self.classes);
        let mut out = vec![0.0; d * c];
        let mut p = vec![0.0; c];
        for v in 0..d {
            self.probabilities(bands.row(v), &mut p);
            for k in 0..c {
                out[k * d + v] = p[k];
            }
        }
        if let Some(s) = smoother.filter(|s| s.vertex_count() == d)
            && s.smooth(&mut out, c).is_ok()
        {
            for v in 0..d {
                let sum: f64 = (0..c).map(|k| out[k * d + v].max(0.0)).sum();
                for k in 0..c {
                    out[k * d + v] = if sum > 0.0 {
                        out[k * d + v].max(0.0) / sum
                    } else {
                        1.0 / c as f64
                    };
                }
            }
        }
        out
    }
}

/// The first index of the largest value.
fn argmax(p: &[f64]) -> usize {
    let mut best = 0;
    for (k, &x) in p.iter().enumerate() {
        if x > p[best] {
            best = k;
        }
    }
    best
}
