//! The model problem with the friction of slipping nodes coupled to their normal force.
//!
//! A slipping node carries the friction force mu N d (d its friction direction). Held as
//! a fixed load, N from the last model problem, the contact updates converge the
//! magnitudes only linearly (a tenth per update on the paper's wedge and the extreme
//! suite's drags), and a step took ten or more updates to reach the solver tolerance. Here
//! N is that of the iterate: the residual is
//!     r(u) = T^T (f_ext + F(N(u)) - f_int(u)),  F = mu N d on the slave, -w mu N d on the
//! master nodes of its master point, N the normal row's multiplier of f_ext - f_int;
//! for linear bodies r is affine in u with a non-symmetric operator (the friction's
//! dependence on the normal force), solved by BiCGStab with the CG's preconditioner (a
//! preconditioner of the symmetric part, which dominates: mu is below 1 and the coupling
//! acts at the slipping nodes only). The magnitudes held in the model problem's fixed loads
//! are corrected, (mu N - held) d, so the solution is the fixed point the contact updates
//! converge to: the next update finds every magnitude at its capacity.
//!
//! Nonlinear bodies (no follower loads): Newton's method on the same residual, each step
//! BiCGStab on the tangent at the step's start (a finite difference of the internal
//! forces) until the linearised residual is a tenth of the true one; a step that does not
//! reduce the true residual, or fails (an inverted element), hands over to the plain solve.
//!
//! Every reduction is an exact dot product or a maximum of values only their owner rank
//! holds (the others hold minus infinity), so 1, 2 and 3 ranks agree bitwise.

use super::failure::SolveFailure;
use super::links::FrictionLink;
use super::model::{agree, agree_alloc, max_abs, residual, CgSettings, ModelOutcome, ModelProblem};
use super::state::Cg;
use crate::comm::{self, Comm};
use crate::math::Vec3;
use crate::solver::assembly::Elastic;

/// The friction forces `scale_k * mu_k * dir_k` of the links added to `f` (slave +, master
/// nodes -w), in the order of the links.
fn spread(links: &[FrictionLink], scale: &[f64], f: &mut [Vec3]) {
    for (l, &c) in links.iter().zip(scale) {
        let g: Vec3 = std::array::from_fn(|i| c * l.dir[i]);
        if let Some(s) = l.slave {
            f[s] = crate::math::add(&f[s], &g);
        }
        for &(m, w) in &l.masters {
            f[m] = crate::math::sub(&f[m], &crate::math::scale(&g, w));
        }
    }
}

/// The normal force of each link (on its owner rank, shared): from the multipliers `mult`
/// of a force that holds the friction magnitudes `held` (or none: `held` false), the normal
/// force with the friction at mu times it, N = (n0 - m held) / (1 - m mu) with m the link's
/// `own` coupling. Collective.
fn normals<C: Comm + ?Sized>(
    comm: &C,
    links: &[FrictionLink],
    mult: &[f64],
    held: bool,
    out: &mut Vec<f64>,
) {
    out.clear();
    out.extend(links.iter().map(|l| {
        let g = 1.0 - l.own * l.mu;
        match l.row {
            // Friction that feeds its own normal force at mu m >= 1/2: not a contraction
            // worth coupling; held as it is.
            Some(_) if !(g >= 0.5) => f64::NEG_INFINITY,
            Some(i) => (mult[i] - if held { l.own * l.held } else { 0.0 }) / g,
            None => f64::NEG_INFINITY,
        }
    }));
    comm.max_f64(out);
    for x in out.iter_mut() {
        // A node whose normal row was dropped (in the span of rows that take precedence)
        // has no multiplier of its own: its friction stays as held.
        if !x.is_finite() {
            *x = f64::NAN;
        }
    }
}

/// A residual this many times the starting one ends the coupled solve (the plain one
/// takes over).
const DIVERGED: f64 = 1e6;

