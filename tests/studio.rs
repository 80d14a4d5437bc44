//! The labelling studio's library (`coseg::studio`): crease patches, the palette, edits with
//! undo, incremental propagation, save and resume, paths kept inside the folder. The server's
//! door (token, Origin, loopback) is tested in tests/cli_studio.rs, the page in a real browser
//! in tests/e2e_studio.rs.

mod common;

use common::features::small_pipeline;
use common::generate::{collections_dir, goblets};
use coseg::mesh::{TriMesh, read_mesh};
use coseg::studio::{Palette, PatchOptions, Studio, StudioError, StudioOptions, crease_patches};
use std::path::Path;

fn options(dir: &Path) -> StudioOptions {
    let mut o = StudioOptions::default();
    o.propagate.pipeline = small_pipeline(30, 8);
    o.propagate.cache_dir = Some(dir.join("cache"));
    o
}

fn truth(i: usize) -> Vec<i32> {
    let path = collections_dir()
        .join("goblets")
        .join(format!("goblets_{i:02}.labels.txt"));
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| l.trim().parse().unwrap())
        .collect()
}

/// Two unit cubes' worth of separate triangles: pieces that share no edge.
fn two_triangles() -> TriMesh {
    TriMesh::new(
        vec![
            [0., 0., 0.],
            [1., 0., 0.],
            [0., 1., 0.],
            [5., 0., 0.],
            [6., 0., 0.],
            [5., 1., 0.],
        ],
        vec![[0, 1, 2], [3, 4, 5]],
    )
    .unwrap()
}

#[test]
fn crease_patches_keep_separate_pieces_apart_and_are_deterministic() {
    let mut one = PatchOptions::default();
    one.target_patches = 1;
    let p = crease_patches(&two_triangles(), &one).unwrap();
    assert_eq!(p, vec![0, 0, 0, 1, 1, 1]);
    let mesh = read_mesh(collections_dir().join("chairs/chairs_01.obj")).unwrap();
    let a = crease_patches(&mesh, &PatchOptions::default()).unwrap();
    let b = crease_patches(&mesh, &PatchOptions::default()).unwrap();
    assert_eq!(a, b);
    let count = *a.iter().max().unwrap() as usize + 1;
    assert_eq!(count, PatchOptions::default().target_patches);
    let mut zero = PatchOptions::default();
    zero.target_patches = 0;
    assert!(crease_patches(&mesh, &zero).is_err());
}

#[test]
fn crease_patches_follow_the_goblets_parts() {
    // Patches must be nearly pure so that clicks alone can label a shape (examples/
    // studio_patches measures every shipped family).
    for i in 0..6 {
        let mesh =
            read_mesh(collections_dir().join(format!("goblets/goblets_{i:02}.obj"))).unwrap();
        let p = crease_patches(&mesh, &PatchOptions::default()).unwrap();
        let gt = truth(i);
        let mut counts = std::collections::BTreeMap::<(u32, i32), usize>::new();
        for (&q, &g) in p.iter().zip(&gt) {
            *counts.entry((q, g)).or_default() += 1;
        }
        let mut best = std::collections::BTreeMap::<u32, usize>::new();
        for (&(q, _), &c) in &counts {
            let b = best.entry(q).or_default();
            *b = (*b).max(c);
        }
        let purity = best.values().sum::<usize>() as f64 / gt.len() as f64;
        assert!(purity > 0.95, "goblets_{i:02}: purity {purity}");
    }
}

#[test]
fn palette_refuses_unknown_parts_and_bad_names() {
    let mut p = Palette::default();
    assert_eq!(p.add("bowl").unwrap(), 0);
    assert!(p.add("bad\nname").is_err());
    assert!(p.recolor(3, [0, 0, 0]).is_err());
    assert_eq!(p.parts().len(), 1);
}

