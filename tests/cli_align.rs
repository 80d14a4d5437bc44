//! `coseg align`, the real binary: already-aligned input left bit for bit, a moved collection
//! brought back to one frame, clear errors.

mod common;

use common::motion::random_similarity;
use coseg::align::Similarity;
use coseg::mesh::{read_mesh, write_mesh};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn coseg(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_coseg"))
        .args(args)
        .output()
        .unwrap()
}

fn family(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("collections")
        .join(name)
}

fn transforms(out: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(out.join("transforms.json")).unwrap()).unwrap()
}

fn similarity(v: &serde_json::Value) -> Similarity {
    serde_json::from_value(v["transform"].clone()).unwrap()
}

#[test]
fn already_aligned_collection_is_left_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let input = family("quadrupeds");
    let r = coseg(&[
        "align",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--write-meshes",
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert!(String::from_utf8_lossy(&r.stdout).contains("already aligned"));
    let t = transforms(&out);
    assert_eq!(t["case"], "already_aligned");
    for s in t["shapes"].as_array().unwrap() {
        assert!(similarity(s).is_identity(), "{s}");
        let file = s["file"].as_str().unwrap();
        assert_eq!(
            std::fs::read(input.join(file)).unwrap(),
            std::fs::read(out.join(file)).unwrap(),
            "{file}"
        );
    }
}

/// Every shape moved by a seeded random similarity: the recovered transforms, composed with
/// the motions, are one common rotation (within 5°) for every shape.
#[test]
fn moved_quadrupeds_come_back_to_one_frame() {
    let dir = tempfile::tempdir().unwrap();
    let moved = dir.path().join("moved");
    std::fs::create_dir_all(&moved).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut truth = std::collections::BTreeMap::new();
    for e in std::fs::read_dir(family("quadrupeds")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "obj") {
            truth.insert(p.file_name().unwrap().to_string_lossy().into_owned(), p);
        }
    }
    let mut motions = std::collections::BTreeMap::new();
    for (name, p) in &truth {
        let t = random_similarity(&mut rng);
        let m = read_mesh(p).unwrap().map_positions(|x| t.apply(x)).unwrap();
        write_mesh(moved.join(name), &m, &[]).unwrap();
        motions.insert(name.clone(), t);
    }
    let out = dir.path().join("out");
    let r = coseg(&[
        "align",
        moved.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let t = transforms(&out);
    assert_eq!(t["case"], "synchronised");
    let net: Vec<Similarity> = t["shapes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| similarity(s).compose(&motions[s["file"].as_str().unwrap()]))
        .collect();
    for n in &net {
        assert!(n.rotation_angle_to(&net[0]) < 5.0, "{n:?} vs {:?}", net[0]);
    }
}

#[test]
fn align_refuses_to_write_into_its_input() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_str().unwrap();
    std::fs::copy(
        family("chairs").join("chairs_00.obj"),
        dir.path().join("a.obj"),
    )
    .unwrap();
    let r = coseg(&["align", d, "-o", d]);
    assert!(!r.status.success());
    assert!(String::from_utf8_lossy(&r.stderr).contains("must differ"));
    let empty = tempfile::tempdir().unwrap();
    let r = coseg(&[
        "align",
        empty.path().to_str().unwrap(),
        "-o",
        dir.path().join("o").to_str().unwrap(),
    ]);
    assert!(!r.status.success());
    assert!(String::from_utf8_lossy(&r.stderr).contains("no .obj"));
}
