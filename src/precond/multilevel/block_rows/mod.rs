//! A coarse operator held as the rows one rank computes, in dense 6 x 6 blocks (the six
//! modes of an aggregate against the six of another): one column index per block instead
//! of one per entry (8.1 bytes per entry instead of 12) and the six values of x a block
//! needs read together. The first coarse level is kept this way once its hierarchy is
//! built: its products are most of a V-cycle's memory traffic, and each rank applies only
//! its own rows of it (`super::Split`).
//!
//! Each row's product is the sum `Csr::mul_into` forms, bit for bit: the same terms in the
//! same (column) order from +0.0. The entries a block holds that the sparse rows left out
//! are zeros, and adding a zero product to a sum that started at +0.0 never changes it.
//!
//! The operator is symmetric (its measured entries are 0.5 a + 0.5 b of the two probes
//! either way round), so a block below the diagonal whose transpose is a block of a row
//! held too keeps no values of its own: it is read from that block, transposed (only
//! where the two are the same bits, value by value and entry by entry: checked when rows
//! are made from sparse rows, `of_rows`; the measurement makes them so, every measured
//! value going to both entries of its pair, and stores one of each, `from_placed`).
//! Products and rows read the same values in the same order, so the same bits; about half
//! the values of a rank's rows are not stored twice (block on block at n = 80 on 2 ranks:
//! 137 MiB of blocks per rank before).
//!
//! A level the multilevel cycle smooths is then rounded to f32 (`round_dominant`, with
//! its diagonal raised so that the rounded operator is never less than the measured one)
//! and every block stored again, its own, column-major, in the order the product reads
//! them: the same bytes as the f64 values one of each pair, read once from start to end
//! (the mirrored blocks' transposed reads and the direct blocks' strided columns took
//! most of the product's instructions), each column of a block the next terms of the six
//! row sums.

use super::sparse::{Csr, Rows};

mod round;
pub use round::Rounding;

/// Unknowns per block: the rigid-body modes of an aggregate.
pub const B: usize = 6;

pub struct BlockRows {
    /// The rows held: first..first + len (of the whole operator's rows).
    first: usize,
    len: usize,
    /// The block rows that cover them: first / B onwards.
    block_first: usize,
    /// Blocks of block row i (counted from block_first): ptr[i]..ptr[i + 1].
    ptr: Vec<usize>,
    /// Block column of every block.
    col: Vec<u32>,
    /// Where every block's values are: the index of a block of `val` (with `MIRROR` set:
    /// that block transposed).
    slot: Vec<u32>,
    /// B x B values of the blocks stored, row-major.
    val: Values,
    /// One bit per value of `val`: whether the sparse rows held it (`to_csr`).
    present: Vec<u64>,
    /// Entries of the sparse rows held.
    entries: usize,
    /// Columns of the operator.
    columns: usize,
}

/// The values of the blocks stored: in f64 as made (B x B, row-major, a block read from
/// another transposed where its slot says so), or in f32 once `round_dominant` rounded
/// them, every block its own, column-major, in the order of the blocks (`Columns`: a
/// product reads them once from start to end, each column of a block the six row sums'
/// next terms together; as many bytes as the f64 values one of each symmetric pair).
enum Values {
    Wide(Vec<f64>),
    Columns(Vec<f32>),
}

impl Values {
    #[inline]
    fn get(&self, i: usize) -> f64 {
        match self {
            Values::Wide(v) => v[i],
            Values::Columns(v) => f64::from(v[i]),
        }
    }

    fn len(&self) -> usize {
        match self {
            Values::Wide(v) => v.len(),
            Values::Columns(v) => v.len(),
        }
    }

    fn bytes(&self) -> usize {
        match self {
            Values::Wide(v) => 8 * v.len(),
            Values::Columns(v) => 4 * v.len(),
        }
    }