#[test]
fn a_session_labels_propagates_incrementally_saves_and_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let folder = goblets(dir.path(), 4);
    let opts = options(dir.path());
    let mut s = Studio::open(&folder, &opts).unwrap();
    assert_eq!(s.len(), 4);
    assert_eq!(
        s.labels_dir(),
        std::fs::canonicalize(&folder).unwrap().join("labels")
    );
    // Nothing to propagate yet; a label outside the palette is refused and changes nothing.
    assert!(matches!(
        s.propagate(|_| {}),
        Err(StudioError::BadRequest(_))
    ));
    assert!(s.label_patch(0, 0, 0).is_err());
    assert_eq!(s.history(), (0, 0));
    // Label shape 0 patch by patch with the truth's majority part (the test's clicks).
    let gt = truth(0);
    for l in 0..4 {
        s.add_part(&format!("part {l}")).unwrap();
    }
    let patches = s.patches(0).unwrap().to_vec();
    let count = *patches.iter().max().unwrap() + 1;
    for q in 0..count {
        let mut votes = [0usize; 4];
        for (v, _) in patches.iter().enumerate().filter(|(_, p)| **p == q) {
            votes[gt[v] as usize] += 1;
        }
        let part = (0..4)
            .max_by_key(|&k| (votes[k], std::cmp::Reverse(k)))
            .unwrap();
        s.label_patch(0, q, part as i32).unwrap();
    }
    assert!(s.shapes()[0].source);
    assert!(s.label_patch(0, count, 0).is_err(), "no such patch");
    assert!(s.label_patch(9, 0, 0).is_err(), "no such shape");
    assert!(s.brush(0, &[u32::MAX], 0).is_err(), "no such vertex");
    // Undo and redo the last click.
    let labelled = s.labels(0).unwrap().to_vec();
    assert!(s.undo().is_some());
    assert_ne!(s.labels(0).unwrap(), &labelled[..]);
    assert_eq!(s.redo(), Some(0));
    assert_eq!(s.labels(0).unwrap(), &labelled[..]);
    let first = s.propagate(|_| {}).unwrap();
    assert!(first.full);
    for i in 1..4 {
        assert!(s.labels(i).unwrap().iter().all(|&l| l >= 0));
        assert!(s.shapes()[i].confidence.is_some());
    }
    // Correct shape 2 with the brush (a part shape 0 has: a new part needs a full run):
    // the next run is an incremental update of that shape.
    let brushed: Vec<u32> = (0..20).collect();
    s.brush(2, &brushed, 2).unwrap();
    assert!(s.shapes()[2].source);
    let mut steps = Vec::new();
    let second = s.propagate(|p| steps.push(p)).unwrap();
    assert!(!second.full, "{second:?}");
    assert_eq!(second.changed_shapes, 1);
    assert!(second.transports > 0);
    assert_eq!(steps.len(), 1);
    assert!(s.labels(2).unwrap()[..20].iter().all(|&l| l == 2));
    // A source's erased vertices stay erased (-1) in what it shows.
    s.brush(2, &[0], -1).unwrap();
    assert_eq!(s.labels(2).unwrap()[0], -1);
    s.rename_part(1, "stem").unwrap();
    s.recolor_part(1, [1, 2, 3]).unwrap();
    let files = s.save().unwrap();
    assert_eq!(files.len(), 4 * 2 + 2);
    let shown: Vec<Vec<i32>> = (0..4).map(|i| s.labels(i).unwrap().to_vec()).collect();
    let confidence: Vec<Option<f64>> = s.shapes().iter().map(|x| x.confidence).collect();
    drop(s);
    let r = Studio::open(&folder, &opts).unwrap();
    for (i, labels) in shown.iter().enumerate() {
        assert_eq!(r.labels(i).unwrap(), &labels[..], "shape {i} resumed");
        assert_eq!(r.shapes()[i].confidence, confidence[i]);
    }
    let sources: Vec<bool> = r.shapes().iter().map(|x| x.source).collect();
    assert_eq!(sources, vec![true, false, true, false]);
    assert_eq!(r.palette().get(1).unwrap().name, "stem");
    assert_eq!(r.palette().get(1).unwrap().color, [1, 2, 3]);
    // The grid shows the least confident first, sources last.
    let order = r.grid_order();
    assert_eq!(&order[2..], &[0, 2]);
}

#[test]
fn paths_outside_the_folder_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let folder = goblets(dir.path(), 2);
    let s = Studio::open(&folder, &options(dir.path())).unwrap();
    for bad in ["../x", "/tmp/x", "a/../../x", "", "..", "a\\..\\..\\x"] {
        assert!(
            matches!(
                s.resolve_inside(bad),
                Err(StudioError::OutsideFolder { .. })
            ),
            "{bad:?} accepted"
        );
        assert!(s.export(bad).is_err());
    }
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(dir.path(), folder.join("link")).unwrap();
        assert!(matches!(
            s.resolve_inside("link/out"),
            Err(StudioError::OutsideFolder { .. })
        ));
    }
    assert!(!dir.path().join("x").exists() && !dir.path().join("out").exists());
    let inside = s.resolve_inside("export/a").unwrap();
    assert!(inside.starts_with(s.folder()));
    // Export writes the collection for `coseg eval` (labels, faces, summary with sources).
    let written = s.export("export").unwrap();
    assert!(
        written
            .iter()
            .all(|p| p.starts_with(s.folder().join("export")))
    );
}
