//! The coarsest level's direct solve: a dense Cholesky factor. Unknowns with no stiffness
//! of their own (the modes of an aggregate held entirely by Dirichlet conditions) and
//! unknowns whose pivot is lost to cancellation (a mode the earlier ones already span) are
//! left out: their solution component is zero.

pub struct Dense {
    n: usize,
    l: Vec<f64>,
    kept: Vec<bool>,
}

/// A dense factor of the unknowns with a positive diagonal only (the others solve to
/// zero): a level whose nodes carry rotation modes without stiffness factors at the size
/// of its live unknowns.
pub struct Compressed {
    live: Vec<usize>,
    dense: Dense,
    work: Vec<f64>,
}

impl Compressed {
    pub fn new(a: &super::sparse::Csr) -> Self {
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
            dense: Dense::new(&d, m),
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

impl Dense {
    /// Factors the symmetric matrix `a` (row-major, n x n).
    pub fn new(a: &[f64], n: usize) -> Self {
        let scale = (0..n).map(|i| a[i * n + i].abs()).fold(0.0, f64::max);
        let mut l = vec![0.0; n * n];
        let mut kept = vec![false; n];
        for i in 0..n {
            for j in 0..=i {
                let (ri, rj) = (&l[i * n..i * n + j], &l[j * n..j * n + j]);
                let dot: f64 = ri.iter().zip(rj).map(|(x, y)| x * y).sum();
                let s = a[i * n + j] - dot;
                if j < i {
                    l[i * n + j] = if kept[j] { s / l[j * n + j] } else { 0.0 };
                } else {
                    let d = a[i * n + i];
                    if s > 1e-10 * d && d > 1e-14 * scale {
                        l[i * n + i] = s.sqrt();
                        kept[i] = true;
                    } else {
                        l[i * n..i * n + i + 1].iter_mut().for_each(|v| *v = 0.0);
                    }
                }
            }
        }
        Dense { n, l, kept }
    }

    pub fn num_kept(&self) -> usize {
        self.kept.iter().filter(|&&k| k).count()
    }

    /// x <- A^-1 x on the kept unknowns (zero on the others).
    pub fn solve(&self, x: &mut [f64]) {
        let n = self.n;
        let l = &self.l;
        for i in 0..n {
            if !self.kept[i] {
                x[i] = 0.0;
                continue;
            }
            let s = x[i] - (0..i).map(|j| l[i * n + j] * x[j]).sum::<f64>();
            x[i] = s / l[i * n + i];
        }
        for i in (0..n).rev() {
            if !self.kept[i] {
                x[i] = 0.0;
                continue;
            }
            let mut s = x[i];
            for j in i + 1..n {
                s -= l[j * n + i] * x[j];
            }
            x[i] = s / l[i * n + i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_and_drops_a_dead_unknown() {
        // A = B^T B + I on unknowns 0, 1, 3 and a zero row and column for unknown 2 (no
        // stiffness): the factor drops 2 and solves the rest to round-off.
        let n = 4;
        let live = [0usize, 1, 3];
        let b = [[0.3, -0.2, 0.9], [1.1, 0.4, -0.5], [0.2, 0.8, 0.1]];
        let mut a = vec![0.0; n * n];
        for (p, &i) in live.iter().enumerate() {
            for (q, &j) in live.iter().enumerate() {
                let mut s = if p == q { 1.0 } else { 0.0 };
                for row in &b {
                    s += row[p] * row[q];
                }
                a[i * n + j] = s;
            }
        }
        let f = Dense::new(&a, n);
        assert_eq!(f.num_kept(), 3);
        let x_true = [0.5, -1.0, 0.0, 2.0];
        let mut x: Vec<f64> = (0..n)
            .map(|i| (0..n).map(|j| a[i * n + j] * x_true[j]).sum())
            .collect();
        f.solve(&mut x);
        // Condition number below 10: the solution is exact to a few ulps.
        for i in 0..n {
            assert!((x[i] - x_true[i]).abs() < 1e-14, "{i}: {}", x[i]);
        }
    }
}
