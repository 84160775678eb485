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
//! and `setup` (when and how the coarse operator and the multilevel hierarchy are built);
//! `export` assembles a model problem for other solvers.
//! This file holds the settings, the buffers, the problem and the residual they share.

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
        }
    };
}

mod coupled;
mod export;
mod failure;
mod full_tangent;
mod iteration;
mod newton;
mod precondition;
mod setup;
mod step;
mod trace;

pub use coupled::{self_coupling, FrictionLink};
pub use export::{free_basis, ModelExport};
pub use failure::SolveFailure;
pub use trace::CgTrace;

use super::assembly::{Assembly, ElementError};
use super::loads::Loads;
use crate::comm::{self, Comm};
use crate::constraints::Constraints;
use crate::math::{matvec, Mat3, Vec3};
use crate::memory::{try_filled, AllocError};
use crate::mesh::GlobalMesh;
use crate::precond::coarse::CoarseSpace;
use crate::precond::multilevel::Multilevel;

/// With `preconditioner = "auto"` on meshes below the two-level threshold, CG starts with
/// block Jacobi and moves to the multilevel preconditioner at this iteration of a model
/// problem: problems Jacobi solves quickly keep today's path bit for bit, the hard ones
/// (the Hertz example: 11753 Jacobi iterations, 239 multilevel) pay this once.
pub const SWITCH_AFTER: usize = 300;

#[derive(Clone, Copy, Debug, Default)]
pub struct ModelOutcome {
    pub iterations: usize,
    pub residual: f64,
    pub reference: f64,
}

/// Settings of one model solve.
#[derive(Clone, Copy, Debug)]
pub struct CgSettings {
    pub tolerance: f64,
    pub max_iterations: usize,
    /// A force below which nothing counts (from earlier steps' reference forces): keeps
    /// steps that unload to zero from chasing round-off.
    pub reference_floor: f64,
    /// A length for the finite-difference probe.
    pub length_scale: f64,
    /// Young's modulus times element size times the largest prescribed displacement: the
    /// force scale below which a residual is round-off when the prescribed motion loads
    /// nothing (a body moving rigidly with its supports).
    pub stiffness_floor: f64,
    /// Nonlinear bodies are solved by Newton-Krylov (`newton`) instead of nonlinear CG.
    pub newton: bool,
}

/// Buffers for the model solve, allocated once per run.
pub struct Cg {
    fi: Vec<Vec3>,
    fe: Vec<Vec3>,
    r: Vec<Vec3>,
    r_old: Vec<Vec3>,
    /// Newton-Krylov's direction (nonlinear bodies only).
    du: Vec<Vec3>,
    z: Vec<Vec3>,
    p: Vec<Vec3>,
    pu: Vec<Vec3>,
    q: Vec<Vec3>,
    trial: Vec<Vec3>,
    fi_trial: Vec<Vec3>,
    fe_trial: Vec<Vec3>,
    /// Which nodes of a probe are not zero (`Assembly::internal_force_sparse`).
    nonzero: Vec<bool>,
    /// The inverse diagonal blocks of the block-Jacobi preconditioner (formed in place
    /// from the blocks).
    minv: Vec<Mat3>,
    /// The coarse space of the two-level preconditioner, when used.
    coarse: Option<CoarseSpace>,
    coarse_work: Vec<f64>,
    /// A new load increment began since the coarse operator was measured.
    coarse_stale: bool,
    /// Constraint rows when the coarse operator was measured.
    coarse_rows: usize,
    /// Linear bodies: the fingerprint (`operator_fingerprint`) of the constrained operator
    /// the coarse operator or the multilevel hierarchy was built from.
    coarse_fp: Option<u64>,
    /// The multilevel preconditioner, when used.
    multilevel: Option<Multilevel>,
    /// The multilevel preconditioner waits until a model problem needs SWITCH_AFTER
    /// iterations.
    ml_standby: bool,
    /// Contact rows when the multilevel hierarchy was built.
    ml_contact_rows: usize,
    /// The standby took over (for the rest of the run).
    ml_switched: bool,
    /// Constraint rows and contact rows when the fine smoother's bound was measured.
    ml_smoother_rows: [usize; 2],
    /// Linear bodies: the fingerprint of the operator the fine smoother's bound was
    /// measured on (None once the bound was widened).
    ml_smoother_fp: Option<u64>,
    /// The full tangent preconditioner is used (`full_tangent`), and its factor when built.
    use_tangent: bool,
    tangent: Option<full_tangent::FullTangent>,
    /// The full tangent's order, kept while its pattern does not change.
    tangent_order: Option<full_tangent::Order>,
    tangent_builds: usize,
    /// Builds in the current model problem.
    tangent_builds_here: usize,
    /// Newton-Krylov: the convergence rate of the first inner solve after the coarse space
    /// or hierarchy was built (`newton::judge_rate`).
    built_rate: Option<f64>,
    /// Why the multilevel hierarchy was last rebuilt, until the log takes it.
    pub rebuild_note: Option<String>,
    /// What the CG spent its iterations on since the log last took it.
    pub trace: CgTrace,
    /// The assembled model problem, when asked for (`request_export`).
    export: export::ExportState,
    /// BiCGStab's vectors for the friction-coupled model problem (`coupled`).
    coupled: coupled::Work,
}

