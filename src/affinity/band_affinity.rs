//! [`BandAffinity`]: `W x` and `Wᵀ y` through per-feature band histograms.

use super::AffinityError;
use super::kernel::{Bin, row_sum};
use crate::bands::BandTable;
use rayon::prelude::*;
use std::sync::OnceLock;

/// Fixed number of histogram chunks of a scatter: the reduction order depends only on the input,
/// never on the number of threads, so results are bit-identical serial or parallel.
const SCATTER_CHUNKS: usize = 8;
/// Minimum number of source entries per scatter chunk (fewer entries use fewer chunks).
const MIN_SCATTER_CHUNK: usize = 1024;
/// Rows per parallel gather task.
const GATHER_BLOCK: usize = 512;

/// Which way a vector travels through `W` (`d_b × d_a`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Direction {
    /// `W x`: a vector on A (length `d_a`) to scores on B (length `d_b`).
    AtoB,
    /// `Wᵀ y`: a vector on B (length `d_b`) to scores on A (length `d_a`).
    BtoA,
}

/// How the features of A pair with those of B, and their weights.
///
/// Pair `i` matches feature `pairs[i].0` of A with feature `pairs[i].1` of B with weight
/// `weights[i]`; weights are normalised to sum to one. The default (see
/// [`FeaturePairing::identity`]) pairs feature `k` with feature `k` with equal weights.
#[derive(Debug, Clone, PartialEq)]
pub struct FeaturePairing {
    pairs: Vec<(u32, u32)>,
    weights: Option<Vec<f64>>,
}

impl FeaturePairing {
    /// Feature `k` of A with feature `k` of B for `k in 0..n`, equal weights.
    pub fn identity(n: usize) -> Self {
        Self {
            pairs: (0..n as u32).map(|k| (k, k)).collect(),
            weights: None,
        }
    }

    /// An explicit pairing; `weights = None` means equal weights. Weights must be finite,
    /// non-negative and not all zero (checked by [`BandAffinity::with_pairing`]).
    pub fn new(pairs: Vec<(u32, u32)>, weights: Option<Vec<f64>>) -> Self {
        Self { pairs, weights }
    }

    /// The feature pairs `(k_a, k_b)`.
    pub fn pairs(&self) -> &[(u32, u32)] {
        &self.pairs
    }
}

/// The affinity `W` (`d_b × d_a`) between shapes A and B as an operator on their band tables.
///
/// Internally `W = unit · R` where `R_qp = Σ_i r_i [match_i(q, p)]` with raw pair weights
/// `r_i = w_i · n_pairs` (all `1` for equal weights, so `R` holds exact integers) and
/// `unit = K / (n_pairs d_a d_b)`. Products with indicator vectors
/// ([`BandAffinity::transport_indicator`]) return raw scores `R x` so that ties are exact.
///
/// ```
/// use coseg::affinity::BandAffinity;
/// use coseg::bands::equal_count_bands;
/// let a = equal_count_bands(&[0.0, 1.0, 2.0, 3.0], 1, 4, 2).unwrap();
/// let b = equal_count_bands(&[3.0, 2.0, 1.0, 0.0], 1, 4, 2).unwrap();
/// let w = BandAffinity::new(&a, &b).unwrap();
/// let mut ws = w.workspace();
/// let mut y = vec![0.0; 4];
/// w.apply(&[1.0, 0.0, 0.0, 0.0], &mut y, &mut ws).unwrap();
/// // Vertex 0 of A is in the low band, as are vertices 2 and 3 of B.
/// assert_eq!(y, vec![0.0, 0.0, 2.0 / 16.0, 2.0 / 16.0]);
/// ```
#[derive(Debug, Clone)]
pub struct BandAffinity<'a> {
    a: &'a BandTable,
    b: &'a BandTable,
    bands: usize,
    pairs: Vec<(u32, u32)>,
    /// Raw weights `r_i` (`None` = all one: the integer path).
    raw_weights: Option<Vec<f64>>,
    /// Identity pairing with the same feature count on both sides.
    identity: bool,
    unit: f64,
    /// Pair labels `l_{2i} K + l_{2i+1}` of A and B (vertex-major, `ceil(N/2)` per vertex) when
    /// `K ≤ PAIR_MAX_BANDS`: the integer gather then reads one `u16` and one table entry per two
    /// features. Each side is built on its first gather, since many operators (a propagation's
    /// votes) only ever transport one way.
    pair_labels: Option<(PairLabels, PairLabels)>,
}

