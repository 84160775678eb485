//! The model problem: with the constraint set frozen, find u with the projected residual
//! P (f_ext(u) - f_int(u)) within tolerance, by nonlinear preconditioned CG.
//!
//! Step length along a direction p comes from the directional stiffness p.K p: exact
//! (K p = f_int(p)) when every body is linear, otherwise a finite-difference probe
//! followed by a secant correction. Linear problems therefore get plain linear PCG
//! (Fletcher-Reeves beta); nonlinear ones use Polak-Ribiere+ with restarts.

use super::assembly::{Assembly, ElementError};
use super::coarse::CoarseSpace;
use super::loads::Loads;
use super::multilevel::{FineOperator, Multilevel};
use crate::comm::{self, Comm};
use crate::constraints::Constraints;
use crate::math::{inverse, matvec, Mat3, Vec3};
use crate::memory::{try_filled, AllocError};

/// With `preconditioner = "auto"` on meshes below the two-level threshold, CG starts with
/// block Jacobi and moves to the multilevel preconditioner at this iteration of a model
/// problem: problems Jacobi solves quickly keep today's path bit for bit, the hard ones
/// (the Hertz example: 11753 Jacobi iterations, 239 multilevel) pay this once.
pub const SWITCH_AFTER: usize = 300;

/// Why a model problem could not be solved. Rank-agreed.
#[derive(Clone, Debug, PartialEq)]
pub enum SolveFailure {
    Element(String),
    NotConverged {
        iterations: usize,
        residual: f64,
        reference: f64,
    },
    NonPositiveCurvature {
        iterations: usize,
    },
    NonFinite {
        iterations: usize,
    },
    Unbounded {
        iterations: usize,
        max_displacement: f64,
    },
    ContactNotSettled {
        updates: usize,
        detail: String,
    },
    /// An allocation was refused (on some rank); not retried with a shorter step.
    OutOfMemory(String),
    /// A slave node stayed inside a master body after gap removal (the penetration audit
    /// of the equilibrium query).
    Penetration {
        /// Global node id, 1-based.
        node: u64,
        pair: String,
        depth: f64,
        tolerance: f64,
        /// Under small kinematics: the message then says that small sliding was exceeded.
        small_kinematics: bool,
    },
}

impl std::fmt::Display for SolveFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SolveFailure::Element(m) | SolveFailure::OutOfMemory(m) => write!(f, "{m}"),
            SolveFailure::NotConverged { iterations, residual, reference } => {
                write!(
                    f,
                    "CG did not converge in {iterations} iterations (residual {residual:.3e}, reference force {reference:.3e})"
                )?;
                if *residual < 1e-8 * reference {
                    // The residual came down by eight orders and stalled: a round-off floor
                    // (stiff bodies carry internal forces far above the load), not a
                    // missing support.
                    write!(f, "; it stalled far below the load: the tolerance may be below what round-off allows (a large stiffness contrast), try a larger solver.tolerance")?;
                }
                Ok(())
            }
            SolveFailure::NonPositiveCurvature { iterations } => {
                write!(f, "non-positive curvature along the search direction after {iterations} CG iterations (unstable or unconstrained structure)")
            }
            SolveFailure::NonFinite { iterations } => write!(f, "non-finite residual after {iterations} CG iterations"),
            SolveFailure::Unbounded { max_displacement, .. } => write!(
                f,
                "the displacement grew without bound (max |u| = {max_displacement:.3e}): a body is not held (a rigid-body motion, or friction that cannot carry the load)"
            ),
            SolveFailure::ContactNotSettled { updates, detail } => {
                write!(f, "contact did not settle after {updates} contact updates: {detail}")
            }
            SolveFailure::Penetration { node, pair, depth, tolerance, small_kinematics } => {
                write!(
                    f,
                    "slave node {node} of contact '{pair}' is inside the master body by {depth:.3e} (capture tolerance {tolerance:.3e}) and gap removal did not bring it out"
                )?;
                if *small_kinematics {
                    write!(f, "; small sliding was exceeded: under kinematics = \"small\" the master faces keep their reference normals, which holds only while the bodies slide and rotate little; kinematics = \"large\" follows the sliding")?;
                }
                Ok(())
            }
        }
    }
}

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
}

