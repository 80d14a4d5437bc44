//! Tests of `coseg::mesh`: readers, writers, validation and robustness.

mod common;

use common::mesh::{PlyEncoding, PlyScalar, grid, ply_bytes, tetrahedron};
use coseg::mesh::{
    MeshError, MeshFormat, MeshWarning, PlyVertexProperty, TriMesh, read_mesh,
    read_mesh_from_bytes, read_mesh_with_report, write_atomic, write_mesh,
};
use proptest::prelude::*;
use proptest::test_runner::Config;
use std::path::{Path, PathBuf};

fn tmp() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

fn write_file(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

// ---------------------------------------------------------------- OBJ

#[test]
fn obj_keeps_the_file_vertex_list_across_objects() {
    // Two objects; faces use vertices out of order, across objects, with v/vt/vn corners,
    // negative (relative) indices and a quad; vertex 5 (1-based 6) is used by no face.
    let obj = "\
# two objects
mtllib x.mtl
o first
v 0 0 0
v 1 0 0
v 0 1 0
vt 0 0
vn 0 0 1
g part
usemtl red
f 3/1/1 1/1/1 2/1/1
o second
v 5 5 5
v 6 5 5
v 9 9 9 1.0
v 6 6 5 0.5 0.5 0.5
s 1
f -4 -3 -1 -2
f 2//1 5//1 \\
  1//1
l 1 2
";
    let mesh = read_mesh_from_bytes(obj.as_bytes(), MeshFormat::Obj).unwrap();
    assert_eq!(
        mesh.positions(),
        &[
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [5.0, 5.0, 5.0],
            [6.0, 5.0, 5.0],
            [9.0, 9.0, 9.0],
            [6.0, 6.0, 5.0],
        ]
    );
    // -4 -3 -1 -2 with 7 vertices read → 3 4 6 5 (0-based), fanned.
    assert_eq!(mesh.faces(), &[[2, 0, 1], [3, 4, 6], [3, 6, 5], [1, 4, 0]]);
}

#[test]
fn obj_face_may_name_a_later_vertex() {
    let obj = "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let mesh = read_mesh_from_bytes(obj.as_bytes(), MeshFormat::Obj).unwrap();
    assert_eq!(mesh.faces(), &[[0, 1, 2]]);
}

// ---------------------------------------------------------------- OFF

/// A square pyramid: the base's four corners, then the apex.
#[rustfmt::skip]
const PYRAMID: [[f64; 3]; 5] =
    [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.5, 0.5, 1.0]];
/// [`PYRAMID`]'s faces as a reader gives them: the quad base (0 3 2 1) fanned from its first
/// corner, then the four side triangles.
#[rustfmt::skip]
const PYRAMID_FACES: [[u32; 3]; 6] =
    [[0, 3, 2], [0, 2, 1], [0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]];

