//! The first model problem as an assembled matrix, for other solvers to be run on the same
//! operator (the bench's PyAMG comparison): the constrained operator T^T K T, the
//! right-hand side and the rigid-body modes, in the unknowns CG iterates on.
//!
//! CG works on three values per node, of which a constrained node uses only its free
//! directions (the range of its projector P). Each node gets an orthonormal basis of that
//! range (the coordinate axes at a free node; Gram-Schmidt of the columns of P at a
//! constrained one); the unknowns are the coefficients in these bases, ordered by global
//! node id, then basis vector. The basis is orthonormal, so CG on the exported system
//! A x = b from x = 0 takes the same steps and residual norms as ours does on the model
//! problem (with the same preconditioner).
//!
//! A is measured by probing the matrix-free operator: nodes are coloured so that no node
//! couples to two nodes of one colour (the multilevel colouring with one node per
//! aggregate, contact ties included), and one application per colour and basis index
//! gives every coupling. One rank only (the probes use the local numbering as global).

use super::exported::{free_basis, ExportState, ModelExport};
use super::failure::SolveFailure;
use super::model::{CgSettings, ModelOutcome, ModelProblem};
use super::state::Cg;
use crate::comm::Comm;
use crate::math::{dot, Vec3};
use crate::precond::multilevel::aggregation::Graph;
use crate::precond::multilevel::colouring::{Colouring, Ties};
use crate::precond::multilevel::sparse::Csr;
use crate::precond::multilevel::FineOperator;

