//! The material tangent at one point, in the form the element kernels contract with
//! shape-function gradients.

use crate::math::{Mat3, ZERO33};

/// The algorithmic moduli of a small-kinematics point, C = kappa I(x)I + 2 mu_t I_dev -
/// cn n(x)n (`J2Plastic::surface_moduli`), in the form that applies them to a gradient
/// increment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Moduli {
    pub kappa: f64,
    pub mu_t: f64,
    pub cn: f64,
    pub n: Mat3,
}

impl Moduli {
    /// C : sym(dh).
    #[inline]
    pub fn apply(&self, dh: &Mat3) -> Mat3 {
        let tr = dh[0][0] + dh[1][1] + dh[2][2];
        let mut nd = 0.0;
        for i in 0..3 {
            for j in 0..3 {
                nd += self.n[i][j] * dh[i][j];
            }
        }
        let mut out = ZERO33;
        for i in 0..3 {
            for j in 0..3 {
                out[i][j] = self.mu_t * (dh[i][j] + dh[j][i]) - self.cn * nd * self.n[i][j];
            }
            out[i][i] += (self.kappa - 2.0 * self.mu_t / 3.0) * tr;
        }
        out
    }
}

/// `sum_JL g_J A_iJkL g_L = c v v^T + mu |g|^2 I - cn (n v)(n v)^T`, with v = g under small
/// kinematics and v = F^-T g under large ones (`finv` holds F^-1 then). Linear elasticity:
/// c = lambda + mu. Neo-Hookean: c = mu + lambda - lambda ln J, exact. J2 plasticity (the
/// consistent tangent, see `J2Plastic::tangent_gg`): c = kappa + mu_t / 3, mu = mu_t and
/// cn = 2 mu theta_bar; under large kinematics the same form with v = F^-T g, an
/// approximation that only preconditions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointTangent {
    pub finv: Option<Mat3>,
    pub c: f64,
    pub mu: f64,
    pub n: Mat3,
    pub cn: f64,
}

impl PointTangent {
    /// `c v v^T + mu |g|^2 I` without the flow term.
    #[inline]
    pub fn isotropic(finv: Option<Mat3>, c: f64, mu: f64) -> Self {
        PointTangent {
            finv,
            c,
            mu,
            n: ZERO33,
            cn: 0.0,
        }
    }
}
