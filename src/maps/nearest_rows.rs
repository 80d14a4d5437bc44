//! k-nearest-row search between two row sets (Euclidean): exact brute force for small bases,
//! clustered (an inverted file) for large ones; used by [`zoomout`](super::zoomout)'s point
//! maps.
//!
//! Why clusters: ZoomOut's last match compares every vertex of B with every vertex of A in a
//! space of 150–450 coordinates, `N_A · N_B · D` multiply-adds (10¹² on the 50k-vertex TOSCA
//! pairs). The rows are a function of the surface point, so a row's nearest rows sit in a few
//! of the clusters nearest to it; searching only those is ~15× cheaper at 50k vertices. Not
//! exact: a candidate in an unprobed cluster is missed. The triangle-inequality bound that
//! would make it exact prunes nothing on these embeddings (the descriptor columns are noisy),
//! measured on victoria0 × david0.
//!
//! The base is reordered in place cluster by cluster and the query rows are read a block at a
//! time through [`QueryRows`], so the search holds no copy of either (docs/PERFORMANCE.md,
//! "Fourth pass"). The clustered search compares rows in single precision (products in `f32`,
//! norms and sums in `f64`): half the memory traffic and twice the SIMD width of the products
//! that dominate it, for a TOSCA correspondence ratio within noise of the double-precision
//! search (docs/PERFORMANCE.md, "Fifth pass").

use super::CandidateLists;
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatMut, MatRef, Par};
use rayon::prelude::*;

/// Rows of `query` per block of the brute-force search: fixed, so the result does not depend
/// on the thread count.
const QUERY_BLOCK: usize = 128;

/// Below this many base rows the search is exact brute force.
const PRUNE_FROM: usize = 8192;

/// Target number of base rows per cluster of the clustered search.
const CLUSTER_SIZE: usize = 64;

/// Queries per group of the clustered search at most (a group shares its clusters).
const GROUP_SIZE: usize = 128;

/// Clusters probed per query by the clustered search, at least. 5 instead of 10 halved the
/// search for the same TOSCA correspondence ratio (docs/PERFORMANCE.md, "Map step").
const PROBES: usize = 5;

/// For every row of `query`, the `count` nearest rows of `base` (capped by its rows) and
/// their squared distances, nearest first; ties go to the lowest index. Both have the same
/// number of columns. A NaN distance ranks last.
///
/// The squared distance of base row `a` and query row `q` is `(‖a‖² − 2 a·q) + ‖q‖²`, clamped
/// at 0. With at least `PRUNE_FROM` base rows (and no NaN) only the members of each query's
/// nearest clusters are compared (see the module notes), in single precision: every returned
/// candidate is a row of `base` and its cost that of the rows rounded to `f32` (relative
/// error ~10⁻⁶ of the norms), but a near row in an unprobed cluster can be missed and two rows
/// within rounding of each other can rank either way.
///
/// This is ZoomOut's last-match search; it is public for benchmarks (`benches/core.rs`).
pub fn nearest_candidates(
    base: MatRef<'_, f64>,
    query: MatRef<'_, f64>,
    count: usize,
) -> CandidateLists {
    double_candidates(base, &query, count)
}

/// [`nearest_candidates`] for any query rows.
fn double_candidates<Q: QueryRows + ?Sized>(
    base: MatRef<'_, f64>,
    query: &Q,
    count: usize,
) -> CandidateLists {
    if clustered(&base, query) {
        clustered_candidates(single(base), query, count)
    } else {
        brute_force_candidates(base, query, count)
    }
}

/// A search's base, owned so that the clustered search can reorder it in place (which saves
/// a copy as large as the base): in double precision for the brute force, in single for the
/// clustered search ([`in_single`] says which a base of so many rows takes).
pub(crate) enum OwnedBase {
    /// Rows in double precision.
    Double(Mat<f64>),
    /// Rows in single precision.
    Single(Mat<f32>),
}

impl OwnedBase {
    /// Number of rows.
    pub(crate) fn nrows(&self) -> usize {
        match self {
            OwnedBase::Double(m) => m.nrows(),
            OwnedBase::Single(m) => m.nrows(),
        }
    }
}

/// Whether a base of `rows` rows is best built in single precision: it is when the search
/// will be the clustered one (unless a NaN sends it to the brute force).
pub(crate) fn in_single(rows: usize) -> bool {
    rows >= PRUNE_FROM
}

