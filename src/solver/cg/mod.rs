//! The model problem: with the constraint set frozen, find u with the projected residual
//! P (f_ext(u) - f_int(u)) within tolerance, by nonlinear preconditioned CG.
//!
//! Step length along a direction p comes from the directional stiffness p.K p: exact
//! (K p = f_int(p)) when every body is linear, otherwise a finite-difference probe
//! followed by a secant correction. Linear problems therefore get plain linear PCG
//! (Fletcher-Reeves beta); nonlinear ones use Polak-Ribiere+ with restarts.
//!
//! Split by concept: `failure` (why a model problem could not be solved), `iteration` (the
//! CG loop and the search direction), `step` (the linear and the nonlinear step along it),
//! `precondition` (block Jacobi, the multilevel and coarse corrections, the fine operator)
//! and `setup` (when and how the coarse operator, the multilevel hierarchy and the full
//! tangent are built);
//! `export` assembles a model problem for other solvers (`exported` what it gives), `coupled`
//! the friction-coupled solve (`links` its friction links and vectors), `full_tangent`
//! the full tangent preconditioner. `model` holds the model problem, its settings and
//! residual; `state` the buffers (`Cg`) every part works on.

/// The constrained fine operator (`precondition::FineOp`) at `u`, borrowing the CG's force
/// and trial buffers field by field (a macro, so the other fields of the `Cg` stay free for
/// the caller, e.g. the multilevel preconditioner it is handed to).
macro_rules! fine_op {
    ($cg:ident, $pb:expr, $u:expr, $linear:expr, $s:expr) => {
        $crate::solver::cg::precondition::FineOp {
            pb: $pb,
            linear: $linear,
            eps_scale: $s.length_scale,
            u: $u,
            fi: &$cg.fi,
            fe: &$cg.fe,
            trial: &mut $cg.trial,
            fi_trial: &mut $cg.fi_trial,
            fe_trial: &mut $cg.fe_trial,
            nonzero: &mut $cg.nonzero,
            central: false,
            elastic: None,
            tangents: None,
        }
    };
}

mod coupled;
mod export;
mod exported;
mod failure;
mod full_tangent;
mod iteration;
mod kept;
mod links;
mod model;
mod newton;
mod precondition;
mod setup;
mod state;
mod step;
mod trace;
mod unsupported;

pub use exported::{free_basis, ModelExport};
pub use failure::SolveFailure;
pub use kept::words_fit as hierarchy_words_fit;
pub use links::{self_coupling, FrictionLink};
pub use model::{CgSettings, ModelOutcome, ModelProblem, SWITCH_AFTER};
pub use state::Cg;
pub use trace::CgTrace;
pub use unsupported::FreeBody;