/// A fixed pseudo-random value in [-1, 1) for an index (splitmix64).
fn hash_unit(i: u64) -> f64 {
    let mut z = i.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

/// The unknowns of the owned nodes: per local node its basis, and the index of its first
/// unknown (unknowns ordered by global node id).
struct Unknowns {
    basis: Vec<Vec<Vec3>>,
    first: Vec<usize>,
    node: Vec<u32>,
    direction: Vec<Vec3>,
}

fn unknowns<C: Comm + ?Sized>(pb: &ModelProblem<C>) -> Unknowns {
    let mesh = pb.asm.mesh;
    let owned = mesh.num_owned_nodes;
    let basis: Vec<Vec<Vec3>> = (0..owned)
        .map(|l| free_basis(pb.cons.projector(l)))
        .collect();
    let mut order: Vec<usize> = (0..owned).collect();
    order.sort_by_key(|&l| mesh.node_global[l]);
    let mut first = vec![0usize; owned];
    let (mut node, mut direction) = (Vec::new(), Vec::new());
    for &l in &order {
        first[l] = node.len();
        for d in &basis[l] {
            node.push(mesh.node_global[l]);
            direction.push(*d);
        }
    }
    Unknowns {
        basis,
        first,
        node,
        direction,
    }
}

/// The nodes coloured so that none couples to two of one colour (through an element or a
/// contact tie): the probes of [`assemble`].
fn colour_nodes<C: Comm + ?Sized>(pb: &ModelProblem<C>, n: usize) -> Colouring {
    let mesh = pb.asm.mesh;
    let mut edges = Vec::with_capacity(mesh.elements.len() * 28);
    for e in &mesh.elements {
        for a in 0..e.len() {
            for b in a + 1..e.len() {
                edges.push((
                    mesh.node_global[e[a] as usize],
                    mesh.node_global[e[b] as usize],
                ));
            }
        }
    }
    let graph = Graph::from_edges(n, &edges);
    drop(edges);
    let ties = Ties::gather(pb.comm, pb.cons, mesh);
    let identity: Vec<u32> = (0..n as u32).collect();
    let col = Colouring::new(&graph, &identity, n, &ties);
    drop(graph);
    col
}

/// The matrix of `op` in the unknowns `un`, by one application per colour and basis index.
fn assemble<O: FineOperator<Error = SolveFailure>>(
    un: &Unknowns,
    col: &Colouring,
    local_of: &[usize],
    op: &mut O,
    x: &mut [Vec3],
    y: &mut [Vec3],
) -> Result<Csr, SolveFailure> {
    let m = un.node.len();
    let mut trip: Vec<(u32, u32, f64)> = Vec::new();
    for c in 0..col.num_colours {
        let pairs = col.pairs(c);
        for k in 0..3 {
            x.iter_mut().for_each(|v| *v = [0.0; 3]);
            let mut any = false;
            for (g, &colour) in col.colour.iter().enumerate() {
                let l = local_of[g];
                if colour as usize == c && l != usize::MAX {
                    if let Some(d) = un.basis[l].get(k) {
                        x[l] = *d;
                        any = true;
                    }
                }
            }
            if !any {
                continue;
            }
            op.apply(x, y)?;
            for &(b, a) in pairs {
                let (lb, la) = (local_of[b as usize], local_of[a as usize]);
                if lb == usize::MAX || la == usize::MAX || un.basis[la].len() <= k {
                    continue;
                }
                let col_index = (un.first[la] + k) as u32;
                for (i, d) in un.basis[lb].iter().enumerate() {
                    let v = dot(d, &y[lb]);
                    if v != 0.0 {
                        trip.push(((un.first[lb] + i) as u32, col_index, v));
                    }
                }
            }
        }
    }
    Ok(Csr::from_triplets(m, m, trip))
}

/// max |A x - op(x)| / max |op(x)| for a pseudo-random x in the unknowns.
fn check<O: FineOperator<Error = SolveFailure>>(
    un: &Unknowns,
    a: &Csr,
    op: &mut O,
    x: &mut [Vec3],
    y: &mut [Vec3],
) -> Result<f64, SolveFailure> {
    let m = un.node.len();
    let xs: Vec<f64> = (0..m).map(|i| hash_unit(i as u64)).collect();
    let mut ax = vec![0.0; m];
    a.mul_into(&xs, &mut ax);
    x.iter_mut().for_each(|v| *v = [0.0; 3]);
    for (l, basis) in un.basis.iter().enumerate() {
        for (k, d) in basis.iter().enumerate() {
            for i in 0..3 {
                x[l][i] += xs[un.first[l] + k] * d[i];
            }
        }
    }
    op.apply(x, y)?;
    let (mut diff, mut size) = (0.0f64, 0.0f64);
    for (l, basis) in un.basis.iter().enumerate() {
        for (k, d) in basis.iter().enumerate() {
            let v = dot(d, &y[l]);
            diff = diff.max((v - ax[un.first[l] + k]).abs());
            size = size.max(v.abs());
        }
    }
    Ok(if size > 0.0 { diff / size } else { diff })
}

impl Cg {
    /// Asks for the export of the next model problem that needs a CG iteration.
    pub fn request_export(&mut self) {
        self.export = ExportState::Pending;
    }

    /// An export was asked for and not yet taken.
    pub fn export_pending(&self) -> bool {
        matches!(self.export, ExportState::Pending)
    }

    /// The export once CG finished its model problem (or why there is none), once.
    pub fn take_export(&mut self) -> Option<Result<ModelExport, String>> {
        match std::mem::take(&mut self.export) {
            ExportState::Taken(e) if e.iterations.is_some() || e.failure.is_some() => Some(Ok(*e)),
            ExportState::Refused(why) => Some(Err(why)),
            other => {
                self.export = other;
                None
            }
        }
    }

    /// Assembles the model problem when an export is pending (after the preconditioner's
    /// setup, before the first iteration).
    pub(super) fn capture<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &[Vec3],
        linear: bool,
        s: &CgSettings,
        (residual_start, reference_start): (f64, f64),
    ) -> Result<(), SolveFailure> {
        if !matches!(self.export, ExportState::Pending) {
            return Ok(());
        }
        if pb.comm.size() != 1 {
            self.export = ExportState::Refused(format!(
                "the operator export works on one rank only (this run has {})",
                pb.comm.size()
            ));
            return Ok(());
        }
        if !linear {
            self.export = ExportState::Refused(
                "the operator export needs linear bodies (the operator is otherwise a finite difference)"
                    .into(),
            );
            return Ok(());
        }
        let mesh = pb.asm.mesh;
        let n = mesh.num_nodes();
        let un = unknowns(pb);
        let mut local_of = vec![usize::MAX; n];
        for (l, &g) in mesh.node_global.iter().enumerate() {
            local_of[g as usize] = l;
        }
        let col = colour_nodes(pb, n);
        let mut x = vec![[0.0; 3]; n];
        let mut y = vec![[0.0; 3]; n];
        let mut op = fine_op!(self, pb, u, linear, s);
        let matrix = assemble(&un, &col, &local_of, &mut op, &mut x, &mut y)?;
        let check_error = check(&un, &matrix, &mut op, &mut x, &mut y)?;
        let m = un.node.len();
        let mut rhs = vec![0.0; m];
        let mut centroid = [0.0; 3];
        for x in &mesh.coords {
            for i in 0..3 {
                centroid[i] += x[i] / n as f64;
            }
        }
        let mut modes = vec![[0.0; 6]; m];
        for (l, basis) in un.basis.iter().enumerate() {
            let r = crate::math::sub(&mesh.coords[l], &centroid);
            for (k, d) in basis.iter().enumerate() {
                let i = un.first[l] + k;
                rhs[i] = dot(d, &self.r[l]);
                for axis in 0..3 {
                    let mut e = [0.0; 3];
                    e[axis] = 1.0;
                    modes[i][axis] = d[axis];
                    modes[i][3 + axis] = dot(d, &crate::math::cross(&e, &r));
                }
            }
        }
        let (mut dirichlet_rows, mut contact_rows) = (0, 0);
        for l in 0..mesh.num_owned_nodes {
            for (_, row) in pb.cons.rows(l) {
                match row.kind {
                    crate::constraints::RowKind::Contact { .. } => contact_rows += 1,
                    crate::constraints::RowKind::Dirichlet(_) => dirichlet_rows += 1,
                }
            }
        }
        self.export = ExportState::Taken(Box::new(ModelExport {
            dirichlet_rows,
            contact_rows,
            node: un.node,
            direction: un.direction,
            matrix,
            rhs,
            modes,
            check_error,
            tolerance: s.tolerance,
            reference_start,
            residual_start,
            time: pb.time,
            ..Default::default()
        }));
        Ok(())
    }

    /// Records CG's outcome on the model problem just exported.
    pub(super) fn record_export(&mut self, outcome: &Result<ModelOutcome, SolveFailure>) {
        let ExportState::Taken(e) = &mut self.export else {
            return;
        };
        if e.iterations.is_some() || e.failure.is_some() {
            return;
        }
        match outcome {
            Ok(o) => {
                e.iterations = Some(o.iterations);
                e.residual_end = o.residual;
                e.reference_end = o.reference;
            }
            Err(f) => e.failure = Some(f.to_string()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn free_bases_are_orthonormal_and_span_the_projector() {
        let n = [0.6, 0.0, 0.8];
        let p: crate::math::Mat3 =
            std::array::from_fn(|i| std::array::from_fn(|j| (i == j) as u8 as f64 - n[i] * n[j]));
        for (p, rank) in [(Some(&p), 2), (None, 3)] {
            let b = free_basis(p);
            assert_eq!(b.len(), rank);
            for (i, u) in b.iter().enumerate() {
                for (j, v) in b.iter().enumerate() {
                    let want = (i == j) as u8 as f64;
                    assert!((dot(u, v) - want).abs() < 1e-14);
                }
                if p.is_some() {
                    assert!(dot(u, &n).abs() < 1e-14);
                }
            }
        }
        let fixed = [[0.0; 3]; 3];
        assert!(free_basis(Some(&fixed)).is_empty());
        let x_fixed = [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert_eq!(
            free_basis(Some(&x_fixed)),
            vec![[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
        );
    }
}