/// Buffers for the model solve, allocated once per run.
pub struct Cg {
    fi: Vec<Vec3>,
    fe: Vec<Vec3>,
    r: Vec<Vec3>,
    r_old: Vec<Vec3>,
    z: Vec<Vec3>,
    p: Vec<Vec3>,
    pu: Vec<Vec3>,
    q: Vec<Vec3>,
    trial: Vec<Vec3>,
    fi_trial: Vec<Vec3>,
    fe_trial: Vec<Vec3>,
    diag: Vec<Mat3>,
    minv: Vec<Mat3>,
    /// The coarse space of the two-level preconditioner, when used.
    coarse: Option<CoarseSpace>,
    coarse_work: Vec<f64>,
    /// A new load increment began since the coarse operator was measured.
    coarse_stale: bool,
    /// Constraint rows when the coarse operator was measured.
    coarse_rows: usize,
    /// The multilevel preconditioner, when used.
    multilevel: Option<Multilevel>,
    /// The multilevel preconditioner waits until a model problem needs SWITCH_AFTER
    /// iterations.
    ml_standby: bool,
    /// Contact rows when the multilevel hierarchy was built.
    ml_contact_rows: usize,
    /// Why the multilevel hierarchy was last rebuilt, until the log takes it.
    pub rebuild_note: Option<String>,
}

impl Cg {
    /// Fails only when the memory for the vectors is refused.
    pub fn new(n: usize) -> Result<Self, AllocError> {
        let v = || try_filled([0.0; 3], n, "the CG vectors");
        Ok(Cg {
            fi: v()?,
            fe: v()?,
            r: v()?,
            r_old: v()?,
            z: v()?,
            p: v()?,
            pu: v()?,
            q: v()?,
            trial: v()?,
            fi_trial: v()?,
            fe_trial: v()?,
            diag: try_filled([[0.0; 3]; 3], n, "the preconditioner's diagonal")?,
            minv: try_filled([[0.0; 3]; 3], n, "the preconditioner's diagonal")?,
            coarse: None,
            coarse_work: Vec::new(),
            coarse_stale: true,
            coarse_rows: 0,
            multilevel: None,
            ml_contact_rows: 0,
            ml_standby: false,
            rebuild_note: None,
        })
    }

    /// Uses the multilevel preconditioner; with `standby`, only from the SWITCH_AFTER-th
    /// iteration of a model problem on (the `auto` choice on smaller meshes).
    pub fn set_multilevel(&mut self, ml: Multilevel, standby: bool) {
        self.multilevel = Some(ml);
        self.ml_standby = standby;
    }

    /// Uses the two-level preconditioner with this coarse space.
    pub fn set_coarse(&mut self, coarse: CoarseSpace) {
        self.coarse = Some(coarse);
    }

    /// Marks a new load increment. The coarse operator is measured again when the bodies
    /// are nonlinear (the tangent moved) or the number of constraint rows changed by more
    /// than a tenth; otherwise it is kept: measured with an earlier constraint set it is
    /// still a valid (positive) preconditioner, only a slightly less sharp one, and
    /// measuring costs an operator application per colour and mode.
    pub fn invalidate_coarse(&mut self) {
        self.coarse_stale = true;
    }

    /// The internal and external forces of the last accepted iterate.
    pub fn forces(&self) -> (&[Vec3], &[Vec3]) {
        (&self.fi, &self.fe)
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

pub struct Problem<'a, C: Comm + ?Sized> {
    pub comm: &'a C,
    pub asm: &'a Assembly<'a>,
    pub loads: &'a Loads,
    pub cons: &'a Constraints,
    /// Forces held fixed during the model problem (friction of slipping contact nodes).
    pub extra: &'a [Vec3],
    /// Tangential springs of slipping contact nodes (see `springs`).
    pub springs: &'a [super::springs::Spring],
    pub time: f64,
}

impl<'a, C: Comm + ?Sized> Problem<'a, C> {
    fn owned(&self) -> usize {
        self.asm.mesh.num_owned_nodes
    }

