//! Quasi-static equilibrium: matrix-free nonlinear preconditioned conjugate gradients over
//! load steps.

pub mod assembly;
pub mod cg;
pub mod choice;
pub mod loads;
pub mod shapes;
pub mod stepping;
pub mod support;
pub mod survey;

pub use cg::{ModelOutcome, SolveFailure};
pub use stepping::{StepRecord, Stepper};