impl Cg {
    /// The buffers for `n` local nodes; the previous residual, Newton's direction and the
    /// finite-difference probe's three vectors only when `nonlinear` (bodies or loads that are not linear:
    /// Polak-Ribiere and the probes need them, the linear path never reads them). Fails only
    /// when the memory for the vectors is refused.
    pub fn new(n: usize, nonlinear: bool) -> Result<Self, AllocError> {
        let v = || try_filled([0.0; 3], n, "the CG vectors");
        let w = || try_filled([0.0; 3], if nonlinear { n } else { 0 }, "the CG vectors");
        Ok(Cg {
            fi: v()?,
            fe: v()?,
            r: v()?,
            r_old: w()?,
            du: w()?,
            z: v()?,
            p: v()?,
            pu: v()?,
            q: v()?,
            trial: w()?,
            fi_trial: w()?,
            fe_trial: w()?,
            nonzero: try_filled(false, n, "the probes' node flags")?,
            minv: try_filled([[0.0; 3]; 3], n, "the preconditioner's diagonal")?,
            coarse: None,
            coarse_work: Vec::new(),
            coarse_stale: true,
            coarse_rows: 0,
            coarse_fp: None,
            multilevel: None,
            ml_contact_rows: 0,
            ml_switched: false,
            ml_smoother_rows: [0; 2],
            ml_smoother_fp: None,
            ml_standby: false,
            use_tangent: false,
            tangent: None,
            tangent_order: None,
            tangent_builds: 0,
            tangent_builds_here: 0,
            built_rate: None,
            rebuild_note: None,
            trace: CgTrace::default(),
            export: export::ExportState::Off,
            coupled: coupled::Work::default(),
        })
    }

    /// Uses the multilevel preconditioner; with `standby`, only from the SWITCH_AFTER-th
    /// iteration of a model problem on (the `auto` choice on smaller meshes).
    pub fn set_multilevel(&mut self, ml: Multilevel, standby: bool) {
        self.multilevel = Some(ml);
        self.ml_standby = standby;
    }

    /// Whether the multilevel standby took over (a restart file records it).
    pub fn multilevel_switched(&self) -> bool {
        self.ml_switched
    }

    /// Continues a run whose standby had taken over: multilevel from now on, as the run
    /// did before its restart point (the hierarchy is built at the next model problem, as
    /// at every load increment).
    pub fn resume_switched(&mut self) {
        if self.multilevel.is_some() && self.ml_standby {
            self.ml_standby = false;
            self.ml_switched = true;
            self.coarse = None;
        }
    }

    /// Adds a line to the notes the log shows at -vv (`rebuild_note`).
    fn add_note(&mut self, note: String) {
        self.rebuild_note = Some(match self.rebuild_note.take() {
            Some(old) => format!("{old}\n{note}"),
            None => note,
        });
    }

    /// Uses the full tangent preconditioner (assembled and factored at every model problem).
    pub fn use_full_tangent(&mut self) {
        self.use_tangent = true;
    }

    /// Uses the two-level preconditioner with this coarse space.
    pub fn set_coarse(&mut self, coarse: CoarseSpace) {
        self.coarse = Some(coarse);
    }

    /// Marks a new load increment (or a new attempt at one): the coarse operator and the
    /// multilevel hierarchy are measured again at its first model problem, unless the
    /// bodies are linear and the constrained operator is bit for bit the one they were
    /// measured on (same fingerprint: measuring again would give the same bits). Within
    /// the increment they are kept until the number of constraint rows changes by more
    /// than a tenth: measured with an earlier constraint set they are still valid
    /// (positive) preconditioners, only slightly less sharp ones. Either way the
    /// preconditioner at an increment's start is a function of the increment's own state,
    /// so a run continued from a restart file repeats the uninterrupted run bit for bit.
    pub fn invalidate_coarse(&mut self) {
        self.coarse_stale = true;
    }

