//! Quasi-static equilibrium: matrix-free nonlinear preconditioned conjugate gradients over
//! load steps.

pub mod aggregates;
pub mod assembly;
pub mod cg;
pub mod choice;
pub mod coarse;
pub mod multilevel;
pub use crate::constraints;
pub mod loads;
pub mod shapes;
pub use crate::springs;
pub mod stepping;
pub mod support;

pub use cg::{ModelOutcome, SolveFailure};
pub use stepping::{StepRecord, Stepper};
