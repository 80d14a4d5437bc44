//! [`SurfaceOperators`]: the cotangent weights, Laplacian and unit-area mass of one mesh, under
//! one rule for clamped and degenerate triangles, shared by the spectrum, the heat smoother
//! and the mean curvature.

use super::cotangent_weights::{assemble, halved_within_bound, resolved};
use crate::mesh::{TriMesh, cross, dot, norm, sub};
use faer::sparse::SparseColMat;

/// Which triangulation the cotangent Laplacian is built on ([`SurfaceOperators::with_laplacian`],
/// [`super::SpectrumOptions::laplacian`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub enum LaplacianKind {
    /// The mesh's own triangles (default): the classic cotangent Laplacian.
    #[default]
    Cotangent,
    /// The intrinsic Delaunay triangulation of the mesh ([`super::IntrinsicDelaunay`]): the
    /// same surface and vertices, edges flipped until every weight is non-negative. Robust to
    /// obtuse triangles and slivers (CAD exports, uneven sampling); costs one flip pass.
    IntrinsicDelaunay,
}

impl LaplacianKind {
    /// True for the default, [`LaplacianKind::Cotangent`] (lets option structs leave it out of
    /// their serialised form, so the cache keys of default runs are unchanged).
    pub fn is_cotangent(&self) -> bool {
        *self == LaplacianKind::Cotangent
    }
}

/// The name `coseg --laplacian` takes (`cotan`, `intrinsic-delaunay`).
impl std::fmt::Display for LaplacianKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            LaplacianKind::Cotangent => "cotan",
            LaplacianKind::IntrinsicDelaunay => "intrinsic-delaunay",
        })
    }
}

impl std::str::FromStr for LaplacianKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "cotan" | "cotangent" => Ok(LaplacianKind::Cotangent),
            "intrinsic-delaunay" | "idt" => Ok(LaplacianKind::IntrinsicDelaunay),
            other => Err(format!(
                "unknown Laplacian {other:?}: expected cotan or intrinsic-delaunay"
            )),
        }
    }
}

/// The surface operators of one mesh (`d` vertices, `F` faces), computed once and shared by
/// every algorithm that needs them ([`crate::spectral::laplace_beltrami_spectrum`],
/// [`crate::spectral::HeatSmoother`], [`crate::features::mean_curvature`]):
///
/// - `half_cotangents`: `F × 3`, `cot(θ_k) / 2` of the angle at corner `k` of each face (the
///   weight of the opposite edge `(k+1, k+2)`), under **the one rule** of this crate: a face
///   with a corner of zero, negative or non-finite `|u × v|` is degenerate and gets three
///   zeros, and so does a face whose computed cotangents are rounding noise (collinear up to
///   rounding: they break `c₀c₁ + c₁c₂ + c₂c₀ = 1`, see [`unresolved_triangles`]); a face
///   whose largest `|cot|` exceeds `MAX_COTANGENT` has all three scaled by the
///   same factor (keeps each face's stiffness matrix positive semi-definite, whereas clamping
///   each cotangent apart can make a needle triangle indefinite);
/// - `laplacian`: `d × d`, the weak cotangent Laplacian `L` assembled from those weights,
///   `L_ij = −Σ half-cotangents of edge ij`, `L_ii = −Σ_j L_ij` (so `L 1 = 0`), symmetric
///   positive semi-definite, dimensionless (the same for the mesh scaled to unit area);
/// - `vertex_areas`: length `d`, the barycentric (lumped) vertex areas as read, from the
///   faces with weights (a degenerate face has no area to give, or none that rounding
///   resolves);
/// - `unit_mass`: length `d`, the barycentric (lumped) vertex areas of the mesh scaled to
///   unit total area (they sum to 1 up to rounding; unreferenced vertices get 0);
/// - `total_area`: the mesh's area as read, squared file units.
///
/// ```
/// use coseg::{mesh::TriMesh, spectral::SurfaceOperators};
/// let m = TriMesh::new(vec![[0.,0.,0.],[2.,0.,0.],[2.,2.,0.],[0.,2.,0.]], vec![[0,1,2],[0,2,3]]).unwrap();
/// let ops = SurfaceOperators::new(&m);
/// assert_eq!(ops.total_area(), 4.0);
/// assert!((ops.unit_mass().iter().sum::<f64>() - 1.0).abs() < 1e-15);
/// assert_eq!(ops.laplacian().nrows(), 4);
/// ```
///
/// See also [`crate::spectral::cotan_laplacian`], [`crate::spectral::lumped_mass`].
#[derive(Debug, Clone)]
pub struct SurfaceOperators {
    /// The triangles the weights refer to when they are not the mesh's own (intrinsic
    /// Delaunay); `None`: the mesh's faces.
    faces: Option<Vec<[u32; 3]>>,
    half_cotangents: Vec<[f64; 3]>,
    laplacian: SparseColMat<usize, f64>,
    vertex_areas: Vec<f64>,
    unit_mass: Vec<f64>,
    total_area: f64,
}

