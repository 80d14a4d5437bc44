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

use super::CandidateLists;
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatRef, Par};
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
/// nearest clusters are compared (see the module notes): every returned candidate and cost
/// is right, but a near row in an unprobed cluster can be missed.
///
/// This is ZoomOut's last-match search; it is public for benchmarks (`benches/core.rs`).
pub fn nearest_candidates(
    base: MatRef<'_, f64>,
    query: MatRef<'_, f64>,
    count: usize,
) -> CandidateLists {
    let n = base.nrows();
    let finite =
        |m: MatRef<'_, f64>| (0..m.ncols()).all(|j| m.col(j).iter().all(|x| x.is_finite()));
    if n >= PRUNE_FROM && query.nrows() > 0 && finite(base) && finite(query) {
        clustered_candidates(base, query, count)
    } else {
        brute_force_candidates(base, query, count)
    }
}

fn row_norms(m: MatRef<'_, f64>) -> Vec<f64> {
    let mut norms = vec![0.0; m.nrows()];
    for j in 0..m.ncols() {
        for (s, &x) in norms.iter_mut().zip(m.col(j).iter()) {
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
pub(crate) fn gather_rows(m: MatRef<'_, f64>, rows: &[usize]) -> Mat<f64> {
    let mut out = Mat::<f64>::zeros(rows.len(), m.ncols());
    for j in 0..m.ncols() {
        let dst = out
            .col_mut(j)
            .try_as_col_major_mut()
            .expect("owned")
            .as_slice_mut();
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
    out
}

/// `out = a · bᵀ` (`a.nrows() × b.nrows()`), sequential.
fn dots(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    let mut out = Mat::<f64>::zeros(a.nrows(), b.nrows());
    matmul(
        out.as_mut(),
        Accum::Replace,
        a,
        b.transpose(),
        1.0,
        Par::Seq,
    );
    out
}

/// A query and its nearest rows, as `(‖a‖² − 2 a·q, a)` pairs, nearest first.
type Neighbours = (u32, Vec<(f64, u32)>);

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
fn brute_force_candidates(
    base: MatRef<'_, f64>,
    query: MatRef<'_, f64>,
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
            let block = query.subrows(r0, m);
            let dots = dots(base, block);
            let q_norms = row_norms(block);
            let (mut targets, mut costs) =
                (Vec::with_capacity(m * count), Vec::with_capacity(m * count));
            let mut top = TopK::new(count);
            for (j, &q_norm) in q_norms.iter().enumerate() {
                let col = dots.col(j).try_as_col_major().expect("owned").as_slice();
                if count == 1 {
                    // ZoomOut's steps ask for the nearest row only: a plain minimum, with
                    // `TopK`'s rules (NaN ranks last, ties to the lowest index).
                    let key = |i: usize| {
                        let d = norms[i] - 2.0 * col[i];
                        if d.is_nan() { f64::INFINITY } else { d }
                    };
                    let mut best = (key(0), 0usize);
                    for i in 1..n {
                        let d = key(i);
                        if d < best.0 {
                            best = (d, i);
                        }
                    }
                    targets.push(best.1 as u32);
                    costs.push((best.0 + q_norm).max(0.0));
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

/// Base rows grouped into clusters around fixed centres (every `n / C`-th row).
struct Clusters {
    /// `C × D` centre rows.
    centres: Mat<f64>,
    centre_norms: Vec<f64>,
    /// Members of every cluster, ascending.
    members: Vec<Vec<u32>>,
}

/// For every row of `rows`, its clusters nearest first (ties to the lowest) until they hold
/// `count` members and number at least `probes`.
fn probed_clusters(
    rows: MatRef<'_, f64>,
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
            let d = dots(c.centres.as_ref(), rows.subrows(r0, m));
            let mut nearest: Vec<(f64, u32)> = Vec::with_capacity(probes + 1);
            (0..m)
                .map(|i| {
                    let col = d.col(i).try_as_col_major().expect("owned").as_slice();
                    // The `probes` nearest centres by one pass that keeps them sorted: most
                    // centres are rejected by one comparison with the farthest kept.
                    nearest.clear();
                    for (j, (&cn, &dot)) in c.centre_norms.iter().zip(col).enumerate() {
                        let x = (cn - 2.0 * dot, j as u32);
                        if nearest.len() == probes
                            && cmp(&x, &nearest[probes - 1]) != std::cmp::Ordering::Less
                        {
                            continue;
                        }
                        let at = nearest.partition_point(|y| cmp(y, &x).is_lt());
                        nearest.insert(at, x);
                        nearest.truncate(probes);
                    }
                    let mut held: usize = nearest
                        .iter()
                        .map(|&(_, j)| c.members[j as usize].len())
                        .sum();
                    let mut out: Vec<u32> = nearest.iter().map(|&(_, j)| j).collect();
                    if held < count {
                        // Rare (small clusters): every other centre, nearest first.
                        let mut rest: Vec<(f64, u32)> = c
                            .centre_norms
                            .iter()
                            .zip(col)
                            .enumerate()
                            .map(|(j, (&cn, &dot))| (cn - 2.0 * dot, j as u32))
                            .filter(|x| nearest.iter().all(|y| y.1 != x.1))
                            .collect();
                        rest.sort_unstable_by(cmp);
                        for &(_, j) in &rest {
                            if held >= count {
                                break;
                            }
                            out.push(j);
                            held += c.members[j as usize].len();
                        }
                    }
                    out
                })
                .collect::<Vec<_>>()
        })
        .collect()
}

fn clusters(base: MatRef<'_, f64>) -> Clusters {
    let n = base.nrows();
    let count = (n / CLUSTER_SIZE).max(1);
    let rows: Vec<usize> = (0..count).map(|i| i * n / count).collect();
    let centres = gather_rows(base, &rows);
    let centre_norms = row_norms(centres.as_ref());
    let mut c = Clusters {
        centres,
        centre_norms,
        members: vec![Vec::new(); count],
    };
    for (v, nearest) in probed_clusters(base, &c, 1, 0).into_iter().enumerate() {
        c.members[nearest[0] as usize].push(v as u32);
    }
    c
}

/// The clustered search (an inverted file): queries are grouped by their nearest centre;
/// every query's candidates are the members of its `PROBES` nearest clusters (by centre
/// distance), and a group searches the union of its queries' clusters exactly.
fn clustered_candidates(
    base: MatRef<'_, f64>,
    query: MatRef<'_, f64>,
    count: usize,
) -> CandidateLists {
    let n = base.nrows();
    let count = count.min(n).max(1);
    let c = clusters(base);
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
    for (q, best) in per_group.into_iter().flatten() {
        let at = q as usize * count;
        let q_norm: f64 = (0..query.ncols())
            .map(|j| query[(q as usize, j)].powi(2))
            .sum();
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

/// One group of queries (`(centre, query)` pairs): their `count` nearest rows among the
/// members of their clusters, as `(‖a‖² − 2 a·q, a)` pairs.
fn search_group(
    base: MatRef<'_, f64>,
    query: MatRef<'_, f64>,
    norms: &[f64],
    c: &Clusters,
    probes: &[Vec<u32>],
    group: &[(u32, u32)],
    count: usize,
) -> Vec<Neighbours> {
    let rows: Vec<usize> = group.iter().map(|&(_, q)| q as usize).collect();
    let rows = gather_rows(query, &rows);
    let clusters = c.members.len();
    let mut needed = vec![false; clusters];
    for &(_, q) in group {
        for &j in &probes[q as usize] {
            needed[j as usize] = true;
        }
    }
    let chosen: Vec<u32> = (0..clusters)
        .filter(|&j| needed[j])
        .flat_map(|j| c.members[j].iter().copied())
        .collect();
    let chosen_rows: Vec<usize> = chosen.iter().map(|&a| a as usize).collect();
    let candidates = gather_rows(base, &chosen_rows);
    let d = dots(candidates.as_ref(), rows.as_ref());
    let mut top = TopK::new(count);
    group
        .iter()
        .enumerate()
        .map(|(g, &(_, q))| {
            top.clear();
            let col = d.col(g);
            for (s, &a) in chosen.iter().enumerate() {
                top.offer(norms[a as usize] - 2.0 * col[s], a);
            }
            (q, top.best.clone())
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
        let brute = brute_force_candidates(base.as_ref(), query.as_ref(), 16);
        let clustered = clustered_candidates(base.as_ref(), query.as_ref(), 16);
        assert_eq!(clustered.per_query, 16);
        let mut found = 0;
        for q in 0..700 {
            let (b, c) = (
                &brute.targets[q * 16..][..16],
                &clustered.targets[q * 16..][..16],
            );
            // The nearest is always found, and every kept candidate's cost is its own.
            assert_eq!(b[0], c[0], "query {q}");
            found += c.iter().filter(|t| b.contains(t)).count();
            for (&t, &cost) in c.iter().zip(&clustered.costs[q * 16..][..16]) {
                let t = t as usize;
                let exact: f64 = (0..40)
                    .map(|j| (base[(t, j)] - query[(q, j)]).powi(2))
                    .sum();
                assert!((cost - exact).abs() < 1e-9);
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
        let one = brute_force_candidates(base.as_ref(), query.as_ref(), 1);
        let four = brute_force_candidates(base.as_ref(), query.as_ref(), 4);
        for q in 0..150 {
            assert_eq!(one.targets[q], four.targets[q * 4], "query {q}");
            assert_eq!(one.costs[q].to_bits(), four.costs[q * 4].to_bits());
            assert!(one.targets[q] < 300, "a tie goes to the lower copy");
        }
        let nan_query = Mat::from_fn(1, 40, |_, _| f64::NAN);
        let lists = brute_force_candidates(base.as_ref(), nan_query.as_ref(), 1);
        assert_eq!(lists.targets, vec![0]);
    }

    #[test]
    fn ties_go_to_the_lowest_index_in_both_searches() {
        // Every base row twice: each pair of equal rows is a tie, in the same cluster.
        let half = sheet(4500, 3);
        let base = Mat::from_fn(9000, 40, |i, j| half[(i % 4500, j)]);
        let query = sheet(200, 4);
        for lists in [
            brute_force_candidates(base.as_ref(), query.as_ref(), 8),
            clustered_candidates(base.as_ref(), query.as_ref(), 8),
        ] {
            for list in lists.targets.chunks(8) {
                for w in list.chunks(2) {
                    assert_eq!(w[0] + 4500, w[1], "the copy follows its original: {list:?}");
                }
            }
        }
    }
}
