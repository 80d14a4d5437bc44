//! Fixtures for the shipped shape collections (`collections/<family>/`).

use std::path::PathBuf;

/// `collections/` at the crate root.
pub fn collections_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("collections")
}

/// Reads a `<name>.labels.txt` file: one non-negative integer per line.
pub fn read_labels(path: &std::path::Path) -> Vec<u32> {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .map(|l| {
            l.trim()
                .parse()
                .unwrap_or_else(|e| panic!("{}: bad label {l:?}: {e}", path.display()))
        })
        .collect()
}

/// Signed volume enclosed by a closed mesh (positive when its faces are oriented outwards).
pub fn signed_volume(mesh: &coseg::mesh::TriMesh) -> f64 {
    let p = mesh.positions();
    mesh.faces()
        .iter()
        .map(|f| {
            let (a, b, c) = (p[f[0] as usize], p[f[1] as usize], p[f[2] as usize]);
            (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]))
                / 6.0
        })
        .sum()
}

/// Whether every directed edge of `mesh` is in one face at most (neighbouring faces list their
/// shared edge in opposite directions).
pub fn consistently_oriented(mesh: &coseg::mesh::TriMesh) -> bool {
    let mut directed: Vec<(u32, u32)> = mesh
        .faces()
        .iter()
        .flat_map(|f| [(f[0], f[1]), (f[1], f[2]), (f[2], f[0])])
        .collect();
    directed.sort_unstable();
    let n = directed.len();
    directed.dedup();
    directed.len() == n
}

/// Panics unless `mesh` is a closed, consistently oriented 2-manifold with one component:
/// every undirected edge in exactly two faces, every directed edge in exactly one.
pub fn assert_closed_oriented_single(mesh: &coseg::mesh::TriMesh, what: &str) {
    let (_, counts) = coseg::mesh::edges(mesh);
    assert!(
        counts.iter().all(|&c| c == 2),
        "{what}: an edge is not shared by exactly 2 faces"
    );
    assert!(
        consistently_oriented(mesh),
        "{what}: inconsistent orientation"
    );
    assert_eq!(
        coseg::mesh::connected_components(mesh).count,
        1,
        "{what}: not a single component"
    );
    assert!(signed_volume(mesh) > 0.0, "{what}: not oriented outwards");
}

/// Reads the OBJ files of `collections/` (`v x y z` and `f a b c` lines, 1-based) without the
/// mesh module's reader, so the shipped files are checked independently of it.
pub fn read_collection_obj(path: &std::path::Path) -> coseg::mesh::TriMesh {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut positions = Vec::new();
    let mut faces = Vec::new();
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let v: Vec<f64> = it.map(|x| x.parse().unwrap()).collect();
                positions.push([v[0], v[1], v[2]]);
            }
            Some("f") => {
                let f: Vec<u32> = it.map(|x| x.parse::<u32>().unwrap() - 1).collect();
                faces.push([f[0], f[1], f[2]]);
            }
            _ => {}
        }
    }
    coseg::mesh::TriMesh::new(positions, faces).unwrap()
}

/// The first `count` shipped goblets copied into `dir/shapes` (a collection a test may write
/// beside); the folder.
pub fn goblets(dir: &std::path::Path, count: usize) -> PathBuf {
    let folder = dir.join("shapes");
    std::fs::create_dir_all(&folder).unwrap();
    for i in 0..count {
        let name = format!("goblets_{i:02}.obj");
        std::fs::copy(
            collections_dir().join("goblets").join(&name),
            folder.join(&name),
        )
        .unwrap();
    }
    folder
}
