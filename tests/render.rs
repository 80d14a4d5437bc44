//! Tests of `coseg::render`: the canonical view, the rasteriser, the contact sheet and PNG bytes.

mod common;

use common::features::{blob, permutation, permute_mesh, similarity};
use coseg::mesh::TriMesh;
use coseg::render::{
    RenderOptions, RenderShape, RgbImage, canonical_frame, collection_views, draw_mesh, encode_png,
    render_shape, render_sheet, write_pictures,
};

fn decode(bytes: &[u8]) -> RgbImage {
    let dec = png::Decoder::new(std::io::Cursor::new(bytes));
    let mut reader = dec.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    buf.truncate(info.buffer_size());
    RgbImage {
        width: info.width,
        height: info.height,
        pixels: buf,
    }
}

fn distinct_colors(img: &RgbImage) -> usize {
    let mut c: Vec<&[u8]> = img.pixels.chunks(3).collect();
    c.sort_unstable();
    c.dedup();
    c.len()
}

#[test]
fn canonical_view_is_invariant_to_pose_scale_and_vertex_order() {
    let mesh = blob(3);
    let moved = similarity(&mesh, 2.5);
    let (f0, f1) = (canonical_frame(&mesh), canonical_frame(&moved));
    // Same view coordinates up to the scale: the pose of the file does not change the picture.
    for (p, q) in mesh.positions().iter().zip(moved.positions()) {
        let (a, b) = (f0.project(*p), f1.project(*q));
        for k in 0..3 {
            assert!((2.5 * a[k] - b[k]).abs() < 1e-8, "{a:?} vs {b:?}");
        }
    }
    let perm = permutation(mesh.vertex_count(), 7);
    let f2 = canonical_frame(&permute_mesh(&mesh, &perm));
    for k in 0..3 {
        for j in 0..3 {
            assert!((f0.axes[k][j] - f2.axes[k][j]).abs() < 1e-9);
        }
    }
}

#[test]
fn canonical_frame_is_right_handed_longest_axis_right_and_heavy_tail_positive() {
    // A box elongated along y, with extra vertices (a heavy tail) at negative y.
    let mut pos = Vec::new();
    let mut faces = Vec::new();
    for i in 0..40u32 {
        let y = if i < 30 {
            -3.0 + i as f64 * 0.05
        } else {
            i as f64 * 0.3 - 6.0
        };
        pos.push([0.0, y, 0.0]);
        pos.push([0.4, y, 0.1]);
        pos.push([0.0, y, 0.2]);
        let b = 3 * i;
        faces.push([b, b + 1, b + 2]);
    }
    let mesh = TriMesh::new(pos, faces).unwrap();
    let f = canonical_frame(&mesh);
    assert!(f.axes[0][1].abs() > 0.99, "{:?}", f.axes);
    // Most vertices sit near y = -3..-1.5 with a long sparse tail to +6: third moment along +y
    // is positive, so screen right is +y.
    assert!(f.axes[0][1] > 0.0, "{:?}", f.axes);
    let [a, b, c] = f.axes;
    let cross = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    for k in 0..3 {
        assert!((cross[k] - c[k]).abs() < 1e-12);
    }
}

#[test]
fn rasteriser_fills_the_projected_triangle_and_keeps_the_nearest_surface() {
    // Two squares facing the viewer (smallest axis = z after the frame), red in front of blue.
    let mut pos = Vec::new();
    let mut faces = Vec::new();
    // Each square is a fan of 4 triangles around its centre, so the vertex areas (the
    // frame's weights) are symmetric and the principal axes are the square's sides.
    for (z, o) in [(0.0, 0u32), (-0.01, 5)] {
        pos.extend([
            [0.0, 0.0, z],
            [2.0, 0.0, z],
            [2.0, 1.0, z],
            [0.0, 1.0, z],
            [1.0, 0.5, z],
        ]);
        faces.extend([
            [o, o + 1, o + 4],
            [o + 1, o + 2, o + 4],
            [o + 2, o + 3, o + 4],
            [o + 3, o, o + 4],
        ]);
    }
    let mesh = TriMesh::new(pos, faces).unwrap();
    let colors: Vec<[u8; 3]> = (0..10)
        .map(|v| if v < 5 { [255, 0, 0] } else { [0, 0, 255] })
        .collect();
    let frame = canonical_frame(&mesh);
    let mut img = RgbImage::filled(100, 100, [0, 0, 0]);
    draw_mesh(&mut img, [0, 0, 100, 100], &mesh, &colors, &frame);
    // 90 % of 100 px wide, aspect 2: about 90 × 45 pixels covered.
    let covered = img.pixels.chunks(3).filter(|p| p != &[0, 0, 0]).count();
    assert!((3800..=4300).contains(&covered), "{covered}");
    let front_is_red = frame.axes[2][2] > 0.0;
    let center = img.get(50, 50);
    if front_is_red {
        assert!(center[0] > 0 && center[2] == 0, "{center:?}");
    } else {
        assert!(center[2] > 0 && center[0] == 0, "{center:?}");
    }
}

