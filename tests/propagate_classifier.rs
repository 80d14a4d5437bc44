//! The classifier refinement of the fused labels (`coseg::propagate::classifier_route`) on
//! synthetic band tables and route votes.

use coseg::bands::BandTable;
use coseg::graph::{GraphOptions, ShapeGraph, ShapeNode};
use coseg::propagate::{FusedRoutes, RouteLabels, classifier_route, fuse_routes};
use rand::{RngExt, SeedableRng};

const SHAPES: usize = 6;
const VERTICES: usize = 400;
const FEATURES: usize = 4;
const BANDS: usize = 8;

/// Shape `i`'s band table: feature 0 is the band of the vertex's position along the shape
/// (`8 v / d`), the others seeded noise; the truth is label 0 on the first half, 1 on the
/// second (feature 0 separates them).
fn table(i: usize) -> BandTable {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(i as u64 + 100);
    let mut labels = Vec::with_capacity(VERTICES * FEATURES);
    for v in 0..VERTICES {
        labels.push((BANDS * v / VERTICES) as u8);
        for _ in 1..FEATURES {
            labels.push(rng.random_range(0..BANDS as u8));
        }
    }
    BandTable {
        features: FEATURES,
        vertices: VERTICES,
        bands: BANDS,
        labels,
    }
}

fn truth() -> Vec<i32> {
    (0..VERTICES).map(|v| (2 * v / VERTICES) as i32).collect()
}

fn graph() -> ShapeGraph {
    let nodes = (0..SHAPES)
        .map(|i| ShapeNode::new(format!("s{i}"), table(i), &vec![1.0; VERTICES]).unwrap())
        .collect();
    ShapeGraph::build(nodes, &GraphOptions::default()).unwrap()
}

/// Three routes on shapes 1.. (shape 0 the source): the first right everywhere, the other two
/// both wrong (the same wrong label) on `region` (every fifth vertex of the second half) and
/// each wrong on a different tenth elsewhere, so that the vote outvotes the right route on
/// `region` while the routes agree on most of the shape.
fn routes() -> Vec<RouteLabels> {
    let t = truth();
    (0..3)
        .map(|r| {
            let mut route = RouteLabels::empty(SHAPES);
            for i in 1..SHAPES {
                route.labels[i] = (0..VERTICES)
                    .map(|v| {
                        let region = v >= VERTICES / 2 && v % 5 == 0;
                        let own = v % 10 == r + 4 && v < VERTICES / 2;
                        if r > 0 && (region || own) {
                            1 - t[v]
                        } else {
                            t[v]
                        }
                    })
                    .collect();
                route.confidence[i] = vec![1.0; VERTICES];
            }
            route
        })
        .collect()
}

fn fused(routes: &[RouteLabels]) -> FusedRoutes {
    let refs: Vec<&RouteLabels> = routes.iter().collect();
    let areas = vec![vec![1.0 / VERTICES as f64; VERTICES]; SHAPES];
    let areas: Vec<&[f64]> = areas.iter().map(Vec::as_slice).collect();
    fuse_routes(&refs, &areas)
}

fn accuracy(a: &[i32]) -> f64 {
    a.iter().zip(truth()).filter(|(x, y)| **x == *y).count() as f64 / a.len() as f64
}

fn annotations(source: Vec<i32>) -> Vec<Option<Vec<i32>>> {
    let mut a = vec![None; SHAPES];
    a[0] = Some(source);
    a
}

#[test]
fn the_classifier_settles_a_region_the_routes_get_wrong_together() {
    let g = graph();
    let routes = routes();
    let refs: Vec<&RouteLabels> = routes.iter().collect();
    let mut f = fused(&routes);
    let before: Vec<f64> = (1..SHAPES).map(|i| accuracy(&f.labels[i])).collect();
    // The vote follows the two routes that fail together on the region.
    assert!(before.iter().all(|&a| a < 0.93), "{before:?}");
    let report = classifier_route(&g, &annotations(truth()), &refs, &mut f, None);
    let held = report.held_out.expect("ran");
    assert!(held > 0.95, "held-out accuracy {held}");
    assert!(report.weight > 0.0);
    for i in 1..SHAPES {
        let a = accuracy(&f.labels[i]);
        assert!(a > 0.98, "shape {i}: {} -> {a}", before[i - 1]);
        let s = report.shapes[i].expect("a target");
        assert!(s.changed > 0.05 && s.disputed >= s.changed, "{s:?}");
        assert_eq!(report.before[i].len(), VERTICES);
    }
    assert!(report.shapes[0].is_none());
}

#[test]
fn the_classifier_gives_the_same_labels_twice() {
    let g = graph();
    let routes = routes();
    let refs: Vec<&RouteLabels> = routes.iter().collect();
    let run = || {
        let mut f = fused(&routes);
        let r = classifier_route(&g, &annotations(truth()), &refs, &mut f, None);
        (f, r)
    };
    let (a, ra) = run();
    let (b, rb) = run();
    assert_eq!(a, b);
    assert_eq!(ra, rb);
    assert_eq!(ra.weight.to_bits(), rb.weight.to_bits());
}

#[test]
fn a_single_label_source_changes_nothing() {
    let g = graph();
    let routes = routes();
    let refs: Vec<&RouteLabels> = routes.iter().collect();
    let mut f = fused(&routes);
    let before = f.clone();
    let report = classifier_route(&g, &annotations(vec![0; VERTICES]), &refs, &mut f, None);
    assert_eq!(f, before);
    assert!(report.held_out.is_none());
    assert_eq!(report.weight, 0.0);
    assert!(report.shapes.iter().all(Option::is_none));
}

#[test]
fn unlabelled_source_vertices_are_left_out_of_training_and_scoring() {
    let g = graph();
    let routes = routes();
    let refs: Vec<&RouteLabels> = routes.iter().collect();
    let mut f = fused(&routes);
    // Three quarters of the source unlabelled (-1): the rest still carries both labels.
    let source: Vec<i32> = truth()
        .into_iter()
        .enumerate()
        .map(|(v, l)| if v % 4 == 0 { l } else { -1 })
        .collect();
    let report = classifier_route(&g, &annotations(source), &refs, &mut f, None);
    assert!(report.held_out.expect("ran") > 0.95);
    for i in 1..SHAPES {
        assert!(accuracy(&f.labels[i]) > 0.98);
        assert!(f.labels[i].iter().all(|&l| l == 0 || l == 1));
    }
}

#[test]
fn a_source_with_no_labelled_vertex_changes_nothing() {
    let g = graph();
    let routes = routes();
    let refs: Vec<&RouteLabels> = routes.iter().collect();
    let mut f = fused(&routes);
    let before = f.clone();
    let report = classifier_route(&g, &annotations(vec![-1; VERTICES]), &refs, &mut f, None);
    assert_eq!(f, before);
    assert!(report.held_out.is_none());
}
