//! Constitutive models. Each is a pure pointwise kernel: stress from the displacement
//! gradient, and the tangent contracted with a shape-function gradient on both sides
//! (what the nodal block-diagonal preconditioner needs).

mod j2_large;
mod j2_small;
mod linear_elastic;
mod neo_hookean;

pub use j2_large::{sym_eigen, LargeUpdate};
pub use j2_small::{from_sym6, J2Plastic, PlasticState, Return, STATE_LEN};
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
    /// Von Mises plasticity; its response depends on the history of the point, so the
    /// history-free methods below answer for a virgin point and the element kernels use
    /// `update` with the committed state.
    J2Plastic(J2Plastic),
}

impl Material {
    #[inline]
    pub fn lambda_mu(&self) -> (f64, f64) {
        match self {
            Material::LinearElastic(m) => (m.lambda, m.mu),
            Material::NeoHookean(m) => (m.lambda, m.mu),
            Material::J2Plastic(m) => (m.lambda, m.mu),
        }
    }

    /// True for models written in the reference configuration with finite strain.
    #[inline]
    pub fn is_large(&self) -> bool {
        match self {
            Material::NeoHookean(_) => true,
            Material::J2Plastic(m) => m.large,
            Material::LinearElastic(_) => false,
        }
    }

    /// True for models with an integration-point history.
    #[inline]
    pub fn is_plastic(&self) -> bool {
        matches!(self, Material::J2Plastic(_))
    }

    /// Stress at `h` from the committed state `old`, the state a converged step commits and
    /// the return data; `None` when the deformation is inadmissible. Elastic models return
    /// a virgin state.
    #[inline]
    pub fn update(&self, h: &Mat3, old: &PlasticState) -> Option<(Mat3, PlasticState, Return)> {
        match self {
            Material::J2Plastic(m) if m.large => {
                let r = m.update_large(h, old)?;
                Some((r.pk1, r.state, r.ret))
            }
            Material::J2Plastic(m) => Some(m.update(h, old)),
            _ => Some((self.stress(h)?, PlasticState::default(), Return::ELASTIC)),
        }
    }

    /// Cauchy stress at `h` from the committed state `old`.
    #[inline]
    pub fn cauchy_from(&self, h: &Mat3, old: &PlasticState) -> Option<Mat3> {
        match self {
            Material::J2Plastic(m) if m.large => {
                let r = m.update_large(h, old)?;
                Some(scaled(&r.tau, 1.0 / r.j))
            }
            Material::J2Plastic(m) => Some(m.update(h, old).0),
            _ => self.cauchy(h),
        }
    }

    /// Stress (Cauchy for small kinematics, first Piola-Kirchhoff for large). `None` when
    /// the deformation is inadmissible (J <= 0).
    #[inline]
    pub fn stress(&self, h: &Mat3) -> Option<Mat3> {
        match self {
            Material::LinearElastic(m) => Some(m.stress(h)),
            Material::NeoHookean(m) => m.pk1(h),
            Material::J2Plastic(_) => Some(self.update(h, &PlasticState::default())?.0),
        }
    }

    /// `sum_JL g_J A_iJkL g_L`: the 3x3 block the tangent contributes for one gradient `g`.
    #[inline]
    pub fn tangent_gg(&self, h: &Mat3, g: &Vec3) -> Mat3 {
        match self {
            Material::LinearElastic(m) => m.tangent_gg(g),
            Material::NeoHookean(m) => m.tangent_gg(h, g),
            Material::J2Plastic(m) if !m.large => {
                m.tangent_gg(&m.update(h, &PlasticState::default()).2, g)
            }
            Material::J2Plastic(m) => NeoHookean {
                lambda: m.lambda,
                mu: m.mu,
            }
            .tangent_gg(h, g),
        }
    }

    /// Cauchy stress for output, from the same displacement gradient.
    #[inline]
    pub fn cauchy(&self, h: &Mat3) -> Option<Mat3> {
        match self {
            Material::LinearElastic(m) => Some(m.stress(h)),
            Material::NeoHookean(m) => m.cauchy(h),
            Material::J2Plastic(_) => self.cauchy_from(h, &PlasticState::default()),
        }
    }
}

fn scaled(m: &Mat3, s: f64) -> Mat3 {
    std::array::from_fn(|i| std::array::from_fn(|j| m[i][j] * s))
}
