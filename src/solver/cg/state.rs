//! The buffers of the model solve (`Cg`), allocated once per run, and the choices that
//! last across model problems (the preconditioner in use, its staleness, the notes for the
//! log). The solve itself, `impl Cg`, is spread over the other files of this folder, one
//! concept each.

use super::exported::ExportState;
use super::full_tangent::{Colours, FullTangent, Order};
use super::kept::{self, BuildRows};
use super::links::Work;
use super::model::ModelProblem;
use super::trace::CgTrace;
use crate::comm::Comm;
use crate::math::{Mat3, Vec3};
use crate::memory::{try_filled, AllocError};
use crate::precond::coarse::CoarseSpace;
use crate::precond::multilevel::Multilevel;
use crate::solver::assembly::ElasticMatrices;

/// Buffers for the model solve, allocated once per run.
pub struct Cg {
    pub(super) fi: Vec<Vec3>,
    pub(super) fe: Vec<Vec3>,
    pub(super) r: Vec<Vec3>,
    pub(super) r_old: Vec<Vec3>,
    /// Newton-Krylov's direction (nonlinear bodies only).
    pub(super) du: Vec<Vec3>,
    pub(super) z: Vec<Vec3>,
    pub(super) p: Vec<Vec3>,
    pub(super) pu: Vec<Vec3>,
    pub(super) q: Vec<Vec3>,
    pub(super) trial: Vec<Vec3>,
    pub(super) fi_trial: Vec<Vec3>,
    pub(super) fe_trial: Vec<Vec3>,
    /// Which nodes of a probe are not zero (`Assembly::internal_force_sparse`).
    pub(super) nonzero: Vec<bool>,
    /// The inverse diagonal blocks of the block-Jacobi preconditioner (formed in place
    /// from the blocks).
    pub(super) minv: Vec<Mat3>,
    /// The coarse space of the two-level preconditioner, when used.
    pub(super) coarse: Option<CoarseSpace>,
    pub(super) coarse_work: Vec<f64>,
    /// A new load increment began since the coarse operator was measured.
    pub(super) coarse_stale: bool,
    /// Constraint rows when the coarse operator was measured.
    pub(super) coarse_rows: usize,
    /// Linear bodies: the fingerprint (`operator_fingerprint`) of the constrained operator
    /// the coarse operator or the multilevel hierarchy was built from.
    pub(super) coarse_fp: Option<u64>,
    /// The multilevel preconditioner, when used.
    pub(super) multilevel: Option<Multilevel>,
    /// The multilevel preconditioner waits until a model problem needs SWITCH_AFTER
    /// iterations.
    pub(super) ml_standby: bool,
    /// Contact rows when the multilevel hierarchy was built.
    pub(super) ml_contact_rows: usize,
    /// Linear bodies: the rows and springs the multilevel hierarchy was built from (kept
    /// from one increment to the next while close to them; a restart file carries them).
    pub(super) ml_built: Option<BuildRows>,
    /// A continued run: the earlier run's `ml_built` (its words), until the first model
    /// problem that needs the hierarchy.
    pub(super) ml_resume: Option<Vec<f64>>,
    /// The standby took over (for the rest of the run).
    pub(super) ml_switched: bool,
    /// Constraint rows and contact rows when the fine smoother's bound was measured.
    pub(super) ml_smoother_rows: [usize; 2],
    /// Linear bodies: the fingerprint of the operator the fine smoother's bound was
    /// measured on (None once the bound was widened).
    pub(super) ml_smoother_fp: Option<u64>,
    /// The full tangent preconditioner is used (`full_tangent`), and its factor when built.
    pub(super) use_tangent: bool,
    pub(super) tangent: Option<FullTangent>,
    /// The full tangent's order, kept while its pattern does not change.
    pub(super) tangent_order: Option<Order>,
    /// The full tangent's probing colours, kept while the ties do not change.
    pub(super) tangent_colours: Colours,
    /// The elastic matrices that stand in for an element's finite difference where it
    /// responds elastically (`Assembly::mark_elastic`): in the full tangent's probes
    /// (marked at the build's state, `tangent_marks`) and in the friction-coupled
    /// operator (marked at its linearisation point, `Work::marks`).
    pub(super) elastic: ElasticMatrices,
    pub(super) tangent_marks: Vec<bool>,
    pub(super) tangent_builds: usize,
    /// Builds in the current model problem.
    pub(super) tangent_builds_here: usize,
    /// No model problem of this increment has built the full tangent yet.
    pub(super) tangent_increment: bool,
    /// Newton-Krylov: the convergence rate of the first inner solve after the coarse space
    /// or hierarchy was built (`newton::judge_rate`).
    pub(super) built_rate: Option<f64>,
    /// Why the multilevel hierarchy was last rebuilt, until the log takes it.
    pub rebuild_note: Option<String>,
    /// What the CG spent its iterations on since the log last took it.
    pub trace: CgTrace,
    /// The assembled model problem, when asked for (`request_export`).
    pub(super) export: ExportState,
    /// BiCGStab's vectors for the friction-coupled model problem (`coupled`).
    pub(super) coupled: Work,
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
            ml_built: None,
            ml_resume: None,
            ml_smoother_rows: [0; 2],
            ml_smoother_fp: None,
            ml_standby: false,
            use_tangent: false,
            tangent: None,
            tangent_order: None,
            tangent_colours: Colours::default(),
            elastic: ElasticMatrices::default(),
            tangent_marks: Vec::new(),
            tangent_builds: 0,
            tangent_builds_here: 0,
            tangent_increment: true,
            built_rate: None,
            rebuild_note: None,
            trace: CgTrace::default(),
            export: ExportState::Off,
            coupled: Work::default(),
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

    /// The rows the multilevel hierarchy in use was built from, as a restart file keeps
    /// them (collective; on rank 0, empty elsewhere and when no hierarchy of linear bodies
    /// is in use).
    pub fn hierarchy_words<C: Comm + ?Sized>(&self, comm: &C) -> Vec<f64> {
        let set_up = self.multilevel.as_ref().is_some_and(Multilevel::is_set_up);
        match self
            .ml_built
            .as_ref()
            .filter(|_| set_up && !self.ml_standby)
        {
            Some(b) => kept::merge(comm, &b.local_words()),
            None => Vec::new(),
        }
    }

    /// Continues a run whose hierarchy was built from these rows (`hierarchy_words`): the
    /// first model problem that needs the hierarchy builds it from them when the
    /// uninterrupted run would have kept it there.
    pub fn resume_hierarchy(&mut self, words: Vec<f64>) {
        self.ml_resume = (!words.is_empty()).then_some(words);
    }

    /// Adds a line to the notes the log shows at -vv (`rebuild_note`).
    pub(super) fn add_note(&mut self, note: String) {
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
        self.tangent_increment = true;
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
