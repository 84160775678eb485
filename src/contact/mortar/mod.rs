//! Mortar (segment-to-segment) contact with a dual Lagrange multiplier basis: a slave
//! node's normal constraint is its gap weighted over the slave surface against the master
//! faces it overlaps, a kinematic row tying the node to several master nodes. kind.rs is the `PairKind` the
//! contact set calls.

pub mod dual;
pub(super) mod enforce;
mod kind;
pub mod plane;
pub mod segment;
pub(super) mod slip;
pub mod surfaces;
pub mod ties;

pub(super) use kind::Mortar;
pub use ties::{ties, Face, Tie};
