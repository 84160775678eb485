//! Preconditioners of the constrained model problem, below the solver: they know operators
//! (applied through `multilevel::FineOperator`, or measured), not the CG that uses them.

pub mod aggregates;
pub mod coarse;
pub mod dense_cholesky;
pub mod jacobi;
pub mod multilevel;