/// One side's pair labels, built on first use.
type PairLabels = OnceLock<Vec<u16>>;

/// Largest `K` for which the paired gather is used (its table has `ceil(N/2) K²` entries).
const PAIR_MAX_BANDS: usize = 32;

/// Pair labels of a table: `out[v * P + i] = l(v, 2i) K + l(v, 2i + 1)` (`0` past the last
/// feature).
fn pair_labels(t: &BandTable) -> Vec<u16> {
    let (nf, k) = (t.features, t.bands);
    let np = nf.div_ceil(2);
    let mut out = vec![0u16; t.vertices * np];
    out.par_chunks_mut(np * 1024)
        .zip(t.labels.par_chunks(nf * 1024))
        .for_each(|(o, l)| {
            for (orow, lrow) in o.chunks_exact_mut(np).zip(l.chunks_exact(nf)) {
                let pairs = lrow.chunks_exact(2);
                if let [last] = pairs.remainder() {
                    orow[np - 1] = *last as u16 * k as u16;
                }
                for (x, p) in orow.iter_mut().zip(pairs) {
                    *x = p[0] as u16 * k as u16 + p[1] as u16;
                }
            }
        });
    out
}

/// Per-feature band counts of a 0/1 indicator on one shape, kept up to date incrementally by
/// [`BandAffinity::update_histogram`] (integer counts: exact).
#[derive(Debug, Clone)]
pub struct IndicatorHistogram {
    dir: Direction,
    vertices: usize,
    counts: Vec<u32>,
    support: Vec<u32>,
    added: Vec<u32>,
    removed: Vec<u32>,
}

impl IndicatorHistogram {
    /// The current indicator's vertices, ascending.
    pub fn support(&self) -> &[u32] {
        &self.support
    }

    /// The direction the indicator travels.
    pub fn direction(&self) -> Direction {
        self.dir
    }
}

/// Reusable buffers of a [`BandAffinity`]: products allocate nothing once it exists.
#[derive(Debug, Clone, Default)]
pub struct AffinityWorkspace {
    hist_u: Vec<u32>,
    hist_f: Vec<f64>,
    table_u: Vec<u32>,
    table_f: Vec<f64>,
    table_pair: Vec<u32>,
    support: Vec<u32>,
}

impl AffinityWorkspace {
    fn ensure(&mut self, features: usize, bands: usize) {
        let len = features * bands;
        if self.table_u.len() < len {
            self.hist_u.resize(SCATTER_CHUNKS * len, 0);
            self.hist_f.resize(SCATTER_CHUNKS * len, 0.0);
            self.table_u.resize(len, 0);
            self.table_f.resize(len, 0.0);
            if bands <= PAIR_MAX_BANDS {
                self.table_pair
                    .resize(features.div_ceil(2) * bands * bands, 0);
            }
        }
    }
}