    /// The internal and external forces of the last accepted iterate.
    pub fn forces(&self) -> (&[Vec3], &[Vec3]) {
        (&self.fi, &self.fe)
    }

    /// Row multipliers at the last accepted iterate: the force each constraint row exerts.
    pub fn multipliers<C: Comm + ?Sized>(&mut self, pb: &ModelProblem<C>, out: &mut Vec<f64>) {
        out.clear();
        out.resize(pb.cons.num_rows(), 0.0);
        for a in 0..self.q.len() {
            self.q[a] = crate::math::sub(&self.fe[a], &self.fi[a]);
        }
        pb.cons.reduce(pb.comm, &mut self.q, Some(out));
    }
}

fn agree<C: Comm + ?Sized>(comm: &C, r: Result<(), ElementError>) -> Result<(), SolveFailure> {
    match comm::lowest_error(comm, r.err().map(|e| (e.element as i64, e.to_string()))) {
        None => Ok(()),
        Some(m) => Err(SolveFailure::Element(m)),
    }
}

/// An allocation every rank made: the value, or on every rank the first rank's refusal.
/// Collective.
fn agree_alloc<C: Comm + ?Sized, T>(comm: &C, r: Result<T, AllocError>) -> Result<T, SolveFailure> {
    let local = r.as_ref().err().map(ToString::to_string);
    match (r, comm::first_error(comm, local)) {
        (Ok(v), None) => Ok(v),
        (_, Some(m)) => Err(SolveFailure::OutOfMemory(m)),
        (Err(e), None) => Err(SolveFailure::OutOfMemory(e.to_string())),
    }
}

pub struct ModelProblem<'a, C: Comm + ?Sized> {
    pub comm: &'a C,
    /// The whole mesh (the multilevel preconditioner's colouring follows its node graph).
    pub global: &'a GlobalMesh,
    pub asm: &'a Assembly<'a>,
    pub loads: &'a Loads,
    pub cons: &'a Constraints,
    /// Forces held fixed during the model problem (friction of slipping contact nodes).
    pub extra: &'a [Vec3],
    /// Tangential springs of slipping contact nodes (see `springs`).
    pub springs: &'a [crate::springs::Spring],
    pub time: f64,
}

impl<'a, C: Comm + ?Sized> ModelProblem<'a, C> {
    fn owned(&self) -> usize {
        self.asm.mesh.num_owned_nodes
    }

    /// fi = f_int(u), fe = f_ext(t, u) plus the fixed extra forces.
    fn forces(&self, u: &[Vec3], fi: &mut [Vec3], fe: &mut [Vec3]) -> Result<(), SolveFailure> {
        let r = self.asm.internal_force(u, fi);
        let r = r.and_then(|_| self.loads.external_force(self.asm, self.time, u, fe));
        agree(self.comm, r)?;
        crate::springs::add_forces(self.springs, u, fi);
        if !self.extra.is_empty() {
            for (f, x) in fe.iter_mut().zip(self.extra) {
                *f = crate::math::add(f, x);
            }
        }
        Ok(())
    }

    /// |P r| and the reference force max(|f_ext|, |reaction|).
    fn measure(&self, r: &[Vec3], fi: &[Vec3], fe: &[Vec3]) -> (f64, f64) {
        let n = self.owned();
        let rn = comm::norm(self.comm, r, n);
        let fen = comm::norm(self.comm, fe, n);
        let mut acc = comm::ExactSum::new();
        for a in 0..n {
            if let Some(p) = self.cons.projector(a) {
                let d = crate::math::sub(&fi[a], &fe[a]);
                let free = matvec(p, &d);
                for i in 0..3 {
                    let c = d[i] - free[i];
                    acc.add_product(c, c);
                }
            }
        }
        let reaction = comm::global_sum(self.comm, acc).sqrt();
        (rn, fen.max(reaction))
    }
}

/// r = T^T (f_ext - f_int): the residual in the constrained (free) variables.
fn residual<C: Comm + ?Sized>(
    comm: &C,
    cons: &Constraints,
    fi: &[Vec3],
    fe: &[Vec3],
    r: &mut [Vec3],
) {
    for a in 0..r.len() {
        r[a] = crate::math::sub(&fe[a], &fi[a]);
    }
    cons.reduce(comm, r, None);
}

fn max_abs<C: Comm + ?Sized>(comm: &C, v: &[Vec3], n: usize) -> f64 {
    let m = v[..n].iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    comm::max_f64(comm, m)
}