/// [`nearest_candidates`] with an owned base (see [`OwnedBase`]). A single-precision base
/// that holds a NaN or an infinity is searched by brute force, widened.
pub(crate) fn nearest_candidates_owned<Q: QueryRows + ?Sized>(
    base: OwnedBase,
    query: &Q,
    count: usize,
) -> CandidateLists {
    match base {
        OwnedBase::Double(base) => double_candidates(base.as_ref(), query, count),
        OwnedBase::Single(base) if clustered(&base.as_ref(), query) => {
            clustered_candidates(base, query, count)
        }
        OwnedBase::Single(base) => {
            let wide =
                Mat::<f64>::from_fn(base.nrows(), base.ncols(), |i, j| f64::from(base[(i, j)]));
            brute_force_candidates(wide.as_ref(), query, count)
        }
    }
}

/// Whether [`nearest_candidates`] takes the clustered search: a large base, and no NaN
/// (whose ranking the centre distances cannot follow).
fn clustered<B: QueryRows + ?Sized, Q: QueryRows + ?Sized>(base: &B, query: &Q) -> bool {
    base.nrows() >= PRUNE_FROM && query.nrows() > 0 && base.is_finite() && query.is_finite()
}

/// The element types a base is held in (double for the brute force, single for the
/// clustered search).
pub(crate) trait Element: faer::traits::ComplexField + Copy + Send + Sync + 'static {
    /// The value in double precision.
    fn widen(self) -> f64;
}

impl Element for f64 {
    fn widen(self) -> f64 {
        self
    }
}

impl Element for f32 {
    fn widen(self) -> f64 {
        f64::from(self)
    }
}

/// The rows a search compares with the base, read a block of rows at a time: a matrix, or
/// an embedding assembled block by block (ZoomOut's last match never holds B's whole
/// embedding, 190 MB on a 50k-vertex shape).
pub(crate) trait QueryRows: Sync {
    /// Number of rows.
    fn nrows(&self) -> usize;
    /// The rows `rows`, in that order (`rows.len() ×` the number of columns).
    fn rows(&self, rows: &[usize]) -> Mat<f64>;
    /// [`rows`](QueryRows::rows) rounded to single precision.
    fn single_rows(&self, rows: &[usize]) -> Mat<f32> {
        single(self.rows(rows).as_ref())
    }
    /// Whether every entry is finite.
    fn is_finite(&self) -> bool {
        let n = self.nrows();
        (0..n).step_by(4096).all(|r0| {
            let block = self.rows(&(r0..n.min(r0 + 4096)).collect::<Vec<_>>());
            (0..block.ncols()).all(|j| block.col(j).iter().all(|x| x.is_finite()))
        })
    }
}

/// A base in single precision, as the rows its clusters are found from.
impl QueryRows for MatRef<'_, f32> {
    fn nrows(&self) -> usize {
        MatRef::nrows(self)
    }

    fn rows(&self, rows: &[usize]) -> Mat<f64> {
        let m = gather_rows(*self, rows);
        Mat::from_fn(m.nrows(), m.ncols(), |i, j| f64::from(m[(i, j)]))
    }

    fn single_rows(&self, rows: &[usize]) -> Mat<f32> {
        gather_rows(*self, rows)
    }

    fn is_finite(&self) -> bool {
        (0..self.ncols()).all(|j| self.col(j).iter().all(|x| x.is_finite()))
    }
}

impl QueryRows for MatRef<'_, f64> {
    fn nrows(&self) -> usize {
        MatRef::nrows(self)
    }

    fn rows(&self, rows: &[usize]) -> Mat<f64> {
        gather_rows(*self, rows)
    }

    fn is_finite(&self) -> bool {
        (0..self.ncols()).all(|j| self.col(j).iter().all(|x| x.is_finite()))
    }
}

/// Every row's squared norm, summed in double precision.
fn row_norms<T: Element>(m: MatRef<'_, T>) -> Vec<f64> {
    let mut norms = vec![0.0; m.nrows()];
    for j in 0..m.ncols() {
        for (s, &x) in norms.iter_mut().zip(m.col(j).iter()) {
            let x = x.widen();
            *s += x * x;
        }
    }
    norms
}

/// The rows `rows` of `m`, in that order (`rows.len() × m.ncols()`): column by column, so
/// every read of a column-major `m` stays within one column.
///
/// Why not `Mat::from_fn`: its per-element closure with two-dimensional indexing cost as
/// much as the distance products it feeds (a quarter of `coseg pair`'s CPU on the 50k-vertex
/// TOSCA pair, measured with `perf`).
pub(crate) fn gather_rows<T: Element>(m: MatRef<'_, T>, rows: &[usize]) -> Mat<T> {
    let mut out = Mat::<T>::zeros(rows.len(), m.ncols());
    gather_rows_into(out.as_mut(), m, rows);
    out
}

