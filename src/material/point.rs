//! A constitutive model at a point (`PointModel`), what its update finds (`Update`), and
//! the Lamé parameters of E and nu.

use super::state::PlasticState;
use super::tangent::PointTangent;
use crate::math::Mat3;

/// Lamé parameters from Young's modulus and Poisson's ratio.
pub fn lame(e: f64, nu: f64) -> (f64, f64) {
    let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let mu = e / (2.0 * (1.0 + nu));
    (lambda, mu)
}

/// What `PointModel::update` finds at a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Update {
    /// Cauchy stress (small kinematics) or first Piola-Kirchhoff stress (large).
    pub stress: Mat3,
    /// The state a converged step commits (virgin for a model without history).
    pub state: PlasticState,
    /// Whether the point flowed plastically in this update.
    pub yielded: bool,
}

/// A constitutive model at a point. `h` is the displacement gradient grad_X u.
///
/// Under small kinematics the stress is the Cauchy stress of the linearised strain; under
/// large kinematics it is the first Piola-Kirchhoff stress of F = I + h. Either way the
/// element force is the integral of `stress * grad N`, so one element loop serves both.
/// A model with an integration-point history keeps it in a `PlasticState` per point,
/// committed only after a step converges; the history-free methods answer for a virgin
/// point.
pub trait PointModel {
    /// The model's name in the scene file, for messages.
    fn name(&self) -> &'static str;

    /// Lamé parameters of the small-strain elastic response: the moduli hourglass control,
    /// the preconditioners and the stiffness scale use.
    fn lambda_mu(&self) -> (f64, f64);

    /// True for models written in the reference configuration with finite strain.
    fn is_large(&self) -> bool;

    /// True for models with an integration-point history.
    fn is_plastic(&self) -> bool {
        false
    }

    /// `Some((lambda, mu))` when the stress is isotropic linear elasticity of the small
    /// strain: the body is then linear, its tangent does not depend on the displacement and
    /// the fully integrated element evaluates the stress at all Gauss points at once.
    fn linear(&self) -> Option<(f64, f64)> {
        None
    }

    /// Stress at `h` of a virgin point; `None` when the deformation is inadmissible
    /// (J <= 0).
    fn stress(&self, h: &Mat3) -> Option<Mat3>;

    /// Stress at `h` from the committed state `old` and the state a converged step
    /// commits; `None` when the deformation is inadmissible. A model without history
    /// returns its `stress` and a virgin state.
    #[inline]
    fn update(&self, h: &Mat3, _old: &PlasticState) -> Option<Update> {
        Some(Update {
            stress: self.stress(h)?,
            state: PlasticState::default(),
            yielded: false,
        })
    }

    /// Cauchy stress at `h` from the committed state `old`, for output.
    fn cauchy(&self, h: &Mat3, old: &PlasticState) -> Option<Mat3>;

    /// The tangent at `h` from the committed state `old` (`None`: a virgin point).
    fn tangent(&self, h: &Mat3, old: Option<&PlasticState>) -> PointTangent;

    /// The radius of the yield surface in deviatoric stress after the update to `state`
    /// (the bound hourglass forces are held to); infinite for an elastic model.
    #[inline]
    fn yield_radius(&self, _state: &PlasticState) -> f64 {
        f64::INFINITY
    }
}
