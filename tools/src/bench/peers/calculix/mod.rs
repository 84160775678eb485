//! CalculiX (`ccx`, Debian's calculix-ccx, installed by `run/setup --calculix`).
//!
//! - `deck`: an input deck as data (nodes, C3D8 elements, sets, materials, surfaces,
//!   contact, steps) and its text; nothing in it knows our scenes;
//! - `face_loads`: a traction as the nodal forces of ccx's element (`*CLOAD`);
//! - `scene`: a deck from a scene as the solver loads it (what it cannot translate it
//!   refuses, naming it);
//! - `run`: `ccx` on a deck under limits, with repeats and timing;
//! - `output`: what ccx wrote (.dat totals, its log), read back;
//! - `block`: the block-on-block problem with CalculiX beside our runs;
//! - `ironing`: the ironing example with CalculiX beside our run (`bench --ironing`);
//! - `plasticity`: the flat punch, prescribed and through contact, beside our runs
//!   (`bench --plasticity`);
//! - `robustness`: the Hertz example and the stick/slip bar beside the robustness table
//!   (`bench --robustness`);
//! - `tet`: Cook's membrane and the punch on tetrahedra, C3D10 beside our tet10
//!   (`bench --tet`).
//!
//! A new problem for CalculiX is a file like `block.rs`: its deck from `scene` (extended
//! with what the problem needs) or built with `deck`, run by `run`, read by `output`.

pub mod block;
pub mod deck;
pub mod face_loads;
pub mod ironing;
pub mod output;
pub mod plasticity;
pub mod robustness;
pub mod run;
pub mod scene;
pub mod tet;
