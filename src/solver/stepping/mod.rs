//! Load stepping through the scene's time segments: predictor, the control-contact loop
//! around the model problem, and automatic cut-back of a step that fails.

use super::assembly::Assembly;
use super::cg::{Cg, CgSettings, ModelOutcome, ModelProblem, SolveFailure};
use super::loads::Loads;
use super::survey::Survey;
use crate::comm::Comm;
use crate::constraints::{Constraints, Row, RowKind, RowSpec};
use crate::contact::active::{ContactCounts, ContactState};
use crate::contact::Enforcement;
use crate::math::Vec3;
use crate::mesh::local::LocalMesh;
use crate::mesh::whole::Whole;
use crate::mesh::GlobalMesh;
use crate::problem::Problem;
use crate::springs::Spring;
use std::borrow::Cow;
use std::time::Instant;

mod control;
mod limit;

/// What one load step did.
#[derive(Clone, Copy, Debug, Default)]
pub struct StepRecord {
    pub step: usize,
    pub time: f64,
    pub cg_iterations: u64,
    pub contact_updates: u64,
    pub residual: f64,
    pub reference: f64,
    pub cutbacks: u64,
    pub wall_time: f64,
    pub contact: ContactCounts,
    /// Hexahedra of mean-integrated bodies folded at a corner at the step's end
    /// (`Assembly::folded_mean_elements`), and the most folded: (global id, 0-based; its
    /// smallest Jacobian relative to its mean).
    pub folded: u64,
    pub most_folded: (u32, f64),
}

/// A step that could not be completed even after cutting it back.
#[derive(Clone, Debug)]
pub struct StepFailure {
    pub step: usize,
    /// The time of the (possibly cut-back) increment that failed.
    pub time: f64,
    /// The end of the load step.
    pub target: f64,
    pub cause: SolveFailure,
    pub cutbacks: usize,
    /// What the failing attempt tells of the cause, a line each: bodies its supports did not
    /// hold (see `support`) when the cause is one a missing support produces, and a plastic
    /// body's flowing region near a limit load (see `limit`).
    pub notes: Vec<String>,
}

impl std::fmt::Display for StepFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.time == self.target {
            write!(
                f,
                "step {} (t = {}) failed after {} cut-backs: {}",
                self.step, self.time, self.cutbacks, self.cause
            )
        } else {
            write!(
                f,
                "step {} (to t = {}) failed at t = {} after {} cut-backs: {}",
                self.step, self.target, self.time, self.cutbacks, self.cause
            )
        }?;
        for line in &self.notes {
            write!(f, "; {line}")?;
        }
        Ok(())
    }
}

/// A sink for progress lines.
pub type ProgressLine<'a> = Box<dyn FnMut(&str) + 'a>;

/// The load stepper, generic over how contact is enforced (`E`; node-to-face by default).
pub struct Stepper<'a, C: Comm + ?Sized, E: Enforcement = ContactState> {
    comm: &'a C,
    problem: &'a Problem,
    mesh: &'a LocalMesh,
    asm: Assembly<'a>,
    loads: Loads,
    /// (local node, direction, Dirichlet entry) of every prescribed direction.
    dirichlet: Vec<(usize, Vec3, usize)>,
    /// The prescribed directions' Gram matrices per body (`support::DirichletGrams`).
    supports: super::support::DirichletGrams,
    cg: Cg,
    pub u: Vec<Vec3>,
    u_prev: Vec<Vec3>,
    pub time: f64,
    dt_prev: f64,
    reference_floor: f64,
    length_scale: f64,
    stiffness_scale: f64,
    pub contact: E,
    /// The constraint set and row multipliers of the last converged state.
    cons: Constraints,
    multipliers: Vec<f64>,
    /// Which preconditioner the run uses, for the log.
    pub coarse_note: String,
    /// Which bodies are evaluated by element matrices, for the log (none: no line).
    pub shapes_note: Option<String>,
    /// Depth of the deepest slave node the last step's penetration audit found inside a
    /// master body (0 when none).
    audit_depth: f64,
    /// Where a line on each contact update goes (the run's log at -vv, rank 0); none: quiet.
    pub progress: Option<ProgressLine<'a>>,
}

