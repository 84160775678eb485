//! A distributed-memory, quasi-static, nonlinear finite element solver for 3-D solids with
//! master/slave contact and Coulomb friction.

pub mod comm;
pub mod constraints;
pub mod contact;
pub mod fem;
pub mod material;
pub mod math;
pub mod memory;
pub mod mesh;
pub mod output;
pub mod post;
pub mod precond;
pub mod preflight;
pub mod problem;
pub mod run;
pub mod scene;
pub mod solver;
pub mod springs;
