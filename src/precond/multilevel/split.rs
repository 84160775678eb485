//! A coarse level held as rows split over the ranks (`Split`).

use super::cycle::{Op, Product};
use super::halo::Halo;
use super::prolongation::Prolongation;
use crate::comm::Comm;

/// A coarse level held as rows split over the ranks: rank r holds rows r L to
/// (r + 1) L - 1 of its operator and of its cycle's vectors (L = 6 ceil(aggregates /
/// ranks), the rows it holds: `first::held`); before a product every rank gathers the
/// whole vector (`rows` padded with zeros to L, into `all`) and computes its rows. Each
/// entry is the row sum the whole product computes (`Csr::mul_rows_into`) of the same
/// vector, so the cycle is the same bits on any number of ranks, at half the memory traffic
/// on two (this level's products were a fifth of the 10^6-element block on block's run,
/// every rank computing all of them) and a rank's share of the level's vectors and node
/// blocks.
pub struct Split<'a, C: Comm + ?Sized> {
    pub comm: &'a C,
    pub rows: &'a mut [f64],
    pub all: &'a mut [f64],
}

impl<C: Comm + ?Sized> Split<'_, C> {
    /// Every rank's `mine` (its rows of a vector) into `all`.
    fn gather(&mut self, mine: &[f64]) {
        let (held, pad) = self.rows.split_at_mut(mine.len());
        held.copy_from_slice(mine);
        pad.fill(0.0);
        self.comm.all_gather_equal_f64(self.rows, self.all);
    }
}

impl<C: Comm + ?Sized> Product for Split<'_, C> {
    fn mul(&mut self, a: &Op, halo: Option<&Halo>, x: &[f64], y: &mut [f64]) {
        self.fetch(x, halo);
        a.mul_rows_into(self.all, self.comm.rank() * self.rows.len(), y);
    }
    fn fetch<'s>(&'s mut self, mine: &'s [f64], halo: Option<&Halo>) -> &'s [f64] {
        match halo {
            Some(h) => {
                let first = self.comm.rank() * self.rows.len();
                self.all[first..first + mine.len()].copy_from_slice(mine);
                h.fetch(self.comm, mine, self.all);
            }
            None => self.gather(mine),
        }
        self.all
    }
    fn mul_whole(&mut self, a: &Op, x: &[f64], y: &mut [f64]) {
        a.mul_rows_into(x, self.comm.rank() * self.rows.len(), self.rows);
        self.comm.all_gather_equal_f64(self.rows, self.all);
        y.copy_from_slice(&self.all[..y.len()]);
    }
    fn whole<'s>(&'s mut self, mine: &'s [f64]) -> &'s [f64] {
        self.gather(mine);
        self.all
    }
    fn restrict(&mut self, transfer: &mut Prolongation, r: &[f64], out: &mut [f64]) {
        self.fetch(r, transfer.halo());
        let comm = self.comm;
        transfer.restrict(self.all, out, |m, a| comm.all_gather_equal_f64(m, a));
    }
    type Below<'s>
        = Split<'s, C>
    where
        Self: 's;
    fn below<'s>(&'s mut self, rows: &'s mut [f64], all: &'s mut [f64]) -> Split<'s, C> {
        Split {
            comm: self.comm,
            rows,
            all,
        }
    }
}
