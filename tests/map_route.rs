//! The map route of the fused propagation (`coseg::propagate::{map_route, fuse_with_map}`):
//! the decision on synthetic votes, the route end to end on isometric copies.

mod common;

use coseg::evaluate::vertex_label_agreement;
use coseg::propagate::{
    PropagateCollectionOptions, RouteLabels, fuse_with_map, propagate_collection,
};

/// Route labels on shape 1 of two (shape 0 a source), every vertex equally confident.
fn route(labels: Vec<i32>) -> RouteLabels {
    let d = labels.len();
    let mut r = RouteLabels::empty(2);
    r.labels[1] = labels;
    r.confidence[1] = vec![1.0; d];
    r
}

/// The truth `0..3` in thirds of `d` vertices.
fn thirds(d: usize) -> Vec<i32> {
    (0..d).map(|v| (3 * v / d) as i32).collect()
}

/// `truth` shifted by one label on the vertices of the half-open spans `(start, end)`.
fn wrong(truth: &[i32], spans: &[(usize, usize)]) -> Vec<i32> {
    truth
        .iter()
        .enumerate()
        .map(|(v, &l)| {
            if spans.iter().any(|&(a, b)| (a..b).contains(&v)) {
                (l + 1) % 3
            } else {
                l
            }
        })
        .collect()
}

/// Three routes each wrong on a different sixth of the shape (each right on 5/6, every
/// pair agreeing on 4/6): a map right everywhere agrees with each route as far as that
/// route is right, more than the routes agree with each other, so the triangles rank it
/// first and the shape takes the vote with it — the exact truth. A map wrong on half of the
/// shape, where the routes are right, is ranked below them and not taken, and a map that only repeats one route
/// (a map fitted to that route's labels) is not ranked above it.
#[test]
fn the_map_is_taken_only_where_the_routes_agreement_ranks_it_first() {
    let d = 600;
    let truth = thirds(d);
    let (a, p, r) = (
        route(wrong(&truth, &[(0, 100)])),
        route(wrong(&truth, &[(200, 300)])),
        route(wrong(&truth, &[(400, 500)])),
    );
    let areas_1 = vec![1.0; d];
    let areas: Vec<&[f64]> = vec![&[], &areas_1];
    let routes = [&a, &p, &r];

    let right = route(truth.clone());
    let (fused, taken) = fuse_with_map(&routes, &right, &areas);
    assert_eq!(taken, vec![false, true], "{:?}", fused.weights);
    assert_eq!(fused.labels[1], truth);

    let bad = route(wrong(&truth, &[(100, 200), (300, 400), (500, 600)]));
    let (fused, taken) = fuse_with_map(&routes, &bad, &areas);
    assert_eq!(taken, vec![false, false], "{:?}", fused.weights);

    let copy = route(a.labels[1].clone());
    let (fused, taken) = fuse_with_map(&routes, &copy, &areas);
    assert_eq!(taken, vec![false, false], "{:?}", fused.weights);
}

/// End to end under the default options (the map route on): a blob and two permuted copies
/// (exact isometries) labelled in three slabs from the blob; each copy gets a map-route
/// report naming the blob as its source and ends at ≥ 99 % of the truth; with the route
/// turned off no report is made. Deterministic: a second run gives the same labels.
#[test]
fn the_map_route_runs_by_default_and_reports_each_copy() {
    use common::features::labelled_blob_and_copies;
    let dir = tempfile::tempdir().unwrap();
    let truth_of = common::features::three_slabs;
    let (shapes, _, copies) = labelled_blob_and_copies(dir.path(), truth_of);
    let mut o = PropagateCollectionOptions::default();
    o.pipeline.spectrum.eigenpairs = 40;
    o.cache_dir = Some(dir.path().join("cache"));
    assert!(o.routes.map, "the map route is on by default");
    let labels = [dir.path().join("a.labels.txt")];
    let r = propagate_collection(&shapes, &labels, &o).unwrap();
    assert!(r.map_routes[0].is_none(), "the source has no map");
    for (k, copy) in copies.iter().enumerate() {
        let i = k + 1;
        let report = r.map_routes[i].as_ref().expect("a map-route report");
        assert_eq!(report.source, 0);
        let acc = vertex_label_agreement(copy, &truth_of(copy), &r.propagation.labels[i])
            .unwrap()
            .accuracy;
        assert!(acc >= 0.99, "c{i}: {acc} ({report:?})");
    }
    let again = propagate_collection(&shapes, &labels, &o).unwrap();
    assert_eq!(again.propagation.labels, r.propagation.labels);
    o.routes.map = false;
    let off = propagate_collection(&shapes, &labels, &o).unwrap();
    assert!(off.map_routes.iter().all(Option::is_none));
}