/// [`gather_rows`] into `out` (`rows.len() × m.ncols()`, column-major).
fn gather_rows_into<T: Element>(mut out: MatMut<'_, T>, m: MatRef<'_, T>, rows: &[usize]) {
    for j in 0..m.ncols() {
        let dst = col_slice_mut(out.as_mut(), j);
        match m.col(j).try_as_col_major() {
            Some(src) => {
                let src = src.as_slice();
                for (d, &r) in dst.iter_mut().zip(rows) {
                    *d = src[r];
                }
            }
            None => {
                let src = m.col(j);
                for (d, &r) in dst.iter_mut().zip(rows) {
                    *d = src[r];
                }
            }
        }
    }
}

/// Column `j` of `m` as a slice: the matrices here are faer's own, column-major.
pub(crate) fn col_slice_mut<T>(m: MatMut<'_, T>, j: usize) -> &mut [T] {
    m.col_mut(j)
        .try_as_col_major_mut()
        .expect("column-major")
        .as_slice_mut()
}

/// `m` in single precision, column by column.
pub(crate) fn single(m: MatRef<'_, f64>) -> Mat<f32> {
    let mut out = Mat::<f32>::zeros(m.nrows(), m.ncols());
    for j in 0..m.ncols() {
        let dst = col_slice_mut(out.as_mut(), j);
        for (d, &x) in dst.iter_mut().zip(m.col(j).iter()) {
            *d = x as f32;
        }
    }
    out
}

/// `out = a · bᵀ` (`a.nrows() × b.nrows()`), sequential.
fn dots<T: faer::traits::ComplexField>(a: MatRef<'_, T>, b: MatRef<'_, T>) -> Mat<T> {
    let mut out = Mat::<T>::zeros(a.nrows(), b.nrows());
    matmul(
        out.as_mut(),
        Accum::Replace,
        a,
        b.transpose(),
        T::one_impl(),
        Par::Seq,
    );
    out
}

/// A query, its squared norm and its nearest rows, as `(‖a‖² − 2 a·q, a)` pairs, nearest
/// first.
type Neighbours = (u32, f64, Vec<(f64, u32)>);

/// Keeps the `count` smallest `(d, index)` pairs of a stream, sorted ascending.
struct TopK {
    count: usize,
    best: Vec<(f64, u32)>,
}

impl TopK {
    fn new(count: usize) -> Self {
        TopK {
            count,
            best: Vec::with_capacity(count + 1),
        }
    }

    fn clear(&mut self) {
        self.best.clear();
    }

    /// Offers a candidate; `(d, i)` pairs are ordered lexicographically, so equal distances
    /// keep the lowest index whatever the order of the offers.
    #[inline]
    fn offer(&mut self, d: f64, i: u32) {
        let d = if d.is_nan() { f64::INFINITY } else { d };
        let full = self.best.len() == self.count;
        if full {
            let last = self.best[self.count - 1];
            if d > last.0 || (d == last.0 && i > last.1) {
                return;
            }
        }
        let at = self
            .best
            .partition_point(|x| x.0 < d || (x.0 == d && x.1 < i));
        self.best.insert(at, (d, i));
        self.best.truncate(self.count);
    }
}