#[test]
fn off_variants_comments_and_polygons() {
    let vertices = ["0 0 0", "1 0 0", "1 1 0", "0 1 0", "0.5 0.5 1"];
    let faces = ["4 0 3 2 1", "3 0 1 4", "3 1 2 4", "3 2 3 4", "3 3 0 4"];
    // Each line with `extra` appended (colours, normals), one a line.
    let with = |lines: &[&str], extra: &str| -> String {
        lines
            .iter()
            .map(|l| format!("{l}{extra}"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    let cases: Vec<(&str, String)> = vec![
        (
            "plain, counts on the next line, comments and blank lines",
            format!(
                "# a pyramid\nOFF\n\n5 5 8  # counts\n{}\n\n{}\n",
                vertices.join("\n"),
                faces.join("\n# comment\n")
            ),
        ),
        (
            "counts on the header line, CRLF",
            format!(
                "OFF 5 5 0\r\n{}\r\n{}\r\n",
                vertices.join("\r\n"),
                faces.join("\r\n")
            ),
        ),
        (
            "COFF: per-vertex colours and per-face colours ignored",
            format!(
                "COFF\n5 5 0\n{}\n{}\n",
                with(&vertices, " 255 0 0 255"),
                with(&faces, " 0.1 0.2 0.3")
            ),
        ),
        (
            "NOFF: normals ignored",
            format!(
                "NOFF\n5 5 0\n{}\n{}",
                with(&vertices, " 0 0 1"),
                faces.join("\n")
            ),
        ),
        (
            "CNOFF, counts without the edge count",
            format!(
                "CNOFF\n5 5\n{}\n{}\n",
                with(&vertices, " 0 0 1 1 1 1 1"),
                faces.join("\n")
            ),
        ),
    ];
    for (what, text) in cases {
        let mesh = read_mesh_from_bytes(text.as_bytes(), MeshFormat::Off)
            .unwrap_or_else(|e| panic!("{what}: {e}"));
        assert_eq!(mesh.positions(), &PYRAMID[..], "{what}");
        assert_eq!(mesh.faces(), &PYRAMID_FACES[..], "{what}");
    }
}

#[test]
fn off_truncation_names_the_line() {
    let text = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n";
    let err = read_mesh_from_bytes(text.as_bytes(), MeshFormat::Off).unwrap_err();
    match err {
        MeshError::Truncated { message, .. } => {
            assert!(message.contains("line 7"), "{message}");
            assert!(message.contains("after 1 faces"), "{message}");
        }
        other => panic!("expected Truncated, got {other:?}"),
    }
}

// ---------------------------------------------------------------- PLY

#[test]
fn ply_reads_every_encoding_list_type_and_index_name() {
    let positions = PYRAMID;
    let polygons = vec![
        vec![0, 3, 2, 1],
        vec![0, 1, 4],
        vec![1, 2, 4],
        vec![2, 3, 4],
        vec![3, 0, 4],
    ];
    let mut checked = 0;
    for enc in [PlyEncoding::Ascii, PlyEncoding::Little, PlyEncoding::Big] {
        for coord in [PlyScalar::Float, PlyScalar::Double] {
            for (count, index) in [
                (PlyScalar::UChar, PlyScalar::Int),
                (PlyScalar::UChar, PlyScalar::UInt),
                (PlyScalar::Int, PlyScalar::Int),
                (PlyScalar::UChar, PlyScalar::UChar),
                (PlyScalar::UChar, PlyScalar::Short),
            ] {
                for name in ["vertex_indices", "vertex_index"] {
                    let bytes = ply_bytes(enc, coord, count, index, name, &positions, &polygons);
                    let mesh = read_mesh_from_bytes(&bytes, MeshFormat::Ply).unwrap_or_else(|e| {
                        panic!("{enc:?} {coord:?} {count:?} {index:?} {name}: {e}")
                    });
                    assert_eq!(mesh.positions(), &positions[..]);
                    assert_eq!(mesh.faces(), &PYRAMID_FACES[..]);
                    checked += 1;
                }
            }
        }
    }
    assert_eq!(checked, 60);
}

#[test]
fn ply_float_coordinates_widen_exactly() {
    let positions = [
        [0.1f32 as f64, 0.0, 0.0],
        [1.0, 0.3f32 as f64, 0.0],
        [0.0, 1.0, 0.7f32 as f64],
    ];
    let bytes = ply_bytes(
        PlyEncoding::Little,
        PlyScalar::Float,
        PlyScalar::UChar,
        PlyScalar::Int,
        "vertex_indices",
        &positions,
        &[vec![0, 1, 2]],
    );
    let mesh = read_mesh_from_bytes(&bytes, MeshFormat::Ply).unwrap();
    assert_eq!(mesh.positions(), &positions[..]);
}

#[test]
fn ply_writes_vertex_properties_readable_by_ply_rs() {
    use ply_rs_bw::parser::Parser;
    use ply_rs_bw::ply::{DefaultElement, Property};
    let mesh = grid(2);
    let d = mesh.vertex_count();
    let colors: Vec<[u8; 3]> = (0..d).map(|i| [i as u8, 255 - i as u8, 7]).collect();
    let labels: Vec<i32> = (0..d as i32).map(|i| i * 1000 - 3).collect();
    let quality: Vec<f32> = (0..d).map(|i| i as f32 * 0.25 - 1.0).collect();
    let dir = tmp();
    let path = dir.path().join("props.ply");
    write_mesh(
        &path,
        &mesh,
        &[
            PlyVertexProperty::Color(colors.clone()),
            PlyVertexProperty::Int("label".into(), labels.clone()),
            PlyVertexProperty::Float("quality".into(), quality.clone()),
        ],
    )
    .unwrap();
    assert_eq!(read_mesh(&path).unwrap(), mesh);
    let bytes = std::fs::read(&path).unwrap();
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut &bytes[..])
        .unwrap();
    let verts = &ply.payload["vertex"];
    assert_eq!(verts.len(), d);
    for (i, v) in verts.iter().enumerate() {
        assert_eq!(v["x"], Property::Double(mesh.positions()[i][0]));
        assert_eq!(v["red"], Property::UChar(colors[i][0]));
        assert_eq!(v["green"], Property::UChar(colors[i][1]));
        assert_eq!(v["blue"], Property::UChar(colors[i][2]));
        assert_eq!(v["label"], Property::Int(labels[i]));
        assert_eq!(v["quality"], Property::Float(quality[i]));
    }
}

#[test]
fn ply_rejects_bad_properties_before_writing() {
    let mesh = tetrahedron();
    let dir = tmp();
    let path = dir.path().join("bad.ply");
    let cases = [
        vec![PlyVertexProperty::Int("label".into(), vec![1, 2])],
        vec![PlyVertexProperty::Float("has space".into(), vec![0.0; 4])],
        vec![PlyVertexProperty::Int("x".into(), vec![0; 4])],
        vec![
            PlyVertexProperty::Int("a".into(), vec![0; 4]),
            PlyVertexProperty::Float("a".into(), vec![0.0; 4]),
        ],
        vec![
            PlyVertexProperty::Color(vec![[0; 3]; 4]),
            PlyVertexProperty::Color(vec![[0; 3]; 4]),
        ],
    ];
    for props in cases {
        let err = write_mesh(&path, &mesh, &props).unwrap_err();
        assert!(matches!(err, MeshError::Property { .. }), "{err:?}");
        assert!(err.to_string().contains("bad.ply"), "{err}");
        assert!(!path.exists());
    }
}

// ---------------------------------------------------------------- round trips

fn round_trip_all(mesh: &TriMesh, dir: &Path) {
    for ext in ["obj", "off", "ply"] {
        let path = dir.join(format!("rt.{ext}"));
        write_mesh(&path, mesh, &[]).unwrap();
        let back = read_mesh(&path).unwrap();
        assert_eq!(back.positions().len(), mesh.positions().len(), "{ext}");
        for (a, b) in back.positions().iter().zip(mesh.positions()) {
            for k in 0..3 {
                assert_eq!(a[k].to_bits(), b[k].to_bits(), "{ext}: {a:?} vs {b:?}");
            }
        }
        assert_eq!(back.faces(), mesh.faces(), "{ext}");
    }
}

#[test]
fn writers_round_trip_fixtures_bit_for_bit() {
    let dir = tmp();
    round_trip_all(&tetrahedron(), dir.path());
    round_trip_all(&grid(7), dir.path());
    // Awkward values: negative zero, subnormals, extremes, unused vertex.
    let odd = TriMesh::new(
        vec![
            [-0.0, 5e-324, 1e150],
            [1.7976931348623157e-300, 2.2250738585072014e-308, -1e-300],
            [0.1, 1.0 / 3.0, -123_456_789.123_456_78],
            [f64::EPSILON, 1.0 + f64::EPSILON, 2.0f64.sqrt()],
        ],
        vec![[0, 1, 2], [2, 2, 1]],
    )
    .unwrap();
    round_trip_all(&odd, dir.path());
}

/// Finite doubles with arbitrary sign and mantissa bits and binary exponents in ±200 (so
/// triangle areas neither overflow nor underflow), plus zeros of both signs.
fn finite_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        20 => (any::<bool>(), -200i64..=200, any::<u64>()).prop_map(|(neg, e, m)| {
            let bits = ((neg as u64) << 63) | (((1023 + e) as u64) << 52) | (m >> 12);
            f64::from_bits(bits)
        }),
        1 => prop::sample::select(vec![0.0, -0.0]),
    ]
}

