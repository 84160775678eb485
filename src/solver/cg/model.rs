//! The model problem CG solves (`ModelProblem`: the operator's parts, the constraints, the
//! fixed loads), its settings and outcome, and the residual and the collective agreements
//! every part of the solve shares.

use super::failure::SolveFailure;
use crate::comm::{self, Comm};
use crate::constraints::Constraints;
use crate::math::{matvec, Vec3};
use crate::memory::AllocError;
use crate::mesh::GlobalMesh;
use crate::solver::assembly::{Assembly, ElementError};
use crate::solver::loads::Loads;

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

pub(super) fn agree<C: Comm + ?Sized>(
    comm: &C,
    r: Result<(), ElementError>,
) -> Result<(), SolveFailure> {
    match comm::lowest_error(comm, r.err().map(|e| (e.element as i64, e.to_string()))) {
        None => Ok(()),
        Some(m) => Err(SolveFailure::Element(m)),
    }
}

/// An allocation every rank made: the value, or on every rank the first rank's refusal.
/// Collective.
pub(super) fn agree_alloc<C: Comm + ?Sized, T>(
    comm: &C,
    r: Result<T, AllocError>,
) -> Result<T, SolveFailure> {
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
    pub(super) fn owned(&self) -> usize {
        self.asm.mesh.num_owned_nodes
    }

    /// fi = f_int(u), fe = f_ext(t, u) plus the fixed extra forces.
    pub(super) fn forces(
        &self,
        u: &[Vec3],
        fi: &mut [Vec3],
        fe: &mut [Vec3],
    ) -> Result<(), SolveFailure> {
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
    pub(super) fn measure(&self, r: &[Vec3], fi: &[Vec3], fe: &[Vec3]) -> (f64, f64) {
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
pub(super) fn residual<C: Comm + ?Sized>(
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

pub(super) fn max_abs<C: Comm + ?Sized>(comm: &C, v: &[Vec3], n: usize) -> f64 {
    let m = v[..n].iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    comm::max_f64(comm, m)
}
