//! The node-block diagonal of a coarse level and its inverse: each coarse node carries the
//! six modes of an aggregate (three translations, three rotations about its centre), which
//! its own block couples strongly (an aggregate not symmetric about its centre couples a
//! translation with a rotation; a node held in some directions by Dirichlet conditions
//! leaves a mode without stiffness). Relaxation with the inverse of the whole block reduces
//! such a node's error in one step where a point (diagonal) relaxation does not.
//! Unknowns without stiffness, and modes the block's other modes already span, are left
//! out of the inverse (they relax to zero), like the coarsest direct solve does.

use super::sparse::{Csr, Offset, RowProduct, Rows};
use crate::precond::dense_cholesky::DenseCholesky;

/// Per node, the dense inverse of its diagonal block (row-major, size b x b for a node of
/// b unknowns).
pub struct BlockInverse {
    node_ptr: Vec<usize>,
    /// Offsets of each node's inverse in `inv`.
    off: Vec<usize>,
    inv: Vec<f64>,
}

impl BlockInverse {
    /// The inverses of the diagonal blocks of `a` (unknowns grouped by `node_ptr`).
    pub fn new(a: &Csr, node_ptr: &[usize]) -> Self {
        let inv = Self::inverses(&mut Offset { a, first: 0 }, node_ptr, 0..node_ptr.len() - 1);
        Self::from_inverses(node_ptr, inv)
    }

    /// The inverses of the diagonal blocks of `nodes` (b x b values, row-major, for a node
    /// of b unknowns, node after node); `a` gives the rows of the level's operator.
    pub fn inverses(
        a: &mut impl Rows,
        node_ptr: &[usize],
        nodes: std::ops::Range<usize>,
    ) -> Vec<f64> {
        let mut inv = Vec::new();
        for i in nodes {
            let (lo, hi) = (node_ptr[i], node_ptr[i + 1]);
            let b = hi - lo;
            let mut block = vec![0.0; b * b];
            for p in lo..hi {
                let (c, v) = a.row(p);
                for (&q, &x) in c.iter().zip(v) {
                    let q = q as usize;
                    if (lo..hi).contains(&q) {
                        block[(p - lo) * b + (q - lo)] = x;
                    }
                }
            }
            let f = DenseCholesky::new(&block, b);
            // Column k of the inverse: the solve of unit vector k (zero for a dropped mode).
            let mut cols = vec![0.0; b * b];
            let mut e = vec![0.0; b];
            for k in 0..b {
                e.fill(0.0);
                e[k] = 1.0;
                f.solve(&mut e);
                for r in 0..b {
                    cols[r * b + k] = e[r];
                }
            }
            inv.extend_from_slice(&cols);
        }
        inv
    }

    /// From the inverses of every node's block (`inverses` over all nodes, or its pieces
    /// concatenated in node order).
    pub fn from_inverses(node_ptr: &[usize], inv: Vec<f64>) -> Self {
        let mut off = Vec::with_capacity(node_ptr.len());
        off.push(0);
        for w in node_ptr.windows(2) {
            let b = w[1] - w[0];
            off.push(off.last().expect("one offset") + b * b);
        }
        assert_eq!(
            *off.last().expect("one offset"),
            inv.len(),
            "one inverse per node"
        );
        BlockInverse {
            node_ptr: node_ptr.to_vec(),
            off,
            inv,
        }
    }

    /// From the inverses of `nodes` only (`inverses` over them), their unknowns numbered
    /// from the first's: what a rank holds of a level whose rows are split over the ranks.
    pub fn of_nodes(node_ptr: &[usize], nodes: std::ops::Range<usize>, inv: Vec<f64>) -> Self {
        if nodes.is_empty() {
            // No node (a rank whose share starts past the last one, `first::held`).
            return Self::from_inverses(&[0], inv);
        }
        let lo = node_ptr[nodes.start];
        let ptr: Vec<usize> = node_ptr[nodes.start..=nodes.end]
            .iter()
            .map(|&p| p - lo)
            .collect();
        Self::from_inverses(&ptr, inv)
    }

    /// z = D^-1 r.
    pub fn apply(&self, r: &[f64], z: &mut [f64]) {
        for i in 0..self.node_ptr.len() - 1 {
            let (lo, hi) = (self.node_ptr[i], self.node_ptr[i + 1]);
            let b = hi - lo;
            let m = &self.inv[self.off[i]..self.off[i + 1]];
            for p in 0..b {
                let row = &m[p * b..(p + 1) * b];
                z[lo + p] = row.iter().zip(&r[lo..hi]).map(|(x, y)| x * y).sum();
            }
        }
    }

    /// Nodes of the level.
    pub fn nodes(&self) -> usize {
        self.node_ptr.len() - 1
    }

    /// The unknowns of node i.
    pub fn unknowns(&self, i: usize) -> std::ops::Range<usize> {
        self.node_ptr[i]..self.node_ptr[i + 1]
    }

