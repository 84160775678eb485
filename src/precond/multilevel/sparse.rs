//! Compressed sparse row matrices for the coarse levels: products, transposes and
//! matrix-vector products, each a fixed sequence of floating-point operations (rows in
//! order, entries of a row in column order), so every rank that builds a coarse level from
//! the same data gets it bitwise the same.

/// The node of every unknown, for unknowns grouped in nodes by `node_ptr` (node i holds
/// unknowns node_ptr[i]..node_ptr[i + 1]).
pub fn node_of(node_ptr: &[usize]) -> Vec<u32> {
    let nodes = node_ptr.len() - 1;
    let mut node_of = vec![0u32; node_ptr[nodes]];
    for i in 0..nodes {
        node_of[node_ptr[i]..node_ptr[i + 1]].fill(i as u32);
    }
    node_of
}

/// A sparse matrix in CSR form with sorted column indices in every row.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Csr {
    pub rows: usize,
    pub cols: usize,
    pub ptr: Vec<usize>,
    pub idx: Vec<u32>,
    pub val: Vec<f64>,
}

impl Csr {
    /// Builds a matrix from (row, column, value) triplets; duplicates are summed in the
    /// order given.
    pub fn from_triplets(rows: usize, cols: usize, t: Vec<(u32, u32, f64)>) -> Self {
        // Ordered as a stable sort by (row, column) orders them, which keeps duplicates in
        // the order given, so their sum is fixed: a stable bucketing by row (linear time),
        // then a stable sort of each row by column.
        let mut start = vec![0usize; rows + 1];
        for &(i, _, _) in &t {
            start[i as usize + 1] += 1;
        }
        for i in 0..rows {
            start[i + 1] += start[i];
        }
        let mut next = start.clone();
        let mut sorted = vec![(0u32, 0u32, 0.0f64); t.len()];
        for e in t {
            let k = &mut next[e.0 as usize];
            sorted[*k] = e;
            *k += 1;
        }
        drop(next);
        for i in 0..rows {
            sorted[start[i]..start[i + 1]].sort_by_key(|&(_, j, _)| j);
        }
        let t = sorted;
        let mut ptr = vec![0usize; rows + 1];
        let mut idx = Vec::with_capacity(t.len());
        let mut val: Vec<f64> = Vec::with_capacity(t.len());
        let mut last = (u32::MAX, u32::MAX);
        for (i, j, v) in t {
            if (i, j) == last {
                *val.last_mut().expect("a previous entry") += v;
            } else {
                idx.push(j);
                val.push(v);
                ptr[i as usize + 1] += 1;
                last = (i, j);
            }
        }
        for i in 0..rows {
            ptr[i + 1] += ptr[i];
        }
        Csr {
            rows,
            cols,
            ptr,
            idx,
            val,
        }
    }

    pub fn nnz(&self) -> usize {
        self.val.len()
    }

    /// The entries of row i.
    #[inline]
    pub fn row(&self, i: usize) -> (&[u32], &[f64]) {
        let r = self.ptr[i]..self.ptr[i + 1];
        (&self.idx[r.clone()], &self.val[r])
    }

    /// The diagonal (zero where a row has no diagonal entry).
    pub fn diagonal(&self) -> Vec<f64> {
        (0..self.rows)
            .map(|i| {
                let (c, v) = self.row(i);
                c.binary_search(&(i as u32)).map_or(0.0, |k| v[k])
            })
            .collect()
    }

    /// y = A x.
    pub fn mul_into(&self, x: &[f64], y: &mut [f64]) {
        for (i, yi) in y.iter_mut().enumerate().take(self.rows) {
            *yi = self.row_times(i, x);
        }
    }

    /// y = rows `first..first + y.len()` of A x (rows beyond the last give 0): the same
    /// bits as `mul_into`'s, row by row.
    pub fn mul_rows_into(&self, x: &[f64], first: usize, y: &mut [f64]) {
        for (k, yi) in y.iter_mut().enumerate() {
            let i = first + k;
            *yi = if i < self.rows {
                self.row_times(i, x)
            } else {
                0.0
            };
        }
    }