impl<'a, C: Comm + ?Sized> Stepper<'a, C> {
    /// The stepper of a run on one rank, with node-to-face contact (the paper's). Fails as
    /// `with_enforcement`. `whole` is the whole mesh (`problem.mesh`, or the one a run's
    /// outline came from: `Problem::outline`), read while the stepper is built only: an
    /// owned one is freed before the stepper's vectors and element data are allocated.
    pub fn new<'w>(
        comm: &'a C,
        problem: &'a Problem,
        mesh: &'a LocalMesh,
        whole: impl Into<Cow<'w, GlobalMesh>>,
    ) -> Result<Self, String> {
        assert_eq!(
            comm.size(),
            1,
            "a stepper over several ranks is `with_enforcement`'s"
        );
        Self::with_enforcement(comm, problem, mesh, Some(Whole::one_rank(whole.into())))
    }
}

impl<'a, C: Comm + ?Sized, E: Enforcement> Stepper<'a, C, E> {
    /// The stepper with contact enforced by `E`, set up from the whole mesh `whole`, which
    /// rank 0 holds (None on the other ranks). Fails only when the memory for the element
    /// geometry or the solver's vectors is refused on some rank: every rank then returns
    /// that rank's error. Collective.
    pub fn with_enforcement(
        comm: &'a C,
        problem: &'a Problem,
        mesh: &'a LocalMesh,
        whole: Option<Whole<'_>>,
    ) -> Result<Self, String> {
        let built = Self::build(comm, problem, mesh, whole);
        let refused = built.as_ref().err().map(ToString::to_string);
        match (built, crate::comm::first_error(comm, refused)) {
            (Ok(s), None) => Ok(s),
            (_, Some(e)) => Err(e),
            (Err(e), None) => Err(e.to_string()),
        }
    }

    fn build(
        comm: &'a C,
        problem: &'a Problem,
        mesh: &'a LocalMesh,
        whole: Option<Whole<'_>>,
    ) -> Result<Self, crate::memory::AllocError> {
        assert!(
            whole.as_ref().is_none_or(|w| !w.mesh.is_outline()),
            "the stepper is built from the whole mesh, not an outline"
        );
        let n = mesh.num_nodes();
        let survey = Survey::given(comm, problem, whole.as_ref().map(|w| &*w.mesh));
        let (coarse, multilevel, coarse_note) = super::choice::choose_preconditioner(
            comm,
            problem,
            (mesh, whole.as_ref()),
            &survey.tangent,
        );
        // Nothing below reads the whole mesh.
        drop(whole);
        let Survey {
            tangent,
            plan,
            length_scale,
            stiffness_scale,
        } = survey;
        let shapes_note = plan.describe(&problem.mesh);
        let full_tangent = super::choice::full_tangent(&tangent);
        let mut dirichlet = Vec::new();
        for (k, bc) in problem.dirichlet.iter().enumerate() {
            for &g in &problem.node_sets[bc.node_set].nodes {
                if let Some(l) = mesh.local_node(g) {
                    dirichlet.push((l, bc.direction, k));
                }
            }
        }
        let zero = |what| crate::memory::try_filled([0.0; 3], n, what);
        let asm = Assembly::new(mesh, &problem.body_models, &plan)?;
        let loads = Loads::new(problem, mesh);
        // As the model solve decides it (cg::iteration): the nonlinear path's vectors only
        // where it is taken.
        let nonlinear = !asm.linear || loads.is_follower();
        Ok(Stepper {
            comm,
            problem,
            mesh,
            asm,
            loads,
            dirichlet,
            supports: super::support::DirichletGrams::new(problem),
            cg: {
                let mut cg = Cg::new(n, nonlinear)?;
                if let Some(c) = coarse {
                    cg.set_coarse(c);
                }
                if let Some((m, standby)) = multilevel {
                    cg.set_multilevel(m, standby);
                }
                if full_tangent {
                    cg.use_full_tangent();
                }
                cg
            },
            coarse_note,
            shapes_note,
            u: zero("the displacement")?,
            u_prev: zero("the previous displacement")?,
            time: problem.start_time,
            dt_prev: 0.0,
            reference_floor: 0.0,
            audit_depth: 0.0,
            progress: None,
            length_scale,
            stiffness_scale,
            contact: E::default(),
            cons: Constraints::none(mesh),
            multipliers: Vec::new(),
        })
    }

