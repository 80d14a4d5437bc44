//! Tests of the feature families chosen from the data (src/parts/choose_features.rs), through
//! `parts::segment_collection` with its default `FeatureSelection::Chosen`.

mod common;

use coseg::graph::ShapeNode;
use coseg::mesh::{TriMesh, read_mesh};
use coseg::parts::{
    ChooseFeaturesOptions, FeatureSelection, FeatureSet, PartsFrom, SegmentCollectionOptions,
    segment_collection,
};

/// Three shipped goblets with the small test pipeline's spectral columns.
fn goblets() -> (Vec<TriMesh>, Vec<ShapeNode>) {
    let o = common::features::small_pipeline(20, 6);
    let dir = common::generate::collections_dir().join("goblets");
    let meshes: Vec<TriMesh> = (0..3)
        .map(|i| read_mesh(dir.join(format!("goblets_{i:02}.obj"))).unwrap())
        .collect();
    let nodes = common::graph::shape_nodes(&meshes, &o, "g");
    (meshes, nodes)
}

/// By default the families are chosen and the choice is reported with both candidates'
/// scores (the extrinsic one for each up axis tried), the paired test over shapes and the
/// spectra's agreement; the goblets are different bodies (not near-isometric), so both
/// families are kept at any level of the test; without the spectral prior, the level decides;
/// the run is deterministic; with the columns given, nothing is chosen or reported.
#[test]
fn the_feature_families_are_chosen_by_the_consistency_each_reaches() {
    let (meshes, nodes) = goblets();
    let spectral = nodes[0].bands.features;
    let mut o = SegmentCollectionOptions::equal_areas(4);
    o.refine = None;
    let out = segment_collection(nodes.clone(), &meshes, &o).unwrap();
    let f = out.features.as_ref().expect("the choice is reported");
    // One up axis for files whose frames agree (the positive file axis), two (as found and
    // reversed) for shapes moved into a synchronised frame.
    assert!((1..=2).contains(&f.aligned_scores.len()), "{f:?}");
    let aligned = f.aligned_score.unwrap();
    assert!((0.0..=1.0).contains(&f.intrinsic_score) && (0.0..=1.0).contains(&aligned));
    let test = f.spectral_advantage.expect("the paired test is reported");
    assert_eq!(test.shapes, 3);
    assert!((0.0..=1.0).contains(&test.p_value), "{test:?}");
    assert_eq!(f.significance, 0.05);
    assert!(f.reason.contains("paired t-test p "), "{}", f.reason);
    let agreement = f
        .spectral_agreement
        .as_ref()
        .expect("the spectra are compared");
    assert!(!agreement.near_isometric, "{agreement:?}");
    assert_eq!(f.chosen, FeatureSet::IntrinsicExtrinsic, "{}", f.reason);
    assert!(f.reason.contains("near-isometric partner"), "{}", f.reason);
    match f.chosen {
        FeatureSet::IntrinsicExtrinsic => {
            assert!(test.p_value >= f.significance, "{test:?}");
            assert!(
                f.reason.starts_with("features spectral,extrinsic"),
                "{}",
                f.reason
            );
            // The extrinsic columns were added to the graph's nodes.
            assert!(out.graph.node(0).bands.features > spectral);
        }
        FeatureSet::Intrinsic => {
            assert!(test.p_value < f.significance && test.mean > 0.0, "{test:?}");
            assert!(f.reason.starts_with("features spectral:"), "{}", f.reason);
            assert_eq!(out.graph.node(0).bands.features, spectral);
        }
    }
    let again = segment_collection(nodes.clone(), &meshes, &o).unwrap();
    assert_eq!(again.segmentation, out.segmentation);
    assert_eq!(again.features, out.features);
    // Not near-isometric: both families at any level, even one every p-value is below.
    let mut c = ChooseFeaturesOptions::default();
    c.significance = 1.0 + 1e-9;
    let mut ol = o.clone();
    ol.features = FeatureSelection::Chosen(c);
    let f = segment_collection(nodes.clone(), &meshes, &ol)
        .unwrap()
        .features
        .unwrap();
    assert_eq!(f.chosen, FeatureSet::IntrinsicExtrinsic, "{}", f.reason);
    assert!(f.reason.contains("not near-isometric"), "{}", f.reason);
    // Without the spectral prior the level decides on the same statistic: at level 0 both
    // families are kept; at a level above the p-value the spectral family alone is used.
    for (level, chosen) in [
        (0.0, FeatureSet::IntrinsicExtrinsic),
        ((test.p_value + 1e-9).min(1.0), FeatureSet::Intrinsic),
    ] {
        let mut c = ChooseFeaturesOptions::default();
        c.significance = level;
        c.require_near_isometric = false;
        let mut ol = o.clone();
        ol.features = FeatureSelection::Chosen(c);
        let f = segment_collection(nodes.clone(), &meshes, &ol)
            .unwrap()
            .features
            .unwrap();
        assert_eq!(f.spectral_advantage, Some(test));
        assert!(f.spectral_agreement.is_none());
        if level < 1.0 {
            assert_eq!(f.chosen, chosen, "level {level}: {test:?}");
        }
    }
    o.features = FeatureSelection::Given;
    let given = segment_collection(nodes, &meshes, &o).unwrap();
    assert!(given.features.is_none());
    assert_eq!(given.graph.node(0).bands.features, spectral);
}

