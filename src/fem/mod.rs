//! Finite element kernels: the element kinds (kind.rs: what the layers above ask of one),
//! the 8-node hexahedron, its faces, and the element force and diagonal-tangent
//! kernels. Everything here is pure: fixed-size arrays in, arrays out.

pub mod consistent;
pub mod element;
pub mod face;
pub mod hex8;
pub mod history;
pub mod kind;
pub mod tet10;

pub use element::{ElementFailure, Formulation, Stabilization};
pub use kind::{ElementKind, FaceKind};