    /// What a restart needs beyond the displacements: (time, last step length, reference
    /// force floor).
    pub fn scalars(&self) -> (f64, f64, f64) {
        (self.time, self.dt_prev, self.reference_floor)
    }

    /// Whether the preconditioner's multilevel standby has taken over.
    pub fn multilevel_switched(&self) -> bool {
        self.cg.multilevel_switched()
    }

    /// The rows the multilevel hierarchy in use was built from, for a restart file
    /// (collective; on rank 0; empty when none is kept: `Cg::hierarchy_words`).
    pub fn hierarchy_words(&self) -> Vec<f64> {
        self.cg.hierarchy_words(self.comm)
    }

    /// The displacement before the last step (the predictor's second point).
    pub fn previous_displacement(&self) -> &[Vec3] {
        &self.u_prev
    }

    /// Continues from a saved state: displacements of the local nodes (in the local mesh's
    /// order: the restart sends each rank its own), the scalars of
    /// `scalars`, whether the multilevel standby had taken over and the rows its hierarchy
    /// was built from (`hierarchy_words`), and the contact state.
    pub fn restore(
        &mut self,
        u: &[Vec3],
        u_prev: &[Vec3],
        (time, dt_prev, reference_floor): (f64, f64, f64),
        (multilevel_switched, hierarchy): (bool, Vec<f64>),
        contact: E,
    ) {
        self.u.copy_from_slice(u);
        self.u_prev.copy_from_slice(u_prev);
        self.time = time;
        self.dt_prev = dt_prev;
        self.reference_floor = reference_floor;
        self.contact = contact;
        if multilevel_switched {
            self.cg.resume_switched();
        }
        self.cg.resume_hierarchy(hierarchy);
    }

    /// What the multilevel preconditioner's last rebuild made and why, once.
    pub fn take_rebuild_note(&mut self) -> Option<String> {
        self.cg.rebuild_note.take()
    }

    /// What the CG spent its iterations on since last asked (`CgTrace`), once.
    pub fn take_cg_trace(&mut self) -> super::cg::CgTrace {
        std::mem::take(&mut self.cg.trace)
    }

    /// Asks for the first model problem that needs a CG iteration, assembled
    /// (`Cg::request_export`).
    pub fn request_export(&mut self) {
        self.cg.request_export();
    }

    /// An export was asked for and no model problem has been assembled yet.
    pub fn export_pending(&self) -> bool {
        self.cg.export_pending()
    }

    /// The assembled model problem once CG finished it, or why there is none; once.
    pub fn take_export(&mut self) -> Option<Result<super::cg::ModelExport, String>> {
        self.cg.take_export()
    }

