//! The map route's point maps on disk (`src/propagate/point_map_store.rs`): a rerun reads
//! each shape's map instead of fitting it again and gives the labels of a run with no cache
//! folder at all, bit for bit; labels that change give another entry.

mod common;

use coseg::propagate::{PropagateCollectionOptions, propagate_collection, propagate_loaded};

/// The point-map entries of `cache`, sorted, with their bytes.
fn maps(cache: &std::path::Path) -> Vec<(std::path::PathBuf, Vec<u8>)> {
    common::outputs::cache_entries(cache, "coseg-map")
}

#[test]
fn a_rerun_reads_the_maps_and_equals_a_run_without_a_cache() {
    let dir = tempfile::tempdir().unwrap();
    let (shapes, _, copies) =
        common::features::labelled_blob_and_copies(dir.path(), common::features::three_slabs);
    let cache = dir.path().join("cache");
    let mut o = PropagateCollectionOptions::default();
    o.pipeline.spectrum.eigenpairs = 40;
    o.cache_dir = Some(cache.clone());
    let labels = [dir.path().join("a.labels.txt")];
    let cold = propagate_collection(&shapes, &labels, &o).unwrap();
    let written = maps(&cache);
    assert_eq!(written.len(), copies.len(), "one map per unlabelled shape");
    let warm = propagate_collection(&shapes, &labels, &o).unwrap();
    assert_eq!(warm.propagation.labels, cold.propagation.labels);
    assert_eq!(warm.map_routes, cold.map_routes);
    assert_eq!(maps(&cache), written, "nothing rewritten");
    // The same shapes in memory, no cache folder: every map fitted, the same labels.
    let loaded = coseg::graph::load_collection(&shapes, &o.pipeline, &cache, |_, _, _| {}).unwrap();
    let mut annotations = vec![None; loaded.meshes.len()];
    let source = &cold.sources[0];
    let name = &loaded.nodes[source.shape].name;
    let read = coseg::labels::read_shape_labels(&source.path, &loaded.meshes[source.shape], name);
    annotations[source.shape] = Some(read.unwrap().vertex_labels);
    let mut none = o.clone();
    none.cache_dir = None;
    let meshes = loaded.meshes.clone();
    let bare = propagate_loaded(loaded.nodes, &meshes, &annotations, &none).unwrap();
    assert_eq!(bare.propagation.labels, cold.propagation.labels);
    assert_eq!(bare.map_route, cold.map_routes);
}