/// The probe is scored on as many regions as the default parts are grouped from.
#[test]
fn the_probe_has_the_regions_of_the_default_parts() {
    let leaves = match SegmentCollectionOptions::default().parts_from {
        PartsFrom::Geometry { leaves, .. } => leaves,
        PartsFrom::Adaptive => panic!("the default parts come from geometry"),
    };
    assert_eq!(ChooseFeaturesOptions::default().probe_regions, leaves);
}

/// A near-isometric collection (one body moved by similarities): the spectra agree, so the
/// paired test decides, and at a level above its p-value the spectral family alone is used;
/// deterministic.
#[test]
fn a_near_isometric_collection_lets_the_paired_test_choose_the_spectral_family() {
    let o = common::features::small_pipeline(20, 6);
    let dir = common::generate::collections_dir().join("humanoids");
    let body = read_mesh(dir.join("humanoids_00.obj")).unwrap();
    let meshes = vec![
        body.clone(),
        common::features::similarity(&body, 2.0),
        common::features::similarity(&body, 0.5),
    ];
    let nodes = common::graph::shape_nodes(&meshes, &o, "h");
    let mut s = SegmentCollectionOptions::equal_areas(4);
    s.refine = None;
    let f = segment_collection(nodes.clone(), &meshes, &s)
        .unwrap()
        .features
        .unwrap();
    let agreement = f
        .spectral_agreement
        .clone()
        .expect("the spectra are compared");
    assert!(
        agreement.near_isometric && agreement.with_partner == 3,
        "{agreement:?}"
    );
    let test = f.spectral_advantage.expect("an extrinsic candidate");
    // Whatever the default chose, it is the paired test's verdict.
    assert_eq!(
        f.chosen == FeatureSet::Intrinsic,
        test.p_value < f.significance,
        "{}",
        f.reason
    );
    let mut c = ChooseFeaturesOptions::default();
    c.significance = (test.p_value + 1e-9).min(1.0 + 1e-9);
    s.features = FeatureSelection::Chosen(c);
    let out = segment_collection(nodes.clone(), &meshes, &s).unwrap();
    let f = out.features.as_ref().unwrap();
    assert_eq!(f.chosen, FeatureSet::Intrinsic, "{}", f.reason);
    assert!(
        f.reason
            .starts_with("features spectral: the collection is near-isometric (")
    );
    assert_eq!(out.graph.node(0).bands.features, nodes[0].bands.features);
    let again = segment_collection(nodes, &meshes, &s).unwrap();
    assert_eq!(again.features, out.features);
    assert_eq!(again.segmentation, out.segmentation);
}