    pub fn assembly(&self) -> &Assembly<'a> {
        &self.asm
    }

    /// The assembly, to set its committed history from a restart file.
    pub fn assembly_mut(&mut self) -> &mut Assembly<'a> {
        &mut self.asm
    }

    /// The constraint set of the last converged state.
    pub fn constraints(&self) -> &Constraints {
        &self.cons
    }

    /// Row multipliers (constraint forces) of the last converged state.
    pub fn multipliers(&self) -> &[f64] {
        &self.multipliers
    }

    /// Internal and external force at the last converged state.
    pub fn forces(&self) -> (&[Vec3], &[Vec3]) {
        self.cg.forces()
    }

    fn build_constraints(&self, t: f64, contact: &E) -> Result<Constraints, SolveFailure> {
        let owned = self.mesh.num_owned_nodes;
        let mut specs: Vec<RowSpec> = self
            .dirichlet
            .iter()
            .filter(|d| d.0 < owned)
            .map(|&(node, dir, k)| RowSpec {
                node,
                row: Row {
                    dir,
                    value: self.problem.dirichlet[k].function.eval(t),
                    masters: Vec::new(),
                    kind: RowKind::Dirichlet(k),
                },
            })
            .collect();
        specs.extend(contact.rows(self.problem, self.mesh));
        Constraints::new(self.comm, self.mesh, specs).map_err(|c| {
            SolveFailure::Element(format!(
                "circular master/slave dependency at node {}: a slave node is (through other contact pairs) its own master",
                c.0 as u64 + 1
            ))
        })
    }

    /// Advances to `target` (the end of load step `step`, 1-based), cutting back as needed:
    /// predict, solve the increment (the control-contact loop), then accept it or retry
    /// (without the predictor, then halved) until the cut-backs run out.
    pub fn advance(&mut self, step: usize, target: f64) -> Result<StepRecord, StepFailure> {
        let start = Instant::now();
        let mut record = StepRecord {
            step,
            time: target,
            ..Default::default()
        };
        let mut dt = target - self.time;
        let mut cutbacks = 0usize;
        let mut use_predictor = self.problem.solver.predictor;
        while self.time < target {
            let t_new = if self.time + dt >= target - 1e-12 * dt.abs() {
                target
            } else {
                self.time + dt
            };
            let h = t_new - self.time;
            let mut trial = self.predict(h, use_predictor);
            let mut contact = self.contact.clone();
            contact.begin_step();
            let fail = |cause, notes| StepFailure {
                step,
                time: t_new,
                target,
                cause,
                cutbacks,
                notes,
            };
            match self.solve_step(t_new, &mut trial, &mut contact, &mut record) {
                Ok(outcome) => {
                    self.accept(t_new, trial, contact, &outcome)
                        .map_err(|e| fail(SolveFailure::Element(e), Vec::new()))?;
                    record.residual = outcome.residual;
                    record.reference = outcome.reference;
                }
                Err(cause) => {
                    // A shorter step needs the same memory: no retry.
                    let retry = !matches!(cause, SolveFailure::OutOfMemory(_));
                    if retry && use_predictor && self.dt_prev > 0.0 {
                        // First retry the same step from the last converged state.
                        use_predictor = false;
                    } else if retry && cutbacks < self.problem.solver.max_cutbacks {
                        cutbacks += 1;
                        dt = h / 2.0;
                    } else {
                        let mut notes = self.unheld_after(&cause, &contact);
                        notes.extend(self.limit_load_note(&cause, &trial));
                        return Err(fail(cause, notes));
                    }
                }
            }
        }
        record.cutbacks = cutbacks as u64;
        record.contact = self.contact.counts();
        record.contact.max_penetration = self.max_penetration();
        (record.folded, record.most_folded) = self.folded();
        record.wall_time = start.elapsed().as_secs_f64();
        Ok(record)
    }

    /// The start of an increment of length `h`: the last converged displacement, moved on
    /// along the last increment's (scaled) when the predictor is used.
    fn predict(&self, h: f64, use_predictor: bool) -> Vec<Vec3> {
        let mut trial = self.u.clone();
        if use_predictor && self.dt_prev > 0.0 {
            let ratio = h / self.dt_prev;
            for (a, v) in trial.iter_mut().enumerate() {
                for i in 0..3 {
                    v[i] += ratio * (self.u[a][i] - self.u_prev[a][i]);
                }
            }
        }
        trial
    }

    /// Takes a converged increment to `t_new`. Integration-point history moves only with a
    /// converged increment; a failed one leaves it as it was, which is the cut-back's
    /// restore.
    fn accept(
        &mut self,
        t_new: f64,
        trial: Vec<Vec3>,
        contact: E,
        outcome: &ModelOutcome,
    ) -> Result<(), String> {
        self.asm.commit(&trial).map_err(|e| e.to_string())?;
        self.u_prev = std::mem::replace(&mut self.u, trial);
        self.dt_prev = t_new - self.time;
        self.time = t_new;
        self.contact = contact;
        // Later steps are judged against at least the largest force seen so far, so a
        // step that unloads to zero does not chase round-off.
        self.reference_floor = self.reference_floor.max(outcome.reference);
        Ok(())
    }

    /// The bodies the supports of a failed increment did not hold, when the failure is one
    /// a singular model problem shows as (a body its supports no longer hold, e.g. a slave
    /// body pushed off its master).
    fn unheld_after(&self, cause: &SolveFailure, contact: &E) -> Vec<String> {
        match cause {
            SolveFailure::NotConverged {
                residual,
                reference,
                ..
            } if *residual >= 1e-8 * reference => {
                super::support::unheld_bodies(self.problem, contact)
            }
            SolveFailure::NonPositiveCurvature { .. }
            | SolveFailure::NonFinite { .. }
            | SolveFailure::Unbounded { .. } => {
                super::support::unheld_bodies(self.problem, contact)
            }
            _ => Vec::new(),
        }
    }

    /// The deepest of the active nodes' gaps and of the penetration audit's findings at
    /// the converged state (0 without contact).
    fn max_penetration(&self) -> f64 {
        if self.problem.contacts.is_empty() {
            return 0.0;
        }
        let local = self
            .contact
            .gaps(self.comm, self.problem, self.mesh, &self.u)
            .iter()
            .map(|&(_, g)| -g)
            .fold(0.0, f64::max);
        crate::comm::max_f64(self.comm, local).max(self.audit_depth)
    }

    /// The folded mean-integrated hexahedra of every rank at the current displacement: how
    /// many, and the most folded (the smallest ratio, then the lowest id: the same on any
    /// number of ranks). Collective where some body is mean-integrated.
    fn folded(&self) -> (u64, (u32, f64)) {
        let mean = |m: &crate::problem::BodyModel| {
            matches!(m.formulation, crate::fem::Formulation::Mean { .. })
        };
        if !self.problem.body_models.iter().any(mean) {
            return (0, (0, 0.0));
        }
        let local = self.assembly().folded_mean_elements(&self.u);
        let worst = local
            .iter()
            .copied()
            .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
        let (id, ratio) = worst.unwrap_or((u32::MAX, f64::INFINITY));
        let mine = [local.len() as f64, ratio, f64::from(id)];
        let mut count = 0;
        let mut most = (u32::MAX, f64::INFINITY);
        for r in self.comm.all_gather_f64(&mine) {
            count += r[0] as u64;
            let theirs = (r[2] as u32, r[1]);
            if theirs.1 < most.1 || (theirs.1 == most.1 && theirs.0 < most.0) {
                most = theirs;
            }
        }
        (count, most)
    }
}