fn check_table(t: &BandTable, shape: &'static str) -> Result<(), AffinityError> {
    let expected = t.vertices * t.features;
    if t.labels.len() != expected {
        return Err(AffinityError::TableSize {
            shape,
            expected,
            got: t.labels.len(),
        });
    }
    if t.vertices == 0 || t.features == 0 {
        return Err(AffinityError::Empty(format!(
            "shape {shape} has {} vertices and {} features",
            t.vertices, t.features
        )));
    }
    // The largest label first, a reduction that vectorises: this check runs on both tables
    // every time an operator is built (each vote of a propagation), and a `position` scan
    // over the 3 MB of a 10k-vertex table was a tenth of `propagate`'s CPU (`perf`).
    let largest = t
        .labels
        .par_chunks(1 << 16)
        .map(|c| c.iter().copied().fold(0u8, u8::max))
        .max();
    if (largest.unwrap_or(0) as usize) < t.bands {
        return Ok(());
    }
    if let Some(i) = t.labels.iter().position(|&l| l as usize >= t.bands) {
        return Err(AffinityError::LabelOutOfRange {
            shape,
            vertex: i / t.features,
            label: t.labels[i],
            bands: t.bands,
        });
    }
    Ok(())
}

impl<'a> BandAffinity<'a> {
    /// The affinity with the identity pairing and equal weights. Both tables must have the same
    /// band count and feature count.
    pub fn new(a: &'a BandTable, b: &'a BandTable) -> Result<Self, AffinityError> {
        if a.features != b.features {
            return Err(AffinityError::Empty(format!(
                "identity pairing needs equal feature counts, got {} and {}",
                a.features, b.features
            )));
        }
        Self::with_pairing(a, b, &FeaturePairing::identity(a.features))
    }

    /// The affinity with an explicit feature pairing. Validates the tables (every label `< K`),
    /// which makes the unchecked indexing of the hot loops sound.
    pub fn with_pairing(
        a: &'a BandTable,
        b: &'a BandTable,
        pairing: &FeaturePairing,
    ) -> Result<Self, AffinityError> {
        if a.bands != b.bands {
            return Err(AffinityError::BandCountMismatch {
                a: a.bands,
                b: b.bands,
            });
        }
        if a.bands == 0 || a.bands > 256 {
            return Err(AffinityError::Empty(format!("K = {}", a.bands)));
        }
        check_table(a, "A")?;
        check_table(b, "B")?;
        let pairs = pairing.pairs.clone();
        if pairs.is_empty() {
            return Err(AffinityError::Empty("no feature pairs".into()));
        }
        for (i, &(ka, kb)) in pairs.iter().enumerate() {
            if ka as usize >= a.features || kb as usize >= b.features {
                return Err(AffinityError::PairOutOfRange {
                    index: i,
                    a: ka as usize,
                    b: kb as usize,
                    features_a: a.features,
                    features_b: b.features,
                });
            }
        }
        let n = pairs.len();
        let raw_weights = match &pairing.weights {
            None => None,
            Some(w) => {
                if w.len() != n {
                    return Err(AffinityError::BadWeights(format!(
                        "{} weights for {n} pairs",
                        w.len()
                    )));
                }
                if w.iter().any(|x| !x.is_finite() || *x < 0.0) {
                    return Err(AffinityError::BadWeights(
                        "weights must be finite and non-negative".into(),
                    ));
                }
                let s: f64 = w.iter().sum();
                if s <= 0.0 {
                    return Err(AffinityError::BadWeights("weights sum to zero".into()));
                }
                if w.iter().all(|&x| x == w[0]) {
                    None
                } else {
                    Some(w.iter().map(|x| x / s * n as f64).collect())
                }
            }
        };
        let identity = a.features == b.features
            && n == a.features
            && pairs
                .iter()
                .enumerate()
                .all(|(i, &(x, y))| x as usize == i && y as usize == i);
        let unit = a.bands as f64 / (n as f64 * a.vertices as f64 * b.vertices as f64);
        let pair_labels = (raw_weights.is_none() && a.bands <= PAIR_MAX_BANDS)
            .then(|| (OnceLock::new(), OnceLock::new()));
        Ok(Self {
            a,
            b,
            bands: a.bands,
            pairs,
            raw_weights,
            identity,
            unit,
            pair_labels,
        })
    }