impl Cg {
    /// Solves the linear model problem with the links' friction coupled to their normal
    /// forces (see the module). Falls back to the plain solve, friction as held, when
    /// BiCGStab breaks down or does not converge. Returns the outcome.
    pub fn solve_coupled<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &mut [Vec3],
        s: &CgSettings,
        links: &[FrictionLink],
    ) -> Result<ModelOutcome, SolveFailure> {
        if pb.loads.is_follower() || links.is_empty() {
            return self.solve(pb, u, s);
        }
        let linear = pb.asm.linear;
        let start = u.to_vec();
        match self.bicgstab(pb, u, s, links, linear) {
            Ok(Some(outcome)) => Ok(outcome),
            Ok(None) => {
                u.copy_from_slice(&start);
                self.solve(pb, u, s)
            }
            // A Newton step of a nonlinear body that inverts an element (or fails
            // otherwise short of memory): the plain solve, friction as held, decides.
            Err(e) if !linear && !matches!(e, SolveFailure::OutOfMemory(_)) => {
                u.copy_from_slice(&start);
                self.solve(pb, u, s)
            }
            Err(e) => Err(e),
        }
    }

    /// fi, fe (with the coupled friction) and the residual at `u`; returns (|r|, reference).
    fn coupled_residual<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &[Vec3],
        links: &[FrictionLink],
    ) -> Result<(f64, f64), SolveFailure> {
        pb.forces(u, &mut self.fi, &mut self.fe)?;
        for a in 0..self.q.len() {
            self.q[a] = crate::math::sub(&self.fe[a], &self.fi[a]);
        }
        let work = &mut self.coupled;
        work.mult.clear();
        work.mult.resize(pb.cons.num_rows(), 0.0);
        pb.cons.reduce(pb.comm, &mut self.q, Some(&mut work.mult));
        normals(pb.comm, links, &work.mult, true, &mut work.normal);
        for (x, l) in work.normal.iter_mut().zip(links) {
            *x = if x.is_nan() { 0.0 } else { l.mu * *x - l.held };
        }
        spread(links, &work.normal, &mut self.fe);
        residual(pb.comm, pb.cons, &self.fi, &self.fe, &mut self.r);
        if self.coupled.res.len() == self.r.len() {
            self.coupled.res.copy_from_slice(&self.r);
            // Nonlinear bodies: the operator is linearised here from now on (Newton).
            self.coupled.base.copy_from_slice(u);
            // Its elastic elements are marked when the operator is first applied there.
            self.coupled.marked = None;
        }
        Ok(pb.measure(&self.r, &self.fi, &self.fe))
    }

    /// out = A y: the coupled operator on a vector of the free variables (its expansion to
    /// all displacements left in `pu`).
    fn coupled_apply<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        s: &CgSettings,
        links: &[FrictionLink],
        which: Which,
        linear: bool,
    ) -> Result<(), SolveFailure> {
        let comm = pb.comm;
        let work = &mut self.coupled;
        let (y, out) = match which {
            Which::P => (&work.ph, &mut work.v),
            Which::S => (&work.sh, &mut work.t),
        };
        self.pu.copy_from_slice(y);
        pb.cons.expand(comm, &mut self.pu);
        pb.asm.mesh.exchange(comm, &mut self.pu);
        if linear {
            agree(comm, pb.asm.internal_force(&self.pu, out))?;
            crate::springs::add_action(pb.springs, &self.pu, out);
        } else {
            // The tangent at the linearisation point by a forward difference of the
            // internal forces of the elements that are not elastic there, the elastic
            // matrices' product for those that are, and the springs' K p (they are
            // linear; the loads do not follow the body).
            let pmax = max_abs(comm, &self.pu, pb.owned()).max(f64::MIN_POSITIVE);
            let eps = 1e-7 * s.length_scale / pmax;
            let marked = match work.marked {
                Some(m) => m,
                None => {
                    let m = pb
                        .asm
                        .mark_elastic(&work.base, &mut self.elastic, &mut work.marks);
                    let m = comm::sum_u64(comm, m as u64);
                    if m > 0 {
                        work.base_force.resize(work.base.len(), [0.0; 3]);
                        let elastic = Elastic {
                            matrices: &self.elastic,
                            marks: &work.marks,
                        };
                        let r = pb
                            .asm
                            .kernel_force(&work.base, elastic, &mut work.base_force);
                        agree(comm, r)?;
                    }
                    work.marked = Some(m);
                    m
                }
            };
            if marked == 0 {
                // No element elastic at the linearisation point on any rank: the forward
                // difference of the whole force.
                for a in 0..self.pu.len() {
                    for i in 0..3 {
                        self.trial[a][i] = work.base[a][i] + eps * self.pu[a][i];
                    }
                }
                pb.forces(&self.trial, &mut self.fi_trial, &mut self.fe_trial)?;
                for a in 0..self.pu.len() {
                    for i in 0..3 {
                        out[a][i] = (self.fi_trial[a][i] - self.fi[a][i]) / eps;
                    }
                }
            } else {
                let elastic = Elastic {
                    matrices: &self.elastic,
                    marks: &work.marks,
                };
                let r = pb.asm.forward_difference(
                    &work.base,
                    &self.pu,
                    eps,
                    &work.base_force,
                    elastic,
                    out,
                );
                agree(comm, r)?;
                crate::springs::add_action(pb.springs, &self.pu, out);
            }
        }
        self.q.copy_from_slice(out);
        work.mult.clear();
        work.mult.resize(pb.cons.num_rows(), 0.0);
        pb.cons.reduce(comm, &mut self.q, Some(&mut work.mult));
        normals(comm, links, &work.mult, false, &mut work.normal);
        // A p = T^T (K p - dF), dF the friction's change: mu dN d with dN = -N(K p).
        for (x, l) in work.normal.iter_mut().zip(links) {
            *x = if x.is_nan() { 0.0 } else { l.mu * *x };
        }
        spread(links, &work.normal, out);
        pb.cons.reduce(comm, out, None);
        Ok(())
    }

    /// M^-1 applied to `p` (into `ph`) or `s` (into `sh`).
    fn coupled_precondition<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &mut [Vec3],
        s: &CgSettings,
        which: Which,
        linear: bool,
    ) -> Result<(), SolveFailure> {
        match which {
            Which::P => self.r.copy_from_slice(&self.coupled.p),
            Which::S => self.r.copy_from_slice(&self.coupled.s),
        }
        self.apply_preconditioner(pb, u, linear, s)?;
        match which {
            Which::P => self.coupled.ph.copy_from_slice(&self.z),
            Which::S => self.coupled.sh.copy_from_slice(&self.z),
        }
        Ok(())
    }

    /// BiCGStab's start: the work vectors, the true residual and its gauge (with the outcome
    /// when it has converged already), the preconditioners set up.
    fn bicgstab_start<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &mut [Vec3],
        s: &CgSettings,
        links: &[FrictionLink],
        linear: bool,
    ) -> Result<(Gauge, Option<ModelOutcome>), SolveFailure> {
        agree_alloc(pb.comm, self.coupled.ensure(u.len()))?;
        let roundoff = s.stiffness_floor * 1e3 * f64::EPSILON / s.tolerance;
        let mut g = Gauge {
            rnorm: 0.0,
            refv: 0.0,
            floor: s.reference_floor.max(roundoff),
            tolerance: s.tolerance,
        };
        if let Some(o) = self.true_residual(pb, u, links, &mut g, 0)? {
            return Ok((g, Some(o)));
        }
        if !g.rnorm.is_finite() {
            return Err(SolveFailure::NonFinite { iterations: 0 });
        }
        self.coupled.base_rnorm = g.rnorm;
        self.precondition(pb, u)?;
        self.setup_coarse(pb, u, linear, s)?;
        self.setup_multilevel(pb, u, linear, s)?;
        if !linear {
            self.refresh_full_tangent(pb, u, s)?;
        }
        Ok((g, None))
    }

    /// Right-preconditioned BiCGStab on the coupled problem; None on a breakdown or when
    /// the iteration limit is reached (the caller solves plainly instead).
    fn bicgstab<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &mut [Vec3],
        s: &CgSettings,
        links: &[FrictionLink],
        linear: bool,
    ) -> Result<Option<ModelOutcome>, SolveFailure> {
        let (comm, n, nl) = (pb.comm, pb.owned(), u.len());
        let (mut g, converged) = self.bicgstab_start(pb, u, s, links, linear)?;
        if converged.is_some() {
            return Ok(converged);
        }
        let initial = g.rnorm;
        let mut fresh = true;
        let (mut rho, mut alpha, mut omega): (f64, f64, f64) = (1.0, 1.0, 1.0);
        for it in 1..=s.max_iterations {
            if self.ml_standby && it == super::SWITCH_AFTER {
                self.switch_to_multilevel(pb, u, linear, s)?;
            }
            let w = &mut self.coupled;
            if fresh {
                w.rhat.copy_from_slice(&w.res);
                w.p.iter_mut().for_each(|x| *x = [0.0; 3]);
                w.v.iter_mut().for_each(|x| *x = [0.0; 3]);
                (rho, alpha, omega) = (1.0, 1.0, 1.0);
                fresh = false;
            }
            let rho_new = comm::dot(comm, &w.rhat, &w.res, n);
            if !(rho_new.abs() > 0.0) || !(omega.abs() > 0.0) {
                return Ok(None);
            }
            let beta = (rho_new / rho) * (alpha / omega);
            for a in 0..nl {
                for i in 0..3 {
                    w.p[a][i] = w.res[a][i] + beta * (w.p[a][i] - omega * w.v[a][i]);
                }
            }
            self.coupled_precondition(pb, u, s, Which::P, linear)?;
            self.coupled_apply(pb, s, links, Which::P, linear)?;
            let w = &mut self.coupled;
            let rv = comm::dot(comm, &w.rhat, &w.v, n);
            if !(rv.abs() > 0.0) {
                return Ok(None);
            }
            alpha = rho_new / rv;
            for a in 0..nl {
                for i in 0..3 {
                    u[a][i] += alpha * self.pu[a][i];
                    w.s[a][i] = w.res[a][i] - alpha * w.v[a][i];
                }
            }
            let snorm = comm::norm(comm, &w.s, n);
            if g.done(snorm) || newton_step_done(linear, snorm, w.base_rnorm) {
                if let Some(o) = self.newton_residual(pb, u, links, &mut g, it, linear)? {
                    return Ok(o);
                }
                fresh = true;
                rho = rho_new;
                continue;
            }
            self.coupled_precondition(pb, u, s, Which::S, linear)?;
            self.coupled_apply(pb, s, links, Which::S, linear)?;
            let w = &mut self.coupled;
            let ts = comm::dot(comm, &w.t, &w.s, n);
            let tt = comm::dot(comm, &w.t, &w.t, n);
            if !(tt > 0.0) {
                return Ok(None);
            }
            omega = ts / tt;
            for a in 0..nl {
                for i in 0..3 {
                    u[a][i] += omega * self.pu[a][i];
                    w.res[a][i] = w.s[a][i] - omega * w.t[a][i];
                }
            }
            rho = rho_new;
            g.rnorm = comm::norm(comm, &w.res, n);
            if !(g.rnorm <= DIVERGED * initial) {
                // Not finite, or grown far beyond where it began: not a solve to go on with.
                return Ok(None);
            }
            if g.done(g.rnorm)
                || it.is_multiple_of(50)
                || newton_step_done(linear, g.rnorm, self.coupled.base_rnorm)
            {
                // The recurrence's residual drifts from the true one: replace it, and
                // start the recurrence again from there (for a nonlinear body, from the
                // tangent at the new point: Newton's next step).
                if let Some(o) = self.newton_residual(pb, u, links, &mut g, it, linear)? {
                    return Ok(o);
                }
                fresh = true;
            }
        }
        Ok(None)
    }

    /// The true residual in place of the recurrence's (see `true_residual`); for a
    /// nonlinear body also the end of a Newton step: Some(None) when the step did not
    /// reduce the residual (the plain solve takes over), Some(outcome) when converged.
    fn newton_residual<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &[Vec3],
        links: &[FrictionLink],
        g: &mut Gauge,
        it: usize,
        linear: bool,
    ) -> Result<Option<Option<ModelOutcome>>, SolveFailure> {
        if let Some(o) = self.true_residual(pb, u, links, g, it)? {
            return Ok(Some(Some(o)));
        }
        if !linear {
            if !(g.rnorm < self.coupled.base_rnorm) {
                return Ok(Some(None));
            }
            self.coupled.base_rnorm = g.rnorm;
        }
        Ok(None)
    }

    /// The true residual in place of the recurrence's, into `g`: the outcome after `it`
    /// iterations when it meets the tolerance.
    fn true_residual<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &[Vec3],
        links: &[FrictionLink],
        g: &mut Gauge,
        it: usize,
    ) -> Result<Option<ModelOutcome>, SolveFailure> {
        let (rnorm, reference) = self.coupled_residual(pb, u, links)?;
        g.rnorm = rnorm;
        g.refv = reference.max(g.floor);
        Ok(g.done(rnorm).then_some(ModelOutcome {
            iterations: it,
            residual: rnorm,
            reference: g.refv,
        }))
    }
}

/// A Newton step ends (nonlinear bodies) when the linearised residual is this fraction of
/// the true residual the step began from.
const NEWTON_FORCING: f64 = 0.1;

fn newton_step_done(linear: bool, rnorm: f64, base: f64) -> bool {
    !linear && rnorm <= NEWTON_FORCING * base
}

/// BiCGStab's residual norm and the reference force it is measured against.
struct Gauge {
    rnorm: f64,
    refv: f64,
    /// Lower bound of the reference (the settings' floor, round-off).
    floor: f64,
    tolerance: f64,
}

impl Gauge {
    fn done(&self, rnorm: f64) -> bool {
        rnorm <= self.tolerance * self.refv
    }
}

#[derive(Clone, Copy)]
enum Which {
    P,
    S,
}
