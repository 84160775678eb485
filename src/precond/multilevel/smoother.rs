//! The smoother of every level: a Chebyshev polynomial in D^-1 A (D the nodal 3 x 3 block
//! diagonal on the fine level, the node blocks of the coarse ones: `blocks.rs`) on the interval
//! [lmax / 30, lmax], lmax estimated by a power iteration from a fixed start vector. The
//! same polynomial before and after the coarse correction keeps the V-cycle symmetric.
//! Only operator applications, the diagonal and exact dot products are used, so on the
//! fine level it runs on the matrix-free operator.

/// What a level offers the smoother. Vectors are flat (three entries per node on the fine
/// level).
pub trait Space {
    type Error;
    /// y = A x.
    fn apply(&mut self, x: &[f64], y: &mut [f64]) -> Result<(), Self::Error>;
    /// z = D^-1 r.
    fn inv_diag(&self, r: &[f64], z: &mut [f64]);
    /// The dot product over the unknowns this rank owns, summed over all ranks, the same
    /// on any number of ranks.
    fn dot(&self, a: &[f64], b: &[f64]) -> f64;
    /// A start vector for the power iteration that does not depend on the partition.
    fn start(&self, v: &mut [f64]);
}

/// The smoothing polynomial.
#[derive(Clone, Copy, Debug)]
pub struct Chebyshev {
    pub degree: usize,
    pub lmin: f64,
    pub lmax: f64,
}

/// Power iterations for lmax.
const POWER_STEPS: usize = 15;
/// Safety factor on the estimate (the Rayleigh quotient approaches lmax from below).
const SAFETY: f64 = 1.1;
/// The smoothed part of the spectrum: [lmax / LOWER, lmax].
const LOWER: f64 = 30.0;

impl Chebyshev {
    /// Estimates lmax of D^-1 A by power iteration on the Rayleigh quotient
    /// (D^-1 A v, A v) / (v, A v), which never exceeds lmax. Buffers: three of the level's
    /// length.
    pub fn estimate<S: Space>(
        s: &mut S,
        degree: usize,
        v: &mut [f64],
        y: &mut [f64],
        w: &mut [f64],
    ) -> Result<Self, S::Error> {
        s.start(v);
        let mut lmax = 0.0f64;
        for _ in 0..POWER_STEPS {
            s.apply(v, y)?;
            s.inv_diag(y, w);
            let vy = s.dot(v, y);
            let wy = s.dot(w, y);
            if !(vy > 0.0) || !(wy > 0.0) {
                break;
            }
            lmax = lmax.max(wy / vy);
            let norm = s.dot(w, w).sqrt();
            for (a, b) in v.iter_mut().zip(w.iter()) {
                *a = b / norm;
            }
        }
        let lmax = if lmax > 0.0 { SAFETY * lmax } else { 1.0 };
        Ok(Chebyshev {
            degree,
            lmin: lmax / LOWER,
            lmax,
        })
    }

    /// Multiplies the bound on the spectrum by `factor` (the smoothed interval keeps its
    /// ratio).
    pub fn widen(&mut self, factor: f64) {
        self.lmax *= factor;
        self.lmin = self.lmax / LOWER;
    }

    /// x += p(D^-1 A) D^-1 r, the Chebyshev iteration from the residual r (destroyed):
    /// degree - 1 operator applications. Buffer d has the level's length, and so has t
    /// where the degree is 2 or more (degree 1 does not touch it).
    pub fn smooth<S: Space>(
        &self,
        s: &mut S,
        r: &mut [f64],
        x: &mut [f64],
        d: &mut [f64],
        t: &mut [f64],
    ) -> Result<(), S::Error> {
        let theta = 0.5 * (self.lmax + self.lmin);
        let delta = 0.5 * (self.lmax - self.lmin);
        let sigma = theta / delta;
        let mut rho = 1.0 / sigma;
        debug_assert!(
            self.degree < 2 || t.len() == r.len(),
            "the product's buffer"
        );
        s.inv_diag(r, d);
        d.iter_mut().for_each(|v| *v /= theta);
        for k in 0..self.degree {
            for (a, b) in x.iter_mut().zip(d.iter()) {
                *a += b;
            }
            if k + 1 == self.degree {
                break;
            }
            s.apply(d, t)?;
            for (a, b) in r.iter_mut().zip(t.iter()) {
                *a -= b;
            }
            let rho_new = 1.0 / (2.0 * sigma - rho);
            s.inv_diag(r, t);
            let (c1, c2) = (rho_new * rho, 2.0 * rho_new / delta);
            for (a, b) in d.iter_mut().zip(t.iter()) {
                *a = c1 * *a + c2 * b;
            }
            rho = rho_new;
        }
        Ok(())
    }
}