/// Every base row against every query row, in fixed query blocks.
fn brute_force_candidates<Q: QueryRows + ?Sized>(
    base: MatRef<'_, f64>,
    query: &Q,
    count: usize,
) -> CandidateLists {
    let n = base.nrows();
    let count = count.min(n).max(1);
    let norms = row_norms(base);
    let starts: Vec<usize> = (0..query.nrows()).step_by(QUERY_BLOCK).collect();
    let blocks: Vec<(Vec<u32>, Vec<f64>)> = starts
        .par_iter()
        .map(|&r0| {
            let m = QUERY_BLOCK.min(query.nrows() - r0);
            let block = query.rows(&(r0..r0 + m).collect::<Vec<_>>());
            let dots = dots(base, block.as_ref());
            let q_norms = row_norms(block.as_ref());
            let (mut targets, mut costs) =
                (Vec::with_capacity(m * count), Vec::with_capacity(m * count));
            let mut top = TopK::new(count);
            for (j, &q_norm) in q_norms.iter().enumerate() {
                let col = dots.col(j).try_as_col_major().expect("owned").as_slice();
                if count == 1 {
                    // ZoomOut's steps ask for the nearest row only: a plain minimum, with
                    // `TopK`'s rules (NaN ranks last, ties to the lowest index).
                    let (i, d) = nearest_one(&norms, col);
                    targets.push(i as u32);
                    costs.push((d + q_norm).max(0.0));
                    continue;
                }
                top.clear();
                // `‖a‖² − 2 a·q` orders the rows as the squared distance does; `‖q‖²` is added
                // to the kept ones only.
                for (i, &norm) in norms.iter().enumerate() {
                    top.offer(norm - 2.0 * col[i], i as u32);
                }
                targets.extend(top.best.iter().map(|&(_, i)| i));
                costs.extend(top.best.iter().map(|&(d, _)| (d + q_norm).max(0.0)));
            }
            (targets, costs)
        })
        .collect();
    CandidateLists {
        per_query: count,
        targets: blocks.iter().flat_map(|b| b.0.iter().copied()).collect(),
        costs: blocks.iter().flat_map(|b| b.1.iter().copied()).collect(),
    }
}

/// The index and value of the smallest `norms[i] − 2 col[i]`, a NaN ranking as +∞ and ties
/// going to the lowest index (as [`TopK`] with one slot), over `norms.len() ≥ 1` rows.
///
/// Two passes, because the first vectorises: eight running minima (a NaN never wins a `<`),
/// then the first row whose value equals the least of them. A scan that kept the index
/// alongside the minimum did not vectorise and was a tenth of `coseg pair`'s CPU on TOSCA's
/// dog0 × cat0 (ZoomOut's steps, `perf`).
fn nearest_one(norms: &[f64], col: &[f64]) -> (usize, f64) {
    const LANES: usize = 8;
    let key = |n: f64, c: f64| n - 2.0 * c;
    let mut lanes = [f64::INFINITY; LANES];
    let (norm_chunks, col_chunks) = (norms.chunks_exact(LANES), col.chunks_exact(LANES));
    let (norm_rest, col_rest) = (norm_chunks.remainder(), col_chunks.remainder());
    for (n, c) in norm_chunks.zip(col_chunks) {
        for l in 0..LANES {
            let d = key(n[l], c[l]);
            lanes[l] = if d < lanes[l] { d } else { lanes[l] };
        }
    }
    for (&n, &c) in norm_rest.iter().zip(col_rest) {
        let d = key(n, c);
        lanes[0] = if d < lanes[0] { d } else { lanes[0] };
    }
    let least = lanes
        .iter()
        .fold(f64::INFINITY, |m, &x| if x < m { x } else { m });
    // Every value is a number, +∞ or NaN; with none below +∞ the first row wins, as it would
    // in a scan that starts from row 0 and replaces only on `<`.
    let i = if least == f64::INFINITY {
        0
    } else {
        norms
            .iter()
            .zip(col)
            .position(|(&n, &c)| key(n, c) == least)
            .expect("the least is one of the values")
    };
    let d = key(norms[i], col[i]);
    (i, if d.is_nan() { f64::INFINITY } else { d })
}

/// Base rows grouped into clusters around fixed centres (every `n / C`-th row), the base
/// reordered so that every cluster is one run of rows.
struct Clusters {
    /// `C × D` centre rows, in single precision: they only rank centres (see
    /// [`probed_clusters`]).
    centres: Mat<f32>,
    centre_norms: Vec<f64>,
    /// Cluster `j` is rows `starts[j]..starts[j + 1]` of the reordered base (`C + 1`).
    starts: Vec<usize>,
    /// The original index of every row of the reordered base: clusters in order, each
    /// cluster's members ascending.
    original: Vec<u32>,
}

impl Clusters {
    fn count(&self) -> usize {
        self.starts.len() - 1
    }

    fn size(&self, j: usize) -> usize {
        self.starts[j + 1] - self.starts[j]
    }
}

