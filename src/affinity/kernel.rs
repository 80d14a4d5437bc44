//! The one gather of the band-affinity operator, shared by every algorithm that scores vertices
//! through band tables: the pair algorithms ([`super::BandAffinity`]), the co-segmentation's
//! engine and the refinement of a co-segmentation (region blocks).
//!
//! Every product `W x` ends in the same inner loop: for a destination vertex with band labels
//! `row` (one per feature), `Σ_f table[f K + row[f]]`, where `table` holds, per (feature, band),
//! the mass of the source indicator or function in that band. [`row_sum`] is that loop, generic
//! over the entry type ([`Bin`]): exact integer counts (`u32`, summed in `u64`), `f64` values,
//! `f32` score tables and [`Block`]s of [`LANES`] regions scored at once.

/// Regions scored together by one pass over a band table (one [`Block`] per (feature, band)).
pub(crate) const LANES: usize = 8;

/// `LANES` regions' values for one (feature, band).
pub(crate) type Block = [f32; LANES];

/// An entry type of the tables [`row_sum`] gathers from, with its accumulator.
pub(crate) trait Bin: Copy + Send + Sync {
    /// What the partial sums are kept in.
    type Acc: Copy;
    /// The accumulator's zero.
    const ZERO: Self::Acc;
    /// `acc + x`.
    fn add(acc: Self::Acc, x: Self) -> Self::Acc;
    /// `(a₀ + a₁) + (a₂ + a₃)`.
    fn combine(a: [Self::Acc; 4]) -> Self::Acc;
}

impl Bin for u32 {
    type Acc = u64;
    const ZERO: u64 = 0;
    #[inline(always)]
    fn add(acc: u64, x: u32) -> u64 {
        acc + x as u64
    }
    #[inline(always)]
    fn combine(a: [u64; 4]) -> u64 {
        (a[0] + a[1]) + (a[2] + a[3])
    }
}

/// Floating-point entries sum in their own type.
macro_rules! float_bin {
    ($t:ty) => {
        impl Bin for $t {
            type Acc = $t;
            const ZERO: $t = 0.0;
            #[inline(always)]
            fn add(acc: $t, x: $t) -> $t {
                acc + x
            }
            #[inline(always)]
            fn combine(a: [$t; 4]) -> $t {
                (a[0] + a[1]) + (a[2] + a[3])
            }
        }
    };
}

float_bin!(f64);
float_bin!(f32);

impl Bin for Block {
    type Acc = Block;
    const ZERO: Block = [0.0; LANES];
    #[inline(always)]
    fn add(mut acc: Block, x: Block) -> Block {
        for l in 0..LANES {
            acc[l] += x[l];
        }
        acc
    }
    #[inline(always)]
    fn combine(a: [Block; 4]) -> Block {
        let mut out = [0.0f32; LANES];
        for (l, o) in out.iter_mut().enumerate() {
            *o = (a[0][l] + a[1][l]) + (a[2][l] + a[3][l]);
        }
        out
    }
}

/// `Σ_f table[f K + row[f]]` for one vertex's band labels `row` (`N` entries, each `< K`; `u8`
/// band labels, or `u16` labels of feature pairs with `K²` "bands") and a table of `N · K`
/// entries (`K = bands`), in four interleaved partial sums (features
/// `f ≡ 0, 1, 2, 3 mod 4`, combined as `(s₀ + s₁) + (s₂ + s₃)`): one running sum would make
/// every addition wait for the previous one, and this is the inner loop of every product. The
/// order of additions is fixed, so results are the same bit for bit on every run and thread
/// count.
///
/// Panics if `table` is shorter than `N · K`. Every label must be `< K`: tables are checked
/// where they enter an operator (`BandAffinity::new` and `ShapeGraph::build` reject a label
/// `≥ K`; the pair labels are built from two checked labels), and debug builds assert it here.
#[inline(always)]
pub(crate) fn row_sum<T: Bin, L: Copy + Into<usize>>(
    table: &[T],
    row: &[L],
    bands: usize,
) -> T::Acc {
    let table = &table[..row.len() * bands];
    let mut acc = [T::ZERO; 4];
    let quads = row.len() / 4;
    // Unchecked reads: a bounds check per entry costs 5–20 % of every product (measured with
    // `cargo bench --bench core -- affinity_apply` against the checked form).
    // SAFETY: `table.len() == row.len() · bands` (sliced above) and every label is `< bands`
    // (the band tables' invariant, asserted in debug builds), so `f · bands + row[f] <
    // row.len() · bands` for every `f < row.len()`.
    unsafe {
        for i in 0..quads {
            let f = 4 * i;
            for (j, a) in acc.iter_mut().enumerate() {
                let l: usize = (*row.get_unchecked(f + j)).into();
                debug_assert!(l < bands);
                *a = T::add(*a, *table.get_unchecked((f + j) * bands + l));
            }
        }
        for f in 4 * quads..row.len() {
            let l: usize = (*row.get_unchecked(f)).into();
            debug_assert!(l < bands);
            acc[0] = T::add(acc[0], *table.get_unchecked(f * bands + l));
        }
    }
    T::combine(acc)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Labels and a table for `n` features of `k` bands (deterministic, not symmetric).
    fn fixture(n: usize, k: usize) -> (Vec<u8>, Vec<u32>) {
        let row = (0..n).map(|f| ((f * 7 + 3) % k) as u8).collect();
        let table = (0..n * k)
            .map(|i| ((i * 2654435761) % 1000) as u32)
            .collect();
        (row, table)
    }

    #[test]
    fn integer_sums_equal_the_plain_sum_for_every_length() {
        for n in [0, 1, 3, 4, 5, 8, 13, 100] {
            let (row, table) = fixture(n, 6);
            let plain: u64 = (0..n).map(|f| table[f * 6 + row[f] as usize] as u64).sum();
            assert_eq!(row_sum(&table, &row, 6), plain, "{n} features");
            // The same labels as u16 (the pair gather's type) give the same sum.
            let wide: Vec<u16> = row.iter().map(|&l| l as u16).collect();
            assert_eq!(row_sum(&table, &wide, 6), plain);
        }
    }

    #[test]
    fn every_lane_of_a_block_is_the_scalar_sum_bit_for_bit() {
        let (row, table) = fixture(23, 5);
        let lanes: Vec<Vec<f32>> = (0..LANES)
            .map(|l| {
                table
                    .iter()
                    .map(|&x| x as f32 * 0.37 + l as f32 * 1e-3)
                    .collect()
            })
            .collect();
        let blocks: Vec<Block> = (0..table.len())
            .map(|i| std::array::from_fn(|l| lanes[l][i]))
            .collect();
        let got = row_sum(&blocks, &row, 5);
        for l in 0..LANES {
            assert_eq!(
                got[l].to_bits(),
                row_sum(&lanes[l], &row, 5).to_bits(),
                "lane {l}"
            );
        }
        // And the f64 path sums in the same fixed order (four partial sums).
        let t64: Vec<f64> = lanes[0].iter().map(|&x| x as f64).collect();
        let mut acc = [0.0f64; 4];
        for (f, &b) in row.iter().enumerate() {
            let j = if f < 20 { f % 4 } else { 0 };
            acc[j] += t64[f * 5 + b as usize];
        }
        let want = (acc[0] + acc[1]) + (acc[2] + acc[3]);
        assert_eq!(row_sum(&t64, &row, 5).to_bits(), want.to_bits());
    }
}