fn fixed(cases: u32) -> Config {
    common::fixed_cases(cases, 0xC05E6)
}

proptest! {
    #![proptest_config(fixed(64))]
    #[test]
    fn writers_round_trip_arbitrary_coordinates(
        coords in proptest::collection::vec(finite_f64(), 27),
    ) {
        let positions: Vec<[f64; 3]> = coords.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
        let faces = vec![[0, 1, 2], [3, 4, 5], [6, 7, 8], [8, 0, 4]];
        let mesh = TriMesh::new(positions, faces);
        // Zero total area (all triangles degenerate) is not a valid mesh: nothing to write.
        prop_assume!(mesh.is_ok());
        let mesh = mesh.unwrap();
        let dir = tmp();
        round_trip_all(&mesh, dir.path());
    }
}

// ---------------------------------------------------------------- validation and reports

#[test]
fn repeated_index_is_a_degenerate_warning_not_an_error() {
    let off = "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 1 1 3\n";
    let dir = tmp();
    let p = write_file(dir.path(), "deg.off", off);
    let (mesh, report) = read_mesh_with_report(&p).unwrap();
    assert_eq!(mesh.faces(), &[[0, 1, 2], [1, 1, 3]]);
    assert!(
        report
            .warnings
            .contains(&MeshWarning::DegenerateFaces { count: 1, first: 1 }),
        "{report:?}"
    );
}