/// For every row of `rows`, its clusters nearest first (ties to the lowest) until they hold
/// `count` members and number at least `probes`.
///
/// The centre distances are products in single precision (`‖c‖²` stays double): they only
/// choose which clusters a row is compared with, and the comparisons themselves are in double
/// precision. That halved the cost of clustering and probing (half of the search on
/// victoria0 × david0) and left the pair's regions unchanged there and on dog0 × cat0;
/// where two centres are within single-precision rounding of each other the other may be
/// probed.
fn probed_clusters<R: QueryRows + ?Sized>(
    rows: &R,
    c: &Clusters,
    probes: usize,
    count: usize,
) -> Vec<Vec<u32>> {
    let cmp = |x: &(f64, u32), y: &(f64, u32)| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1));
    let starts: Vec<usize> = (0..rows.nrows()).step_by(1024).collect();
    starts
        .par_iter()
        .flat_map_iter(|&r0| {
            let m = 1024.min(rows.nrows() - r0);
            // Centres × rows, so that each row's distances are one contiguous column.
            let block = rows.single_rows(&(r0..r0 + m).collect::<Vec<_>>());
            let d = dots(c.centres.as_ref(), block.as_ref());
            let mut nearest: Vec<(f64, u32)> = Vec::with_capacity(probes + 1);
            (0..m)
                .map(|i| {
                    let col = d.col(i).try_as_col_major().expect("owned").as_slice();
                    // The `probes` nearest centres by one pass that keeps them sorted: most
                    // centres are rejected by one comparison with the farthest kept.
                    nearest.clear();
                    for (j, (&cn, &dot)) in c.centre_norms.iter().zip(col).enumerate() {
                        let x = (cn - 2.0 * f64::from(dot), j as u32);
                        if nearest.len() == probes
                            && cmp(&x, &nearest[probes - 1]) != std::cmp::Ordering::Less
                        {
                            continue;
                        }
                        let at = nearest.partition_point(|y| cmp(y, &x).is_lt());
                        nearest.insert(at, x);
                        nearest.truncate(probes);
                    }
                    let mut held: usize = nearest.iter().map(|&(_, j)| c.size(j as usize)).sum();
                    let mut out: Vec<u32> = nearest.iter().map(|&(_, j)| j).collect();
                    if held < count {
                        // Rare (small clusters): every other centre, nearest first.
                        let mut rest: Vec<(f64, u32)> = c
                            .centre_norms
                            .iter()
                            .zip(col)
                            .enumerate()
                            .map(|(j, (&cn, &dot))| (cn - 2.0 * f64::from(dot), j as u32))
                            .filter(|x| nearest.iter().all(|y| y.1 != x.1))
                            .collect();
                        rest.sort_unstable_by(cmp);
                        for &(_, j) in &rest {
                            if held >= count {
                                break;
                            }
                            out.push(j);
                            held += c.size(j as usize);
                        }
                    }
                    out
                })
                .collect::<Vec<_>>()
        })
        .collect()
}

/// Clusters `base` and reorders its rows in place, cluster by cluster.
///
/// Why reorder: a group of queries searches ~10 clusters of ~64 rows; gathering those rows
/// from a column-major base one by one was a tenth of `coseg pair`'s CPU on the 50k-vertex
/// TOSCA pair (`perf`), and runs of rows copy as whole cache lines.
fn clusters(base: &mut Mat<f32>) -> Clusters {
    let n = base.nrows();
    let count = (n / CLUSTER_SIZE).max(1);
    let rows: Vec<usize> = (0..count).map(|i| i * n / count).collect();
    let centres = gather_rows(base.as_ref(), &rows);
    let centre_norms = row_norms(centres.as_ref());
    let mut c = Clusters {
        centres,
        centre_norms,
        starts: vec![0; count + 1],
        original: Vec::new(),
    };
    let nearest: Vec<u32> = probed_clusters(&base.as_ref(), &c, 1, 0)
        .into_iter()
        .map(|p| p[0])
        .collect();
    for &j in &nearest {
        c.starts[j as usize + 1] += 1;
    }
    for j in 0..count {
        c.starts[j + 1] += c.starts[j];
    }
    let mut next = c.starts.clone();
    c.original = vec![0; n];
    for (v, &j) in nearest.iter().enumerate() {
        c.original[next[j as usize]] = v as u32;
        next[j as usize] += 1;
    }
    let original = &c.original;
    base.as_mut().par_col_iter_mut().for_each(|col| {
        let col = col.try_as_col_major_mut().expect("owned").as_slice_mut();
        let old = col.to_vec();
        for (x, &o) in col.iter_mut().zip(original) {
            *x = old[o as usize];
        }
    });
    c
}