/// A fixed pseudo-random value in [-1, 1) for an index (a global id on the fine level).
pub fn hash_value(i: u64) -> f64 {
    let mut z = i.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::convert::Infallible;

    /// The 1D Laplacian with Dirichlet ends, diagonal 2.
    struct Lap(usize);

    impl Space for Lap {
        type Error = Infallible;
        fn apply(&mut self, x: &[f64], y: &mut [f64]) -> Result<(), Infallible> {
            let n = self.0;
            for i in 0..n {
                let l = if i > 0 { x[i - 1] } else { 0.0 };
                let r = if i + 1 < n { x[i + 1] } else { 0.0 };
                y[i] = 2.0 * x[i] - l - r;
            }
            Ok(())
        }
        fn inv_diag(&self, r: &[f64], z: &mut [f64]) {
            for (a, b) in z.iter_mut().zip(r) {
                *a = 0.5 * b;
            }
        }
        fn dot(&self, a: &[f64], b: &[f64]) -> f64 {
            a.iter().zip(b).map(|(x, y)| x * y).sum()
        }
        fn start(&self, v: &mut [f64]) {
            for (i, x) in v.iter_mut().enumerate() {
                *x = hash_value(i as u64);
            }
        }
    }

    #[test]
    fn estimate_brackets_lmax_and_smoothing_damps_the_upper_spectrum() {
        let n = 50;
        let mut s = Lap(n);
        let (mut v, mut y, mut w) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let ch = Chebyshev::estimate(&mut s, 3, &mut v, &mut y, &mut w).unwrap();
        // The eigenvalues of D^-1 A are 1 - cos(k pi / (n + 1)), the largest just below 2:
        // the estimate times the 1.1 safety factor must lie in [2 * 0.95, 2 * 1.1].
        let exact = 1.0 - (n as f64 * std::f64::consts::PI / (n as f64 + 1.0)).cos();
        assert!(
            ch.lmax >= exact && ch.lmax <= 1.1 * exact + 1e-12,
            "{}",
            ch.lmax
        );
        // The error propagation I - p(D^-1 A) D^-1 A on the highest eigenvector, which lies
        // in [lmin, lmax]: the degree-3 Chebyshev residual polynomial is bounded there by
        // 1 / T_3(sigma), sigma = (lmax + lmin) / (lmax - lmin) = 31 / 29.
        let k = n;
        let e: Vec<f64> = (0..n)
            .map(|i| ((i + 1) as f64 * k as f64 * std::f64::consts::PI / (n as f64 + 1.0)).sin())
            .collect();
        let mut r = vec![0.0; n];
        s.apply(&e, &mut r).unwrap();
        let mut x = vec![0.0; n];
        let (mut d, mut t) = (vec![0.0; n], vec![0.0; n]);
        ch.smooth(&mut s, &mut r, &mut x, &mut d, &mut t).unwrap();
        let err: f64 = e
            .iter()
            .zip(&x)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt();
        let e0: f64 = e.iter().map(|a| a * a).sum::<f64>().sqrt();
        let sigma = 31.0 / 29.0;
        let bound = 1.0 / (4.0 * sigma * sigma * sigma - 3.0 * sigma);
        // 1e-12: round-off of 50-term sums of O(1) values.
        assert!(err <= bound * e0 + 1e-12, "{err} vs {bound} * {e0}");
        assert!(bound < 0.6);
    }
}
