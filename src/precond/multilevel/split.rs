//! The first coarse level's operator applied by rows split over the ranks (`Split`).

use super::cycle::{Op, Product};
use crate::comm::Comm;

/// The first coarse level's operator applied by rows split over the ranks: rank r computes
/// rows r L to (r + 1) L - 1 (L = 6 ceil(aggregates / ranks), the rows it holds:
/// `first::held`) and every rank gathers the whole product. Each entry is the row sum the
/// whole product computes (`Csr::mul_rows_into`), so the cycle is the same bits on any
/// number of ranks, at half the memory traffic on two (this level's products were a fifth
/// of the 10^6-element block on block's run, every rank computing all of them).
pub struct Split<'a, C: Comm + ?Sized> {
    pub comm: &'a C,
    pub rows: &'a mut [f64],
    pub all: &'a mut [f64],
}

impl<C: Comm + ?Sized> Product for Split<'_, C> {
    fn mul(&mut self, a: &Op, x: &[f64], y: &mut [f64]) {
        a.mul_rows_into(x, self.comm.rank() * self.rows.len(), self.rows);
        self.comm.all_gather_equal_f64(self.rows, self.all);
        y.copy_from_slice(&self.all[..y.len()]);
    }
    fn gather(&mut self, mine: &[f64], all: &mut [f64]) {
        self.comm.all_gather_equal_f64(mine, all);
    }
}
