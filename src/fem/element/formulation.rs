//! What an element is asked for (its integration and hourglass control) and how it fails.

/// How an element is integrated.
#[derive(serde::Serialize, serde::Deserialize, Clone, Copy, Debug, PartialEq)]
pub enum Formulation {
    /// 2x2x2 Gauss.
    Full,
    /// 2x2x2 Gauss with the volumetric part taken from the element mean: B-bar (mean
    /// dilatation) under small kinematics, F-bar with the volume-averaged J under large.
    FullBar,
    /// One-point uniform-gradient integration with hourglass control.
    Mean { hourglass: Stabilization },
}

/// The hourglass control of a one-point element (`stabilization`).
#[derive(serde::Serialize, serde::Deserialize, Clone, Copy, Debug, PartialEq)]
pub enum Stabilization {
    /// Assumed-strain physical stabilisation: the stiffness from the moduli and the
    /// geometry (Belytschko-Bindeman, Puso), by name (`hourglass = "assumed_strain"`).
    AssumedStrain,
    /// The same with the shear modulus only (lambda = 0 in the hourglass energy), the
    /// default of linear elastic bodies (`hourglass = "assumed_strain_mu"`; docs/elements.md).
    AssumedStrainMu,
    /// Flanagan-Belytschko stiffness of the given coefficient (a scene's `hourglass = c`).
    Coefficient(f64),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ElementFailure {
    /// The reference element has a non-positive Jacobian determinant.
    InvertedReference,
    /// The deformed element has J <= 0 somewhere it is sampled.
    InvertedCurrent,
    /// A non-finite value appeared.
    NonFinite,
}

impl std::fmt::Display for ElementFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ElementFailure::InvertedReference => write!(
                f,
                "inverted or degenerate element (reference Jacobian <= 0)"
            ),
            ElementFailure::InvertedCurrent => {
                write!(f, "inverted element (J <= 0 in the deformed configuration)")
            }
            ElementFailure::NonFinite => write!(f, "non-finite value in the element"),
        }
    }
}