/// The clustered search (an inverted file): queries are grouped by their nearest centre;
/// every query's candidates are the members of its `PROBES` nearest clusters (by centre
/// distance), and a group searches the union of its queries' clusters exactly.
fn clustered_candidates<Q: QueryRows + ?Sized>(
    mut base: Mat<f32>,
    query: &Q,
    count: usize,
) -> CandidateLists {
    let n = base.nrows();
    let count = count.min(n).max(1);
    let c = clusters(&mut base);
    let base = base.as_ref();
    let norms = row_norms(base);
    let probes = probed_clusters(query, &c, PROBES, count);
    let mut by_centre: Vec<(u32, u32)> = probes
        .iter()
        .enumerate()
        .map(|(q, p)| (p[0], q as u32))
        .collect();
    by_centre.sort_unstable();
    let mut groups: Vec<&[(u32, u32)]> = Vec::new();
    for run in by_centre.chunk_by(|x, y| x.0 == y.0) {
        groups.extend(run.chunks(GROUP_SIZE));
    }
    let per_group: Vec<Vec<Neighbours>> = groups
        .par_iter()
        .map(|group| search_group(base, query, &norms, &c, &probes, group, count))
        .collect();
    let mut targets = vec![0u32; query.nrows() * count];
    let mut costs = vec![f64::INFINITY; query.nrows() * count];
    for (q, q_norm, best) in per_group.into_iter().flatten() {
        let at = q as usize * count;
        for (s, &(d, i)) in best.iter().enumerate() {
            targets[at + s] = i;
            costs[at + s] = (d + q_norm).max(0.0);
        }
        // Fewer members than `count` in the probed clusters (tiny clusters only): repeat
        // the farthest found, which keeps the list sorted and valid.
        for s in best.len()..count {
            targets[at + s] = targets[at + s - 1];
            costs[at + s] = costs[at + s - 1];
        }
    }
    CandidateLists {
        per_query: count,
        targets,
        costs,
    }
}

/// `(d, index)` as one integer whose order is [`TopK`]'s: a NaN ranks as +∞, −0 as +0, equal
/// distances by index. The high 64 bits are `d`'s bits mapped to an unsigned order.
fn order_key(d: f64, index: u32) -> u128 {
    // `+ 0.0` turns −0 into +0 and leaves every other value as it is.
    let d = if d.is_nan() { f64::INFINITY } else { d + 0.0 };
    let bits = d.to_bits();
    let ordered = if bits >> 63 == 1 {
        !bits
    } else {
        bits | 1 << 63
    };
    (u128::from(ordered) << 32) | u128::from(index)
}

/// The `(d, index)` of an [`order_key`] (−0 and NaN come back as +0 and +∞).
fn from_order_key(key: u128) -> (f64, u32) {
    let ordered = (key >> 32) as u64;
    let bits = if ordered >> 63 == 1 {
        ordered & !(1 << 63)
    } else {
        !ordered
    };
    (f64::from_bits(bits), key as u32)
}

/// The `count` smallest of `all` ([`order_key`]s), ascending, as `(d, index)` pairs: one
/// selection and a sort of the kept, cheaper than offering the ~640 candidates of a
/// clustered query to a [`TopK`] one by one, and on integers because comparing `(f64, u32)`
/// pairs was a twentieth of `coseg pair`'s CPU on TOSCA's dog0 × cat0 (`perf`).
fn smallest(all: &mut [u128], count: usize) -> Vec<(f64, u32)> {
    let kept = count.min(all.len());
    if kept > 0 && kept < all.len() {
        all.select_nth_unstable(kept - 1);
    }
    let best = &mut all[..kept];
    best.sort_unstable();
    best.iter().map(|&k| from_order_key(k)).collect()
}

