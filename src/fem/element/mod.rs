//! Element kernels for the 8-node hexahedron: internal force, the nodal 3x3 diagonal
//! blocks of the tangent (for the block-Jacobi preconditioner) and the element-average
//! Cauchy stress. Small kinematics use the linearised strain; large kinematics are total
//! Lagrangian. Inputs are the reference coordinates and the displacements of the 8 nodes.
//!
//! One concept per file: `geometry` (the reference-configuration data and the Gauss-point
//! array helpers), `kinematics` (deformation gradient, mean dilatation), `force` (internal
//! force), `matrix` (the stiffness matrix of a linear element), `tangent` (diagonal blocks
//! of the tangent), `stress` (average Cauchy stress), `stabilization` (the hourglass
//! stiffness of one-point elements) and `hourglass` (the hourglass control of plastic
//! one-point elements).

mod force;
mod geometry;
mod hourglass;
mod kinematics;
mod matrix;
mod stabilization;
mod stress;
mod tangent;

pub use force::{internal_force, internal_force_with};
pub use geometry::{geometry, reference_shape, volume, GaussGeometry, Geometry};
pub use hourglass::Hourglass;
pub use matrix::{element_matrix, matrix_force, ElementMatrix};
pub use stress::{average_cauchy, average_cauchy_with};
pub use tangent::{diagonal_blocks, diagonal_blocks_with};

pub(in crate::fem) use force::modes;
pub(in crate::fem) use geometry::hourglass as hourglass_sums;
pub(in crate::fem) use geometry::{at, g_at, gauss_gradient, mean_gradient};
pub(in crate::fem) use hourglass::{centre, dev_sym, forces, SLOTS};
pub(in crate::fem) use kinematics::{deformation, mean_dilatation, scaled, sub_identity};
pub(in crate::fem) use stabilization::Stiffness;
pub(in crate::fem) use tangent::add_tangent;

/// How an element is integrated.
#[derive(Clone, Copy, Debug, PartialEq)]
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
#[derive(Clone, Copy, Debug, PartialEq)]
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
