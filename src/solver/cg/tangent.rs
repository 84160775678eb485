//! Experiment (issue 46, measurement only): the full tangent preconditioner. The
//! constrained tangent at the model problem's start, assembled by probing the fine
//! operator (a finite difference of the forces for nonlinear bodies) and factored by the
//! sparse Cholesky of the multilevel's coarsest level; one rank only. Switched on by the
//! environment variable `SOLVER_TANGENT_PRECONDITIONER` (its value: rebuild after this
//! many iterations without the rate of the first window, 0 = once per model problem).

use super::export::{assembled, Unknowns};
use super::{Cg, CgSettings, Problem, SolveFailure};
use crate::comm::Comm;
use crate::math::{dot, Vec3};
use crate::solver::multilevel::sparse::Csr;
use crate::solver::multilevel::sparse_cholesky::SparseCholesky;

pub(super) struct TangentFactor {
    un: Unknowns,
    chol: SparseCholesky,
    x: Vec<f64>,
}

/// The experiment's setting, when asked for.
pub(super) fn requested() -> Option<usize> {
    std::env::var("SOLVER_TANGENT_PRECONDITIONER")
        .ok()
        .and_then(|v| v.parse().ok())
}

/// A + theta D, D the tangent's nodal diagonal blocks, theta from
/// `SOLVER_TANGENT_SHIFT` (0 when unset): bounds what the factor makes of the nearly
/// singular modes of a perfectly plastic tangent.
fn shifted<C: Comm + ?Sized>(
    pb: &Problem<C>,
    u: &[Vec3],
    un: &Unknowns,
    a: Csr,
) -> Result<Csr, SolveFailure> {
    let theta: f64 = std::env::var("SOLVER_TANGENT_SHIFT")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0.0);
    if theta == 0.0 {
        return Ok(a);
    }
    if std::env::var_os("SOLVER_TANGENT_SHIFT_ELASTIC").is_some() {
        return elastic_shifted(pb, a, theta);
    }
    let mut blocks = vec![[[0.0; 3]; 3]; u.len()];
    super::agree(pb.comm, pb.asm.diagonal(u, &mut blocks))?;
    let mut t = Vec::with_capacity(a.nnz() + 9 * un.basis.len());
    for i in 0..a.rows {
        let (c, v) = a.row(i);
        for (&j, &x) in c.iter().zip(v) {
            t.push((i as u32, j, x));
        }
    }
    for (l, basis) in un.basis.iter().enumerate() {
        for (i, di) in basis.iter().enumerate() {
            let bd = crate::math::matvec(&blocks[l], di);
            for (k, dk) in basis.iter().enumerate() {
                let (r, c) = (un.first[l] + i, un.first[l] + k);
                t.push((r as u32, c as u32, theta * dot(dk, &bd)));
            }
        }
    }
    Ok(Csr::from_triplets(a.rows, a.cols, t))
}

/// Experiment: rebuild the multilevel hierarchy (and block Jacobi) from the current
/// tangent by the same rule, windows of `SOLVER_ML_RULE` iterations.
pub(super) fn multilevel_rule() -> Option<usize> {
    std::env::var("SOLVER_ML_RULE")
        .ok()
        .and_then(|v| v.parse().ok())
}

/// A + theta K_e, K_e the bodies' small-strain elastic stiffness (the same moduli and
/// formulations), probed in the same unknowns.
fn elastic_shifted<C: Comm + ?Sized>(
    pb: &Problem<C>,
    a: Csr,
    theta: f64,
) -> Result<Csr, SolveFailure> {
    let models: Vec<crate::problem::BodyModel> = pb
        .asm
        .models
        .iter()
        .map(|m| {
            let (lambda, mu) = m.material.lambda_mu();
            crate::problem::BodyModel {
                material: crate::material::Material::LinearElastic(
                    crate::material::LinearElastic { lambda, mu },
                ),
                formulation: m.formulation,
                density: m.density,
            }
        })
        .collect();
    let elastic = crate::solver::assembly::Assembly::new(
        pb.asm.mesh,
        &models,
        &crate::solver::shapes::Plan::default(),
    )
    .map_err(|e| SolveFailure::OutOfMemory(e.to_string()))?;
    let n = pb.asm.mesh.num_nodes();
    let (mut x, mut y) = (vec![[0.0; 3]; n], vec![[0.0; 3]; n]);
    let mut op = ElasticOp { pb, asm: &elastic };
    let (_, ke) = assembled(pb, &mut op, &mut x, &mut y)?;
    let mut t = Vec::with_capacity(a.nnz() + ke.nnz());
    for (m, w) in [(&a, 1.0), (&ke, theta)] {
        for i in 0..m.rows {
            let (c, v) = m.row(i);
            for (&j, &x) in c.iter().zip(v) {
                t.push((i as u32, j, w * x));
            }
        }
    }
    Ok(Csr::from_triplets(a.rows, a.cols, t))
}