    /// Row i of A times x.
    #[inline]
    fn row_times(&self, i: usize, x: &[f64]) -> f64 {
        let (c, v) = self.row(i);
        let mut s = 0.0;
        for (&j, &a) in c.iter().zip(v) {
            s += a * x[j as usize];
        }
        s
    }

    /// y = A^T x (scattered by rows of A, in row order): each y_j gets its terms in the
    /// order of row j of A^T, so the same bits as `self.transpose().mul_into(x, y)`.
    pub fn mul_transpose_into(&self, x: &[f64], y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        for (i, &xi) in x.iter().enumerate().take(self.rows) {
            let (c, v) = self.row(i);
            for (&j, &a) in c.iter().zip(v) {
                y[j as usize] += a * xi;
            }
        }
    }

    pub fn transpose(&self) -> Csr {
        let mut count = vec![0usize; self.cols + 1];
        for &j in &self.idx {
            count[j as usize + 1] += 1;
        }
        for j in 0..self.cols {
            count[j + 1] += count[j];
        }
        let ptr = count.clone();
        let mut next = count;
        let mut idx = vec![0u32; self.nnz()];
        let mut val = vec![0.0; self.nnz()];
        for i in 0..self.rows {
            let (c, v) = self.row(i);
            for (&j, &a) in c.iter().zip(v) {
                let k = next[j as usize];
                idx[k] = i as u32;
                val[k] = a;
                next[j as usize] += 1;
            }
        }
        Csr {
            rows: self.cols,
            cols: self.rows,
            ptr,
            idx,
            val,
        }
    }

    /// A B (Gustavson's row-by-row product; every entry summed in a fixed order).
    pub fn matmul(&self, b: &Csr) -> Csr {
        assert_eq!(self.cols, b.rows, "matmul: inner dimensions differ");
        let mut prod = RowProduct::new(b.cols);
        let mut out = Csr::empty(b.cols);
        for i in 0..self.rows {
            prod.push_row(self.row(i), |k| b.row(k), &mut out);
        }
        out
    }

    /// A matrix of no rows yet and `cols` columns, to which rows are pushed.
    pub fn empty(cols: usize) -> Csr {
        Csr {
            rows: 0,
            cols,
            ptr: vec![0],
            idx: Vec::new(),
            val: Vec::new(),
        }
    }

    /// Removes every row (keeping the allocations).
    pub fn clear_rows(&mut self) {
        self.rows = 0;
        self.ptr.truncate(1);
        self.idx.clear();
        self.val.clear();
    }

    /// Closes the row whose entries were pushed last.
    pub fn end_row(&mut self) {
        self.ptr.push(self.idx.len());
        self.rows += 1;
    }

    /// (A + A^T) / 2 for a square matrix (rows sorted by column, as every constructor
    /// here leaves them): each row of A merged with the same row of A^T, an entry in both
    /// 0.5 a + 0.5 b (the sum the triplets of both, in that order, gave before). Holds A,
    /// A^T and the result, 36 bytes per entry of A at most: the triplets of both took 68,
    /// the peak of a multilevel build (block on block n = 40: 4.67 million entries).
    pub fn symmetric_part(&self) -> Csr {
        assert_eq!(self.rows, self.cols, "symmetric_part: a square matrix");
        let t = self.transpose();
        self.merge(
            &t,
            |a, b| 0.5 * a + 0.5 * b,
            |a| 0.5 * a,
            |b| 0.5 * b,
            false,
        )
    }

