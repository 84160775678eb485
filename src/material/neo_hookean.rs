//! Compressible neo-Hookean solid, W = mu/2 (tr C - 3) - mu ln J + lambda/2 (ln J)^2.

use crate::math::{det, inverse, matmul, transpose, Mat3, Vec3, IDENTITY, ZERO33};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NeoHookean {
    pub lambda: f64,
    pub mu: f64,
}

impl NeoHookean {
    pub fn new(e: f64, nu: f64) -> Self {
        let (lambda, mu) = super::lame(e, nu);
        NeoHookean { lambda, mu }
    }

    #[inline]
    fn deformation_gradient(h: &Mat3) -> Mat3 {
        let mut f = *h;
        for (i, row) in f.iter_mut().enumerate() {
            row[i] += IDENTITY[i][i];
        }
        f
    }

    /// P = mu (F - F^-T) + lambda ln J F^-T; `None` if J <= 0.
    #[inline]
    pub fn pk1(&self, h: &Mat3) -> Option<Mat3> {
        let f = Self::deformation_gradient(h);
        let (finv, j) = inverse(&f);
        if !(j > 0.0) {
            return None;
        }
        let lnj = j.ln();
        let mut p = ZERO33;
        for i in 0..3 {
            for k in 0..3 {
                // F^-T_ik = Finv_ki
                p[i][k] = self.mu * (f[i][k] - finv[k][i]) + self.lambda * lnj * finv[k][i];
            }
        }
        Some(p)
    }

    /// sigma = P F^T / J.
    pub fn cauchy(&self, h: &Mat3) -> Option<Mat3> {
        let p = self.pk1(h)?;
        let f = Self::deformation_gradient(h);
        let j = det(&f);
        let mut s = matmul(&p, &transpose(&f));
        for row in s.iter_mut() {
            for v in row.iter_mut() {
                *v /= j;
            }
        }
        Some(s)
    }

    /// `mu |g|^2 I + (mu + lambda - lambda ln J) (F^-T g)(F^-T g)^T`, the exact
    /// contraction of dP/dF with `g` on both sides.
    #[inline]
    pub fn tangent_gg(&self, h: &Mat3, g: &Vec3) -> Mat3 {
        let f = Self::deformation_gradient(h);
        let (finv, j) = inverse(&f);
        let lnj = if j > 0.0 { j.ln() } else { 0.0 };
        // hv = F^-T g: hv_i = sum_L Finv_Li g_L
        let hv = [
            finv[0][0] * g[0] + finv[1][0] * g[1] + finv[2][0] * g[2],
            finv[0][1] * g[0] + finv[1][1] * g[1] + finv[2][1] * g[2],
            finv[0][2] * g[0] + finv[1][2] * g[1] + finv[2][2] * g[2],
        ];
        let gg = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
        let c = self.mu + self.lambda - self.lambda * lnj;
        let mut k = ZERO33;
        for i in 0..3 {
            for m in 0..3 {
                k[i][m] = c * hv[i] * hv[m];
            }
            k[i][i] += self.mu * gg;
        }
        k
    }
}
