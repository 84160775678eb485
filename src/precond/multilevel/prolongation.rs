//! A coarse level's prolongator P as the V-cycle applies it: restriction P^T r and
//! prolongation P x.
//!
//! - `Whole`: P^T on every rank (the levels every rank builds whole, and every level on
//!   one rank); P x is its transposed product, each entry of P x getting its terms in the
//!   order of P's row, so the same bits as with P held too.
//! - `Split`: the first coarse level built split over the ranks (`first`): this rank's rows
//!   of P (those of the aggregates it holds, `first::held`) and of P^T (a range of the next
//!   level's unknowns); each product is computed by rows and every rank's rows gathered
//!   (`gather`, as `Split` applies the level's operator), so every entry is the row sum the
//!   whole matrix gives it, the same bits on any number of ranks. No rank holds P or P^T
//!   whole: P^T was the largest part of the hierarchy every rank held whole (69 B per node
//!   of the mesh, 9.1 MB at n = 40).

use super::sparse::Csr;

pub enum Prolongation {
    /// P^T.
    Whole(Csr),
    Split(SplitRows),
}

/// This rank's rows of P and of P^T, and the buffers of their gathered products.
pub struct SplitRows {
    /// Rows `rank p_per ..` of P, numbered from the first (fewer on the last rank).
    p: Csr,
    p_per: usize,
    /// Rows `rank pt_per ..` of P^T, numbered from the first.
    pt: Csr,
    pt_per: usize,
    mine: Vec<f64>,
    all: Vec<f64>,
}

impl Prolongation {
    /// This rank's rows of P (`p`, `p_per` rows per rank) and of P^T (`pt`, `pt_per` per
    /// rank) on `ranks` ranks.
    pub fn split(p: Csr, p_per: usize, pt: Csr, pt_per: usize, ranks: usize) -> Self {
        let per = p_per.max(pt_per);
        Prolongation::Split(SplitRows {
            p,
            p_per,
            pt,
            pt_per,
            mine: vec![0.0; per],
            all: vec![0.0; per * ranks],
        })
    }

    /// out = P^T r (`gather`: every rank's `mine` into `all`, in rank order; collective
    /// where split).
    pub fn restrict(
        &mut self,
        r: &[f64],
        out: &mut [f64],
        gather: impl FnOnce(&[f64], &mut [f64]),
    ) {
        match self {
            Prolongation::Whole(pt) => pt.mul_into(r, out),
            Prolongation::Split(s) => s.gathered(true, r, out, gather),
        }
    }

    /// out = P x (as `restrict`).
    pub fn prolong(&mut self, x: &[f64], out: &mut [f64], gather: impl FnOnce(&[f64], &mut [f64])) {
        match self {
            Prolongation::Whole(pt) => pt.mul_transpose_into(x, out),
            Prolongation::Split(s) => s.gathered(false, x, out, gather),
        }
    }
}

impl SplitRows {
    /// out = P^T x (`transpose`) or P x: this rank's rows, then every rank's gathered.
    fn gathered(
        &mut self,
        transpose: bool,
        x: &[f64],
        out: &mut [f64],
        gather: impl FnOnce(&[f64], &mut [f64]),
    ) {
        let (m, per) = if transpose {
            (&self.pt, self.pt_per)
        } else {
            (&self.p, self.p_per)
        };
        let ranks = self.all.len() / self.mine.len().max(1);
        let mine = &mut self.mine[..per];
        m.mul_rows_into(x, 0, mine);
        let all = &mut self.all[..per * ranks];
        gather(mine, all);
        out.copy_from_slice(&all[..out.len()]);
    }
}