#[test]
fn report_lists_duplicates_unreferenced_nonmanifold_components_boundary() {
    // Two triangles sharing edge (0,1) plus a third on the same edge (non-manifold), a
    // duplicate of face 0 in another order, a separate triangle, and an unused vertex 7.
    let obj = "\
v 0 0 0
v 1 0 0
v 0 1 0
v 0 -1 0
v 0 0 1
v 5 5 5
v 6 5 5
v 9 9 9
v 5 6 5
f 1 2 3
f 2 1 4
f 1 2 5
f 2 3 1
f 6 7 9
";
    let dir = tmp();
    let p = write_file(dir.path(), "messy.obj", obj);
    let (_, report) = read_mesh_with_report(&p).unwrap();
    let w = &report.warnings;
    assert!(
        w.contains(&MeshWarning::DuplicateFaces { count: 1, first: 3 }),
        "{w:?}"
    );
    assert!(
        w.contains(&MeshWarning::UnreferencedVertices { count: 1, first: 7 }),
        "{w:?}"
    );
    assert!(
        w.iter()
            .any(|x| matches!(x, MeshWarning::NonManifoldEdges { first: [0, 1], .. })),
        "{w:?}"
    );
    assert!(
        w.contains(&MeshWarning::SeveralComponents { count: 2 }),
        "{w:?}"
    );
    assert!(
        w.iter().any(|x| matches!(x, MeshWarning::Boundary { .. })),
        "{w:?}"
    );
    let (_, clean) = {
        let p = dir.path().join("tet.off");
        write_mesh(&p, &tetrahedron(), &[]).unwrap();
        read_mesh_with_report(&p).unwrap()
    };
    assert!(clean.is_clean(), "{clean:?}");
}

// ---------------------------------------------------------------- malformed corpus

fn corpus_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/malformed")
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Empty,
    Header,
    Parse,
    Truncated,
    NonFinite,
    Index,
    ZeroArea,
    Format,
}

fn kind(e: &MeshError) -> Option<Kind> {
    Some(match e {
        MeshError::Empty { .. } => Kind::Empty,
        MeshError::Header { .. } => Kind::Header,
        MeshError::Parse { .. } => Kind::Parse,
        MeshError::Truncated { .. } => Kind::Truncated,
        MeshError::NonFinite { .. } => Kind::NonFinite,
        MeshError::IndexOutOfRange { .. } => Kind::Index,
        MeshError::ZeroArea { .. } => Kind::ZeroArea,
        MeshError::UnsupportedFormat { .. } => Kind::Format,
        _ => return None,
    })
}

