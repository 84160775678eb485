//! Isotropic linear elasticity under small kinematics.

use super::parameters::{check_elastic, ParamError, Parameters};
use super::point::{lame, PointModel};
use super::state::PlasticState;
use super::tangent::PointTangent;
use crate::math::{Mat3, ZERO33};
use serde::Deserialize;

#[derive(serde::Serialize, serde::Deserialize, Clone, Copy, Debug, PartialEq)]
pub struct LinearElastic {
    pub lambda: f64,
    pub mu: f64,
}

impl LinearElastic {
    pub fn new(e: f64, nu: f64) -> Self {
        let (lambda, mu) = lame(e, nu);
        LinearElastic { lambda, mu }
    }
}

impl PointModel for LinearElastic {
    fn name(&self) -> &'static str {
        "linear_elastic"
    }

    #[inline]
    fn lambda_mu(&self) -> (f64, f64) {
        (self.lambda, self.mu)
    }

    #[inline]
    fn is_large(&self) -> bool {
        false
    }

    #[inline]
    fn linear(&self) -> Option<(f64, f64)> {
        Some((self.lambda, self.mu))
    }

    /// Cauchy stress of the symmetric part of `h`.
    #[inline]
    fn stress(&self, h: &Mat3) -> Option<Mat3> {
        let tr = h[0][0] + h[1][1] + h[2][2];
        let mut s = ZERO33;
        for i in 0..3 {
            for j in 0..3 {
                s[i][j] = self.mu * (h[i][j] + h[j][i]);
            }
            s[i][i] += self.lambda * tr;
        }
        Some(s)
    }

    #[inline]
    fn cauchy(&self, h: &Mat3, _old: &PlasticState) -> Option<Mat3> {
        self.stress(h)
    }

    /// `(lambda + mu) g g^T + mu |g|^2 I`.
    #[inline]
    fn tangent(&self, _h: &Mat3, _old: Option<&PlasticState>) -> PointTangent {
        PointTangent::isotropic(None, self.lambda + self.mu, self.mu)
    }
}

/// The scene keys of `linear_elastic`.
#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LinearElasticParams {
    #[serde(rename = "E")]
    pub e: f64,
    pub nu: f64,
    #[serde(default)]
    pub density: f64,
}

impl<M: From<LinearElastic>> Parameters<M> for LinearElasticParams {
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
        true
    }

    fn build(&self, large: bool) -> Result<M, ParamError> {
        check_elastic(self.e, self.nu, self.density)?;
        if large {
            return Err(ParamError::new(
                "model",
                "linear_elastic needs kinematics = \"small\"; use neo_hookean for kinematics = \"large\"",
            ));
        }
        Ok(M::from(LinearElastic::new(self.e, self.nu)))
    }
}