    /// Disables the paired gather (benchmarks compare both; results are identical).
    #[doc(hidden)]
    pub fn without_pair_gather(mut self) -> Self {
        self.pair_labels = None;
        self
    }

    /// `d_b`, the number of rows of `W`.
    pub fn rows(&self) -> usize {
        self.b.vertices
    }

    /// `d_a`, the number of columns of `W`.
    pub fn cols(&self) -> usize {
        self.a.vertices
    }

    /// `K`.
    pub fn bands(&self) -> usize {
        self.bands
    }

    /// The scale from raw scores to entries of `W`: `W = unit · R`.
    pub fn unit(&self) -> f64 {
        self.unit
    }

    /// Shape A's band table.
    pub fn table_a(&self) -> &'a BandTable {
        self.a
    }

    /// Shape B's band table.
    pub fn table_b(&self) -> &'a BandTable {
        self.b
    }

    /// The feature pairs `(k_a, k_b)`.
    pub fn pairs(&self) -> &[(u32, u32)] {
        &self.pairs
    }

    /// Normalised weight of each pair (sums to one).
    pub fn weights(&self) -> Vec<f64> {
        let n = self.pairs.len() as f64;
        match &self.raw_weights {
            None => vec![1.0 / n; self.pairs.len()],
            Some(r) => r.iter().map(|x| x / n).collect(),
        }
    }

    /// Raw weight `r_i` of pair `i` (`W = unit · Σ_i r_i [match_i]`).
    pub fn raw_weight(&self, i: usize) -> f64 {
        self.raw_weights.as_ref().map_or(1.0, |r| r[i])
    }

    /// A workspace sized for this operator.
    pub fn workspace(&self) -> AffinityWorkspace {
        let mut ws = AffinityWorkspace::default();
        ws.ensure(self.a.features.max(self.b.features), self.bands);
        ws
    }

    fn tables(&self, dir: Direction) -> (&'a BandTable, &'a BandTable) {
        match dir {
            Direction::AtoB => (self.a, self.b),
            Direction::BtoA => (self.b, self.a),
        }
    }

    /// `out = W x` (`x` on A of length `d_a`, `out` on B of length `d_b`). Zero entries of `x`
    /// are skipped.
    pub fn apply(
        &self,
        x: &[f64],
        out: &mut [f64],
        ws: &mut AffinityWorkspace,
    ) -> Result<(), AffinityError> {
        self.transport(Direction::AtoB, x, None, out, ws)
    }

    /// `out = Wᵀ y` (`y` on B of length `d_b`, `out` on A of length `d_a`).
    pub fn apply_transpose(
        &self,
        y: &[f64],
        out: &mut [f64],
        ws: &mut AffinityWorkspace,
    ) -> Result<(), AffinityError> {
        self.transport(Direction::BtoA, y, None, out, ws)
    }

    /// General product: `x` lives on the source shape of `dir` (full length). With
    /// `rows = None`, `out` receives the whole product (length of the destination shape); with
    /// `rows = Some(r)`, `out[i]` receives entry `r[i]` of the product (the rows of `W` restricted
    /// to a remaining subset; mask the source subset by zeroing `x`).
    pub fn transport(
        &self,
        dir: Direction,
        x: &[f64],
        rows: Option<&[u32]>,
        out: &mut [f64],
        ws: &mut AffinityWorkspace,
    ) -> Result<(), AffinityError> {
        let (src, dst) = self.tables(dir);
        if x.len() != src.vertices {
            return Err(AffinityError::LengthMismatch {
                expected: src.vertices,
                got: x.len(),
            });
        }
        self.check_rows(dst, rows, out.len())?;
        ws.ensure(self.a.features.max(self.b.features), self.bands);
        let mut support = std::mem::take(&mut ws.support);
        support.clear();
        support.extend(
            x.iter()
                .enumerate()
                .filter(|(_, v)| **v != 0.0)
                .map(|(i, _)| i as u32),
        );
        scatter_f64(src, self.bands, &support, x, &mut ws.hist_f);
        ws.support = support;
        self.mix_f64(dir, ws);
        let nk = dst.features * self.bands;
        gather(dst, self.bands, &ws.table_f[..nk], rows, out, |s| s);
        let unit = self.unit;
        out.par_iter_mut().for_each(|v| *v *= unit);
        Ok(())
    }

    /// Raw scores of an indicator: `out[i] = (R 1_S)_{rows[i]}` where `S = support` (vertex
    /// indices on the source shape of `dir`, each at most once) and `R = W / unit` (see
    /// [`BandAffinity::unit`]). With equal weights the scores are exact integers. `rows = None`
    /// means every destination vertex.
    pub fn transport_indicator(
        &self,
        dir: Direction,
        support: &[u32],
        rows: Option<&[u32]>,
        out: &mut [f64],
        ws: &mut AffinityWorkspace,
    ) -> Result<(), AffinityError> {
        let (src, dst) = self.tables(dir);
        if let Some(&bad) = support.iter().find(|&&p| p as usize >= src.vertices) {
            return Err(AffinityError::IndexOutOfRange {
                index: bad as usize,
                vertices: src.vertices,
            });
        }
        self.check_rows(dst, rows, out.len())?;
        ws.ensure(self.a.features.max(self.b.features), self.bands);
        scatter_count(src, self.bands, support, &mut ws.hist_u);
        self.gather_counts(dir, rows, out, ws);
        Ok(())
    }

    /// A histogram of an empty indicator on the source shape of `dir`, for
    /// [`BandAffinity::update_histogram`] and [`BandAffinity::transport_histogram`].
    pub fn histogram(&self, dir: Direction) -> IndicatorHistogram {
        let (src, _) = self.tables(dir);
        IndicatorHistogram {
            dir,
            vertices: src.vertices,
            counts: vec![0; src.features * self.bands],
            support: Vec::new(),
            added: Vec::new(),
            removed: Vec::new(),
        }
    }

    /// Sets the indicator of `hist` to `support` (ascending, on the source shape of its
    /// direction), updating the per-feature band counts by the symmetric difference with the
    /// previous support when that is smaller than `support` (counts are integers: the result is
    /// exactly a fresh histogram's), else recounting in parallel.
    pub fn update_histogram(
        &self,
        hist: &mut IndicatorHistogram,
        support: &[u32],
        ws: &mut AffinityWorkspace,
    ) -> Result<(), AffinityError> {
        let (src, _) = self.tables(hist.dir);
        if hist.vertices != src.vertices || hist.counts.len() != src.features * self.bands {
            return Err(AffinityError::LengthMismatch {
                expected: src.features * self.bands,
                got: hist.counts.len(),
            });
        }
        if !support.windows(2).all(|w| w[0] < w[1]) {
            return Err(AffinityError::Empty(
                "histogram support must be strictly ascending".into(),
            ));
        }
        if let Some(&bad) = support.last().filter(|&&p| p as usize >= src.vertices) {
            return Err(AffinityError::IndexOutOfRange {
                index: bad as usize,
                vertices: src.vertices,
            });
        }
        // Symmetric difference of two ascending lists.
        let (old, new) = (&hist.support, support);
        hist.added.clear();
        hist.removed.clear();
        let (mut i, mut j) = (0, 0);
        while i < old.len() || j < new.len() {
            if j == new.len() || (i < old.len() && old[i] < new[j]) {
                hist.removed.push(old[i]);
                i += 1;
            } else if i == old.len() || new[j] < old[i] {
                hist.added.push(new[j]);
                j += 1;
            } else {
                i += 1;
                j += 1;
            }
        }
        let k = self.bands;
        if hist.added.len() + hist.removed.len() < support.len() {
            let c = &mut hist.counts;
            for (list, inc) in [(&hist.added, 1u32), (&hist.removed, u32::MAX)] {
                for &p in list.iter() {
                    let row = src.row(p as usize);
                    // SAFETY: labels < K (validated at construction), so every index
                    // `f * K + row[f]` is below `N K = c.len()`.
                    unsafe {
                        for (f, &l) in row.iter().enumerate() {
                            let x = c.get_unchecked_mut(f * k + l as usize);
                            *x = x.wrapping_add(inc);
                        }
                    }
                }
            }
        } else {
            ws.ensure(self.a.features.max(self.b.features), k);
            scatter_count(src, k, support, &mut ws.hist_u);
            let len = hist.counts.len();
            hist.counts.copy_from_slice(&ws.hist_u[..len]);
        }
        hist.support.clear();
        hist.support.extend_from_slice(support);
        Ok(())
    }

    /// Raw scores of the histogram's indicator, as [`BandAffinity::transport_indicator`] gives
    /// for its support.
    pub fn transport_histogram(
        &self,
        hist: &IndicatorHistogram,
        rows: Option<&[u32]>,
        out: &mut [f64],
        ws: &mut AffinityWorkspace,
    ) -> Result<(), AffinityError> {
        let (src, dst) = self.tables(hist.dir);
        if hist.counts.len() != src.features * self.bands {
            return Err(AffinityError::LengthMismatch {
                expected: src.features * self.bands,
                got: hist.counts.len(),
            });
        }
        self.check_rows(dst, rows, out.len())?;
        ws.ensure(self.a.features.max(self.b.features), self.bands);
        ws.hist_u[..hist.counts.len()].copy_from_slice(&hist.counts);
        self.gather_counts(hist.dir, rows, out, ws);
        Ok(())
    }

    /// Scores from the band counts in `ws.hist_u[..N_src K]`.
    fn gather_counts(
        &self,
        dir: Direction,
        rows: Option<&[u32]>,
        out: &mut [f64],
        ws: &mut AffinityWorkspace,
    ) {
        let (src, dst) = self.tables(dir);
        let nk = dst.features * self.bands;
        let k = self.bands;
        if self.raw_weights.is_none() {
            if !self.identity {
                let table = &mut ws.table_u[..nk];
                table.fill(0);
                for &(ka, kb) in &self.pairs {
                    let (s, d) = pick(dir, ka, kb);
                    let h = &ws.hist_u[s * k..(s + 1) * k];
                    for (t, &c) in table[d * k..(d + 1) * k].iter_mut().zip(h) {
                        *t += c;
                    }
                }
            }
            if self.identity {
                ws.table_u[..nk].copy_from_slice(&ws.hist_u[..nk]);
            }
            let table: &[u32] = &ws.table_u[..nk];
            match &self.pair_labels {
                Some((pa, pb)) => {
                    let labels = match dir {
                        Direction::AtoB => pb.get_or_init(|| pair_labels(self.b)),
                        Direction::BtoA => pa.get_or_init(|| pair_labels(self.a)),
                    };
                    let np = dst.features.div_ceil(2);
                    let t2 = &mut ws.table_pair[..np * k * k];
                    build_pair_table(table, dst.features, k, t2);
                    gather_pairs(labels, np, k * k, t2, rows, out);
                }
                None => gather(dst, k, table, rows, out, |s| s),
            }
        } else {
            // Weighted pairing: the 0/1 histogram in f64 (exact counts), then mix.
            let len = src.features * k;
            for (f, &u) in ws.hist_f[..len].iter_mut().zip(&ws.hist_u[..len]) {
                *f = u as f64;
            }
            self.mix_f64(dir, ws);
            gather(dst, k, &ws.table_f[..nk], rows, out, |s| s);
        }
    }

    fn check_rows(
        &self,
        dst: &BandTable,
        rows: Option<&[u32]>,
        out_len: usize,
    ) -> Result<(), AffinityError> {
        let expected = rows.map_or(dst.vertices, <[u32]>::len);
        if out_len != expected {
            return Err(AffinityError::LengthMismatch {
                expected,
                got: out_len,
            });
        }
        if let Some(r) = rows
            && let Some(&bad) = r.iter().find(|&&q| q as usize >= dst.vertices)
        {
            return Err(AffinityError::IndexOutOfRange {
                index: bad as usize,
                vertices: dst.vertices,
            });
        }
        Ok(())
    }

    /// `table_f[dst feature][band] = Σ_pairs r_i · hist_f[src feature][band]`.
    fn mix_f64(&self, dir: Direction, ws: &mut AffinityWorkspace) {
        let (_, dst) = self.tables(dir);
        let k = self.bands;
        let nk = dst.features * k;
        if self.identity && self.raw_weights.is_none() {
            let (h, t) = (&ws.hist_f[..nk], &mut ws.table_f[..nk]);
            t.copy_from_slice(h);
            return;
        }
        let table = &mut ws.table_f[..nk];
        table.fill(0.0);
        for (i, &(ka, kb)) in self.pairs.iter().enumerate() {
            let r = self.raw_weight(i);
            let (s, d) = pick(dir, ka, kb);
            let h = &ws.hist_f[s * k..(s + 1) * k];
            for (t, &c) in table[d * k..(d + 1) * k].iter_mut().zip(h) {
                *t += r * c;
            }
        }
    }
}