impl SurfaceOperators {
    /// Computes the operators of `mesh`: O(F) time and memory.
    pub fn new(mesh: &TriMesh) -> Self {
        let weights = half_cotangents(mesh);
        let areas = weighted_vertex_areas(mesh, mesh.faces(), &weights);
        Self::on(mesh, None, weights, areas)
    }

    /// The operators from per-corner weights on `faces` (`None`: the mesh's own) and lumped
    /// areas; the unit-area mass is taken against the mesh's area either way.
    fn on(
        mesh: &TriMesh,
        faces: Option<Vec<[u32; 3]>>,
        half_cotangents: Vec<[f64; 3]>,
        vertex_areas: Vec<f64>,
    ) -> Self {
        let triangles = faces.as_deref().unwrap_or(mesh.faces());
        let laplacian = assemble(mesh.vertex_count(), triangles, &half_cotangents);
        let total_area = mesh.total_area();
        let unit_mass = vertex_areas.iter().map(|m| m / total_area).collect();
        SurfaceOperators {
            faces,
            half_cotangents,
            laplacian,
            vertex_areas,
            unit_mass,
            total_area,
        }
    }

    /// The operators on the triangulation `kind` names: [`LaplacianKind::Cotangent`] is
    /// [`Self::new`]; [`LaplacianKind::IntrinsicDelaunay`] builds the weights, Laplacian and
    /// lumped areas on the mesh's intrinsic Delaunay triangulation
    /// ([`super::IntrinsicDelaunay`]: same vertices and surface, non-negative weights), and
    /// [`Self::faces`] then returns its triangles. `total_area` is the mesh's either way.
    ///
    /// ```
    /// use coseg::{mesh::TriMesh, spectral::{LaplacianKind, SurfaceOperators}};
    /// let m = TriMesh::new(
    ///     vec![[0., 0., 0.], [1., 0.2, 0.], [2., 0., 0.], [1., -0.2, 0.]],
    ///     vec![[0, 3, 2], [0, 2, 1]],
    /// ).unwrap();
    /// let idt = SurfaceOperators::with_laplacian(&m, LaplacianKind::IntrinsicDelaunay);
    /// assert!(idt.laplacian().triplet_iter().all(|t| t.row == t.col || *t.val <= 0.0));
    /// assert!((idt.unit_mass().iter().sum::<f64>() - 1.0).abs() < 1e-12); // flips keep the area
    /// ```
    pub fn with_laplacian(mesh: &TriMesh, kind: LaplacianKind) -> Self {
        match kind {
            LaplacianKind::Cotangent => Self::new(mesh),
            LaplacianKind::IntrinsicDelaunay => {
                let idt = super::IntrinsicDelaunay::new(mesh);
                let areas = idt.vertex_areas(mesh.vertex_count());
                Self::on(
                    mesh,
                    Some(idt.faces().to_vec()),
                    idt.half_cotangents(),
                    areas,
                )
            }
        }
    }

    /// The triangles the weights refer to (`F × 3`): the mesh's own, or the intrinsic
    /// Delaunay triangulation's under [`LaplacianKind::IntrinsicDelaunay`].
    pub fn faces<'a>(&'a self, mesh: &'a TriMesh) -> &'a [[u32; 3]] {
        self.faces.as_deref().unwrap_or(mesh.faces())
    }

    /// `cot(θ_k) / 2` per face corner (`F × 3`, corners of [`Self::faces`]), under the rule
    /// stated on the type.
    pub fn half_cotangents(&self) -> &[[f64; 3]] {
        &self.half_cotangents
    }

    /// The cotangent Laplacian `L` (`d × d`).
    pub fn laplacian(&self) -> &SparseColMat<usize, f64> {
        &self.laplacian
    }

    /// Lumped (barycentric) vertex areas of the mesh as read (length `d`, squared file units).
    pub fn vertex_areas(&self) -> &[f64] {
        &self.vertex_areas
    }

    /// Lumped mass of the unit-area mesh (length `d`): [`Self::vertex_areas`] over
    /// [`Self::total_area`].
    pub fn unit_mass(&self) -> &[f64] {
        &self.unit_mass
    }

    /// Total area of the mesh as read (squared file units).
    pub fn total_area(&self) -> f64 {
        self.total_area
    }

    /// Number of vertices `d`.
    pub fn vertex_count(&self) -> usize {
        self.unit_mass.len()
    }

