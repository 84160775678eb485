//! A model problem without equilibrium: a body its supports (prescribed directions and
//! contact ties) leave free along a rigid-body motion its loads push along (a cylinder
//! pressed onto a block by a load, every tie released after the first model problem). Its
//! operator is singular there and the residual's component along the motion is out of its
//! range: no iterate removes it, and CG wanders until its iteration limit (20000
//! iterations by default, minutes on a mesh of a few thousand nodes) before the step is
//! cut back. Found before the loop instead, from the starting residual.
//!
//! The free motions m_i (rigid-body fields m(x) = t + w x (x - c) / L in the body's frame)
//! satisfy every row, so in the free variables they are m_i at each node projected onto
//! its free directions (`Constraints::projector`), and they are in the operator's null
//! space: exactly for small kinematics (a rigid motion strains nothing), and for
//! translations under large kinematics too (only those are given there). The part of the
//! residual r in their span has the norm sqrt(b^T G^-1 b), b_i = m_i . r and G_ij =
//! m_i . m_j over the body's nodes: a floor under CG's residual norm.

use super::failure::SolveFailure;
use super::model::{CgSettings, ModelProblem};
use super::state::Cg;
use crate::comm::{self, Comm, ExactSum};
use crate::math::{cross, matvec, Vec3};
use nalgebra::{DMatrix, DVector};

/// How far the floor must stand above the tolerance for the model problem to be judged
/// without equilibrium. CG's test is |r| <= tolerance x reference force, with the
/// reference recomputed as the iterate moves (the reactions at the supports); a motion
/// along the free directions strains nothing and adds no reaction, so the reference the
/// other components reach is the converged state's. A factor of 1000 leaves room for the
/// reactions to grow that much beyond the starting forces; a body pushed off its supports
/// leaves a floor of the order of its load (the Hertz cylinder: 1e10 times the tolerance).
const MARGIN: f64 = 1e3;

/// The rigid-body motions the supports of a model problem leave free on one body.
#[derive(Clone, Debug)]
pub struct FreeBody {
    /// The body's index in the mesh.
    pub body: usize,
    /// The body's frame: its centre and size (lever arms are (x - centre) / size).
    pub centre: Vec3,
    pub size: f64,
    /// The free motions as (t, w), orthonormal.
    pub motions: Vec<[f64; 6]>,
    /// The diagnosis: which motions are free (`support::unheld_bodies`' line).
    pub line: String,
}

impl FreeBody {
    fn motion(&self, i: usize, x: &Vec3) -> Vec3 {
        let m = &self.motions[i];
        let arm = [0, 1, 2].map(|k| (x[k] - self.centre[k]) / self.size);
        let w = cross(&[m[3], m[4], m[5]], &arm);
        [m[0] + w[0], m[1] + w[1], m[2] + w[2]]
    }
}

impl Cg {
    /// Fails with `NoEquilibrium` when the residual at `u` has a component along the free
    /// motions of `free` that CG cannot remove (above MARGIN times its tolerance); `Ok`
    /// otherwise. Reference coordinates place the motions (the bodies' frames are
    /// reference ones). Collective; the same on every rank (exact sums).
    pub fn check_equilibrium<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &[Vec3],
        s: &CgSettings,
        free: &[FreeBody],
    ) -> Result<(), SolveFailure> {
        if free.is_empty() {
            return Ok(());
        }
        let st = self.initial_residual(pb, u, s)?;
        let mesh = pb.asm.mesh;
        let owned = mesh.num_owned_nodes;
        for fb in free {
            let k = fb.motions.len();
            let (mut b, mut g) = (vec![ExactSum::new(); k], vec![ExactSum::new(); k * k]);
            for a in 0..owned {
                let node = mesh.node_global[a] as usize;
                if pb.global.body_of_node(node) != Some(fb.body) {
                    continue;
                }
                let x = &mesh.coords[a];
                let m: Vec<Vec3> = (0..k)
                    .map(|i| {
                        let v = fb.motion(i, x);
                        pb.cons.projector(a).map_or(v, |p| matvec(p, &v))
                    })
                    .collect();
                for i in 0..k {
                    for c in 0..3 {
                        b[i].add_product(m[i][c], self.r[a][c]);
                        for j in 0..k {
                            g[i * k + j].add_product(m[i][c], m[j][c]);
                        }
                    }
                }
            }
            let b = DVector::from_iterator(k, b.into_iter().map(|v| comm::global_sum(pb.comm, v)));
            let g =
                DMatrix::from_iterator(k, k, g.into_iter().map(|v| comm::global_sum(pb.comm, v)));
            let Some(chol) = g.cholesky() else {
                continue;
            };
            let floor = b.dot(&chol.solve(&b)).max(0.0).sqrt();
            if floor > MARGIN * s.tolerance * st.refv {
                return Err(SolveFailure::NoEquilibrium(format!(
                    "{}; the residual keeps {floor:.3e} along those motions, which no displacement of the body removes (CG's tolerance is {:.3e}): its loads push it where nothing holds it",
                    fb.line,
                    s.tolerance * st.refv
                )));
            }
        }
        Ok(())
    }
}