#[inline]
fn pick(dir: Direction, ka: u32, kb: u32) -> (usize, usize) {
    match dir {
        Direction::AtoB => (ka as usize, kb as usize),
        Direction::BtoA => (kb as usize, ka as usize),
    }
}

/// Number of chunks a scatter of `len` entries uses: a function of `len` only.
fn chunk_count(len: usize) -> usize {
    len.div_ceil(MIN_SCATTER_CHUNK).clamp(1, SCATTER_CHUNKS)
}

/// `hist[k*K + band_src[k][p]] += value(p)` over `p ∈ support` into `hist[..N*K]`: each chunk
/// of `support` into its own histogram, then the chunks' histograms summed in chunk order (a
/// function of `support.len()` only, so the sums are deterministic).
fn scatter<T>(
    src: &BandTable,
    bands: usize,
    support: &[u32],
    hist: &mut [T],
    value: impl Fn(usize) -> T + Sync,
) where
    T: Copy + Default + std::ops::AddAssign + Send,
{
    let nf = src.features;
    let len = nf * bands;
    let chunks = chunk_count(support.len());
    let per = support.len().div_ceil(chunks);
    hist[..chunks * len]
        .par_chunks_mut(len)
        .enumerate()
        .for_each(|(c, h)| {
            h.fill(T::default());
            let lo = (c * per).min(support.len());
            let hi = ((c + 1) * per).min(support.len());
            for &p in &support[lo..hi] {
                let row = src.row(p as usize);
                let v = value(p as usize);
                // SAFETY: every label is < bands (validated by `check_table` when the operator
                // was built; the tables are borrowed immutably since), `row.len() == nf` and
                // `h.len() == nf * bands`, so `k * bands + row[k] < h.len()`.
                unsafe {
                    for (k, &l) in row.iter().enumerate() {
                        *h.get_unchecked_mut(k * bands + l as usize) += v;
                    }
                }
            }
        });
    let (first, rest) = hist.split_at_mut(len);
    for c in 1..chunks {
        for (a, &b) in first.iter_mut().zip(&rest[(c - 1) * len..c * len]) {
            *a += b;
        }
    }
}

