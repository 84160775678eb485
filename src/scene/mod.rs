//! Scene files: TOML, read and validated once, up front. Nothing below this layer looks up
//! names; it gets indices and resolved numbers.

pub mod refine;
mod text;
mod types;
mod validate;

pub use crate::problem::{Kinematics, PiecewiseLinear};
pub use types::*;
pub use validate::{load_scene, load_scene_refined, mesh_files, parse_scene, SceneError};