    /// `L X` for `d` points `X` (e.g. the vertex positions), assembled face by face from the
    /// same weights as [`Self::laplacian`] without a sparse product: `(L X)_i = Σ_j w_ij (x_i −
    /// x_j)`. `mesh` must be the mesh the operators were built from.
    pub fn laplacian_times(&self, mesh: &TriMesh, x: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let mut lx = vec![[0.0f64; 3]; x.len()];
        for (idx, w) in self.faces(mesh).iter().zip(&self.half_cotangents) {
            for (k, &wk) in w.iter().enumerate() {
                if wk == 0.0 {
                    continue;
                }
                let (a, b) = (idx[(k + 1) % 3] as usize, idx[(k + 2) % 3] as usize);
                for c in 0..3 {
                    let e = wk * (x[a][c] - x[b][c]);
                    lx[a][c] += e;
                    lx[b][c] -= e;
                }
            }
        }
        lx
    }

    /// `Σ_j |w_ij|` for every vertex `i` (length `d`): the off-diagonal weights of
    /// [`Self::laplacian`] in absolute value, summed per row (half-cotangents of obtuse corners
    /// are negative). How far `(L X)_i` can move when every coordinate of `X` moves by at most
    /// `ε`: `2 ε Σ_j |w_ij|` per component. `mesh` must be the mesh the operators were built
    /// from.
    pub fn absolute_weight_sums(&self, mesh: &TriMesh) -> Vec<f64> {
        let mut s = vec![0.0f64; self.vertex_count()];
        for (idx, w) in self.faces(mesh).iter().zip(&self.half_cotangents) {
            for (k, &wk) in w.iter().enumerate() {
                let (a, b) = (idx[(k + 1) % 3] as usize, idx[(k + 2) % 3] as usize);
                s[a] += wk.abs();
                s[b] += wk.abs();
            }
        }
        s
    }
}

/// The cotangent Laplacian alone (see [`super::cotan_laplacian`]).
pub(super) fn laplacian(mesh: &TriMesh) -> SparseColMat<usize, f64> {
    assemble(mesh.vertex_count(), mesh.faces(), &half_cotangents(mesh))
}

/// The per-corner half-cotangents of every face under the rule of [`SurfaceOperators`].
pub(super) fn half_cotangents(mesh: &TriMesh) -> Vec<[f64; 3]> {
    (0..mesh.face_count())
        .map(|f| corner_cotangents(mesh.corners(f)).map_or([0.0; 3], halved_within_bound))
        .collect()
}

/// Cotangent of the angle at each corner `k` (opposite edge `(k+1, k+2)`); `None` for a
/// degenerate triangle (a corner of zero, negative or non-finite `|u × v|`).
fn corner_cotangents(p: [[f64; 3]; 3]) -> Option<[f64; 3]> {
    let mut cot = [0.0f64; 3];
    for (k, ck) in cot.iter_mut().enumerate() {
        let u = sub(p[(k + 1) % 3], p[k]);
        let v = sub(p[(k + 2) % 3], p[k]);
        let c = norm(cross(u, v));
        if c.is_nan() || c <= 0.0 || !c.is_finite() {
            return None;
        }
        *ck = dot(u, v) / c;
    }
    Some(cot)
}

/// Vertex areas of the triangles that carry weights (`half_cotangents` not all zero): the
/// lumped mass of [`TriMesh::vertex_areas`], without the triangles the rule of
/// [`SurfaceOperators`] treats as zero-area. Summed in the same order, so a mesh with no such
/// triangle gets the same bits.
pub(super) fn weighted_vertex_areas(
    mesh: &TriMesh,
    faces: &[[u32; 3]],
    half_cotangents: &[[f64; 3]],
) -> Vec<f64> {
    let mut w = vec![0.0; mesh.vertex_count()];
    for ((f, a), hc) in faces.iter().zip(mesh.face_areas()).zip(half_cotangents) {
        if *hc == [0.0; 3] {
            continue;
        }
        for &i in f {
            w[i as usize] += a / 3.0;
        }
    }
    w
}

/// How many triangles of `mesh` have a positive area as computed, yet cotangents that are
/// rounding noise, which the rule of [`SurfaceOperators`] treats as zero-area (no weight, no
/// mass): triangles whose vertices are collinear up to rounding. 0 on every sound mesh. O(F).
///
/// ```
/// use coseg::{mesh::TriMesh, spectral::unresolved_triangles};
/// // A vertex a third of the way along the edge 0–1, which rounding puts a hair off it.
/// let (a, b) = ([0.1, 0.7, 0.3], [0.9, 0.2, 0.6]);
/// let p = [0, 1, 2].map(|k| a[k] + (b[k] - a[k]) / 3.0);
/// let m = TriMesh::new(vec![a, b, [0.5, 1.5, 0.0], p], vec![[0, 1, 2], [0, 3, 1]]).unwrap();
/// assert_eq!(unresolved_triangles(&m), 1);
/// ```
pub fn unresolved_triangles(mesh: &TriMesh) -> usize {
    (0..mesh.face_count())
        .filter(|&f| corner_cotangents(mesh.corners(f)).is_some_and(|cot| !resolved(cot)))
        .count()
}