/// One group of queries (`(centre, query)` pairs): their `count` nearest rows among the
/// members of their clusters, as `(‖a‖² − 2 a·q, a)` pairs (`a` the original index). `base`
/// and `norms` are in the clusters' order.
fn search_group<Q: QueryRows + ?Sized>(
    base: MatRef<'_, f32>,
    query: &Q,
    norms: &[f64],
    c: &Clusters,
    probes: &[Vec<u32>],
    group: &[(u32, u32)],
    count: usize,
) -> Vec<Neighbours> {
    let rows: Vec<usize> = group.iter().map(|&(_, q)| q as usize).collect();
    let rows = query.single_rows(&rows);
    let q_norms = row_norms(rows.as_ref());
    let clusters = c.count();
    let mut needed = vec![false; clusters];
    for &(_, q) in group {
        for &j in &probes[q as usize] {
            needed[j as usize] = true;
        }
    }
    // Runs of the reordered base, adjacent clusters merged.
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for j in (0..clusters).filter(|&j| needed[j]) {
        let (s, e) = (c.starts[j], c.starts[j + 1]);
        match runs.last_mut() {
            Some(last) if last.1 == s => last.1 = e,
            _ => runs.push((s, e)),
        }
    }
    let total: usize = runs.iter().map(|r| r.1 - r.0).sum();
    let mut candidates = Mat::<f32>::zeros(total, base.ncols());
    for j in 0..base.ncols() {
        let src = base.col(j).try_as_col_major().expect("owned").as_slice();
        let dst = col_slice_mut(candidates.as_mut(), j);
        let mut at = 0;
        for &(s, e) in &runs {
            dst[at..at + e - s].copy_from_slice(&src[s..e]);
            at += e - s;
        }
    }
    let d = dots(candidates.as_ref(), rows.as_ref());
    let original: Vec<u32> = runs
        .iter()
        .flat_map(|&(r0, r1)| c.original[r0..r1].iter().copied())
        .collect();
    let chosen_norms: Vec<f64> = runs
        .iter()
        .flat_map(|&(r0, r1)| norms[r0..r1].iter().copied())
        .collect();
    let mut all: Vec<u128> = Vec::with_capacity(total);
    group
        .iter()
        .enumerate()
        .map(|(g, &(_, q))| {
            let col = d.col(g).try_as_col_major().expect("owned").as_slice();
            all.clear();
            all.extend(
                chosen_norms
                    .iter()
                    .zip(col)
                    .zip(&original)
                    .map(|((&norm, &dot), &a)| order_key(norm - 2.0 * f64::from(dot), a)),
            );
            (q, q_norms[g], smallest(&mut all, count))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_chacha::ChaCha8Rng;
    use rand_chacha::rand_core::{Rng, SeedableRng};

    /// Rows on a wavy two-dimensional sheet in 40 dimensions, plus noise: the shape of a
    /// spectral embedding.
    fn sheet(n: usize, seed: u64) -> Mat<f64> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut unit = || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        let uv: Vec<(f64, f64)> = (0..n).map(|_| (unit(), unit())).collect();
        Mat::from_fn(n, 40, |i, j| {
            let (u, v) = uv[i];
            let f = (j / 2 + 1) as f64;
            let x = if j % 2 == 0 { u } else { v };
            (f * 3.0 * x).sin() / f + 1e-3 * ((i * 31 + j * 17) % 13) as f64
        })
    }

    #[test]
    fn clustered_search_finds_nearly_all_brute_force_candidates() {
        let base = sheet(9000, 1);
        let query = sheet(700, 2);
        let brute = brute_force_candidates(base.as_ref(), &query.as_ref(), 16);
        let clustered = clustered_candidates(single(base.as_ref()), &query.as_ref(), 16);
        assert_eq!(clustered.per_query, 16);
        let mut found = 0;
        for q in 0..700 {
            let (b, c) = (
                &brute.targets[q * 16..][..16],
                &clustered.targets[q * 16..][..16],
            );
            // The nearest is always found, and every kept candidate's cost is its own up to
            // single-precision products: ~10⁻⁶ of the squared norms, which cancel.
            assert_eq!(b[0], c[0], "query {q}");
            found += c.iter().filter(|t| b.contains(t)).count();
            let q_norm: f64 = (0..40).map(|j| query[(q, j)].powi(2)).sum();
            for (&t, &cost) in c.iter().zip(&clustered.costs[q * 16..][..16]) {
                let t = t as usize;
                let exact: f64 = (0..40)
                    .map(|j| (base[(t, j)] - query[(q, j)]).powi(2))
                    .sum();
                let t_norm: f64 = (0..40).map(|j| base[(t, j)].powi(2)).sum();
                assert!(
                    (cost - exact).abs() < 1e-5 * (q_norm + t_norm),
                    "{cost} {exact}"
                );
            }
            assert!(
                clustered.costs[q * 16..][..16]
                    .windows(2)
                    .all(|w| w[0] <= w[1])
            );
        }
        let recall = found as f64 / (700 * 16) as f64;
        assert!(recall > 0.99, "recall {recall}");
    }

    /// The nearest-only path agrees with the first of the k-nearest lists, ties (every base
    /// row twice) and a NaN row included.
    #[test]
    fn the_nearest_alone_is_the_first_of_the_nearest_lists() {
        let half = sheet(300, 5);
        let mut base = Mat::from_fn(600, 40, |i, j| half[(i % 300, j)]);
        base[(7, 3)] = f64::NAN;
        let query = sheet(150, 6);
        let one = brute_force_candidates(base.as_ref(), &query.as_ref(), 1);
        let four = brute_force_candidates(base.as_ref(), &query.as_ref(), 4);
        for q in 0..150 {
            assert_eq!(one.targets[q], four.targets[q * 4], "query {q}");
            assert_eq!(one.costs[q].to_bits(), four.costs[q * 4].to_bits());
            assert!(one.targets[q] < 300, "a tie goes to the lower copy");
        }
        let nan_query = Mat::from_fn(1, 40, |_, _| f64::NAN);
        let lists = brute_force_candidates(base.as_ref(), &nan_query.as_ref(), 1);
        assert_eq!(lists.targets, vec![0]);
    }

    /// The selection the clustered search keeps its candidates by agrees with `TopK`, ties,
    /// NaN, infinities, signed zeros, subnormals and lists shorter than `count` included.
    #[test]
    fn smallest_keeps_what_top_k_keeps() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for round in 0..200 {
            let len = (rng.next_u64() % 90) as usize;
            let count = 1 + (rng.next_u64() % 70) as usize;
            let all: Vec<(f64, u32)> = (0..len)
                .map(|i| {
                    let d = match rng.next_u64() % 16 {
                        0 => f64::NAN,
                        1 => -0.0,
                        2 => 0.0,
                        3 => f64::INFINITY,
                        4 => f64::NEG_INFINITY,
                        5 => -5e-324,
                        6 => 5e-324,
                        7 => -1e300,
                        r => (r % 4) as f64 - 1.5,
                    };
                    (d, (i as u32 * 7919) % 1000)
                })
                .collect();
            let mut top = TopK::new(count);
            for &(d, i) in &all {
                top.offer(d, i);
            }
            let mut keys: Vec<u128> = all.iter().map(|&(d, i)| order_key(d, i)).collect();
            let got = smallest(&mut keys, count);
            // Bit for bit, but for the sign of a zero: the costs made of them, `(d + ‖q‖²)
            // .max(0)` with `‖q‖² ≥ 0`, are the same either way.
            let bits = |v: &[(f64, u32)]| {
                v.iter()
                    .map(|x| ((x.0 + 0.0).to_bits(), x.1))
                    .collect::<Vec<_>>()
            };
            assert_eq!(bits(&got), bits(&top.best), "round {round}");
        }
    }

    /// The two-pass minimum agrees with the one-pass scan it replaced, bit for bit: ties,
    /// NaN, infinities, signed zeros and lengths that are not a multiple of the lanes.
    #[test]
    fn nearest_one_is_the_first_least_of_a_scan() {
        let scan = |norms: &[f64], col: &[f64]| {
            let key = |i: usize| {
                let d = norms[i] - 2.0 * col[i];
                if d.is_nan() { f64::INFINITY } else { d }
            };
            let mut best = (key(0), 0usize);
            for i in 1..norms.len() {
                if key(i) < best.0 {
                    best = (key(i), i);
                }
            }
            (best.1, best.0)
        };
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        for round in 0..2000 {
            let len = 1 + (rng.next_u64() % 40) as usize;
            let mut value = || match rng.next_u64() % 12 {
                0 => f64::NAN,
                1 => f64::INFINITY,
                2 => f64::NEG_INFINITY,
                3 => -0.0,
                4 => 0.0,
                r => (r % 3) as f64 - 1.0,
            };
            let norms: Vec<f64> = (0..len).map(|_| value()).collect();
            let col: Vec<f64> = (0..len).map(|_| value()).collect();
            let (i, d) = nearest_one(&norms, &col);
            let (j, e) = scan(&norms, &col);
            assert_eq!(
                (i, d.to_bits()),
                (j, e.to_bits()),
                "round {round}: {norms:?} {col:?}"
            );
        }
    }

    #[test]
    fn ties_go_to_the_lowest_index_in_both_searches() {
        // Every base row twice: each pair of equal rows is a tie, in the same cluster.
        let half = sheet(4500, 3);
        let base = Mat::from_fn(9000, 40, |i, j| half[(i % 4500, j)]);
        let query = sheet(200, 4);
        for lists in [
            brute_force_candidates(base.as_ref(), &query.as_ref(), 8),
            clustered_candidates(single(base.as_ref()), &query.as_ref(), 8),
        ] {
            for list in lists.targets.chunks(8) {
                for w in list.chunks(2) {
                    assert_eq!(w[0] + 4500, w[1], "the copy follows its original: {list:?}");
                }
            }
        }
    }
}
