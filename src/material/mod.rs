//! Constitutive models. Each is a pure pointwise kernel behind `PointModel`: stress from the
//! displacement gradient and the committed history, the history a converged step commits,
//! and the tangent in the form the element kernels contract with shape-function gradients.
//! Each model's file also holds its scene keys and their checks (`Parameters`).
//!
//! Adding a model: its file implements `PointModel` and `Parameters`; here it takes a
//! `mod` line, a variant of `Material` and an arm of `each!`; `scene/types.rs` takes a
//! variant of `MaterialDef` and an arm of `MaterialDef::params` (docs/layout.md).

mod j2_large;
mod j2_small;
mod linear_elastic;
mod neo_hookean;
mod parameters;
mod point;
mod state;
mod tangent;

pub use j2_large::{sym_eigen, LargeUpdate};
pub use j2_small::{from_sym6, J2Params, J2Plastic, Return};
pub use linear_elastic::{LinearElastic, LinearElasticParams};
pub use neo_hookean::{NeoHookean, NeoHookeanParams};
pub use parameters::{check_elastic, ParamError, Parameters};
pub use point::{lame, PointModel, Update};
pub use state::{PlasticState, STATE_LEN};
pub use tangent::{Moduli, PointTangent};

use crate::math::Mat3;

/// A body's material: one variant per model, each delegating to its `PointModel`.
#[derive(serde::Serialize, serde::Deserialize, Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum Material {
    LinearElastic(LinearElastic),
    NeoHookean(NeoHookean),
    /// Von Mises plasticity, under small or large kinematics, with a history per point.
    J2Plastic(J2Plastic),
}

/// `$e` with `$m` bound to the model of `$material`: the one place models are matched.
macro_rules! each {
    ($material:expr, $m:ident => $e:expr) => {
        match $material {
            Material::LinearElastic($m) => $e,
            Material::NeoHookean($m) => $e,
            Material::J2Plastic($m) => $e,
        }
    };
}

/// A model as the `Material` its `Parameters` build (`Parameters<Material>`).
macro_rules! from_model {
    ($($model:ident),*) => {
        $(impl From<$model> for Material {
            fn from(m: $model) -> Self {
                Material::$model(m)
            }
        })*
    };
}
from_model!(LinearElastic, NeoHookean, J2Plastic);

/// `PointModel`'s methods, dispatched to the model (see there).
impl Material {
    #[inline]
    pub fn name(&self) -> &'static str {
        each!(self, m => m.name())
    }

    #[inline]
    pub fn lambda_mu(&self) -> (f64, f64) {
        each!(self, m => m.lambda_mu())
    }

    #[inline]
    pub fn is_large(&self) -> bool {
        each!(self, m => m.is_large())
    }

    #[inline]
    pub fn is_plastic(&self) -> bool {
        each!(self, m => m.is_plastic())
    }

    #[inline]
    pub fn linear(&self) -> Option<(f64, f64)> {
        each!(self, m => m.linear())
    }

    #[inline]
    pub fn stress(&self, h: &Mat3) -> Option<Mat3> {
        each!(self, m => m.stress(h))
    }

    #[inline]
    pub fn update(&self, h: &Mat3, old: &PlasticState) -> Option<Update> {
        each!(self, m => m.update(h, old))
    }

    #[inline]
    pub fn cauchy(&self, h: &Mat3, old: &PlasticState) -> Option<Mat3> {
        each!(self, m => m.cauchy(h, old))
    }

    #[inline]
    pub fn tangent(&self, h: &Mat3, old: Option<&PlasticState>) -> PointTangent {
        each!(self, m => m.tangent(h, old))
    }

    #[inline]
    pub fn yield_radius(&self, state: &PlasticState) -> f64 {
        each!(self, m => m.yield_radius(state))
    }
}

#[cfg(test)]
mod tests;