    /// D^-1 M for a sparse M of the level's rows (row p of the result combines the rows
    /// of p's node block). Entry (p, j) is the sum over q of inv[p][q] m[q][j] in the order
    /// of q, from its first term, over the q with inv[p][q] != 0 whose row has column j,
    /// written row by row (no triplets: their list, six times the entries of M, was the
    /// peak of a multilevel build).
    pub fn left_multiply(&self, m: &Csr) -> Csr {
        let mut out = Csr::empty(m.cols);
        out.ptr.reserve(m.rows);
        out.idx.reserve(m.nnz());
        out.val.reserve(m.nnz());
        let mut ws = RowProduct::new(m.cols);
        for i in 0..self.nodes() {
            let lo = self.node_ptr[i];
            self.left_multiply_node(i, |q| m.row(lo + q), &mut ws, &mut out);
        }
        out
    }

    /// Pushes to `out` the rows of node i of D^-1 M, given that node's rows of M (`row(q)`:
    /// the node's q-th row), by `left_multiply`'s rule.
    pub fn left_multiply_node<'m>(
        &self,
        i: usize,
        row: impl Fn(usize) -> (&'m [u32], &'m [f64]),
        ws: &mut RowProduct,
        out: &mut Csr,
    ) {
        let b = self.node_ptr[i + 1] - self.node_ptr[i];
        let inv = &self.inv[self.off[i]..self.off[i + 1]];
        for p in 0..b {
            for q in 0..b {
                let w = inv[p * b + q];
                if w == 0.0 {
                    continue;
                }
                let (c, v) = row(q);
                for (&j, &x) in c.iter().zip(v) {
                    let j = j as usize;
                    if ws.seen[j] {
                        ws.acc[j] += w * x;
                    } else {
                        ws.seen[j] = true;
                        ws.acc[j] = w * x;
                        ws.cols.push(j as u32);
                    }
                }
            }
            ws.cols.sort_unstable();
            for &j in &ws.cols {
                out.idx.push(j);
                out.val.push(ws.acc[j as usize]);
                ws.seen[j as usize] = false;
            }
            ws.cols.clear();
            out.end_row();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_range_of_nodes_applies_as_the_whole_does_on_their_rows() {
        // Four nodes of two, one, two and one unknowns, a tridiagonal operator: the
        // inverses of nodes 1..3 alone give the whole's rows 2..5, bit for bit.
        let node_ptr = [0usize, 2, 3, 5, 6];
        let mut t = Vec::new();
        for i in 0..6 {
            t.push((i, i, 4.0 + i as f64));
            if i + 1 < 6 {
                t.push((i, i + 1, -1.0 / (1.0 + i as f64)));
                t.push((i + 1, i, -1.0 / (1.0 + i as f64)));
            }
        }
        let a = Csr::from_triplets(6, 6, t);
        let whole = BlockInverse::new(&a, &node_ptr);
        let mut rows = Offset { a: &a, first: 0 };
        let part = BlockInverse::of_nodes(
            &node_ptr,
            1..3,
            BlockInverse::inverses(&mut rows, &node_ptr, 1..3),
        );
        assert_eq!(part.nodes(), 2);
        let r = [0.3, -1.2, 2.5, 0.7, -0.4, 1.9];
        let (mut zw, mut zp) = ([0.0; 6], [0.0; 3]);
        whole.apply(&r, &mut zw);
        part.apply(&r[2..5], &mut zp);
        assert_eq!(zp, zw[2..5]);
    }

    #[test]
    fn inverts_each_block_and_drops_a_dead_unknown() {
        // Two nodes of two unknowns and one node of one; the middle node's second unknown
        // has no stiffness. D^-1 D x = x on the live unknowns, 0 on the dead one.
        let node_ptr = [0usize, 2, 4, 5];
        let t = vec![
            (0, 0, 4.0),
            (0, 1, 1.0),
            (1, 0, 1.0),
            (1, 1, 3.0),
            (2, 2, 2.0),
            (4, 4, 5.0),
            (0, 4, -1.0),
            (4, 0, -1.0),
        ];
        let a = Csr::from_triplets(5, 5, t);
        let d = BlockInverse::new(&a, &node_ptr);
        let dx = [4.0 - 2.0, 1.0 - 6.0, 1.0, 0.0, 15.0];
        let mut z = [0.0; 5];
        d.apply(&dx, &mut z);
        let want = [1.0, -2.0, 0.5, 0.0, 3.0];
        // 2 x 2 and 1 x 1 solves of condition number below 2: exact to a few ulps.
        for i in 0..5 {
            assert!(
                (z[i] - want[i]).abs() < 1e-15,
                "{i}: {} vs {}",
                z[i],
                want[i]
            );
        }
        // The sparse product agrees with applying D^-1 column by column.
        let m = d.left_multiply(&a);
        let dense = m.to_dense();
        for j in 0..5 {
            let col: Vec<f64> = (0..5).map(|i| a.to_dense()[i * 5 + j]).collect();
            let mut zc = [0.0; 5];
            d.apply(&col, &mut zc);
            for i in 0..5 {
                assert!((dense[i * 5 + j] - zc[i]).abs() < 1e-15);
            }
        }
    }
}