/// Every corpus file with the error kind it must give and a fragment its message must contain
/// (`tests/data/malformed.expected`, one tab-separated line a file).
fn corpus_expectations() -> Vec<(String, String, String)> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/malformed.expected");
    std::fs::read_to_string(&path)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let f: Vec<&str> = l.split('\t').collect();
            assert_eq!(
                f.len(),
                3,
                "{}: {l:?} is not name, kind, fragment",
                path.display()
            );
            (f[0].to_string(), f[1].to_string(), f[2].to_string())
        })
        .collect()
}

#[test]
fn malformed_corpus_gives_the_expected_error_naming_the_file() {
    let dir = corpus_dir();
    let corpus = corpus_expectations();
    let mut listed: Vec<&str> = corpus.iter().map(|c| c.0.as_str()).collect();
    listed.sort_unstable();
    let mut present: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    present.sort_unstable();
    assert_eq!(listed, present, "every corpus file is listed exactly once");
    for (name, expected, fragment) in &corpus {
        let path = dir.join(name);
        let err = match read_mesh_with_report(&path) {
            Ok(_) => panic!("{name}: read without error"),
            Err(e) => e,
        };
        assert_eq!(
            kind(&err).map(|k| format!("{k:?}")).as_deref(),
            Some(expected.as_str()),
            "{name}: {err:?}"
        );
        let msg = err.to_string();
        assert!(
            msg.starts_with(&path.display().to_string()),
            "{name}: message does not name the file: {msg}"
        );
        assert!(
            msg.contains(fragment.as_str()),
            "{name}: `{fragment}` not in: {msg}"
        );
    }
}

/// Regression (#18): an OFF file with a record after the faces its header declares was an
/// error where other readers warn; the declared mesh is read, with a warning naming the line.
#[test]
fn off_with_data_after_the_declared_elements_is_read_with_a_warning() {
    let path = corpus_dir().parent().unwrap().join("extra_data.off");
    let (mesh, report) = read_mesh_with_report(&path).unwrap();
    assert_eq!((mesh.vertex_count(), mesh.face_count()), (3, 1));
    let ignored: Vec<String> = report
        .warnings
        .iter()
        .filter(|w| matches!(w, coseg::mesh::MeshWarning::IgnoredData { .. }))
        .map(|w| w.to_string())
        .collect();
    assert_eq!(ignored.len(), 1, "{:?}", report.warnings);
    assert!(ignored[0].contains("line 7"), "{}", ignored[0]);
}

#[test]
fn missing_file_is_an_io_error_naming_it() {
    let path = corpus_dir().join("does_not_exist.off");
    let err = read_mesh(&path).unwrap_err();
    assert!(matches!(err, MeshError::Io(_)), "{err:?}");
    assert!(err.to_string().contains("does_not_exist.off"));
}

#[test]
fn write_to_unknown_extension_or_missing_dir_fails_cleanly() {
    let dir = tmp();
    let err = write_mesh(dir.path().join("m.stl"), &tetrahedron(), &[]).unwrap_err();
    assert!(
        matches!(err, MeshError::UnsupportedFormat { .. }),
        "{err:?}"
    );
    let err = write_mesh(dir.path().join("no/such/dir/m.off"), &tetrahedron(), &[]).unwrap_err();
    assert!(matches!(err, MeshError::Io(_)), "{err:?}");
    assert!(err.to_string().contains("m.off"), "{err}");
}

// ---------------------------------------------------------------- atomic writes

#[test]
fn write_atomic_replaces_whole_or_not_at_all() {
    use std::io::Write;
    let dir = tmp();
    let path = dir.path().join("out.txt");
    write_atomic(&path, |w| w.write_all(b"first")).unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), b"first");
    let err = write_atomic(&path, |w| {
        w.write_all(&vec![b'x'; 100_000])?;
        Err(std::io::Error::other("interrupted"))
    })
    .unwrap_err();
    assert_eq!(err.to_string(), "interrupted");
    assert_eq!(std::fs::read(&path).unwrap(), b"first");
    write_atomic(&path, |w| w.write_all(b"second")).unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), b"second");
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(
        names,
        vec![std::ffi::OsString::from("out.txt")],
        "no temporary file left"
    );
    // A relative path (no parent directory component) works too.
    let rel = format!("coseg-atomic-test-{}.txt", std::process::id());
    write_atomic(&rel, |w| w.write_all(b"rel")).unwrap();
    assert_eq!(std::fs::read(&rel).unwrap(), b"rel");
    std::fs::remove_file(&rel).unwrap();
}