/// The constrained elastic operator T^T K_e T x.
struct ElasticOp<'b, 'a, C: Comm + ?Sized> {
    pb: &'b Problem<'a, C>,
    asm: &'b crate::solver::assembly::Assembly<'b>,
}

impl<C: Comm + ?Sized> crate::solver::multilevel::FineOperator for ElasticOp<'_, '_, C> {
    type Error = SolveFailure;
    fn apply(&mut self, x: &mut [Vec3], y: &mut [Vec3]) -> Result<(), SolveFailure> {
        let (pb, comm) = (self.pb, self.pb.comm);
        pb.cons.expand(comm, x);
        pb.asm.mesh.exchange(comm, x);
        super::agree(comm, self.asm.internal_force(x, y))?;
        pb.cons.reduce(comm, y, None);
        Ok(())
    }
}

impl Cg {
    /// Assembles and factors the tangent at `u` (one rank, nonlinear bodies).
    pub(super) fn setup_tangent<C: Comm + ?Sized>(
        &mut self,
        pb: &Problem<C>,
        u: &[Vec3],
        s: &CgSettings,
    ) -> Result<(), SolveFailure> {
        let n = pb.asm.mesh.num_nodes();
        let mut x = vec![[0.0; 3]; n];
        let mut y = vec![[0.0; 3]; n];
        let start = std::time::Instant::now();
        let mut op = fine_op!(self, pb, u, false, s);
        let (un, a) = assembled(pb, &mut op, &mut x, &mut y)?;
        let a = shifted(pb, u, &un, a.symmetric_part())?;
        let mut node_ptr = vec![0usize];
        for i in 1..un.node.len() {
            if un.node[i] != un.node[i - 1] {
                node_ptr.push(i);
            }
        }
        node_ptr.push(un.node.len());
        let (perm, counts) = SparseCholesky::analyse(&a, &node_ptr, usize::MAX / 4)
            .expect("the tangent's factor fits");
        let chol = SparseCholesky::new(&a, perm, &counts);
        self.trace.tangent_builds += 1;
        self.trace.tangent_seconds += start.elapsed().as_secs_f64();
        self.tangent = Some(TangentFactor {
            x: vec![0.0; un.node.len()],
            un,
            chol,
        });
        Ok(())
    }

    /// z = K_t^-1 r through the factor; false when there is none.
    pub(super) fn apply_tangent(&mut self) -> bool {
        let Some(t) = self.tangent.as_mut() else {
            return false;
        };
        for (l, basis) in t.un.basis.iter().enumerate() {
            for (k, d) in basis.iter().enumerate() {
                t.x[t.un.first[l] + k] = dot(d, &self.r[l]);
            }
        }
        t.chol.solve(&mut t.x);
        for (l, basis) in t.un.basis.iter().enumerate() {
            let mut z = [0.0; 3];
            for (k, d) in basis.iter().enumerate() {
                for i in 0..3 {
                    z[i] += t.x[t.un.first[l] + k] * d[i];
                }
            }
            self.z[l] = z;
        }
        true
    }
}

/// The rule that rebuilds the tangent: the residual's reduction over each window of
/// iterations against that of the first window after the last rebuild. Stale when a
/// window reduces less than half as many orders of magnitude per iteration, or less than
/// a factor of 2 in all.
pub(super) struct RateWatch {
    window: usize,
    since: usize,
    start: f64,
    reference: Option<f64>,
}

impl RateWatch {
    pub(super) fn new(window: usize, rnorm: f64) -> Self {
        RateWatch {
            window: window.max(1),
            since: 0,
            start: rnorm,
            reference: None,
        }
    }

    /// Records the residual of one more iteration; true when the preconditioner went stale
    /// (the watch then starts over, from this residual).
    pub(super) fn stale(&mut self, rnorm: f64) -> Option<String> {
        self.since += 1;
        if self.since < self.window {
            return None;
        }
        let orders = (rnorm / self.start).log10();
        let rate = orders / self.window as f64;
        self.since = 0;
        self.start = rnorm;
        let why = match self.reference {
            _ if orders > -std::f64::consts::LOG10_2 => {
                format!(
                    "the residual fell by {:.2} orders in {} iterations",
                    -orders, self.window
                )
            }
            Some(r) if rate > 0.5 * r => format!(
                "{:.3} orders per iteration against {:.3} after the last rebuild",
                -rate, -r
            ),
            Some(_) => return None,
            None => {
                self.reference = Some(rate);
                return None;
            }
        };
        self.reference = None;
        Some(why)
    }
}