    /// fi = f_int(u), fe = f_ext(t, u) plus the fixed extra forces.
    fn forces(&self, u: &[Vec3], fi: &mut [Vec3], fe: &mut [Vec3]) -> Result<(), SolveFailure> {
        let r = self.asm.internal_force(u, fi);
        let r = r.and_then(|_| self.loads.external_force(self.asm, self.time, u, fe));
        agree(self.comm, r)?;
        super::springs::add_forces(self.springs, u, fi);
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

/// Where a CG solve stands between iterations.
struct Progress {
    /// Norm of the residual and the force it is measured against.
    rnorm: f64,
    refv: f64,
    /// The smallest reference force (a round-off floor).
    floor: f64,
    /// r.z of the previous iteration.
    rz_old: f64,
    /// The next direction is the preconditioned residual (beta = 0).
    restart: bool,
    /// Linear iterations since the residual was last recomputed from the forces.
    since_true: usize,
}

impl Progress {
    #[inline]
    fn converged(&self, s: &CgSettings) -> bool {
        self.rnorm <= s.tolerance * self.refv
    }

    #[inline]
    fn outcome(&self, iterations: usize) -> ModelOutcome {
        ModelOutcome {
            iterations,
            residual: self.rnorm,
            reference: self.refv,
        }
    }
}

impl Cg {
    /// Solves the model problem in place; `u` must satisfy the constraints on entry.
    pub fn solve<C: Comm + ?Sized>(
        &mut self,
        pb: &Problem<C>,
        u: &mut [Vec3],
        s: &CgSettings,
    ) -> Result<ModelOutcome, SolveFailure> {
        let linear = pb.asm.linear && !pb.loads.is_follower();
        let mut st = self.initial_residual(pb, u, s)?;
        if st.converged(s) {
            return Ok(st.outcome(0));
        }
        self.precondition(pb, u)?;
        self.setup_coarse(pb, u, linear, s)?;
        self.setup_multilevel(pb, u, linear, s)?;

        for it in 1..=s.max_iterations {
            if self.ml_standby && it == SWITCH_AFTER {
                self.switch_to_multilevel(pb, u, linear, s)?;
                st.restart = true;
            }
            self.apply_preconditioner(pb, u, linear, s)?;
            let Some(rp) = self.update_direction(pb, linear, &mut st, u.len()) else {
                // The preconditioned residual vanished: the residual is at round-off level.
                return Ok(st.outcome(it - 1));
            };
            if linear {
                self.linear_step(pb, u, rp, it, s, &mut st)?;
            } else {
                self.nonlinear_step(pb, u, rp, it, s, &mut st)?;
            }
            if !st.rnorm.is_finite() {
                return Err(SolveFailure::NonFinite { iterations: it });
            }
            if st.converged(s) {
                return Ok(st.outcome(it));
            }
        }
        Err(SolveFailure::NotConverged {
            iterations: s.max_iterations,
            residual: st.rnorm,
            reference: st.refv,
        })
    }

    /// Forces and residual at the starting point.
    fn initial_residual<C: Comm + ?Sized>(
        &mut self,
        pb: &Problem<C>,
        u: &[Vec3],
        s: &CgSettings,
    ) -> Result<Progress, SolveFailure> {
        pb.forces(u, &mut self.fi, &mut self.fe)?;
        residual(pb.comm, pb.cons, &self.fi, &self.fe, &mut self.r);
        let (rnorm, reference) = pb.measure(&self.r, &self.fi, &self.fe);
        // The prescribed motion's force scale enters only at round-off level: a residual
        // within 1e3 eps of it cannot be resolved further (a body moving rigidly with its
        // supports loads nothing), but it must not loosen the tolerance on real loads.
        let roundoff = s.stiffness_floor * 1e3 * f64::EPSILON / s.tolerance;
        let floor = s.reference_floor.max(roundoff);
        if !rnorm.is_finite() {
            return Err(SolveFailure::NonFinite { iterations: 0 });
        }
        Ok(Progress {
            rnorm,
            refv: reference.max(floor),
            floor,
            rz_old: 0.0,
            restart: true,
            since_true: 0,
        })
    }

    /// Block Jacobi is not enough here: from now on the multilevel preconditioner.
    fn switch_to_multilevel<C: Comm + ?Sized>(
        &mut self,
        pb: &Problem<C>,
        u: &mut [Vec3],
        linear: bool,
        s: &CgSettings,
    ) -> Result<(), SolveFailure> {
        self.ml_standby = false;
        self.setup_multilevel(pb, u, linear, s)?;
        if let Some(note) = self.rebuild_note.as_mut() {
            *note = format!("switched to the multilevel preconditioner after {SWITCH_AFTER} CG iterations; {note}");
        }
        Ok(())
    }

    /// z = M^-1 r (multilevel or block Jacobi, then the coarse correction).
    #[inline]
    fn apply_preconditioner<C: Comm + ?Sized>(
        &mut self,
        pb: &Problem<C>,
        u: &mut [Vec3],
        linear: bool,
        s: &CgSettings,
    ) -> Result<(), SolveFailure> {
        let comm = pb.comm;
        if let Some(ml) = self.multilevel.as_mut().filter(|_| !self.ml_standby) {
            let mut op = FineOp {
                pb,
                linear,
                eps_scale: s.length_scale,
                u,
                fi: &self.fi,
                fe: &self.fe,
                trial: &mut self.trial,
                fi_trial: &mut self.fi_trial,
                fe_trial: &mut self.fe_trial,
            };
            ml.apply(comm, pb.cons, &self.minv, &mut op, &self.r, &mut self.z)?;
        } else {
            for a in 0..u.len() {
                self.z[a] = matvec(&self.minv[a], &self.r[a]);
            }
        }
        if let Some(c) = &self.coarse {
            c.apply(
                comm,
                pb.cons,
                pb.owned(),
                &self.r,
                &mut self.z,
                &mut self.coarse_work,
            );
        }
        Ok(())
    }

    /// The new search direction p (Fletcher-Reeves when linear, Polak-Ribiere+ otherwise)
    /// and its expansion to all displacements in `pu`; returns r.p, or None when the
    /// preconditioned residual vanished.
    #[inline]
    fn update_direction<C: Comm + ?Sized>(
        &mut self,
        pb: &Problem<C>,
        linear: bool,
        st: &mut Progress,
        nl: usize,
    ) -> Option<f64> {
        let (comm, n) = (pb.comm, pb.owned());
        let rz = comm::dot(comm, &self.r, &self.z, n);
        let beta = if st.restart || st.rz_old == 0.0 {
            0.0
        } else if linear {
            rz / st.rz_old
        } else {
            let zr_old = comm::dot(comm, &self.z, &self.r_old, n);
            ((rz - zr_old) / st.rz_old).max(0.0)
        };
        for a in 0..nl {
            for i in 0..3 {
                self.p[a][i] = self.z[a][i] + beta * self.p[a][i];
            }
        }
        let mut rp = comm::dot(comm, &self.r, &self.p, n);
        if !(rp > 0.0) {
            self.p.copy_from_slice(&self.z);
            rp = rz;
        }
        if !(rp > 0.0) {
            return None;
        }
        st.restart = false;
        st.rz_old = rz;
        self.r_old.copy_from_slice(&self.r);
        // The search direction in the free variables, mapped to all displacements.
        self.pu.copy_from_slice(&self.p);
        pb.cons.expand(comm, &mut self.pu);
        pb.asm.mesh.exchange(comm, &mut self.pu);
        Some(rp)
    }

    /// Linear PCG step: exact curvature p.K p, recurrence for the residual, replaced by the
    /// true residual every 50 iterations and before convergence is accepted.
    #[inline]
    fn linear_step<C: Comm + ?Sized>(
        &mut self,
        pb: &Problem<C>,
        u: &mut [Vec3],
        rp: f64,
        it: usize,
        s: &CgSettings,
        st: &mut Progress,
    ) -> Result<(), SolveFailure> {
        let (comm, n) = (pb.comm, pb.owned());
        agree(comm, pb.asm.internal_force(&self.pu, &mut self.q))?;
        super::springs::add_action(pb.springs, &self.pu, &mut self.q);
        let pkp = comm::dot(comm, &self.pu, &self.q, n);
        if !(pkp > 0.0) {
            return Err(SolveFailure::NonPositiveCurvature { iterations: it });
        }
        let alpha = rp / pkp;
        let nl = u.len();
        for a in 0..nl {
            for i in 0..3 {
                u[a][i] += alpha * self.pu[a][i];
            }
        }
        pb.cons.reduce(comm, &mut self.q, None);
        for a in 0..nl {
            for i in 0..3 {
                self.r[a][i] -= alpha * self.q[a][i];
            }
        }
        st.since_true += 1;
        st.rnorm = comm::norm(comm, &self.r, n);
        let maybe_done = st.converged(s);
        if maybe_done || st.since_true >= 50 {
            // Replace the recurrence by the true residual.
            pb.forces(u, &mut self.fi, &mut self.fe)?;
            residual(comm, pb.cons, &self.fi, &self.fe, &mut self.r);
            let (rn, reference) = pb.measure(&self.r, &self.fi, &self.fe);
            st.rnorm = rn;
            st.refv = reference.max(st.floor);
            st.since_true = 0;
            st.restart = !maybe_done;
        }
        Ok(())
    }

    /// Nonlinear step: curvature from a finite-difference probe, the Newton step along p
    /// (halved while an element inverts), then one secant correction when the directional
    /// residual is far from zero; block Jacobi is rebuilt every 100 iterations.
    fn nonlinear_step<C: Comm + ?Sized>(
        &mut self,
        pb: &Problem<C>,
        u: &mut [Vec3],
        rp: f64,
        it: usize,
        s: &CgSettings,
        st: &mut Progress,
    ) -> Result<(), SolveFailure> {
        let (comm, n) = (pb.comm, pb.owned());
        let pmax = max_abs(comm, &self.pu, n).max(f64::MIN_POSITIVE);
        let eps = 1e-7 * s.length_scale / pmax;
        for a in 0..u.len() {
            for i in 0..3 {
                self.trial[a][i] = u[a][i] + eps * self.pu[a][i];
            }
        }
        pb.forces(&self.trial, &mut self.fi_trial, &mut self.fe_trial)?;
        for a in 0..u.len() {
            for i in 0..3 {
                self.q[a][i] = ((self.fi_trial[a][i] - self.fe_trial[a][i])
                    - (self.fi[a][i] - self.fe[a][i]))
                    / eps;
            }
        }
        let pkp = comm::dot(comm, &self.pu, &self.q, n);
        if !(pkp > 0.0) {
            return Err(SolveFailure::NonPositiveCurvature { iterations: it });
        }
        let mut alpha = rp / pkp;
        for attempt in 0..12 {
            match self.try_step(pb, u, alpha) {
                Ok(()) => break,
                Err(e) if attempt == 11 => return Err(e),
                Err(_) => alpha *= 0.5,
            }
        }
        let s1 = comm::dot(comm, &self.r, &self.p, n);
        if s1.abs() > 0.25 * rp {
            // try_step leaves the state untouched when the corrected point fails.
            let a2 = (alpha * rp / (rp - s1)).clamp(0.1 * alpha, 4.0 * alpha);
            let _ = self.try_step(pb, u, a2 - alpha);
        }
        let (rn, reference) = pb.measure(&self.r, &self.fi, &self.fe);
        st.rnorm = rn;
        st.refv = reference.max(st.floor);
        if it.is_multiple_of(100) {
            self.precondition(pb, u)?;
            st.restart = true;
        }
        Ok(())
    }

    /// u += alpha p with forces and residual at the new point; on an element failure u is
    /// left unchanged.
    fn try_step<C: Comm + ?Sized>(
        &mut self,
        pb: &Problem<C>,
        u: &mut [Vec3],
        alpha: f64,
    ) -> Result<(), SolveFailure> {
        for a in 0..u.len() {
            for i in 0..3 {
                self.trial[a][i] = u[a][i] + alpha * self.pu[a][i];
            }
        }
        pb.forces(&self.trial, &mut self.fi_trial, &mut self.fe_trial)?;
        u.copy_from_slice(&self.trial);
        std::mem::swap(&mut self.fi, &mut self.fi_trial);
        std::mem::swap(&mut self.fe, &mut self.fe_trial);
        residual(pb.comm, pb.cons, &self.fi, &self.fe, &mut self.r);
        Ok(())
    }

    /// Measures and factors the coarse operator Q^T A Q when it is out of date: one
    /// operator application per colour and mode (exact for linear bodies, a
    /// finite-difference probe at u otherwise).
    fn setup_coarse<C: Comm + ?Sized>(
        &mut self,
        pb: &Problem<C>,
        u: &[Vec3],
        linear: bool,
        s: &CgSettings,
    ) -> Result<(), SolveFailure> {
        let Some(mut cs) = self.coarse.take() else {
            return Ok(());
        };
        let rows = pb.cons.num_rows() as f64;
        let rows = comm::global_sum(pb.comm, {
            let mut acc = comm::ExactSum::new();
            acc.add(rows);
            acc
        });
        let similar = (rows - self.coarse_rows as f64).abs() <= 0.1 * self.coarse_rows as f64;
        if cs.is_set_up() && similar && (linear || !self.coarse_stale) {
            self.coarse = Some(cs);
            return Ok(());
        }
        self.coarse_stale = false;
        self.coarse_rows = rows as usize;
        let comm = pb.comm;
        let owned = pb.owned();
        let dim = cs.dim();
        let mut kc = match agree_alloc(comm, try_filled(0.0, dim * dim, "the coarse operator")) {
            Ok(kc) => kc,
            Err(e) => {
                self.coarse = Some(cs);
                return Err(e);
            }
        };
        let mut restricted = Vec::new();
        let mut result = Ok(());
        'probes: for c in 0..cs.num_colors() {
            for m in 0..6 {
                cs.probe(pb.cons, c, m, owned, &mut self.pu);
                pb.cons.expand(comm, &mut self.pu);
                pb.asm.mesh.exchange(comm, &mut self.pu);
                if linear {
                    // A probe is non-zero on one colour's aggregates only.
                    let r = pb.asm.internal_force_sparse(&self.pu, &mut self.q);
                    if let Err(e) = agree(comm, r) {
                        result = Err(e);
                        break 'probes;
                    }
                } else {
                    let pmax = max_abs(comm, &self.pu, owned).max(f64::MIN_POSITIVE);
                    let eps = 1e-7 * s.length_scale / pmax;
                    for a in 0..u.len() {
                        for i in 0..3 {
                            self.trial[a][i] = u[a][i] + eps * self.pu[a][i];
                        }
                    }
                    if let Err(e) = pb.forces(&self.trial, &mut self.fi_trial, &mut self.fe_trial) {
                        result = Err(e);
                        break 'probes;
                    }
                    for a in 0..u.len() {
                        for i in 0..3 {
                            self.q[a][i] = ((self.fi_trial[a][i] - self.fe_trial[a][i])
                                - (self.fi[a][i] - self.fe[a][i]))
                                / eps;
                        }
                    }
                }
                pb.cons.reduce(comm, &mut self.q, None);
                cs.restrict(comm, &self.q, &mut restricted);
                cs.record(c, m, &restricted, &mut kc);
            }
        }
        if result.is_ok() {
            result = agree_alloc(comm, cs.factor(kc)).map(|_| ());
        }
        self.coarse = Some(cs);
        result
    }

    /// Builds the multilevel hierarchy when it is out of date, by the rule of the coarse
    /// space (`invalidate_coarse`): first use, the number of constraint rows changed by
    /// more than a tenth, or a new increment of a nonlinear body.
    fn setup_multilevel<C: Comm + ?Sized>(
        &mut self,
        pb: &Problem<C>,
        u: &[Vec3],
        linear: bool,
        s: &CgSettings,
    ) -> Result<(), SolveFailure> {
        let Some(ml) = self.multilevel.as_mut().filter(|_| !self.ml_standby) else {
            return Ok(());
        };
        // Contact rows counted apart: a body held only by contact has its rigid modes in
        // the coarse levels only through them.
        let mut counts = [0i64; 2];
        for l in 0..pb.owned() {
            for (_, row) in pb.cons.rows(l) {
                let contact = matches!(row.kind, crate::constraints::RowKind::Contact { .. });
                counts[contact as usize] += 1;
            }
        }
        pb.comm.sum_i64(&mut counts);
        let rows = (counts[0] + counts[1]) as usize;
        let contact = counts[1] as usize;
        let (old, old_contact) = (self.coarse_rows, self.ml_contact_rows);
        let near = |a: usize, b: usize| a.abs_diff(b) as f64 <= 0.1 * b as f64;
        let similar = near(rows, old) && near(contact, old_contact);
        if ml.is_set_up() && similar && (linear || !self.coarse_stale) {
            return Ok(());
        }
        let why = if !ml.is_set_up() {
            "first use".to_string()
        } else if !similar {
            format!("constraint rows {old} -> {rows}, of them contact {old_contact} -> {contact}")
        } else {
            "new increment of a nonlinear body".to_string()
        };
        self.ml_contact_rows = contact;
        self.coarse_stale = false;
        self.coarse_rows = rows;
        let mut op = FineOp {
            pb,
            linear,
            eps_scale: s.length_scale,
            u,
            fi: &self.fi,
            fe: &self.fe,
            trial: &mut self.trial,
            fi_trial: &mut self.fi_trial,
            fe_trial: &mut self.fe_trial,
        };
        let start = std::time::Instant::now();
        ml.setup(pb.comm, pb.cons, pb.asm.mesh, &self.minv, &mut op, linear)?;
        self.rebuild_note = Some(format!(
            "{} (build {}: {why}; {:.3} s)",
            ml.summary,
            ml.builds,
            start.elapsed().as_secs_f64()
        ));
        Ok(())
    }

    /// Block-Jacobi preconditioner in the constrained space: M = P D P + (I - P) d, with
    /// d a positive scale so M is invertible, then z = P M^-1 P r.
    fn precondition<C: Comm + ?Sized>(
        &mut self,
        pb: &Problem<C>,
        u: &[Vec3],
    ) -> Result<(), SolveFailure> {
        agree(pb.comm, pb.asm.diagonal(u, &mut self.diag))?;
        super::springs::add_diagonal(pb.springs, &mut self.diag);
        pb.cons.precondition_blocks(pb.comm, &mut self.diag);
        for a in 0..u.len() {
            let m = &self.diag[a];
            let (inv, det) = inverse(m);
            self.minv[a] =
                if det.is_finite() && det != 0.0 && inv.iter().flatten().all(|v| v.is_finite()) {
                    inv
                } else {
                    let s = 1.0 / (m[0][0] + m[1][1] + m[2][2]).abs().max(f64::MIN_POSITIVE);
                    [[s, 0.0, 0.0], [0.0, s, 0.0], [0.0, 0.0, s]]
                };
        }
        pb.cons.project_inverse_blocks(&mut self.minv);
        Ok(())
    }

    /// Row multipliers at the last accepted iterate: the force each constraint row exerts.
    pub fn multipliers<C: Comm + ?Sized>(&mut self, pb: &Problem<C>, out: &mut Vec<f64>) {
        out.clear();
        out.resize(pb.cons.num_rows(), 0.0);
        for a in 0..self.q.len() {
            self.q[a] = crate::math::sub(&self.fe[a], &self.fi[a]);
        }
        pb.cons.reduce(pb.comm, &mut self.q, Some(out));
    }
}

/// The constrained fine operator for the multilevel preconditioner: T^T K T x, exact for
/// linear bodies, a finite difference of the forces at u otherwise.
struct FineOp<'b, 'a, C: Comm + ?Sized> {
    pb: &'b Problem<'a, C>,
    linear: bool,
    eps_scale: f64,
    u: &'b [Vec3],
    fi: &'b [Vec3],
    fe: &'b [Vec3],
    trial: &'b mut [Vec3],
    fi_trial: &'b mut [Vec3],
    fe_trial: &'b mut [Vec3],
}

impl<C: Comm + ?Sized> FineOperator for FineOp<'_, '_, C> {
    type Error = SolveFailure;
    fn apply(&mut self, x: &mut [Vec3], y: &mut [Vec3]) -> Result<(), SolveFailure> {
        let (pb, comm) = (self.pb, self.pb.comm);
        pb.cons.expand(comm, x);
        pb.asm.mesh.exchange(comm, x);
        if self.linear {
            agree(comm, pb.asm.internal_force_sparse(x, y))?;
        } else {
            let owned = pb.owned();
            let eps = 1e-7 * self.eps_scale / max_abs(comm, x, owned).max(f64::MIN_POSITIVE);
            for a in 0..x.len() {
                for i in 0..3 {
                    self.trial[a][i] = self.u[a][i] + eps * x[a][i];
                }
            }
            pb.forces(self.trial, self.fi_trial, self.fe_trial)?;
            for a in 0..x.len() {
                for i in 0..3 {
                    y[a][i] = ((self.fi_trial[a][i] - self.fe_trial[a][i])
                        - (self.fi[a][i] - self.fe[a][i]))
                        / eps;
                }
            }
        }
        pb.cons.reduce(comm, y, None);
        Ok(())
    }
}

fn max_abs<C: Comm + ?Sized>(comm: &C, v: &[Vec3], n: usize) -> f64 {
    let m = v[..n].iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    comm::max_f64(comm, m)
}