    /// `symmetric_part`, its bits, in place where the pattern is symmetric (every entry's
    /// mirror is present, as in a Galerkin product of a symmetric pattern): each pair
    /// becomes 0.5 a + 0.5 b (the same sum either way round), a diagonal entry 0.5 a +
    /// 0.5 a, as the merge computes them. Holds no copy: `symmetric_part` holds A, A^T
    /// and the result, three times the matrix, where this one is a coarse level held
    /// whole on every rank. An unsymmetric pattern goes through `symmetric_part`.
    pub fn into_symmetric_part(mut self) -> Csr {
        assert_eq!(self.rows, self.cols, "symmetric_part: a square matrix");
        let mirror = |m: &Csr, i: usize, j: u32| {
            let (c, _) = m.row(j as usize);
            c.binary_search(&(i as u32))
                .ok()
                .map(|k| m.ptr[j as usize] + k)
        };
        let symmetric = (0..self.rows).all(|i| {
            let (c, _) = self.row(i);
            c.iter().all(|&j| mirror(&self, i, j).is_some())
        });
        if !symmetric {
            return self.symmetric_part();
        }
        for i in 0..self.rows {
            for k in self.ptr[i]..self.ptr[i + 1] {
                let j = self.idx[k];
                if (j as usize) < i {
                    continue;
                }
                let m = mirror(&self, i, j).expect("the pattern is symmetric");
                let v = 0.5 * self.val[k] + 0.5 * self.val[m];
                self.val[k] = v;
                self.val[m] = v;
            }
        }
        self
    }

    /// Row by row, the sorted union of the entries of `self` and `b` (of the same shape):
    /// `both(a, b)` where both have the column, `only_a(a)` or `only_b(b)` where one has;
    /// with `drop_zeros`, entries that come out exactly zero are left out.
    pub fn merge(
        &self,
        b: &Csr,
        both: impl Fn(f64, f64) -> f64,
        only_a: impl Fn(f64) -> f64,
        only_b: impl Fn(f64) -> f64,
        drop_zeros: bool,
    ) -> Csr {
        assert_eq!((self.rows, self.cols), (b.rows, b.cols), "merge: one shape");
        let mut out = Csr::empty(self.cols);
        out.ptr.reserve(self.rows);
        out.idx.reserve(self.nnz().max(b.nnz()));
        out.val.reserve(self.nnz().max(b.nnz()));
        for i in 0..self.rows {
            merge_row(
                self.row(i),
                b.row(i),
                (&both, &only_a, &only_b),
                drop_zeros,
                &mut out,
            );
        }
        out.idx.shrink_to_fit();
        out.val.shrink_to_fit();
        out
    }

    /// Every entry as a dense row-major matrix (for the coarsest level).
    pub fn to_dense(&self) -> Vec<f64> {
        let mut d = vec![0.0; self.rows * self.cols];
        for i in 0..self.rows {
            let (c, v) = self.row(i);
            for (&j, &a) in c.iter().zip(v) {
                d[i * self.cols + j as usize] = a;
            }
        }
        d
    }
}

/// Rows of a matrix handed out one at a time by row number (each valid until the next).
pub trait Rows {
    fn row(&mut self, r: usize) -> (&[u32], &[f64]);
}

/// The rows of a Csr numbered from `first` (its row i is row first + i).
pub struct Offset<'a> {
    pub a: &'a Csr,
    pub first: usize,
}

impl Rows for Offset<'_> {
    fn row(&mut self, r: usize) -> (&[u32], &[f64]) {
        self.a.row(r - self.first)
    }
}

/// What `merge_row` makes of an entry in both rows, only in the first, only in the second.
pub type MergeRule<'f> = (
    &'f dyn Fn(f64, f64) -> f64,
    &'f dyn Fn(f64) -> f64,
    &'f dyn Fn(f64) -> f64,
);

/// Pushes to `out` the sorted union of two sorted rows (`Csr::merge`'s rule) and closes
/// the row.
pub fn merge_row(
    (ca, va): (&[u32], &[f64]),
    (cb, vb): (&[u32], &[f64]),
    (both, only_a, only_b): MergeRule,
    drop_zeros: bool,
    out: &mut Csr,
) {
    let (mut x, mut y) = (0, 0);
    while x < ca.len() || y < cb.len() {
        let s = ca.get(x).copied().unwrap_or(u32::MAX);
        let t = cb.get(y).copied().unwrap_or(u32::MAX);
        let (j, v) = if s == t {
            x += 1;
            y += 1;
            (s, both(va[x - 1], vb[y - 1]))
        } else if s < t {
            x += 1;
            (s, only_a(va[x - 1]))
        } else {
            y += 1;
            (t, only_b(vb[y - 1]))
        };
        if !drop_zeros || v != 0.0 {
            out.idx.push(j);
            out.val.push(v);
        }
    }
    out.end_row();
}