/// Counts `hist[k*K + band_src[k][p]] += 1` over `p ∈ support` into `hist[..N*K]`.
fn scatter_count(src: &BandTable, bands: usize, support: &[u32], hist: &mut [u32]) {
    scatter(src, bands, support, hist, |_| 1);
}

/// `hist[k*K + band_src[k][p]] += x_p` over `p ∈ support`, chunked and summed in chunk order.
fn scatter_f64(src: &BandTable, bands: usize, support: &[u32], x: &[f64], hist: &mut [f64]) {
    scatter(src, bands, support, hist, |p| x[p]);
}

/// A table entry [`gather`] sums, and how its sum becomes an `f64`.
trait Gathered: Bin {
    fn finish(a: Self::Acc) -> f64;
}

impl Gathered for u32 {
    #[inline(always)]
    fn finish(a: u64) -> f64 {
        a as f64
    }
}

impl Gathered for f64 {
    #[inline(always)]
    fn finish(a: f64) -> f64 {
        a
    }
}

/// `out[i] = Σ_k table[k*K + band_dst[k][rows[i]]]` (or over all destination vertices).
fn gather<T: Gathered>(
    dst: &BandTable,
    bands: usize,
    table: &[T],
    rows: Option<&[u32]>,
    out: &mut [f64],
    post: impl Fn(f64) -> f64 + Sync,
) {
    let nf = dst.features;
    match rows {
        None => {
            out.par_chunks_mut(GATHER_BLOCK)
                .zip(dst.labels.par_chunks(GATHER_BLOCK * nf))
                .for_each(|(o, labels)| {
                    for (v, row) in o.iter_mut().zip(labels.chunks_exact(nf)) {
                        *v = post(T::finish(row_sum(table, row, bands)));
                    }
                });
        }
        Some(r) => {
            out.par_chunks_mut(GATHER_BLOCK)
                .zip(r.par_chunks(GATHER_BLOCK))
                .for_each(|(o, idx)| {
                    for (v, &q) in o.iter_mut().zip(idx) {
                        *v = post(T::finish(row_sum(table, dst.row(q as usize), bands)));
                    }
                });
        }
    }
}

