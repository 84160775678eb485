//! A model's keys in the scene's `material` table and their checks. Each model's file
//! defines its keys (a serde struct) and implements `Parameters`; the scene layer names a
//! model only to parse its table.

/// A model's parameters as the scene gives them; `M` is what they build, `Material`
/// (which each model converts into, so that a model's file does not name `Material`).
pub trait Parameters<M> {
    /// Young's modulus and Poisson's ratio as given (the elastic constants Hertz's
    /// solution and the scene's size use).
    fn young_poisson(&self) -> (f64, f64);

    /// Mass density (0 when not given).
    fn density(&self) -> f64;

    /// Whether the model keeps an integration-point history.
    fn is_plastic(&self) -> bool;

    /// Whether the model is linear elastic under small kinematics.
    fn is_linear(&self) -> bool;

    /// The model under small (`large` false) or large kinematics, or the first key that is
    /// out of range (or the model, for kinematics it does not support) and why.
    fn build(&self, large: bool) -> Result<M, ParamError>;
}

/// A key of the `material` table (relative to it) and what is wrong with its value.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamError {
    pub key: &'static str,
    pub message: String,
}

impl ParamError {
    pub fn new(key: &'static str, message: impl Into<String>) -> Self {
        ParamError {
            key,
            message: message.into(),
        }
    }
}

/// The checks every model's elastic constants and density pass, in this order.
pub fn check_elastic(e: f64, nu: f64, density: f64) -> Result<(), ParamError> {
    if !(e.is_finite() && e > 0.0) {
        return Err(ParamError::new(
            "E",
            format!("expected Young's modulus > 0, got {e}"),
        ));
    }
    if !(nu.is_finite() && nu > -1.0 && nu < 0.5) {
        return Err(ParamError::new(
            "nu",
            format!("expected Poisson's ratio in (-1, 0.5), got {nu}"),
        ));
    }
    if !(density.is_finite() && density >= 0.0) {
        return Err(ParamError::new(
            "density",
            format!("expected a density >= 0, got {density}"),
        ));
    }
    Ok(())
}
