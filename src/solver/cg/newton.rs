//! Newton-Krylov for the model problem of plastic bodies: at the current iterate u the
//! consistent tangent K_t(u) (applied as a finite difference of the internal forces about
//! u, with the integration points' history held at the increment's start, which is the
//! tangent of the discrete return map) is solved for the Newton direction by linear PCG to
//! a relative tolerance eta (Eisenstat and Walker's second choice), with the
//! preconditioner built on that tangent; an energy line search along the direction (the
//! directional residual du.r(u + a du) driven towards zero, Matthies and Strang) gives the
//! step. The preconditioner follows the tangent: block Jacobi from the tangent's diagonal
//! blocks at every Newton step; the coarse space or multilevel hierarchy at the first
//! Newton step of an increment and again whenever an inner solve converges at less than
//! half the rate per iteration the first solve after its build did (the rule `-vv` logs).
//!
//! Why: the nonlinear CG's directions lose conjugacy wherever a point yields or unloads
//! within a step (the tangent jumps), so it restarts and crawls as the plastic zone
//! spreads; Newton's linear inner solves see one fixed tangent each and converge at the
//! rate of the preconditioned linear problem (docs/plasticity-solve.md has the measurements).

use super::failure::SolveFailure;
use super::model::{max_abs, CgSettings, ModelOutcome, ModelProblem, SWITCH_AFTER};
use super::state::Cg;
use crate::comm::{self, Comm};
use crate::math::Vec3;
use crate::precond::multilevel::FineOperator;

/// Newton steps one model problem may take before it counts as not converging.
const MAX_NEWTON: usize = 60;
/// The inner solve's relative tolerance at the first Newton step, and its upper bound.
const ETA_FIRST: f64 = 0.1;
const ETA_MAX: f64 = 0.5;
/// The line search ends when |du.r(u + a du)| is at most this fraction of du.r(u).
const LINE_TOLERANCE: f64 = 0.1;
/// Line-search trials per Newton step (each one force evaluation).
const LINE_TRIALS: usize = 8;
/// A coarse space or hierarchy is rebuilt once an inner solve's convergence rate per
/// iteration falls below this fraction of the first solve's after the build.
const STALE_RATE: f64 = 0.5;

/// What one inner solve did.
struct Inner {
    iterations: usize,
    /// ln(|r_end| / |r_start|) / iterations: the mean convergence rate (negative).
    rate: f64,
}

