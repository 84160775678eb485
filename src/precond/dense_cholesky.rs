//! A dense Cholesky factor (lower, row-major) that leaves out unknowns with no stiffness of
//! their own (the modes of an aggregate held entirely by Dirichlet conditions) and unknowns
//! whose pivot is lost to cancellation (a mode the earlier ones already span): their
//! solution component is zero. The two-level coarse space factors its whole coarse operator
//! with it, the multilevel preconditioner its coarsest level and its node blocks.

use crate::memory::{try_filled, AllocError};

pub struct DenseCholesky {
    n: usize,
    l: Vec<f64>,
    kept: Vec<bool>,
}

impl DenseCholesky {
    /// Factors the symmetric matrix `a` (row-major, n x n).
    pub fn new(a: &[f64], n: usize) -> Self {
        Self::factor(a, n, vec![0.0; n * n])
    }

    /// `new`, failing only when the memory for the factor (`what`) is refused.
    pub fn try_new(a: &[f64], n: usize, what: &str) -> Result<Self, AllocError> {
        Ok(Self::factor(a, n, try_filled(0.0, n * n, what)?))
    }

    /// Row-oriented Cholesky into `l` (n x n zeros): each entry is a contiguous dot product
    /// of two row prefixes.
    fn factor(a: &[f64], n: usize, mut l: Vec<f64>) -> Self {
        let scale = (0..n).map(|i| a[i * n + i].abs()).fold(0.0, f64::max);
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
        DenseCholesky { n, l, kept }
    }

    pub fn num_kept(&self) -> usize {
        self.kept.iter().filter(|&&k| k).count()
    }

    /// x <- A^-1 x on the kept unknowns (zero on the others); the forward substitution
    /// subtracts each row's dot product with the solved unknowns at once.
    pub fn solve(&self, x: &mut [f64]) {
        let (n, l) = (self.n, &self.l);
        for i in 0..n {
            if !self.kept[i] {
                x[i] = 0.0;
                continue;
            }
            let s = x[i] - (0..i).map(|j| l[i * n + j] * x[j]).sum::<f64>();
            x[i] = s / l[i * n + i];
        }
        self.backward(x);
    }

    /// `solve` with a forward substitution that subtracts term by term (the two-level
    /// coarse space's order: the same solution, other rounding).
    pub fn solve_term_by_term(&self, x: &mut [f64]) {
        let (n, l) = (self.n, &self.l);
        for i in 0..n {
            if !self.kept[i] {
                x[i] = 0.0;
                continue;
            }
            let mut s = x[i];
            for j in 0..i {
                s -= l[i * n + j] * x[j];
            }
            x[i] = s / l[i * n + i];
        }
        self.backward(x);
    }

    /// x <- L^-T x on the kept unknowns (zero on the others).
    fn backward(&self, x: &mut [f64]) {
        let (n, l) = (self.n, &self.l);
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
        let f = DenseCholesky::new(&a, n);
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

    #[test]
    fn drops_dependent_unknowns() {
        // A = B^T B + I on 5 unknowns, then a sixth unknown that copies the first (its row
        // and column duplicate unknown 0, so A is singular): the factor must drop it and
        // solve the other five exactly, in either forward order.
        let n0 = 5;
        let b: Vec<f64> = (0..25)
            .map(|k| ((k * 7 + 3) % 11) as f64 / 11.0 - 0.4)
            .collect();
        let mut a = vec![0.0; 36];
        for i in 0..n0 {
            for j in 0..n0 {
                let mut s = if i == j { 1.0 } else { 0.0 };
                for k in 0..n0 {
                    s += b[k * n0 + i] * b[k * n0 + j];
                }
                a[i * 6 + j] = s;
            }
        }
        for j in 0..6 {
            let v = if j == 5 { a[0] } else { a[j] };
            a[5 * 6 + j] = v;
            a[j * 6 + 5] = v;
        }
        let f = DenseCholesky::try_new(&a, 6, "a test factor").unwrap();
        assert_eq!(f.kept, vec![true, true, true, true, true, false]);
        let x_true = [0.3, -1.2, 0.7, 2.0, -0.5, 0.0];
        let rhs: Vec<f64> = (0..6)
            .map(|i| (0..5).map(|j| a[i * 6 + j] * x_true[j]).sum())
            .collect();
        let (mut x, mut y) = (rhs.clone(), rhs);
        f.solve(&mut x);
        f.solve_term_by_term(&mut y);
        // The system's condition number is below 100, so the solution is exact to about
        // 100 eps relative.
        for i in 0..6 {
            for v in [x[i], y[i]] {
                assert!((v - x_true[i]).abs() < 1e-13, "{i}: {v} vs {}", x_true[i]);
            }
        }
    }
}
