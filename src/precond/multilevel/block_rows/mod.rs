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
    /// that block transposed). Empty once rounded: `Values::Columns` has every block, in
    /// order.
    slot: Vec<u32>,
    /// The values of the blocks (`Values`).
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

/// By how much at least `BlockRows::round_dominant` raises each held row's diagonal entry
/// (None: a row without one, and nothing off its diagonal to make up for).
pub struct Rounding(Vec<Option<f64>>);

impl BlockRows {
    /// How `round_dominant` would change the values (`diag` the whole operator's
    /// diagonal, row by row): for each held row i, at least how much its diagonal entry
    /// must rise, the sum over the row's entries off the diagonal of |e_ij| sqrt(d_i /
    /// d_j), e_ij an entry's change, summed in the order of the row's entries. None where
    /// the values cannot be so rounded: one not finite or beyond f32's range, a held row
    /// with values off the diagonal and no diagonal entry, or a change in a row or column
    /// whose diagonal is not positive.
    pub fn rounding(&self, diag: &[f64]) -> Option<Rounding> {
        let Values::Wide(val) = &self.val else {
            return Some(Rounding(Vec::new()));
        };
        if val
            .iter()
            .any(|v| !v.is_finite() || v.abs() > 0.5 * f64::from(f32::MAX))
        {
            return None;
        }
        let mut raise = Vec::with_capacity(self.len);
        for r in self.first..self.first + self.len {
            let i = r / B - self.block_first;
            let (mut diagonal, mut sum) = (None, 0.0f64);
            for b in self.ptr[i]..self.ptr[i + 1] {
                for c in 0..B {
                    let at = self.at(b, r % B, c);
                    if self.present[at / 64] & (1 << (at % 64)) == 0 {
                        continue;
                    }
                    let j = B * self.col[b] as usize + c;
                    let change = (val[at] - f64::from(val[at] as f32)).abs();
                    if j == r {
                        diagonal = Some(at);
                    } else if change > 0.0 {
                        let (di, dj) = (diag[r], diag[j]);
                        if !(di > 0.0 && dj > 0.0) {
                            return None;
                        }
                        sum += change * (di / dj).sqrt();
                    }
                }
            }
            match diagonal {
                Some(_) => raise.push(Some(sum)),
                None if sum > 0.0 => return None,
                None => raise.push(None),
            }
        }
        Some(Rounding(raise))
    }

    /// Stores the values in f32, every block its own and column-major in the order of the
    /// blocks (`Values::Columns`; `rounding` the change, of these rows): every value off
    /// the diagonal rounded to the nearest f32, and every diagonal entry of a held row
    /// raised to an f32 at or above d_i + sum_j |e_ij| sqrt(d_i / d_j). The change
    /// E = A' - A, scaled as D^-1/2 E D^-1/2, is then diagonally dominant with a non-negative
    /// diagonal, so E is positive semi-definite (Gershgorin's theorem; the operator is
    /// symmetric, its values mirrored bit for bit, and a value rounds alike wherever it
    /// stands) and A' is at least A: positive definite where A is, however nearly
    /// singular A is (a body held only by contact). Scaled so, each diagonal rises by at
    /// most 2^-24 times the row's entries in relative terms (|a_ij| <= sqrt(d_i d_j)), a
    /// few parts in 10^6 of it, however different the rows' scales (a row's own sum of
    /// changes can exceed a small diagonal by far). Each row's change is a function of
    /// that row's values and the diagonal alone, so every split of the rows over the ranks
    /// gives the same bits.
    pub fn round_dominant(&mut self, rounding: Rounding) {
        const BB: usize = B * B;
        if self.is_rounded() {
            return;
        }
        // A diagonal entry d raised to an f32 at or above d + sum (the sum's own rounding,
        // a few ulps of each term over a row's entries, covered by a margin of 2^-40 of
        // it): the nearest f32 to d + need, then the next ones up until it is above (one
        // or two steps).
        let raise = |d: f64, sum: f64| {
            let need = sum * (1.0 + f64::from(1u32 << 12) * f64::EPSILON);
            let mut t = (d + need) as f32;
            for _ in 0..8 {
                if f64::from(t) >= d + need && f64::from(t) - d >= need {
                    break;
                }
                t = t.next_up();
            }
            t
        };
        let blocks = self.col.len();
        let mut columns = vec![0.0f32; BB * blocks];
        let mut present = vec![0u64; (BB * blocks).div_ceil(64)];
        for i in 0..self.ptr.len() - 1 {
            for b in self.ptr[i]..self.ptr[i + 1] {
                for r in 0..B {
                    let row = B * (self.block_first + i) + r;
                    let held = (self.first..self.first + self.len).contains(&row);
                    for c in 0..B {
                        let at = self.at(b, r, c);
                        let to = BB * b + B * c + r;
                        let v = self.val.get(at);
                        let on = self.present[at / 64] & (1 << (at % 64)) != 0;
                        columns[to] = match rounding.0.get(row.wrapping_sub(self.first)) {
                            Some(&Some(sum))
                                if held && on && B * self.col[b] as usize + c == row =>
                            {
                                raise(v, sum)
                            }
                            _ => v as f32,
                        };
                        if on {
                            present[to / 64] |= 1 << (to % 64);
                        }
                    }
                }
            }
        }
        self.val = Values::Columns(columns);
        self.present = present;
        self.slot = Vec::new();
    }

    /// The first row held.
    pub fn first(&self) -> usize {
        self.first
    }
}

#[cfg(test)]
mod tests;