#[test]
fn sheet_has_the_documented_size_and_same_part_same_colour() {
    let a = blob(2);
    let b = similarity(&blob(2), 0.5);
    let labels: Vec<i32> = (0..a.vertex_count()).map(|i| (i % 3) as i32).collect();
    let shapes = [
        RenderShape {
            name: "a",
            mesh: &a,
            labels: &labels,
            confidence: Some(0.5),
            view: None,
        },
        RenderShape {
            name: "b",
            mesh: &b,
            labels: &labels,
            confidence: None,
            view: None,
        },
        RenderShape {
            name: "c",
            mesh: &a,
            labels: &labels,
            confidence: None,
            view: None,
        },
    ];
    let mut opts = RenderOptions::default();
    opts.cell_size = 64;
    opts.legend = false;
    let sheet = render_sheet(&shapes, None, &opts).unwrap();
    let caption = 9 * opts.font_scale + 4;
    assert_eq!((sheet.width, sheet.height), (2 * 64, 2 * (64 + caption)));
    let one = render_shape(&shapes[0], &opts).unwrap();
    assert_eq!((one.width, one.height), (64, 64 + caption));
    // Shape "a" drawn in cell 0 and "c" (same mesh, same labels) in cell 2: same pixels.
    for y in 0..64 {
        for x in 0..64 {
            assert_eq!(sheet.get(x, y), sheet.get(x, y + 64 + caption));
        }
    }
    let err = render_sheet(
        &[RenderShape {
            name: "x",
            mesh: &a,
            labels: &[0],
            confidence: None,
            view: None,
        }],
        None,
        &opts,
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("x:") && err.contains("1 labels"), "{err}");
}

#[test]
fn pictures_decode_with_expected_size_many_colours_and_identical_bytes_twice() {
    let a = blob(3);
    let labels: Vec<i32> = a
        .positions()
        .iter()
        .map(|p| {
            if p[0] > 0.3 {
                0
            } else if p[1] > 0.0 {
                1
            } else {
                2
            }
        })
        .collect();
    let shapes = [RenderShape {
        name: "blob",
        mesh: &a,
        labels: &labels,
        confidence: None,
        view: None,
    }];
    let dir = tempfile::tempdir().unwrap();
    let paths = write_pictures(dir.path(), &shapes, None, &RenderOptions::default()).unwrap();
    let first: Vec<Vec<u8>> = paths.iter().map(|p| std::fs::read(p).unwrap()).collect();
    let img = decode(&first[1]);
    assert_eq!(img.width, 240);
    // Three parts, shaded: far more than 3 colours, and all three hues present.
    assert!(distinct_colors(&img) > 50, "{}", distinct_colors(&img));
    write_pictures(dir.path(), &shapes, None, &RenderOptions::default()).unwrap();
    for (p, bytes) in paths.iter().zip(&first) {
        assert_eq!(&std::fs::read(p).unwrap(), bytes, "{}", p.display());
    }
    assert_eq!(decode(&encode_png(&img)), img);
}

/// The shipped quadrupeds, read from the repository.
fn quadrupeds() -> Vec<TriMesh> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("collections/quadrupeds");
    (0..3)
        .map(|i| coseg::mesh::read_mesh(dir.join(format!("quadrupeds_0{i}.obj"))).unwrap())
        .collect()
}

/// Different shapes, each moved at random, are drawn from one side: each view's axes, carried
/// back through the shape's motion, are the same directions of the unmoved files for every
/// shape (each shape's own principal frame is not: the quadrupeds' longest axes differ).
#[test]
fn collection_views_see_every_moved_shape_from_the_same_side() {
    let shapes = quadrupeds();
    let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(3);
    let motions: Vec<coseg::align::Similarity> = shapes
        .iter()
        .map(|_| common::motion::random_similarity(&mut rng))
        .collect();
    let moved: Vec<TriMesh> = shapes
        .iter()
        .zip(&motions)
        .map(|(m, t)| m.map_positions(|p| t.apply(p)).unwrap())
        .collect();
    let alignment =
        coseg::align::align_collection(&moved, &coseg::align::AlignOptions::default()).unwrap();
    assert_eq!(alignment.case, coseg::align::FrameCase::Synchronised);
    let views = collection_views(&moved, &alignment);
    // An axis of the view in the unmoved file's coordinates.
    let unmoved = |i: usize, k: usize| motions[i].inverse().rotate(views[i].axes[k]);
    let degrees = |a: [f64; 3], b: [f64; 3]| {
        let c = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        c.clamp(-1.0, 1.0).acos().to_degrees()
    };
    for i in 1..shapes.len() {
        for k in 0..3 {
            let angle = degrees(unmoved(0, k), unmoved(i, k));
            // The alignment places these quadrupeds within 5° of each other (tests/cli_align.rs);
            // a flipped or swapped axis is 90° or 180° off.
            assert!(angle < 10.0, "shape {i}, axis {k}: {angle}°");
        }
    }
}

/// Files whose frames already agree are drawn upright as written (`+y` on screen up, seen
/// from 20° above) and all from one camera.
#[test]
fn collection_views_keep_the_files_up_axis_when_already_aligned() {
    let meshes = quadrupeds();
    let alignment =
        coseg::align::align_collection(&meshes, &coseg::align::AlignOptions::default()).unwrap();
    assert_eq!(alignment.case, coseg::align::FrameCase::AlreadyAligned);
    let views = collection_views(&meshes, &alignment);
    for v in &views {
        assert!(
            (v.axes[1][1] - 20f64.to_radians().cos()).abs() < 1e-9,
            "{v:?}"
        );
        assert!(
            v.axes[0][1].abs() < 1e-9,
            "screen right is horizontal: {v:?}"
        );
        assert_eq!(v.axes, views[0].axes);
    }
    // Unlike each shape's own principal frame, which follows the longest axis.
    assert!(
        views
            .iter()
            .zip(&meshes)
            .any(|(v, m)| canonical_frame(m).axes != v.axes)
    );
}