    /// The values as made (before `round_dominant`).
    fn wide(&mut self) -> &mut Vec<f64> {
        match self {
            Values::Wide(v) => v,
            Values::Columns(_) => unreachable!("BlockRows: blocks are mirrored as made, in f64"),
        }
    }
}

/// A block read from another one, transposed.
pub(super) const MIRROR: u32 = 1 << 31;

impl BlockRows {
    /// Rows first..first + len of `a` (clipped to its rows), whose unknowns come in nodes
    /// of B. None when the rows are not grouped so.
    pub fn new(a: &Csr, first: usize, len: usize) -> Option<Self> {
        Self::of_rows(|r| a.row(r), (a.rows, a.cols), first, len)
    }

    /// `new` for an operator of `(rows, cols)` whose row r is `row(r)` (only rows first..
    /// first + len are asked for).
    pub fn of_rows<'a>(
        row: impl Fn(usize) -> (&'a [u32], &'a [f64]),
        (rows, cols): (usize, usize),
        first: usize,
        len: usize,
    ) -> Option<Self> {
        if !rows.is_multiple_of(B) || !cols.is_multiple_of(B) {
            return None;
        }
        let (rows_count, columns) = (rows, cols);
        let end = (first + len).min(rows);
        let block_first = first / B;
        let block_end = end.div_ceil(B).max(block_first);
        let mut ptr = Vec::with_capacity(block_end - block_first + 1);
        ptr.push(0usize);
        let mut cols: Vec<u32> = Vec::new();
        // Pass 1: the block columns of every block row.
        for bi in block_first..block_end {
            let start = cols.len();
            for r in B * bi..B * (bi + 1) {
                cols.extend(row(r).0.iter().map(|&j| j / B as u32));
            }
            cols[start..].sort_unstable();
            let mut w = start;
            for k in start..cols.len() {
                if k == start || cols[k] != cols[w - 1] {
                    cols[w] = cols[k];
                    w += 1;
                }
            }
            cols.truncate(w);
            ptr.push(cols.len());
        }
        cols.shrink_to_fit();
        // Pass 2: the values.
        let mut val = vec![0.0; B * B * cols.len()];
        let mut present = vec![0u64; val.len().div_ceil(64)];
        for (i, bi) in (block_first..block_end).enumerate() {
            let blocks = &cols[ptr[i]..ptr[i + 1]];
            for r in 0..B {
                let (c, v) = row(B * bi + r);
                let mut t = 0;
                for (&j, &x) in c.iter().zip(v) {
                    let bj = j / B as u32;
                    while blocks[t] != bj {
                        t += 1;
                    }
                    let at = B * B * (ptr[i] + t) + B * r + (j as usize % B);
                    val[at] = x;
                    present[at / 64] |= 1 << (at % 64);
                }
            }
        }
        let rows = BlockRows {
            first,
            len: end.saturating_sub(first),
            block_first,
            slot: Vec::new(),
            ptr,
            col: cols,
            val: Values::Wide(val),
            present,
            entries: 0,
            columns,
        };
        // Only a square operator has blocks that are each other's transposes.
        Some(BlockRows::mirrored(rows, rows_count == columns))
    }

    /// Rows first..first + len (`first` a multiple of B) from their blocks: block row i
    /// (counted from first / B) has blocks ptr[i]..ptr[i + 1]; block b, of block column
    /// `col[b]`, has the values `val[B * B * slot[b]..]` (B x B, row-major), transposed
    /// where `slot[b]` has `MIRROR` set (a block below the diagonal read from the one above
    /// it that is its transpose, bit for bit and present bit for present bit: the
    /// caller's guarantee, which `mirrored` checks), and `present` a bit per value stored
    /// of whether the sparse row holds it (a value without one is 0.0).
    pub fn from_placed(
        (first, len): (usize, usize),
        ptr: Vec<usize>,
        (col, slot): (Vec<u32>, Vec<u32>),
        val: Vec<f64>,
        present: Vec<u64>,
        columns: usize,
    ) -> Self {
        const BB: usize = B * B;
        assert!(first.is_multiple_of(B) && len.is_multiple_of(B));
        assert_eq!(ptr.len(), len / B + 1);
        assert_eq!(col.len(), slot.len());
        let stored = val.len() / BB;
        assert!(slot.iter().all(|&s| ((s & !MIRROR) as usize) < stored));
        let count = |s: u32| {
            let at = BB * (s & !MIRROR) as usize;
            (at..at + BB)
                .filter(|&i| present[i / 64] & (1 << (i % 64)) != 0)
                .count()
        };
        let entries = slot.iter().map(|&s| count(s)).sum();
        BlockRows {
            first,
            len,
            block_first: first / B,
            ptr,
            col,
            slot,
            val: Values::Wide(val),
            present,
            entries,
            columns,
        }
    }

    /// `rows` (every block stored, `slot` empty) with each block below the diagonal that
    /// is the same bits as the transpose of a block held above it read from that block
    /// (where `square`), and the values of the blocks stored moved together.
    fn mirrored(mut rows: BlockRows, square: bool) -> BlockRows {
        const BB: usize = B * B;
        let bit = |present: &[u64], at: usize| present[at / 64] & (1 << (at % 64)) != 0;
        rows.entries = rows.present.iter().map(|w| w.count_ones() as usize).sum();
        let blocks = rows.col.len();
        let (lo, hi) = (rows.block_first, rows.block_first + rows.ptr.len() - 1);
        // The block of row bj and column bi, for bi > bj, if row bj is held.
        let partner = |rows: &BlockRows, bj: usize, bi: usize| -> Option<usize> {
            (lo..hi).contains(&bj).then_some(())?;
            let range = rows.ptr[bj - lo]..rows.ptr[bj - lo + 1];
            let at = rows.col[range.clone()].binary_search(&(bi as u32)).ok()?;
            Some(range.start + at)
        };
        let same = |rows: &BlockRows, b: usize, t: usize| {
            (0..B).all(|r| {
                (0..B).all(|c| {
                    let (x, y) = (BB * b + B * r + c, BB * t + B * c + r);
                    rows.val.get(x).to_bits() == rows.val.get(y).to_bits()
                        && bit(&rows.present, x) == bit(&rows.present, y)
                })
            })
        };
        // Which block each one is read from (itself where none): a partner is above the
        // diagonal, so it is never read from another.
        let mut from: Vec<u32> = (0..blocks as u32).collect();
        for i in 0..rows.ptr.len() - 1 {
            let bi = lo + i;
            for b in rows.ptr[i]..rows.ptr[i + 1] {
                let bj = rows.col[b] as usize;
                if square && bj < bi {
                    if let Some(t) = partner(&rows, bj, bi).filter(|&t| same(&rows, b, t)) {
                        from[b] = t as u32;
                    }
                }
            }
        }
        let mut present = vec![0u64; 0];
        let mut slot = vec![0u32; blocks];
        let mut kept = 0usize;
        for b in 0..blocks {
            let t = from[b] as usize;
            if t != b {
                slot[b] = slot[t] | MIRROR;
                continue;
            }
            present.resize((BB * (kept + 1)).div_ceil(64), 0);
            for e in 0..BB {
                if bit(&rows.present, BB * b + e) {
                    let at = BB * kept + e;
                    present[at / 64] |= 1 << (at % 64);
                }
            }
            // kept <= b: the block moves forward over ones already read.
            rows.val.wide().copy_within(BB * b..BB * (b + 1), BB * kept);
            slot[b] = kept as u32;
            kept += 1;
        }
        assert!(kept < MIRROR as usize, "BlockRows: blocks to number");
        rows.val.wide().truncate(BB * kept);
        rows.val.wide().shrink_to_fit();
        present.shrink_to_fit();
        rows.present = present;
        rows.slot = slot;
        rows
    }

    /// Entries of the sparse rows held.
    pub fn nnz(&self) -> usize {
        self.entries
    }

    /// Blocks whose values are stored (the others are read from them, transposed).
    pub fn stored_blocks(&self) -> usize {
        self.val.len() / (B * B)
    }

    /// Whether the values are f32s (`round_dominant`).
    pub fn is_rounded(&self) -> bool {
        matches!(self.val, Values::Columns(_))
    }

    /// Where the value of row r, column c of block b is: its index in `val`.
    #[inline]
    fn at(&self, b: usize, r: usize, c: usize) -> usize {
        if let Values::Columns(_) = self.val {
            return B * B * b + B * c + r;
        }
        let s = self.slot[b];
        if s & MIRROR == 0 {
            B * B * s as usize + B * r + c
        } else {
            B * B * (s & !MIRROR) as usize + B * c + r
        }
    }

    /// Row r (held) as the sparse row it was made from, into `cols` and `vals`.
    pub fn row_into(&self, r: usize, cols: &mut Vec<u32>, vals: &mut Vec<f64>) {
        cols.clear();
        vals.clear();
        assert!(
            r >= self.first && r < self.first + self.len,
            "BlockRows: the rows held"
        );
        let i = r / B - self.block_first;
        let r = r % B;
        for b in self.ptr[i]..self.ptr[i + 1] {
            for c in 0..B {
                let at = self.at(b, r, c);
                if self.present[at / 64] & (1 << (at % 64)) != 0 {
                    cols.push(B as u32 * self.col[b] + c as u32);
                    vals.push(self.val.get(at));
                }
            }
        }
    }

    /// The rows held as the sparse rows they were made from (numbered from the first held
    /// one, global columns): the same entries and bits.
    pub fn to_csr(&self) -> Csr {
        let mut out = Csr::empty(self.columns);
        let (mut cols, mut vals) = (Vec::new(), Vec::new());
        for r in self.first..self.first + self.len {
            self.row_into(r, &mut cols, &mut vals);
            out.idx.extend_from_slice(&cols);
            out.val.extend_from_slice(&vals);
            out.end_row();
        }
        out
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        8 * (self.ptr.len() + self.present.len())
            + self.val.bytes()
            + 4 * (self.col.len() + self.slot.len())
    }

    /// y = rows `first..first + y.len()` of A x (rows beyond the operator's give 0), for
    /// the rows this holds: `first` must be the first row held and y no longer than the
    /// rows held, padding aside.
    pub fn mul_rows_into(&self, x: &[f64], first: usize, y: &mut [f64]) {
        assert_eq!(first, self.first, "BlockRows: the rows held");
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor has AVX2, checked just above.
            return unsafe {
                match &self.val {
                    Values::Wide(v) => self.mul_rows_avx2(v, x, y),
                    Values::Columns(v) => self.mul_columns_avx2(v, x, y),
                }
            };
        }
        match &self.val {
            Values::Wide(v) => self.mul_rows_body(v, x, y),
            Values::Columns(v) => self.mul_columns_body(v, x, y),
        }
    }

    /// `mul_rows_body` compiled for AVX2 (the caller checks the processor has it).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn mul_rows_avx2(&self, val: &[f64], x: &[f64], y: &mut [f64]) {
        self.mul_rows_body(val, x, y)
    }

    /// `mul_columns_body` compiled for AVX2 (the caller checks the processor has it).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn mul_columns_avx2(&self, val: &[f32], x: &[f64], y: &mut [f64]) {
        self.mul_columns_body(val, x, y)
    }

    /// `mul_rows_body` for the rounded values, every block column-major in the order of
    /// the blocks: the same products (of the values widened, exactly) and sums in the
    /// same order, read from start to end.
    #[inline(always)]
    fn mul_columns_body(&self, val: &[f32], x: &[f64], y: &mut [f64]) {
        y.fill(0.0);
        for i in 0..self.ptr.len() - 1 {
            let mut s = [0.0f64; B];
            let (lo, hi) = (self.ptr[i], self.ptr[i + 1]);
            let blocks = val[B * B * lo..B * B * hi].chunks_exact(B * B);
            for (v, &j) in blocks.zip(&self.col[lo..hi]) {
                let xj: &[f64; B] = x[B * j as usize..][..B]
                    .try_into()
                    .expect("a block's B values");
                for (column, &xc) in v.chunks_exact(B).zip(xj) {
                    for (sr, &a) in s.iter_mut().zip(column) {
                        *sr += f64::from(a) * xc;
                    }
                }
            }
            self.store_rows(i, &s, y);
        }
    }

    /// Each entry of a block row is its own sum, in the order of the blocks and, within a
    /// block, of its columns; the six entries' sums advance together, column by column of
    /// a block (a vector of the six rows' products at each column: the same products and
    /// sums as entry after entry).
    #[inline(always)]
    fn mul_rows_body(&self, val: &[f64], x: &[f64], y: &mut [f64]) {
        y.fill(0.0);
        for i in 0..self.ptr.len() - 1 {
            let mut s = [0.0f64; B];
            for b in self.ptr[i]..self.ptr[i + 1] {
                let xj: &[f64; B] = x[B * self.col[b] as usize..][..B]
                    .try_into()
                    .expect("a block's B values");
                let t = self.slot[b];
                let v: &[f64; B * B] = val[B * B * (t & !MIRROR) as usize..][..B * B]
                    .try_into()
                    .expect("a block's B x B values");
                // The same products in the same order either way: row r of the block is
                // column r of the one it is read from.
                if t & MIRROR == 0 {
                    for (c, &xc) in xj.iter().enumerate() {
                        for (r, sr) in s.iter_mut().enumerate() {
                            *sr += v[B * r + c] * xc;
                        }
                    }
                } else {
                    for (c, &xc) in xj.iter().enumerate() {
                        for (r, sr) in s.iter_mut().enumerate() {
                            *sr += v[B * c + r] * xc;
                        }
                    }
                }
            }
            self.store_rows(i, &s, y);
        }
    }

    /// Block row i's sums into y, for the rows held that y covers.
    #[inline(always)]
    fn store_rows(&self, i: usize, s: &[f64; B], y: &mut [f64]) {
        for (r, &sr) in s.iter().enumerate() {
            let row = B * (self.block_first + i) + r;
            if row >= self.first && row < self.first + self.len {
                let k = row - self.first;
                if k < y.len() {
                    y[k] = sr;
                }
            }
        }
    }
}