/// Which springs of the slipping nodes a model problem carried (see `solve_model`).
#[derive(Clone, Copy, Debug)]
pub(super) struct Carried {
    /// Coulomb's tangent beyond the stick range (linear bodies).
    pub newton: bool,
    /// The onset springs (`contact::slip::onset_spring`).
    pub onset: bool,
}

impl<'a, C: Comm + ?Sized, E: Enforcement> Stepper<'a, C, E> {
    /// Solves the model problem at time `t`. A friction force is a load, so a body held
    /// only by slipping nodes is a mechanism within the model problem: when the supports
    /// do not hold a body (`support::unheld_bodies`, slipping nodes tied along the normal
    /// only), or CG finds non-positive curvature, the model problem is solved (again, from
    /// the same start) with a tangential spring at each slipping node
    /// (see `springs`). Otherwise, with linear bodies, the slipping nodes beyond their
    /// stick range carry Coulomb's tangent, and (any bodies) those within it on a rigid
    /// master the onset spring (`Enforcement::tangent_springs`). Returns the outcome, the
    /// springs it used and which they were. Collective: the failure and the contact state
    /// are the same on every rank.
    #[allow(clippy::too_many_arguments)]
    fn solve_model(
        &mut self,
        t: f64,
        u: &mut [Vec3],
        (cons, extra, links): (&Constraints, &[Vec3], &[super::cg::FrictionLink]),
        contact: &mut E,
        settings: &CgSettings,
        diag: &mut Vec<crate::math::Mat3>,
        record: &mut StepRecord,
    ) -> Result<(ModelOutcome, Vec<Spring>, Carried), SolveFailure> {
        let start = contact.slipping().then(|| u.to_vec());
        let mut springs = Vec::new();
        let mut with_springs = false;
        let mut tangent = false;
        let mut onset = false;
        if start.is_some()
            && !super::support::unheld_with(&self.supports, self.problem, contact).is_empty()
        {
            springs = self.slip_springs(contact, u, diag);
            with_springs = true;
        } else if start.is_some() {
            self.nodal_diagonal(u, diag);
            springs = contact.tangent_springs(self.problem, self.mesh, u, self.asm.linear, diag);
            tangent = self.asm.linear;
            onset = true;
        }
        // Without springs or friction links, a body the supports leave free along a motion
        // its loads push along has no equilibrium: said at once, not after CG's whole
        // iteration budget (the step is then cut back as for any failure).
        let free = if springs.is_empty() && links.is_empty() {
            super::support::free_bodies(&self.supports, self.problem, contact)
        } else {
            Vec::new()
        };
        loop {
            let pb = ModelProblem {
                comm: self.comm,
                global: &self.problem.mesh,
                asm: &self.asm,
                loads: &self.loads,
                cons,
                extra,
                springs: &springs,
                time: t,
            };
            let free: &[_] = if springs.is_empty() { &free } else { &[] };
            let solved = match self.cg.check_equilibrium(&pb, u, settings, free) {
                Ok(()) => self.cg.solve_coupled(&pb, u, settings, links),
                Err(e) => Err(e),
            };
            let e = match solved {
                Ok(o) => {
                    record.cg_iterations += o.iterations as u64;
                    return Ok((
                        o,
                        springs,
                        Carried {
                            newton: tangent,
                            onset,
                        },
                    ));
                }
                Err(e) => e,
            };
            if let SolveFailure::NotConverged { iterations, .. }
            | SolveFailure::NonPositiveCurvature { iterations }
            | SolveFailure::Unbounded { iterations, .. }
            | SolveFailure::NonFinite { iterations }
            | SolveFailure::IndefinitePreconditioner { iterations } = e
            {
                record.cg_iterations += iterations as u64;
            }
            // (Not a CG that does not converge: a retry costs a whole CG budget, 120000
            // iterations more for nothing in the extreme suite's drag_deformable; the
            // support check above finds the mechanisms that show that way.)
            let mechanism = matches!(e, SolveFailure::NonPositiveCurvature { .. });
            match &start {
                Some(u0) if mechanism && !with_springs => {
                    u.copy_from_slice(u0);
                    springs = self.slip_springs(contact, u, diag);
                    with_springs = true;
                    tangent = false;
                    onset = false;
                }
                _ => return Err(e),
            }
        }
    }
}

impl<'a, C: Comm + ?Sized, E: Enforcement> Stepper<'a, C, E> {
    /// The slipping nodes' springs at `u`, with the nodal stiffness blocks computed once
    /// per step into `diag`.
    fn slip_springs(
        &self,
        contact: &E,
        u: &[Vec3],
        diag: &mut Vec<crate::math::Mat3>,
    ) -> Vec<Spring> {
        self.nodal_diagonal(u, diag);
        contact.slip_springs(self.mesh, u, diag)
    }

    /// The structure's nodal diagonal stiffness blocks at `u` into `diag`, once per step
    /// (when `diag` is empty).
    fn nodal_diagonal(&self, u: &[Vec3], diag: &mut Vec<crate::math::Mat3>) {
        if diag.is_empty() {
            diag.resize(self.mesh.num_nodes(), [[0.0; 3]; 3]);
            // An element that fails here fails the model problem too.
            let _ = self.asm.diagonal(u, diag);
        }
    }
}