/// The workspace of a product A B computed a row at a time (Gustavson): a row of A times
/// B, every entry summed over the row's entries in their order, the columns sorted. The
/// one routine behind `Csr::matmul` and the products that do not hold a whole factor
/// (`triple_product`, `prolongator::smooth`): their entries are the same bits. Also the
/// workspace of `BlockInverse::left_multiply_node`.
pub struct RowProduct {
    pub(super) acc: Vec<f64>,
    pub(super) seen: Vec<bool>,
    pub(super) cols: Vec<u32>,
}

impl RowProduct {
    /// For products with `cols` columns.
    pub fn new(cols: usize) -> Self {
        RowProduct {
            acc: vec![0.0; cols],
            seen: vec![false; cols],
            cols: Vec::new(),
        }
    }

    /// Starts the next row's sums from the entries of `row` (a partial sum computed
    /// earlier, `triple_product_part`) instead of from zero.
    pub fn seed(&mut self, (c, v): (&[u32], &[f64])) {
        for (&j, &x) in c.iter().zip(v) {
            self.seen[j as usize] = true;
            self.acc[j as usize] = x;
            self.cols.push(j);
        }
    }

    /// Pushes to `out` the row (ca, va) of A times B (`b_row(k)`: row k of B) and closes it.
    pub fn push_row<'b>(
        &mut self,
        (ca, va): (&[u32], &[f64]),
        b_row: impl Fn(usize) -> (&'b [u32], &'b [f64]),
        out: &mut Csr,
    ) {
        for (&k, &a) in ca.iter().zip(va) {
            let (cb, vb) = b_row(k as usize);
            for (&j, &bv) in cb.iter().zip(vb) {
                let j = j as usize;
                if !self.seen[j] {
                    self.seen[j] = true;
                    self.cols.push(j as u32);
                }
                self.acc[j] += a * bv;
            }
        }
        self.cols.sort_unstable();
        for &j in &self.cols {
            out.idx.push(j);
            out.val.push(self.acc[j as usize]);
            self.acc[j as usize] = 0.0;
            self.seen[j as usize] = false;
        }
        self.cols.clear();
        out.end_row();
    }
}

