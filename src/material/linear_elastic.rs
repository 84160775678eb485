//! Isotropic linear elasticity under small kinematics.

use crate::math::{Mat3, Vec3, ZERO33};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearElastic {
    pub lambda: f64,
    pub mu: f64,
}

impl LinearElastic {
    pub fn new(e: f64, nu: f64) -> Self {
        let (lambda, mu) = super::lame(e, nu);
        LinearElastic { lambda, mu }
    }

    /// Cauchy stress of the symmetric part of `h`.
    #[inline]
    pub fn stress(&self, h: &Mat3) -> Mat3 {
        let tr = h[0][0] + h[1][1] + h[2][2];
        let mut s = ZERO33;
        for i in 0..3 {
            for j in 0..3 {
                s[i][j] = self.mu * (h[i][j] + h[j][i]);
            }
            s[i][i] += self.lambda * tr;
        }
        s
    }

    /// `(lambda + mu) g g^T + mu |g|^2 I`.
    #[inline]
    pub fn tangent_gg(&self, g: &Vec3) -> Mat3 {
        let gg = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
        let mut k = ZERO33;
        for i in 0..3 {
            for j in 0..3 {
                k[i][j] = (self.lambda + self.mu) * g[i] * g[j];
            }
            k[i][i] += self.mu * gg;
        }
        k
    }
}
