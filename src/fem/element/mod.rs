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
mod formulation;
mod geometry;
mod hourglass;
mod kinematics;
mod matrix;
mod stabilization;
mod stress;
mod tangent;

pub use force::{internal_force, internal_force_with};
pub use formulation::{ElementFailure, Formulation, Stabilization};
pub use geometry::{geometry, reference_shape, volume, GaussGeometry, Geometry};
pub use hourglass::Hourglass;
pub use kinematics::point_gradients;
pub use matrix::{
    consistent_matrix, elastic_matrix, element_matrix, matrix_force, responds_elastically,
    ElementMatrix,
};
pub use stress::{average_cauchy, average_cauchy_with};
pub use tangent::{diagonal_blocks, diagonal_blocks_with};

pub(in crate::fem) use force::modes;
pub(in crate::fem) use geometry::hourglass as hourglass_sums;
pub(in crate::fem) use geometry::mean_gradient;
pub(in crate::fem) use hourglass::{centre, dev_sym, forces, SLOTS};
pub(in crate::fem) use stabilization::Stiffness;
pub(in crate::fem) use tangent::add_tangent;
