//! Applying the preconditioner: block Jacobi (`precond::jacobi`, from the diagonal tangent
//! blocks) or the multilevel cycle, then the two-level coarse correction; the switch from
//! block Jacobi to multilevel; and the constrained fine operator the multilevel cycle
//! applies.

use super::failure::SolveFailure;
use super::model::{agree, max_abs, CgSettings, ModelProblem, SWITCH_AFTER};
use super::state::Cg;
use crate::comm::Comm;
use crate::math::Vec3;
use crate::precond::jacobi;
use crate::precond::multilevel::FineOperator;
use crate::solver::assembly::{Elastic, Tangents};

impl Cg {
    /// Block Jacobi is not enough here: from now on the multilevel preconditioner.
    pub(super) fn switch_to_multilevel<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &mut [Vec3],
        linear: bool,
        s: &CgSettings,
    ) -> Result<(), SolveFailure> {
        self.ml_standby = false;
        self.ml_switched = true;
        // The multilevel cycle replaces the two-level correction, if any.
        self.coarse = None;
        self.setup_multilevel(pb, u, linear, s)?;
        if let Some(note) = self.rebuild_note.as_mut() {
            *note = format!("switched to the multilevel preconditioner after {SWITCH_AFTER} CG iterations; {note}");
        }
        Ok(())
    }

    /// z = M^-1 r (multilevel or block Jacobi, then the coarse correction).
    #[inline]
    pub(super) fn apply_preconditioner<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &mut [Vec3],
        linear: bool,
        s: &CgSettings,
    ) -> Result<(), SolveFailure> {
        let comm = pb.comm;
        if let Some(t) = self.tangent.as_mut() {
            t.apply(comm, &pb.asm.mesh.node_global, &self.r, &mut self.z);
            for z in &mut self.z[pb.owned()..] {
                *z = [0.0; 3];
            }
            return Ok(());
        }
        if let Some(ml) = self.multilevel.as_mut().filter(|_| !self.ml_standby) {
            let mut op = fine_op!(self, pb, u, linear, s);
            let at = (pb.cons, pb.asm.mesh.coords.as_slice());
            // q is idle until the next direction's product: the cycle's scratch.
            let rq = (self.r.as_slice(), self.q.as_mut_slice());
            ml.apply(comm, at, &self.minv, &mut op, rq, &mut self.z)?;
        } else {
            jacobi::apply(&self.minv[..u.len()], &self.r, &mut self.z);
        }
        if let Some(c) = &self.coarse {
            c.apply(
                comm,
                pb.cons,
                (pb.owned(), &pb.asm.mesh.coords),
                &self.r,
                &mut self.z,
                &mut self.coarse_work,
            );
        }
        Ok(())
    }

    /// Block-Jacobi preconditioner in the constrained space: M = P D P + (I - P) d, with
    /// d a positive scale so M is invertible, then z = P M^-1 P r.
    pub(super) fn precondition<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &[Vec3],
    ) -> Result<(), SolveFailure> {
        // The blocks first, each then replaced by its inverse.
        agree(pb.comm, pb.asm.diagonal(u, &mut self.minv))?;
        crate::springs::add_diagonal(pb.springs, &mut self.minv);
        pb.cons.precondition_blocks(pb.comm, &mut self.minv);
        jacobi::invert_blocks(&mut self.minv[..u.len()]);
        pb.cons.project_inverse_blocks(&mut self.minv);
        Ok(())
    }
}

