//! Constitutive models. Each is a pure pointwise kernel: stress from the displacement
//! gradient, and the tangent contracted with a shape-function gradient on both sides
//! (what the nodal block-diagonal preconditioner needs).

mod linear_elastic;
mod neo_hookean;

pub use linear_elastic::LinearElastic;
pub use neo_hookean::NeoHookean;

use crate::math::{Mat3, Vec3};

/// Lamé parameters from Young's modulus and Poisson's ratio.
pub fn lame(e: f64, nu: f64) -> (f64, f64) {
    let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let mu = e / (2.0 * (1.0 + nu));
    (lambda, mu)
}

/// A material at a point. `h` is the displacement gradient grad_X u.
///
/// Under small kinematics `stress` is the Cauchy stress of the linearised strain; under
/// large kinematics it is the first Piola-Kirchhoff stress of F = I + h. Either way the
/// element force is the integral of `stress * grad N`, so one element loop serves both.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    LinearElastic(LinearElastic),
    NeoHookean(NeoHookean),
}

impl Material {
    #[inline]
    pub fn lambda_mu(&self) -> (f64, f64) {
        match self {
            Material::LinearElastic(m) => (m.lambda, m.mu),
            Material::NeoHookean(m) => (m.lambda, m.mu),
        }
    }

    /// True for models written in the reference configuration with finite strain.
    #[inline]
    pub fn is_large(&self) -> bool {
        matches!(self, Material::NeoHookean(_))
    }

    /// Stress (Cauchy for small kinematics, first Piola-Kirchhoff for large). `None` when
    /// the deformation is inadmissible (J <= 0).
    #[inline]
    pub fn stress(&self, h: &Mat3) -> Option<Mat3> {
        match self {
            Material::LinearElastic(m) => Some(m.stress(h)),
            Material::NeoHookean(m) => m.pk1(h),
        }
    }

    /// `sum_JL g_J A_iJkL g_L`: the 3x3 block the tangent contributes for one gradient `g`.
    #[inline]
    pub fn tangent_gg(&self, h: &Mat3, g: &Vec3) -> Mat3 {
        match self {
            Material::LinearElastic(m) => m.tangent_gg(g),
            Material::NeoHookean(m) => m.tangent_gg(h, g),
        }
    }

    /// Cauchy stress for output, from the same displacement gradient.
    #[inline]
    pub fn cauchy(&self, h: &Mat3) -> Option<Mat3> {
        match self {
            Material::LinearElastic(m) => Some(m.stress(h)),
            Material::NeoHookean(m) => m.cauchy(h),
        }
    }
}
