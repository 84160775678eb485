//! The CG iteration of a model problem: the starting residual, the loop, and the search
//! direction (Fletcher-Reeves when linear, Polak-Ribiere+ otherwise).

use super::failure::SolveFailure;
use super::failure::MAX_WIDEN;
use super::full_tangent::{RateWatch, MODEL_START};
use super::model::{residual, CgSettings, ModelOutcome, ModelProblem, SWITCH_AFTER};
use super::state::Cg;
use crate::comm::{self, Comm};
use crate::math::Vec3;

/// Builds of the full tangent one model problem may make before block Jacobi takes over:
/// a bound on the probing's cost where the factor does not keep up with the tangent (the
/// punch at 80 x 80 rebuilds most in its first increment, where the plastic zone forms;
/// with a bound of 4 Jacobi took over there and the increment took 1593 CG iterations).
const MAX_TANGENT_BUILDS: usize = 12;

/// Where a CG solve stands between iterations.
pub(super) struct Progress {
    /// Norm of the residual and the force it is measured against.
    pub(super) rnorm: f64,
    pub(super) refv: f64,
    /// The smallest reference force (a round-off floor).
    pub(super) floor: f64,
    /// r.z of the previous iteration.
    rz_old: f64,
    /// The next direction is the preconditioned residual (beta = 0).
    pub(super) restart: bool,
    /// Linear iterations since the residual was last recomputed from the forces.
    pub(super) since_true: usize,
}

impl Progress {
    #[inline]
    pub(super) fn converged(&self, s: &CgSettings) -> bool {
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
        pb: &ModelProblem<C>,
        u: &mut [Vec3],
        s: &CgSettings,
    ) -> Result<ModelOutcome, SolveFailure> {
        let outcome = self.solve_model(pb, u, s);
        self.trace.end_loop(pb.comm.traffic());
        self.record_export(&outcome);
        outcome
    }

    fn solve_model<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &mut [Vec3],
        s: &CgSettings,
    ) -> Result<ModelOutcome, SolveFailure> {
        let linear = pb.asm.linear && !pb.loads.is_follower();
        if !linear && s.newton {
            return self.solve_newton(pb, u, s);
        }
        let mut st = self.initial_residual(pb, u, s)?;
        if st.converged(s) {
            return Ok(st.outcome(0));
        }
        self.precondition(pb, u)?;
        self.setup_coarse(pb, u, linear, s)?;
        self.setup_multilevel(pb, u, linear, s)?;
        self.capture(pb, u, linear, s, (st.rnorm, st.refv))?;
        self.setup_full_tangent(pb, u, linear, s, MODEL_START)?;
        let mut watch = self.use_tangent.then(|| RateWatch::new(st.rnorm));

        self.trace.start(pb.comm.traffic());
        let mut window_start = st.rnorm;
        let mut widened = 0;
        for it in 1..=s.max_iterations {
            if self.ml_standby && it == SWITCH_AFTER {
                self.switch_to_multilevel(pb, u, linear, s)?;
                st.restart = true;
            }
            self.apply_preconditioner(pb, u, linear, s)?;
            let Some(rp) = self.update_direction(pb, linear, &mut st, u.len()) else {
                if self.tangent.is_some() {
                    // r.z <= 0 (or not finite) above the tolerance: the factor does not
                    // precondition; block Jacobi takes the rest of this model problem.
                    self.drop_full_tangent(&format!("iteration {it}: r.z is not positive"));
                    watch = None;
                    st.restart = true;
                    continue;
                }
                let Some(ml) = self.multilevel.as_mut().filter(|_| !self.ml_standby) else {
                    // Block Jacobi is positive definite on the free directions: the
                    // preconditioned residual vanished, the residual is at round-off level.
                    return Ok(st.outcome(it - 1));
                };
                // r.z <= 0 for a residual above the tolerance: the cycle is not positive
                // definite, never a converged solve. Its fine smoother's bound fell short
                // of the spectrum; widened, the smoother is a contraction again.
                if ml.smooths_fine() && widened < MAX_WIDEN {
                    ml.widen_smoother();
                    self.ml_smoother_fp = None;
                    widened += 1;
                    st.restart = true;
                    continue;
                }
                return Err(SolveFailure::IndefinitePreconditioner { iterations: it });
            };
            if linear {
                self.linear_step(pb, u, rp, it, s, &mut st)?;
            } else {
                self.nonlinear_step(pb, u, rp, it, s, &mut st)?;
            }
            if !st.rnorm.is_finite() {
                return Err(SolveFailure::NonFinite { iterations: it });
            }
            self.trace.record(it, st.rnorm, &mut window_start);
            if st.converged(s) {
                return Ok(st.outcome(it));
            }
            if let Some(why) = watch.as_mut().and_then(|w| w.stale(st.rnorm)) {
                if self.tangent_builds_here >= MAX_TANGENT_BUILDS {
                    self.drop_full_tangent(&format!(
                        "iteration {it}: {why}, after {MAX_TANGENT_BUILDS} builds in this model problem"
                    ));
                    watch = None;
                } else {
                    self.setup_full_tangent(pb, u, linear, s, &format!("iteration {it}: {why}"))?;
                }
                st.restart = true;
            }
        }
        Err(SolveFailure::NotConverged {
            iterations: s.max_iterations,
            residual: st.rnorm,
            reference: st.refv,
        })
    }

    /// Forces and residual at the starting point.
    pub(super) fn initial_residual<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
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

    /// The new search direction p (Fletcher-Reeves when linear, Polak-Ribiere+ otherwise)
    /// and its expansion to all displacements in `pu`; returns r.p, or None when the
    /// preconditioned residual vanished.
    #[inline]
    fn update_direction<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
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
            let b = (rz - zr_old) / st.rz_old;
            if !(b > 0.0) {
                self.trace.restarts_pr += 1;
            }
            b.max(0.0)
        };
        for a in 0..nl {
            for i in 0..3 {
                self.p[a][i] = self.z[a][i] + beta * self.p[a][i];
            }
        }
        let mut rp = comm::dot(comm, &self.r, &self.p, n);
        if !(rp > 0.0) {
            self.trace.restarts_descent += 1;
            self.p.copy_from_slice(&self.z);
            rp = rz;
        }
        if !(rp > 0.0) {
            return None;
        }
        st.restart = false;
        st.rz_old = rz;
        if !linear {
            self.r_old.copy_from_slice(&self.r);
        }
        // The search direction in the free variables, mapped to all displacements.
        self.pu.copy_from_slice(&self.p);
        pb.cons.expand(comm, &mut self.pu);
        pb.asm.mesh.exchange(comm, &mut self.pu);
        Some(rp)
    }
}