/// The constrained fine operator for the multilevel preconditioner: T^T (K + K_s) T x with
/// the slipping nodes' springs K_s, exact for linear bodies, a finite difference of the
/// forces at u otherwise.
pub(super) struct FineOp<'b, 'a, C: Comm + ?Sized> {
    pub(super) pb: &'b ModelProblem<'a, C>,
    pub(super) linear: bool,
    pub(super) eps_scale: f64,
    pub(super) u: &'b [Vec3],
    pub(super) fi: &'b [Vec3],
    pub(super) fe: &'b [Vec3],
    pub(super) trial: &'b mut [Vec3],
    pub(super) fi_trial: &'b mut [Vec3],
    pub(super) fe_trial: &'b mut [Vec3],
    /// One flag per local node for `internal_force_sparse`.
    pub(super) nonzero: &'b mut [bool],
    /// Nonlinear bodies: a central difference about u (two force evaluations) instead of
    /// the forward one. At an integration point on the yield surface the forward
    /// difference takes the loading branch for +x and so mixes loading and unloading
    /// responses over the probes; the central one averages the two branches symmetrically
    /// (what the full tangent's factor needs: docs/plasticity-solve.md).
    pub(super) central: bool,
    /// Elements whose central difference is their elastic matrix's product (marked at
    /// this state; the full tangent's probes only).
    pub(super) elastic: Option<Elastic<'b>>,
    /// The consistent tangents of the elements that have one at u (the full tangent's
    /// probes only): their products replace the central difference.
    pub(super) tangents: Option<&'b Tangents>,
}

impl<C: Comm + ?Sized> FineOp<'_, '_, C> {
    /// y = (r(u + eps x) - r(u - eps x)) / (2 eps) for the forces' parts that depend on u:
    /// the elements where x is not zero (`Assembly::internal_force_difference`), the
    /// springs (linear: K x exactly) and follower loads; `trial` holds u + eps x on entry.
    /// The fixed extra forces do not depend on u.
    fn central_difference(
        &mut self,
        x: &[Vec3],
        y: &mut [Vec3],
        eps: f64,
    ) -> Result<(), SolveFailure> {
        let pb = self.pb;
        let r = pb.asm.internal_force_difference(
            self.u,
            x,
            eps,
            y,
            self.nonzero,
            self.elastic,
            self.tangents,
        );
        agree(pb.comm, r)?;
        crate::springs::add_action(pb.springs, x, y);
        if pb.loads.is_follower() {
            let r = pb
                .loads
                .external_force(pb.asm, pb.time, self.trial, self.fe_trial);
            agree(pb.comm, r)?;
            for a in 0..x.len() {
                for i in 0..3 {
                    self.trial[a][i] = self.u[a][i] - eps * x[a][i];
                }
            }
            let r = pb
                .loads
                .external_force(pb.asm, pb.time, self.trial, self.fi_trial);
            agree(pb.comm, r)?;
            for a in 0..x.len() {
                for i in 0..3 {
                    y[a][i] -= (self.fe_trial[a][i] - self.fi_trial[a][i]) / (2.0 * eps);
                }
            }
        }
        Ok(())
    }
}

impl<C: Comm + ?Sized> FineOperator for FineOp<'_, '_, C> {
    type Error = SolveFailure;
    fn apply(&mut self, x: &mut [Vec3], y: &mut [Vec3]) -> Result<(), SolveFailure> {
        let (pb, comm) = (self.pb, self.pb.comm);
        pb.cons.expand(comm, x);
        pb.asm.mesh.exchange(comm, x);
        if self.linear {
            agree(comm, pb.asm.internal_force_sparse(x, y, self.nonzero))?;
            // The slipping nodes' springs are part of the model problem's operator (the
            // nonlinear branch gets them through the forces): without them the cycle would
            // smooth with a diagonal that has them against an operator that has not.
            crate::springs::add_action(pb.springs, x, y);
        } else {
            let owned = pb.owned();
            let eps = 1e-7 * self.eps_scale / max_abs(comm, x, owned).max(f64::MIN_POSITIVE);
            for a in 0..x.len() {
                for i in 0..3 {
                    self.trial[a][i] = self.u[a][i] + eps * x[a][i];
                }
            }
            if self.central {
                self.central_difference(x, y, eps)?;
            } else {
                pb.forces(self.trial, self.fi_trial, self.fe_trial)?;
                for a in 0..x.len() {
                    for i in 0..3 {
                        y[a][i] = ((self.fi_trial[a][i] - self.fe_trial[a][i])
                            - (self.fi[a][i] - self.fe[a][i]))
                            / eps;
                    }
                }
            }
        }
        pb.cons.reduce(comm, y, None);
        Ok(())
    }
}