/// `t2[i K² + l K + m] = table[2i K + l] + table[(2i + 1) K + m]` (second term `0` past the last
/// feature).
fn build_pair_table(table: &[u32], features: usize, k: usize, t2: &mut [u32]) {
    for (i, blk) in t2.chunks_exact_mut(k * k).enumerate() {
        let h0 = &table[2 * i * k..(2 * i + 1) * k];
        let h1 = table
            .get((2 * i + 1) * k..(2 * i + 2) * k)
            .filter(|_| 2 * i + 1 < features);
        for (l, row) in blk.chunks_exact_mut(k).enumerate() {
            match h1 {
                Some(h1) => {
                    for (x, &m) in row.iter_mut().zip(h1) {
                        *x = h0[l] + m;
                    }
                }
                None => row.fill(h0[l]),
            }
        }
    }
}

/// Sum of `t2[i K² + pl[i]]` with four accumulators.
#[inline(always)]
fn pair_row_sum(t2: &[u32], pl: &[u16], kk: usize) -> f64 {
    row_sum(t2, pl, kk) as f64
}

/// The paired integer gather (see [`gather`]).
fn gather_pairs(
    labels: &[u16],
    np: usize,
    kk: usize,
    t2: &[u32],
    rows: Option<&[u32]>,
    out: &mut [f64],
) {
    match rows {
        None => {
            out.par_chunks_mut(GATHER_BLOCK)
                .zip(labels.par_chunks(GATHER_BLOCK * np))
                .for_each(|(o, l)| {
                    for (v, row) in o.iter_mut().zip(l.chunks_exact(np)) {
                        *v = pair_row_sum(t2, row, kk);
                    }
                });
        }
        Some(r) => {
            out.par_chunks_mut(GATHER_BLOCK)
                .zip(r.par_chunks(GATHER_BLOCK))
                .for_each(|(o, idx)| {
                    for (v, &q) in o.iter_mut().zip(idx) {
                        let q = q as usize;
                        *v = pair_row_sum(t2, &labels[q * np..(q + 1) * np], kk);
                    }
                });
        }
    }
}
