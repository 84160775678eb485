//! A coarse level's operator as the cycle applies it (`Op`).

use super::block_rows::BlockRows;
use super::sparse::Csr;

/// A level's operator: sparse rows while the hierarchy is built, the first level's then
/// held as this rank's rows in blocks (`Hierarchy::keep_rows`).
pub enum Op {
    Sparse(Csr),
    Rows(BlockRows),
}

impl Op {
    /// The sparse operator of a level being built.
    pub(super) fn csr(&self) -> &Csr {
        match self {
            Op::Sparse(a) => a,
            Op::Rows(_) => unreachable!("a level's sparse rows are used only while it is built"),
        }
    }

    /// y = A x (the whole product: a sparse level, or rows in blocks held whole).
    pub fn mul_into(&self, x: &[f64], y: &mut [f64]) {
        match self {
            Op::Sparse(a) => a.mul_into(x, y),
            Op::Rows(r) => r.mul_rows_into(x, 0, y),
        }
    }

    /// y = rows `first..first + y.len()` of A x, the same bits as `mul_into`'s.
    pub fn mul_rows_into(&self, x: &[f64], first: usize, y: &mut [f64]) {
        match self {
            Op::Sparse(a) => a.mul_rows_into(x, first, y),
            Op::Rows(r) => r.mul_rows_into(x, first, y),
        }
    }
}