impl Cg {
    /// Solves the model problem by Newton-Krylov (see the module); `u` satisfies the
    /// constraints on entry.
    pub(super) fn solve_newton<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &mut [Vec3],
        s: &CgSettings,
    ) -> Result<ModelOutcome, SolveFailure> {
        let mut st = self.initial_residual(pb, u, s)?;
        let mut total = 0;
        let mut eta = ETA_FIRST;
        let mut r_prev = st.rnorm;
        // Per Newton step: inner iterations and the residual's reduction (the -vv note).
        let mut steps = Vec::new();
        for newton in 1..=MAX_NEWTON {
            if st.converged(s) {
                break;
            }
            self.precondition(pb, u)?;
            self.setup_coarse(pb, u, false, s)?;
            self.setup_multilevel(pb, u, false, s)?;
            // Eisenstat-Walker: eta from the last reduction, never finer than the tolerance
            // asks for (a tenth of it: the outer residual is the one that must meet it).
            if newton > 1 {
                let ratio = st.rnorm / r_prev;
                let ew = 0.9 * ratio * ratio;
                let floor = 0.9 * eta * eta;
                eta = if floor > 0.1 { ew.max(floor) } else { ew }.min(ETA_MAX);
            }
            let target = (eta * st.rnorm).max(0.1 * s.tolerance * st.refv);
            let budget = s.max_iterations.saturating_sub(total);
            let inner = self.inner_solve(pb, u, s, st.rnorm, target, budget, total)?;
            total += inner.iterations;
            self.judge_rate(&inner);
            r_prev = st.rnorm;
            let (rn, reference) = self.line_search(pb, u)?;
            steps.push(format!("{}:{:.2}", inner.iterations, rn / st.rnorm));
            st.rnorm = rn;
            st.refv = reference.max(st.floor);
            if !st.rnorm.is_finite() {
                return Err(SolveFailure::NonFinite { iterations: total });
            }
            if total >= s.max_iterations && !st.converged(s) {
                break;
            }
        }
        self.add_note(format!(
            "Newton-Krylov: {} steps (inner CG iterations:residual reduction) {}",
            steps.len(),
            steps.join(" ")
        ));
        if st.converged(s) {
            return Ok(ModelOutcome {
                iterations: total,
                residual: st.rnorm,
                reference: st.refv,
            });
        }
        Err(SolveFailure::NotConverged {
            iterations: total,
            residual: st.rnorm,
            reference: st.refv,
        })
    }

    /// Linear PCG on T^T K_t(u) T du = r to |r - A du| <= target or `budget` iterations;
    /// the direction in `self.du`, the outer residual kept in `self.r`. A direction of
    /// non-positive curvature (the finite-difference tangent of a point at the yield
    /// surface can show one) ends the solve with du so far, or z when it came first: either
    /// is a descent direction for the line search.
    #[allow(clippy::too_many_arguments)]
    fn inner_solve<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &mut [Vec3],
        s: &CgSettings,
        rnorm: f64,
        target: f64,
        budget: usize,
        done_before: usize,
    ) -> Result<Inner, SolveFailure> {
        let (comm, n, nl) = (pb.comm, pb.owned(), u.len());
        // The outer residual waits in r_old; r is the inner residual (the preconditioner
        // reads r).
        self.r_old.copy_from_slice(&self.r);
        self.du.iter_mut().for_each(|v| *v = [0.0; 3]);
        let mut rz_old = 0.0;
        let mut restart = true;
        let mut norm = rnorm;
        let mut it = 0;
        while it < budget.max(1) && norm > target {
            if self.ml_standby && done_before + it == SWITCH_AFTER {
                self.switch_to_multilevel(pb, u, false, s)?;
                restart = true;
            }
            self.apply_preconditioner(pb, u, false, s)?;
            let rz = comm::dot(comm, &self.r, &self.z, n);
            if !(rz > 0.0) {
                break;
            }
            let beta = if restart { 0.0 } else { rz / rz_old };
            restart = false;
            for a in 0..nl {
                for i in 0..3 {
                    self.p[a][i] = self.z[a][i] + beta * self.p[a][i];
                }
            }
            self.pu.copy_from_slice(&self.p);
            {
                let mut op = fine_op!(self, pb, u, false, s);
                op.apply(&mut self.pu, &mut self.q)?;
            }
            let pq = comm::dot(comm, &self.p, &self.q, n);
            it += 1;
            if !(pq > 0.0) {
                if it == 1 {
                    self.du.copy_from_slice(&self.z);
                }
                break;
            }
            let alpha = rz / pq;
            for a in 0..nl {
                for i in 0..3 {
                    self.du[a][i] += alpha * self.p[a][i];
                    self.r[a][i] -= alpha * self.q[a][i];
                }
            }
            rz_old = rz;
            norm = comm::norm(comm, &self.r, n);
        }
        self.r.copy_from_slice(&self.r_old);
        let rate = if it > 0 && norm > 0.0 {
            (norm / rnorm).ln() / it as f64
        } else {
            0.0
        };
        Ok(Inner {
            iterations: it,
            rate,
        })
    }

    /// The coarse space or hierarchy goes stale (rebuilt at the next Newton step) when an
    /// inner solve converged at less than STALE_RATE of the rate the first solve after its
    /// build had.
    fn judge_rate(&mut self, inner: &Inner) {
        if self.coarse.is_none() && (self.multilevel.is_none() || self.ml_standby) {
            return;
        }
        if inner.iterations < 5 {
            return;
        }
        match self.built_rate {
            None => self.built_rate = Some(inner.rate),
            Some(built) if inner.rate > STALE_RATE * built => {
                self.coarse_stale = true;
                self.built_rate = None;
                self.add_note(format!(
                    "preconditioner stale: an inner solve converged at {:.3} per iteration (ln of the residual's reduction), against {:.3} after the last build; rebuilt from the current tangent",
                    inner.rate, built
                ));
            }
            Some(_) => {}
        }
    }

    /// The energy line search along du from u (see the module); moves u, the forces and the
    /// residual to the accepted point and returns its (|r|, reference).
    fn line_search<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &mut [Vec3],
    ) -> Result<(f64, f64), SolveFailure> {
        let (comm, n) = (pb.comm, pb.owned());
        let g0 = comm::dot(comm, &self.du, &self.r, n);
        self.pu.copy_from_slice(&self.du);
        pb.cons.expand(comm, &mut self.pu);
        pb.asm.mesh.exchange(comm, &mut self.pu);
        if !(g0 > 0.0) || max_abs(comm, &self.pu, n) == 0.0 {
            return Ok(pb.measure(&self.r, &self.fi, &self.fe));
        }
        // (a, g) where g > 0 (still descending) and where g < 0 (past the minimum).
        let mut below = (0.0, g0);
        let mut above: Option<(f64, f64)> = None;
        let mut at = 0.0;
        let mut a = 1.0;
        let mut last_err = None;
        for _ in 0..LINE_TRIALS {
            match self.try_step(pb, u, a - at) {
                Ok(()) => at = a,
                Err(e) => {
                    // An element inverts at a: the minimum lies before it.
                    last_err = Some(e);
                    a = 0.5 * (below.0 + a);
                    continue;
                }
            }
            let g = comm::dot(comm, &self.du, &self.r, n);
            if g.abs() <= LINE_TOLERANCE * g0 {
                break;
            }
            if g > 0.0 {
                below = (a, g);
            } else {
                above = Some((a, g));
            }
            a = match above {
                // Regula falsi inside the bracket, kept off its ends.
                Some((ah, gh)) => {
                    let (al, gl) = below;
                    let x = al + (ah - al) * gl / (gl - gh);
                    x.clamp(al + 0.1 * (ah - al), ah - 0.1 * (ah - al))
                }
                // Still descending at a: the secant through (0, g0) and (a, g), at most 4a.
                None => (a * g0 / (g0 - g)).clamp(1.5 * a, 4.0 * a),
            };
        }
        if at == 0.0 {
            // Not one point of the line could be evaluated.
            if let Some(e) = last_err {
                return Err(e);
            }
        }
        Ok(pb.measure(&self.r, &self.fi, &self.fe))
    }
}
