//! The coarsest level's direct solve: a dense Cholesky factor of the unknowns with a
//! positive diagonal.

use super::sparse::Csr;
use crate::precond::dense_cholesky::DenseCholesky;

/// A dense factor of the unknowns with a positive diagonal only (the others solve to
/// zero): a level whose nodes carry rotation modes without stiffness factors at the size
/// of its live unknowns.
pub struct Compressed {
    live: Vec<usize>,
    dense: DenseCholesky,
    work: Vec<f64>,
}

impl Compressed {
    pub fn new(a: &Csr) -> Self {
        let diag = a.diagonal();
        let live: Vec<usize> = (0..a.rows).filter(|&i| diag[i] > 0.0).collect();
        let m = live.len();
        let mut pos = vec![usize::MAX; a.rows];
        for (k, &i) in live.iter().enumerate() {
            pos[i] = k;
        }
        let mut d = vec![0.0; m * m];
        for (k, &i) in live.iter().enumerate() {
            let (c, v) = a.row(i);
            for (&j, &x) in c.iter().zip(v) {
                let q = pos[j as usize];
                if q != usize::MAX {
                    d[k * m + q] = x;
                }
            }
        }
        Compressed {
            dense: DenseCholesky::new(&d, m),
            live,
            work: vec![0.0; m],
        }
    }

    /// x <- A^-1 x (zero on the unknowns left out).
    pub fn solve(&mut self, x: &mut [f64]) {
        for (w, &i) in self.work.iter_mut().zip(&self.live) {
            *w = x[i];
        }
        self.dense.solve(&mut self.work);
        x.fill(0.0);
        for (w, &i) in self.work.iter().zip(&self.live) {
            x[i] = *w;
        }
    }
}