impl Csr {
    /// The matrix as bytes (`from_bytes` reads them back), to send between ranks.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut b = Vec::with_capacity(24 + 8 * self.ptr.len() + 12 * self.nnz());
        for x in [self.rows, self.cols, self.nnz()] {
            b.extend_from_slice(&(x as u64).to_le_bytes());
        }
        for &x in &self.ptr {
            b.extend_from_slice(&(x as u64).to_le_bytes());
        }
        for &x in &self.idx {
            b.extend_from_slice(&x.to_le_bytes());
        }
        for &x in &self.val {
            b.extend_from_slice(&x.to_bits().to_le_bytes());
        }
        b
    }

    /// Rows `rows` as a matrix of their own, as bytes (`to_bytes`).
    pub fn rows_to_bytes(&self, rows: std::ops::Range<usize>) -> Vec<u8> {
        let (a, b) = (self.ptr[rows.start], self.ptr[rows.end]);
        Csr {
            rows: rows.len(),
            cols: self.cols,
            ptr: self.ptr[rows.start..=rows.end]
                .iter()
                .map(|&x| x - a)
                .collect(),
            idx: self.idx[a..b].to_vec(),
            val: self.val[a..b].to_vec(),
        }
        .to_bytes()
    }

    /// Appends the rows of `rows` (of the same columns).
    pub fn append(&mut self, rows: &Csr) {
        assert_eq!(rows.cols, self.cols, "append: one number of columns");
        let base = self.idx.len();
        self.ptr.extend(rows.ptr[1..].iter().map(|&x| base + x));
        self.idx.extend_from_slice(&rows.idx);
        self.val.extend_from_slice(&rows.val);
        self.rows += rows.rows;
    }

    /// Appends the rows of a matrix written by `to_bytes` (of the same columns).
    pub fn append_bytes(&mut self, b: &[u8]) {
        let u64_at =
            |o: usize| u64::from_le_bytes(b[o..o + 8].try_into().expect("8 bytes")) as usize;
        let (rows, cols, nnz) = (u64_at(0), u64_at(8), u64_at(16));
        assert_eq!(cols, self.cols, "append_bytes: one number of columns");
        let base = self.idx.len();
        let mut o = 24;
        for r in 1..=rows {
            self.ptr.push(base + u64_at(o + 8 * r));
        }
        o += 8 * (rows + 1);
        self.idx.extend(
            b[o..o + 4 * nnz]
                .chunks_exact(4)
                .map(|c| u32::from_le_bytes(c.try_into().expect("4 bytes"))),
        );
        o += 4 * nnz;
        self.val.extend(
            b[o..o + 8 * nnz]
                .chunks_exact(8)
                .map(|c| f64::from_bits(u64::from_le_bytes(c.try_into().expect("8 bytes")))),
        );
        self.rows += rows;
    }

    /// A matrix written by `to_bytes`.
    pub fn from_bytes(b: &[u8]) -> Csr {
        let cols = u64::from_le_bytes(b[8..16].try_into().expect("8 bytes")) as usize;
        let mut m = Csr::empty(cols);
        m.append_bytes(b);
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dense_mul(a: &[f64], b: &[f64], n: usize, k: usize, m: usize) -> Vec<f64> {
        let mut c = vec![0.0; n * m];
        for i in 0..n {
            for j in 0..m {
                for l in 0..k {
                    c[i * m + j] += a[i * k + l] * b[l * m + j];
                }
            }
        }
        c
    }

    fn sample(rows: usize, cols: usize, seed: u32) -> Csr {
        let mut t = Vec::new();
        for i in 0..rows {
            for j in 0..cols {
                let h = (i as u32 * 31 + j as u32 * 17 + seed * 7) % 5;
                if h < 2 {
                    // Small integers: every product and sum below is exact in f64.
                    t.push((
                        i as u32,
                        j as u32,
                        (h as f64 + 1.0) * if j % 2 == 0 { 1.0 } else { -2.0 },
                    ));
                }
            }
        }
        Csr::from_triplets(rows, cols, t)
    }

    /// Rows split into blocks (the last one padded, as `multilevel::Split` splits them over
    /// ranks) give the bits of the whole product, with non-integer entries whose sums round.
    #[test]
    fn a_product_by_blocks_of_rows_is_the_whole_product_bit_for_bit() {
        let a = sample(11, 9, 3);
        let x: Vec<f64> = (0..9).map(|j| 1.0 / (j as f64 + 3.0)).collect();
        let mut whole = vec![0.0; 11];
        a.mul_into(&x, &mut whole);
        for ranks in 1..=4usize {
            let l = 11usize.div_ceil(ranks);
            let mut all = vec![f64::NAN; l * ranks];
            for (r, block) in all.chunks_mut(l).enumerate() {
                a.mul_rows_into(&x, r * l, block);
            }
            assert!(all[11..].iter().all(|&v| v == 0.0), "padding is zero");
            let same = all[..11]
                .iter()
                .zip(&whole)
                .all(|(p, q)| p.to_bits() == q.to_bits());
            assert!(same, "{ranks} blocks: {:?} vs {whole:?}", &all[..11]);
        }
    }

    #[test]
    fn products_match_dense_exactly() {
        // Integer entries: the sparse and dense products must agree bit for bit.
        let a = sample(7, 5, 1);
        let b = sample(5, 6, 2);
        let c = a.matmul(&b);
        assert_eq!(
            c.to_dense(),
            dense_mul(&a.to_dense(), &b.to_dense(), 7, 5, 6)
        );
        let at = a.transpose();
        let ad = a.to_dense();
        for i in 0..7 {
            for j in 0..5 {
                assert_eq!(at.to_dense()[j * 7 + i], ad[i * 5 + j]);
            }
        }
        let x: Vec<f64> = (0..5).map(|i| i as f64 - 2.0).collect();
        let mut y = vec![0.0; 7];
        a.mul_into(&x, &mut y);
        assert_eq!(y, dense_mul(&ad, &x, 7, 5, 1));
        let xt: Vec<f64> = (0..7).map(|i| 3.0 - i as f64).collect();
        let mut yt = vec![0.0; 5];
        a.mul_transpose_into(&xt, &mut yt);
        assert_eq!(yt, dense_mul(&at.to_dense(), &xt, 5, 7, 1));
    }

    /// Entries that round: the products below must give the whole products' bits.
    #[test]
    fn triplets_sum_duplicates_and_symmetric_part() {
        let m = Csr::from_triplets(
            2,
            2,
            vec![(1, 0, 1.0), (0, 1, 3.0), (1, 0, 2.0), (0, 0, 4.0)],
        );
        assert_eq!(m.to_dense(), vec![4.0, 3.0, 3.0, 0.0]);
        let s = Csr::from_triplets(2, 2, vec![(0, 1, 2.0), (1, 0, 4.0)]).symmetric_part();
        assert_eq!(s.to_dense(), vec![0.0, 3.0, 3.0, 0.0]);
        assert_eq!(m.diagonal(), vec![4.0, 0.0]);
    }

    #[test]
    fn symmetric_part_is_the_triplet_sum_bit_for_bit() {
        // An unsymmetric pattern (entries on one side only, on both, on the diagonal) with
        // values whose halves round: the merge must give the entries (and bits) of the
        // triplets of A and A^T summed in that order.
        let mut trip = Vec::new();
        for i in 0..9u32 {
            for j in 0..9u32 {
                if (i * 7 + j * 2) % 4 != 0 {
                    trip.push((i, j, 0.1 * (i as f64 + 1.0) / (j as f64 + 3.0) - 0.37));
                }
            }
        }
        let a = Csr::from_triplets(9, 9, trip);
        let at = a.transpose();
        let mut both = Vec::new();
        for m in [&a, &at] {
            for i in 0..9 {
                let (c, v) = m.row(i);
                for (&j, &x) in c.iter().zip(v) {
                    both.push((i as u32, j, 0.5 * x));
                }
            }
        }
        let expected = Csr::from_triplets(9, 9, both);
        let s = a.symmetric_part();
        assert_eq!(s.ptr, expected.ptr);
        assert_eq!(s.idx, expected.idx);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&s.val), bits(&expected.val));
        assert!(s.nnz() > a.nnz(), "the pattern was unsymmetric");
        let bits_of = |m: &Csr| (m.ptr.clone(), m.idx.clone(), bits(&m.val));
        assert_eq!(bits_of(&a.clone().into_symmetric_part()), bits_of(&s));
    }

    /// In place on a symmetric pattern (values that are not, halves that round, a
    /// subnormal diagonal whose half rounds): the merge's bits.
    #[test]
    fn symmetric_part_in_place_gives_the_merge_bits() {
        let mut trip = Vec::new();
        for i in 0..11u32 {
            for j in 0..11u32 {
                if (i * j + i + j) % 3 != 1 {
                    let v = if i == j && i % 4 == 0 {
                        f64::from_bits(3 + i as u64)
                    } else {
                        0.1 * (i as f64 + 1.0) / (j as f64 + 3.0) - 0.37
                    };
                    trip.push((i, j, v));
                }
            }
        }
        let a = Csr::from_triplets(11, 11, trip);
        assert_ne!(a.to_dense(), a.transpose().to_dense(), "values unsymmetric");
        let s = a.symmetric_part();
        assert_eq!(s.nnz(), a.nnz(), "the pattern is symmetric");
        let bits = |m: &Csr| m.val.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let t = a.into_symmetric_part();
        assert_eq!((&t.ptr, &t.idx, bits(&t)), (&s.ptr, &s.idx, bits(&s)));
    }
}
