//! The step along a search direction: exact curvature and a residual recurrence for linear
//! problems, a finite-difference curvature, step halving and a secant correction for
//! nonlinear ones.

use super::failure::SolveFailure;
use super::iteration::Progress;
use super::model::{agree, max_abs, residual, CgSettings, ModelProblem};
use super::state::Cg;
use crate::comm::{self, Comm};
use crate::math::Vec3;

/// Corrections of a nonlinear step's length at most (each a force evaluation).
const MAX_SECANTS: usize = 4;

impl Cg {
    /// Linear PCG step: exact curvature p.K p, recurrence for the residual, replaced by the
    /// true residual every 50 iterations and before convergence is accepted.
    #[inline]
    pub(super) fn linear_step<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &mut [Vec3],
        rp: f64,
        it: usize,
        s: &CgSettings,
        st: &mut Progress,
    ) -> Result<(), SolveFailure> {
        let (comm, n) = (pb.comm, pb.owned());
        agree(comm, pb.asm.internal_force(&self.pu, &mut self.q))?;
        crate::springs::add_action(pb.springs, &self.pu, &mut self.q);
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
    pub(super) fn nonlinear_step<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
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
        self.trace.force_evaluations += 1;
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
                Err(_) => {
                    self.trace.halvings += 1;
                    alpha *= 0.5
                }
            }
        }
        self.secant_search(pb, u, rp, alpha);
        let (rn, reference) = pb.measure(&self.r, &self.fi, &self.fe);
        st.rnorm = rn;
        st.refv = reference.max(st.floor);
        if it.is_multiple_of(100) {
            self.trace.jacobi_rebuilds += 1;
            self.precondition(pb, u)?;
            st.restart = true;
        }
        Ok(())
    }

    /// The step length's correction along p from `alpha`, where the residual's component
    /// along p is still above a quarter of its start `rp`: a secant through the start and
    /// the probed step, kept within [0.1, 4] of it; then, while the component stays above
    /// a quarter, regula falsi (Illinois) within the bracket once the component changed
    /// sign, or the secant through the last two points (at most 4 times as far) while it
    /// has not; at most `MAX_SECANTS` corrections. Where the tangent at u is the soft one of a yielded region that
    /// unloads along p, the curvature probe overestimates the step by the ratio of the
    /// elastic to the plastic modulus, far more than one secant recovers.
    fn secant_search<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &mut [Vec3],
        rp: f64,
        alpha: f64,
    ) {
        let (comm, n) = (pb.comm, pb.owned());
        // (step, residual along p) at the bracket's ends: the root lies between them once
        // `hi` is set.
        let mut lo = (0.0, rp);
        let mut hi: Option<(f64, f64)> = None;
        let mut prev = lo;
        let mut at = (alpha, comm::dot(comm, &self.r, &self.p, n));
        let mut last_side = 0;
        for k in 0..MAX_SECANTS {
            if !(at.1.abs() > 0.25 * rp) {
                break;
            }
            let side = if at.1 > 0.0 { 1 } else { -1 };
            if side > 0 {
                lo = at;
            } else {
                hi = Some(at);
            }
            // Illinois: the same end replaced twice in a row halves the other end's value.
            if side == last_side {
                match (side, hi.as_mut()) {
                    (1, Some(h)) => h.1 *= 0.5,
                    (1, None) => {}
                    _ => lo.1 *= 0.5,
                }
            }
            last_side = side;
            let next = match hi {
                // The first correction: the secant through the start and the probed step,
                // kept within [0.1, 4] of it.
                _ if k == 0 => (alpha * rp / (rp - at.1)).clamp(0.1 * alpha, 4.0 * alpha),
                Some(h) => lo.0 + (h.0 - lo.0) * lo.1 / (lo.1 - h.1),
                // Still descending: the secant through the last two points, at most 4
                // times as far.
                None if prev.1 > at.1 => {
                    (at.0 + at.1 * (at.0 - prev.0) / (prev.1 - at.1)).min(4.0 * at.0)
                }
                None => 4.0 * at.0,
            };
            prev = at;
            self.trace.secants += 1;
            // try_step leaves the state untouched when the corrected point fails.
            if !next.is_finite() || self.try_step(pb, u, next - at.0).is_err() {
                self.trace.secants_refused += 1;
                break;
            }
            at = (next, comm::dot(comm, &self.r, &self.p, n));
        }
    }

    /// u += alpha p with forces and residual at the new point; on an element failure u is
    /// left unchanged.
    pub(super) fn try_step<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &mut [Vec3],
        alpha: f64,
    ) -> Result<(), SolveFailure> {
        for a in 0..u.len() {
            for i in 0..3 {
                self.trial[a][i] = u[a][i] + alpha * self.pu[a][i];
            }
        }
        self.trace.force_evaluations += 1;
        pb.forces(&self.trial, &mut self.fi_trial, &mut self.fe_trial)?;
        u.copy_from_slice(&self.trial);
        std::mem::swap(&mut self.fi, &mut self.fi_trial);
        std::mem::swap(&mut self.fe, &mut self.fe_trial);
        residual(pb.comm, pb.cons, &self.fi, &self.fe, &mut self.r);
        Ok(())
    }
}