/// The rows of a `BlockRows` handed out as sparse rows (`sparse::Rows`).
pub struct View<'a> {
    pub rows: &'a BlockRows,
    cols: Vec<u32>,
    vals: Vec<f64>,
}

impl<'a> View<'a> {
    pub fn new(rows: &'a BlockRows) -> Self {
        View {
            rows,
            cols: Vec::new(),
            vals: Vec::new(),
        }
    }
}

impl Rows for View<'_> {
    fn row(&mut self, r: usize) -> (&[u32], &[f64]) {
        self.rows.row_into(r, &mut self.cols, &mut self.vals);
        (&self.cols, &self.vals)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `a`'s rows split as over 1 to 5 ranks (at rows within blocks too): each rank's
    /// product and rows are the sparse ones bit for bit; `more` checks each rank's rows
    /// further (ranks, rank, its rows, them as sparse rows).
    pub(super) fn split_rows_give_the_sparse_bits(
        a: &Csr,
        mut more: impl FnMut(usize, usize, &BlockRows, &Csr),
    ) {
        let n = a.rows;
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let x: Vec<f64> = (0..n).map(|j| (j as f64 * 0.37).sin()).collect();
        let mut whole = vec![0.0; n];
        a.mul_into(&x, &mut whole);
        for ranks in 1..=5usize {
            let l = n.div_ceil(ranks);
            for r in 0..ranks {
                let rows = BlockRows::new(a, r * l, l).expect("grouped in blocks");
                let mut y = vec![f64::NAN; l];
                rows.mul_rows_into(&x, r * l, &mut y);
                for (k, &v) in y.iter().enumerate() {
                    let want = whole.get(r * l + k).copied().unwrap_or(0.0);
                    assert_eq!(
                        v.to_bits(),
                        want.to_bits(),
                        "ranks {ranks} rank {r} row {k}"
                    );
                }
                // The sparse rows come back: the same entries (an explicit zero
                // included) and bits.
                let back = rows.to_csr();
                assert_eq!(
                    (back.rows, back.cols),
                    ((n.min((r + 1) * l)).saturating_sub(r * l), n)
                );
                for k in 0..back.rows {
                    let ((c, v), (wc, wv)) = (back.row(k), a.row(r * l + k));
                    assert_eq!(c, wc, "ranks {ranks} rank {r} row {k}");
                    assert_eq!(bits(v), bits(wv));
                }
                more(ranks, r, &rows, &back);
            }
        }
    }

    /// Rows of blocks give the bits of the sparse product, whole or split at rows that do
    /// not fall on block boundaries, with entries whose sums round and zeros the sparse
    /// rows leave out.
    #[test]
    fn block_rows_give_the_sparse_product_bit_for_bit() {
        let n = 4 * B;
        let mut t = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let h = (i * 31 + j * 17) % 7;
                if h < 3 && (i / B + j / B) % 3 != 2 {
                    t.push((i as u32, j as u32, 1.0 / (h as f64 + 3.0) - 0.1 * j as f64));
                }
            }
        }
        t.push((1, 2, 0.0));
        split_rows_give_the_sparse_bits(&Csr::from_triplets(n, n, t), |_, _, _, _| {});
        assert!(BlockRows::new(&Csr::from_triplets(7, 7, vec![]), 0, 7).is_none());
    }

    /// A symmetric operator: the blocks below the diagonal whose transposes are held are
    /// not stored again, and the product and the rows are the sparse ones bit for bit,
    /// whole and split (at rows within blocks too). One entry breaks the symmetry of its
    /// block pair, which is then stored twice.
    #[test]
    fn symmetric_rows_store_a_mirrored_block_once_and_give_the_same_bits() {
        let n = 6 * B;
        let mut t = Vec::new();
        for i in 0..n {
            for j in 0..=i {
                let h = (i * 31 + j * 17 + i * j) % 7;
                if h < 4 && (i / B + j / B) % 3 != 2 {
                    let v = 1.0 / (h as f64 + 3.0) - 0.1 * (i + j) as f64;
                    t.push((i as u32, j as u32, v));
                    if i != j {
                        t.push((j as u32, i as u32, v));
                    }
                }
            }
        }
        // Not symmetric: row 4 * B, column B (block (4, 1)) against block (1, 4).
        t.push((4 * B as u32, B as u32 + 1, 0.25));
        let a = Csr::from_triplets(n, n, t);
        let mut mirrored_somewhere = false;
        split_rows_give_the_sparse_bits(&a, |ranks, _, rows, back| {
            let stored = rows.stored_blocks();
            let mirrored = rows.slot.iter().filter(|&&s| s & MIRROR != 0).count();
            assert_eq!(stored + mirrored, rows.col.len());
            mirrored_somewhere |= mirrored > 0;
            if ranks == 1 {
                assert_eq!(rows.nnz(), back.idx.len());
                // Every block below the diagonal but the broken pair's is mirrored.
                let below = (0..n / B)
                    .map(|i| {
                        let cols = &rows.col[rows.ptr[i]..rows.ptr[i + 1]];
                        cols.iter().filter(|&&j| (j as usize) < i).count()
                    })
                    .sum::<usize>();
                assert_eq!(mirrored, below - 1);
            }
        });
        assert!(mirrored_somewhere);
    }
}
