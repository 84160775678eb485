//! A coarse level's prolongator P as the V-cycle applies it: restriction P^T r and
//! prolongation P x.
//!
//! - `Whole`: P^T on every rank (the levels every rank builds whole, and every level on
//!   one rank); P x is its transposed product, each entry of P x getting its terms in the
//!   order of P's row, so the same bits as with P held too.
//! - `Split`: a coarse level built split over the ranks (`first`): this rank's rows
//!   of P (those of the aggregates it holds, `first::held`) and of P^T (a range of the next
//!   level's unknowns). P x is computed by this rank's rows, which are those of the level's
//!   vectors it holds (`cycle::Split`); P^T r by this rank's range, every rank's gathered
//!   (`gather`, as `Split` applies the level's operator). Every entry is the row sum the
//!   whole matrix gives it, the same bits on any number of ranks. No rank holds P or P^T
//!   whole: P^T was the largest part of the hierarchy every rank held whole (69 B per node
//!   of the mesh, 9.1 MB at n = 40). The rows are kept in 6 x 6 blocks (`BlockRows`: P
//!   maps the six modes of an aggregate to the six of the next level's, and its blocks
//!   are full), one column index per block: 8.1 bytes per entry instead of 12, the same
//!   row sums.

use super::block_rows::BlockRows;
use super::halo::Halo;
use super::sparse::Csr;

pub enum Prolongation {
    /// P^T.
    Whole(Csr),
    Split(Box<SplitRows>),
}

/// This rank's rows of P and of P^T, and the buffers of P^T's gathered products.
pub struct SplitRows {
    /// Rows `rank p_per ..` of P, numbered from the first (fewer on the last rank).
    p: Rows,
    /// Rows `rank pt_per ..` of P^T.
    pt: Rows,
    mine: Vec<f64>,
    all: Vec<f64>,
    /// The level's unknowns the rows of P^T read that other ranks hold, fetched before a
    /// restriction (`Product::fetch`) in place of the whole residual gathered.
    halo: Option<Halo>,
}

/// A rank's rows of P or P^T: in blocks where they come so, else as they are.
enum Rows {
    Blocks(BlockRows),
    Sparse(Csr),
}

impl Rows {
    /// Rows `first..first + rows.rows` of a matrix of `total` rows (`rows` numbered from
    /// the first), in blocks where the matrix's rows and columns come in blocks.
    fn new(rows: Csr, first: usize, total: usize) -> Self {
        let n = rows.rows;
        let blocks = BlockRows::of_rows(
            |r| match r.checked_sub(first).filter(|&k| k < n) {
                Some(k) => rows.row(k),
                None => (&[], &[]),
            },
            (total, rows.cols),
            first,
            n,
        );
        match blocks {
            Some(b) => Rows::Blocks(b),
            None => Rows::Sparse(rows),
        }
    }

    /// y = the rows held times x (y's entries beyond them 0).
    fn mul_into(&self, x: &[f64], y: &mut [f64]) {
        match self {
            Rows::Blocks(b) => b.mul_rows_into(x, b.first(), y),
            Rows::Sparse(a) => a.mul_rows_into(x, 0, y),
        }
    }
}

impl Prolongation {
    /// This rank's rows of P (`p`, `p_per` rows per rank) and of P^T (`pt`, `pt_per` per
    /// rank) on `ranks` ranks; each numbered from its first row.
    pub fn split(p: Csr, p_per: usize, pt: Csr, pt_per: usize, ranks: usize, rank: usize) -> Self {
        let (fine, coarse) = (pt.cols, p.cols);
        let p = Rows::new(p, rank * p_per, fine);
        let pt = Rows::new(pt, (rank * pt_per).min(coarse), coarse);
        Prolongation::Split(Box::new(SplitRows {
            p,
            pt,
            mine: vec![0.0; pt_per],
            all: vec![0.0; pt_per * ranks],
            halo: None,
        }))
    }

    /// Gives a split prolongator the exchange of its restriction.
    pub fn set_halo(&mut self, halo: Halo) {
        if let Prolongation::Split(s) = self {
            s.halo = Some(halo);
        }
    }

    /// The exchange of a split prolongator's restriction (None: the residual whole).
    pub fn halo(&self) -> Option<&Halo> {
        match self {
            Prolongation::Split(s) => s.halo.as_ref(),
            Prolongation::Whole(_) => None,
        }
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
            Prolongation::Split(s) => {
                s.pt.mul_into(r, &mut s.mine);
                gather(&s.mine, &mut s.all);
                out.copy_from_slice(&s.all[..out.len()]);
            }
        }
    }

    /// out = P x: the whole product (`Whole`), or this rank's rows of it (`Split`; out as
    /// long as the rows held).
    pub fn prolong(&mut self, x: &[f64], out: &mut [f64]) {
        match self {
            Prolongation::Whole(pt) => pt.mul_transpose_into(x, out),
            Prolongation::Split(s) => s.p.mul_into(x, out),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rank's rows of P and of P^T in blocks give the products of the sparse rows bit
    /// for bit, also where a rank's range of P^T starts within a block (`pt_per` not a
    /// multiple of six) and where a rank holds fewer rows or none.
    #[test]
    fn rows_in_blocks_give_the_sparse_rows_products_bit_for_bit() {
        let (fine, coarse) = (6 * 11, 6 * 4);
        let mut t = Vec::new();
        for i in 0..fine {
            for j in 0..coarse {
                if (i / 6 + j / 6) % 3 != 1 && (i * 7 + j * 5) % 11 != 0 {
                    t.push((i as u32, j as u32, ((i * 13 + j) as f64 * 0.71).sin() / 3.0));
                }
            }
        }
        let p = Csr::from_triplets(fine, coarse, t);
        let pt = p.transpose();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let xf: Vec<f64> = (0..fine).map(|i| (i as f64 * 0.37).cos()).collect();
        let xc: Vec<f64> = (0..coarse).map(|j| 1.0 / (j as f64 + 1.5)).collect();
        for ranks in 1..=5usize {
            let p_per = 6 * (fine / 6).div_ceil(ranks);
            let pt_per = coarse.div_ceil(ranks);
            for rank in 0..ranks {
                let rows_of = |m: &Csr, first: usize, per: usize| {
                    let mut c = Csr::empty(m.cols);
                    for r in first.min(m.rows)..(first + per).min(m.rows) {
                        let (cols, vals) = m.row(r);
                        c.idx.extend_from_slice(cols);
                        c.val.extend_from_slice(vals);
                        c.end_row();
                    }
                    c
                };
                let (own, range) = (
                    rows_of(&p, rank * p_per, p_per),
                    rows_of(&pt, rank * pt_per, pt_per),
                );
                for (sparse, first, total, per, x) in [
                    (own, rank * p_per, fine, p_per, &xc),
                    (range, (rank * pt_per).min(coarse), coarse, pt_per, &xf),
                ] {
                    let mut want = vec![f64::NAN; per];
                    sparse.mul_rows_into(x, 0, &mut want);
                    let mut got = vec![f64::NAN; per];
                    let rows = Rows::new(sparse, first, total);
                    assert!(matches!(rows, Rows::Blocks(_)), "in blocks");
                    rows.mul_into(x, &mut got);
                    assert_eq!(bits(&got), bits(&want), "ranks {ranks} rank {rank}");
                }
            }
        }
    }
}
