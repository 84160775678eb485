//! Compressible neo-Hookean solid, W = mu/2 (tr C - 3) - mu ln J + lambda/2 (ln J)^2.

use super::parameters::{check_elastic, ParamError, Parameters};
use super::point::{lame, PointModel};
use super::state::PlasticState;
use super::tangent::PointTangent;
use crate::math::{det, inverse, matmul, transpose, Mat3, IDENTITY, ZERO33};
use serde::Deserialize;

#[derive(serde::Serialize, serde::Deserialize, Clone, Copy, Debug, PartialEq)]
pub struct NeoHookean {
    pub lambda: f64,
    pub mu: f64,
}

impl NeoHookean {
    pub fn new(e: f64, nu: f64) -> Self {
        let (lambda, mu) = lame(e, nu);
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
}

impl PointModel for NeoHookean {
    fn name(&self) -> &'static str {
        "neo_hookean"
    }

    #[inline]
    fn lambda_mu(&self) -> (f64, f64) {
        (self.lambda, self.mu)
    }

    #[inline]
    fn is_large(&self) -> bool {
        true
    }

    /// The first Piola-Kirchhoff stress `pk1`.
    #[inline]
    fn stress(&self, h: &Mat3) -> Option<Mat3> {
        self.pk1(h)
    }

    /// sigma = P F^T / J.
    fn cauchy(&self, h: &Mat3, _old: &PlasticState) -> Option<Mat3> {
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
    fn tangent(&self, h: &Mat3, _old: Option<&PlasticState>) -> PointTangent {
        let (finv, j) = inverse(&Self::deformation_gradient(h));
        let lnj = if j > 0.0 { j.ln() } else { 0.0 };
        PointTangent::isotropic(
            Some(finv),
            self.mu + self.lambda - self.lambda * lnj,
            self.mu,
        )
    }
}

/// The scene keys of `neo_hookean`.
#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct NeoHookeanParams {
    #[serde(rename = "E")]
    pub e: f64,
    pub nu: f64,
    #[serde(default)]
    pub density: f64,
}

impl<M: From<NeoHookean>> Parameters<M> for NeoHookeanParams {
    fn young_poisson(&self) -> (f64, f64) {
        (self.e, self.nu)
    }

    fn density(&self) -> f64 {
        self.density
    }

    fn is_plastic(&self) -> bool {
        false
    }

    fn is_linear(&self) -> bool {
        false
    }

    fn build(&self, large: bool) -> Result<M, ParamError> {
        check_elastic(self.e, self.nu, self.density)?;
        if !large {
            return Err(ParamError::new(
                "model",
                "neo_hookean needs kinematics = \"large\"",
            ));
        }
        Ok(M::from(NeoHookean::new(self.e, self.nu)))
    }
}