// ---------------------------------------------------------------- no panics

fn valid_samples() -> Vec<(MeshFormat, Vec<u8>)> {
    let dir = tmp();
    let mesh = grid(2);
    let mut out = Vec::new();
    for (ext, fmt) in [
        ("obj", MeshFormat::Obj),
        ("off", MeshFormat::Off),
        ("ply", MeshFormat::Ply),
    ] {
        let p = dir.path().join(format!("m.{ext}"));
        write_mesh(&p, &mesh, &[]).unwrap();
        out.push((fmt, std::fs::read(&p).unwrap()));
    }
    let polys: Vec<Vec<u32>> = mesh.faces().iter().map(|f| f.to_vec()).collect();
    out.push((
        MeshFormat::Ply,
        ply_bytes(
            PlyEncoding::Ascii,
            PlyScalar::Float,
            PlyScalar::UChar,
            PlyScalar::Int,
            "vertex_indices",
            mesh.positions(),
            &polys,
        ),
    ));
    out.push((
        MeshFormat::Ply,
        ply_bytes(
            PlyEncoding::Big,
            PlyScalar::Double,
            PlyScalar::Int,
            PlyScalar::UInt,
            "vertex_index",
            mesh.positions(),
            &polys,
        ),
    ));
    for (fmt, bytes) in &out {
        read_mesh_from_bytes(bytes, *fmt).expect("samples are valid");
    }
    out
}

/// A byte edit: overwrite, insert, delete or truncate at a position (taken modulo the length).
#[derive(Debug, Clone)]
enum Edit {
    Set(usize, u8),
    Insert(usize, u8),
    Delete(usize),
    Truncate(usize),
    /// Overwrite with an ASCII digit or sign, to make plausible but wrong numbers.
    Digit(usize, u8),
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Edit::Set(i, b)),
        (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Edit::Insert(i, b)),
        any::<usize>().prop_map(Edit::Delete),
        any::<usize>().prop_map(Edit::Truncate),
        (
            any::<usize>(),
            prop::sample::select(b"0123456789-+.eE \n9".to_vec())
        )
            .prop_map(|(i, b)| Edit::Digit(i, b)),
    ]
}

fn apply(bytes: &mut Vec<u8>, edits: &[Edit]) {
    for e in edits {
        let n = bytes.len().max(1);
        match *e {
            Edit::Set(i, b) | Edit::Digit(i, b) => {
                if !bytes.is_empty() {
                    bytes[i % n] = b;
                }
            }
            Edit::Insert(i, b) => bytes.insert(i % (bytes.len() + 1), b),
            Edit::Delete(i) => {
                if !bytes.is_empty() {
                    bytes.remove(i % n);
                }
            }
            Edit::Truncate(i) => bytes.truncate(i % n),
        }
    }
}

const FORMATS: [MeshFormat; 3] = [MeshFormat::Obj, MeshFormat::Off, MeshFormat::Ply];

proptest! {
    #![proptest_config(fixed(512))]

    #[test]
    fn parsers_never_panic_on_arbitrary_bytes(bytes in proptest::collection::vec(any::<u8>(), 0..512)) {
        for fmt in FORMATS {
            let _ = read_mesh_from_bytes(&bytes, fmt);
        }
    }

    #[test]
    fn parsers_never_panic_on_mutated_valid_files(
        which in 0usize..5,
        edits in proptest::collection::vec(edit(), 1..6),
    ) {
        static SAMPLES: std::sync::OnceLock<Vec<(MeshFormat, Vec<u8>)>> =
            std::sync::OnceLock::new();
        let (fmt, mut bytes) = SAMPLES.get_or_init(valid_samples)[which].clone();
        apply(&mut bytes, &edits);
        // Any format's parser on any mutated file: none may panic.
        let _ = read_mesh_from_bytes(&bytes, fmt);
        for other in FORMATS {
            let _ = read_mesh_from_bytes(&bytes, other);
        }
    }

    #[test]
    fn parsers_never_panic_on_text_like_input(
        text in "(OFF|COFF|ply|v|f|format|element|property|end_header|[0-9 .eE+-]{0,12}|#|\n|\r\n| ){0,60}",
    ) {
        for fmt in FORMATS {
            let _ = read_mesh_from_bytes(text.as_bytes(), fmt);
        }
    }
}

