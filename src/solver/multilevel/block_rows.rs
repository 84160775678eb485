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

use super::sparse::Csr;

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
    /// B x B values of every block, row-major.
    val: Vec<f64>,
}

impl BlockRows {
    /// Rows first..first + len of `a` (clipped to its rows), whose unknowns come in nodes
    /// of B. None when the rows are not grouped so.
    pub fn new(a: &Csr, first: usize, len: usize) -> Option<Self> {
        if !a.rows.is_multiple_of(B) || !a.cols.is_multiple_of(B) {
            return None;
        }
        let end = (first + len).min(a.rows);
        let block_first = first / B;
        let block_end = end.div_ceil(B).max(block_first);
        let mut ptr = Vec::with_capacity(block_end - block_first + 1);
        ptr.push(0usize);
        let mut cols: Vec<u32> = Vec::new();
        // Pass 1: the block columns of every block row.
        for bi in block_first..block_end {
            let start = cols.len();
            for r in B * bi..B * (bi + 1) {
                cols.extend(a.row(r).0.iter().map(|&j| j / B as u32));
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
        for (i, bi) in (block_first..block_end).enumerate() {
            let blocks = &cols[ptr[i]..ptr[i + 1]];
            for r in 0..B {
                let (c, v) = a.row(B * bi + r);
                let mut t = 0;
                for (&j, &x) in c.iter().zip(v) {
                    let bj = j / B as u32;
                    while blocks[t] != bj {
                        t += 1;
                    }
                    val[B * B * (ptr[i] + t) + B * r + (j as usize % B)] = x;
                }
            }
        }
        Some(BlockRows {
            first,
            len: end.saturating_sub(first),
            block_first,
            ptr,
            col: cols,
            val,
        })
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        8 * (self.ptr.len() + self.val.len()) + 4 * self.col.len()
    }

    /// y = rows `first..first + y.len()` of A x (rows beyond the operator's give 0), for
    /// the rows this holds: `first` must be the first row held and y no longer than the
    /// rows held, padding aside.
    pub fn mul_rows_into(&self, x: &[f64], first: usize, y: &mut [f64]) {
        assert_eq!(first, self.first, "BlockRows: the rows held");
        y.fill(0.0);
        for i in 0..self.ptr.len() - 1 {
            let mut s = [0.0f64; B];
            for b in self.ptr[i]..self.ptr[i + 1] {
                let xj = &x[B * self.col[b] as usize..][..B];
                let v = &self.val[B * B * b..][..B * B];
                for r in 0..B {
                    for c in 0..B {
                        s[r] += v[B * r + c] * xj[c];
                    }
                }
            }
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
}

#[cfg(test)]
mod tests {
    use super::*;

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
        let a = Csr::from_triplets(n, n, t);
        let x: Vec<f64> = (0..n).map(|j| (j as f64 * 0.37).sin()).collect();
        let mut whole = vec![0.0; n];
        a.mul_into(&x, &mut whole);
        for ranks in 1..=5usize {
            let l = n.div_ceil(ranks);
            for r in 0..ranks {
                let rows = BlockRows::new(&a, r * l, l).expect("grouped in blocks");
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
            }
        }
        assert!(BlockRows::new(&Csr::from_triplets(7, 7, vec![]), 0, 7).is_none());
    }
}
