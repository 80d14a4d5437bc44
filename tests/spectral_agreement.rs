//! Tests of the collection's near-isometry read from its spectra (src/parts/spectral_agreement.rs).

mod common;

use coseg::mesh::{TriMesh, read_mesh};
use coseg::parts::spectral_agreement;

/// Three shipped shapes of one family (different bodies: not near-isometric).
fn shipped(family: &str) -> Vec<TriMesh> {
    let dir = common::generate::collections_dir().join(family);
    (0..3)
        .map(|i| read_mesh(dir.join(format!("{family}_{i:02}.obj"))).unwrap())
        .collect()
}

/// Copies of one shape moved by similarities are isometric up to scale: equal unit-area
/// spectra, every shape has a near-isometric partner.
#[test]
fn moved_copies_of_one_shape_are_near_isometric() {
    let body = shipped("humanoids").swap_remove(0);
    let copies = vec![
        body.clone(),
        common::features::similarity(&body, 2.5),
        common::features::similarity(&body, 0.3),
    ];
    let a = spectral_agreement(&copies);
    assert_eq!((a.shapes, a.with_partner), (3, 3), "{a:?}");
    assert!(a.near_isometric);
    assert!(
        a.nearest.iter().all(|d| d.is_some_and(|d| d < 1e-3)),
        "{a:?}"
    );
}

/// The generated families are bodies of different proportions: no shape's nearest partner is
/// near-isometric to it by the map step's criterion.
#[test]
fn generated_families_are_not_near_isometric() {
    for family in ["chairs", "humanoids"] {
        let a = spectral_agreement(&shipped(family));
        assert!(!a.near_isometric, "{family}: {a:?}");
        assert!(2 * a.with_partner <= a.shapes, "{family}: {a:?}");
        assert!(a.nearest.iter().all(Option::is_some), "{family}: {a:?}");
    }
}

/// Same input, same result; no shape, or one shape alone, is not a near-isometric collection.
#[test]
fn the_agreement_is_deterministic_and_needs_partners() {
    let meshes = shipped("goblets");
    assert_eq!(spectral_agreement(&meshes), spectral_agreement(&meshes));
    let none = spectral_agreement(&[]);
    assert_eq!(
        (none.shapes, none.with_partner, none.near_isometric),
        (0, 0, false)
    );
    let one = spectral_agreement(&meshes[..1]);
    assert_eq!(one.nearest, vec![None]);
    assert!(!one.near_isometric);
}