// ---------------------------------------------------------------- evaluation data

/// Vertex and face counts from an OFF file's header (independent of the library's parser).
fn off_header_counts(path: &Path) -> (usize, usize) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut toks = text
        .lines()
        .map(|l| l.split('#').next().unwrap())
        .flat_map(|l| l.split_whitespace());
    let kw = toks.next().unwrap();
    assert!(kw.ends_with("OFF"), "{}", path.display());
    let nv = toks.next().unwrap().parse().unwrap();
    let nf = toks.next().unwrap().parse().unwrap();
    (nv, nf)
}

fn shared_meshes() -> Vec<PathBuf> {
    let Some(root) = common::shared_data("shared_meshes") else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for sub in ["tosca", "tosca_hires", "faust", "coseg_chairs/shapes"] {
        let Ok(rd) = std::fs::read_dir(root.join(sub)) else {
            continue;
        };
        for e in rd {
            let p = e.unwrap().path();
            if MeshFormat::from_path(&p).is_some() {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// Done-when check of issue 2 on the evaluation data (run with `--ignored`; skips when the
/// data is absent): every mesh loads with the header's counts and round-trips through every
/// writer and reader unchanged.
#[test]
#[ignore]
fn shared_data_loads_with_header_counts_and_round_trips() {
    let files = shared_meshes();
    if files.is_empty() {
        eprintln!("shared data absent: skipped");
        return;
    }
    let dir = tmp();
    for p in &files {
        let mesh = read_mesh(p).unwrap_or_else(|e| panic!("{e}"));
        let (nv, nf) = off_header_counts(p);
        assert_eq!(mesh.vertex_count(), nv, "{}", p.display());
        assert_eq!(mesh.face_count(), nf, "{}", p.display());
        round_trip_all(&mesh, dir.path());
    }
    eprintln!("checked {} files", files.len());
}

#[test]
fn huge_declared_counts_fail_cleanly_without_allocating_them() {
    let off = "OFF\n4000000000 4000000000 0\n0 0 0\n";
    let err = read_mesh_from_bytes(off.as_bytes(), MeshFormat::Off).unwrap_err();
    assert!(matches!(err, MeshError::Truncated { .. }), "{err:?}");
    let off = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4000000000 0 1 2\n";
    let err = read_mesh_from_bytes(off.as_bytes(), MeshFormat::Off).unwrap_err();
    assert!(matches!(err, MeshError::Parse { .. }), "{err:?}");
    for count in ["uint", "int"] {
        let mut ply = format!(
            "ply\nformat binary_little_endian 1.0\nelement vertex 3000000000\nproperty double x\nproperty double y\nproperty double z\nelement face 1\nproperty list {count} int vertex_indices\nend_header\n"
        )
        .into_bytes();
        ply.extend_from_slice(&[0u8; 72]);
        let err = read_mesh_from_bytes(&ply, MeshFormat::Ply).unwrap_err();
        assert!(matches!(err, MeshError::Truncated { .. }), "{err:?}");
        // A face list declaring 4 294 967 295 (or -1) entries.
        let mut ply = format!(
            "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\nelement face 1\nproperty list {count} int vertex_indices\nend_header\n"
        )
        .into_bytes();
        for p in [[0.0f64, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
            for c in p {
                ply.extend_from_slice(&c.to_le_bytes());
            }
        }
        ply.extend_from_slice(&u32::MAX.to_le_bytes());
        ply.extend_from_slice(&[0u8; 12]);
        let err = read_mesh_from_bytes(&ply, MeshFormat::Ply).unwrap_err();
        assert!(
            matches!(err, MeshError::Truncated { .. } | MeshError::Parse { .. }),
            "{err:?}"
        );
    }
}
