//! The step along a search direction: exact curvature and a residual recurrence for linear
//! problems, a finite-difference curvature, step halving and a secant correction for
//! nonlinear ones.

use super::iteration::Progress;
use super::{agree, max_abs, residual, Cg, CgSettings, Problem, SolveFailure};
use crate::comm::{self, Comm};
use crate::math::Vec3;

impl Cg {
    /// Linear PCG step: exact curvature p.K p, recurrence for the residual, replaced by the
    /// true residual every 50 iterations and before convergence is accepted.
    #[inline]
    pub(super) fn linear_step<C: Comm + ?Sized>(
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
        let s1 = comm::dot(comm, &self.r, &self.p, n);
        if s1.abs() > 0.25 * rp {
            // try_step leaves the state untouched when the corrected point fails.
            let a2 = (alpha * rp / (rp - s1)).clamp(0.1 * alpha, 4.0 * alpha);
            self.trace.secants += 1;
            if self.try_step(pb, u, a2 - alpha).is_err() {
                self.trace.secants_refused += 1;
            }
        }
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

    /// u += alpha p with forces and residual at the new point; on an element failure u is
    /// left unchanged.
    pub(super) fn try_step<C: Comm + ?Sized>(
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
        self.trace.force_evaluations += 1;
        pb.forces(&self.trial, &mut self.fi_trial, &mut self.fe_trial)?;
        u.copy_from_slice(&self.trial);
        std::mem::swap(&mut self.fi, &mut self.fi_trial);
        std::mem::swap(&mut self.fe, &mut self.fe_trial);
        residual(pb.comm, pb.cons, &self.fi, &self.fe, &mut self.r);
        Ok(())
    }
}
