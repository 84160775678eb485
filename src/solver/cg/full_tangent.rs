//! The full tangent preconditioner (`solver.preconditioner = "tangent"`): the constrained
//! tangent T^T K_t(u) T of the model problem at its start, assembled and factored by sparse
//! Cholesky, as Sierra/SM's full tangent preconditioner does inside its nonlinear CG. For a
//! nonlinear body the operator is a finite difference of the internal forces about u with
//! the integration points' history held at the increment's start: the consistent tangent
//! of the discrete return map (probed by a central difference, see `FineOp::central`),
//! which softens by orders of magnitude where a body yields,
//! while block Jacobi or an aggregation hierarchy measured on it keep the elastic
//! structure of the operator. Rebuilt at every model problem's start and when CG's
//! convergence rate shows it went stale (`RateWatch`), logged at -vv.
//!
//! Assembled by probing: the nodes of the whole mesh are coloured so that no node couples
//! to two nodes of one colour (contact ties included, as for the multilevel measurement),
//! and one operator application per colour and basis index gives every coupling; each rank
//! measures its owned rows, every rank gathers all of them in global unknown order
//! (nodes by global id, then each node's free basis) and factors the same matrix (its
//! symmetric part; a pivot below a hundredth of its diagonal entry is raised to that, so
//! the factor stays positive definite where the tangent is singular along a mechanism),
//! so the factor and every solve are bitwise the same on any number of ranks. Every rank
//! holds the whole factor: meant for the meshes one machine factors.

use super::exported::free_basis;
use super::failure::SolveFailure;
use super::model::ModelProblem;
use crate::comm::Comm;
use crate::math::{dot, Vec3};
use crate::precond::multilevel::colouring::{Colouring, NodeAggregates, Ties};
use crate::precond::multilevel::sparse::Csr;
use crate::precond::multilevel::sparse_cholesky::SparseCholesky;
use crate::precond::multilevel::supernodal::Factor;
use crate::precond::multilevel::FineOperator;

/// Free directions of a node (unit vectors) that differ by less than this are the same
/// unknowns for the factor (`FullTangent::fits`).
const BASIS_ROUNDOFF: f64 = 1e-9;

/// The factored tangent and how to map nodal vectors to its unknowns.
pub(super) struct FullTangent {
    /// The first unknown of every global node (len: nodes + 1).
    first: Vec<usize>,
    /// The free basis of every owned local node.
    basis: Vec<Vec<Vec3>>,
    chol: Factor,
    /// The global right-hand side and solution.
    x: Vec<f64>,
    /// Factor entries, for the log.
    pub(super) nnz: usize,
    /// Seconds spent colouring, probing, ordering and factoring, for the log.
    pub(super) seconds: [f64; 4],
    pub(super) unknowns: usize,
}

impl FullTangent {
    /// Whether this rank's owned nodes have the free directions the factor was built with
    /// (to round-off: a contact normal recomputed as its node slides along a flat face
    /// differs in its last bits).
    pub(super) fn fits<C: Comm + ?Sized>(&self, pb: &ModelProblem<C>) -> bool {
        let near = |a: &[Vec3], b: &[Vec3]| {
            a.len() == b.len()
                && a.iter().zip(b).all(|(x, y)| {
                    let d = [x[0] - y[0], x[1] - y[1], x[2] - y[2]];
                    dot(&d, &d) <= BASIS_ROUNDOFF * BASIS_ROUNDOFF
                })
        };
        self.basis.len() == pb.asm.mesh.num_owned_nodes
            && self
                .basis
                .iter()
                .enumerate()
                .all(|(l, b)| near(&free_basis(pb.cons.projector(l)), b))
    }

    /// Assembles T^T K T by probing `op` and factors it (collective); Ok(Err(entries)) when
    /// the factor would hold more than MAX_FACTOR_ENTRIES (the same on every rank: every
    /// rank analyses the same matrix).
    pub(super) fn build<C: Comm + ?Sized, O: FineOperator<Error = SolveFailure>>(
        pb: &ModelProblem<C>,
        op: &mut O,
        order: &mut Option<Order>,
        colours: &mut Colours,
    ) -> Result<Result<Self, usize>, SolveFailure> {
        let comm = pb.comm;
        let mesh = pb.asm.mesh;
        let global = pb.global;
        let n = global.num_nodes();
        let owned = mesh.num_owned_nodes;
        let basis: Vec<Vec<Vec3>> = (0..owned)
            .map(|l| free_basis(pb.cons.projector(l)))
            .collect();
        // Every node's number of free directions, summed exactly over the ranks (each node
        // is owned by one).
        let mut count = vec![0i64; n];
        for (l, b) in basis.iter().enumerate() {
            count[mesh.node_global[l] as usize] = b.len() as i64;
        }
        comm.sum_i64(&mut count);
        let mut first = vec![0usize; n + 1];
        for g in 0..n {
            first[g + 1] = first[g] + count[g] as usize;
        }
        let m = first[n];
        let mut owned_of = vec![usize::MAX; n];
        for l in 0..owned {
            owned_of[mesh.node_global[l] as usize] = l;
        }
        let clock = std::time::Instant::now();
        let col = colours.ensure(pb, n);
        let coloured = clock.elapsed().as_secs_f64();
        let nl = mesh.num_nodes();
        let (mut x, mut y) = (vec![[0.0; 3]; nl], vec![[0.0; 3]; nl]);
        // Triplets (row, column, value) of the owned rows, as f64 for the gather.
        let mut mine: Vec<f64> =
            Vec::with_capacity(3 * owned_entries(col, &owned_of, &basis, &count));
        for c in 0..col.num_colours {
            for k in 0..3 {
                x.iter_mut().for_each(|v| *v = [0.0; 3]);
                for (l, b) in basis.iter().enumerate() {
                    if col.colour[mesh.node_global[l] as usize] as usize == c {
                        if let Some(d) = b.get(k) {
                            x[l] = *d;
                        }
                    }
                }
                // Every rank applies the operator (collective), probe empty or not.
                let any = (0..n).any(|g| col.colour[g] as usize == c && count[g] as usize > k);
                if !any {
                    continue;
                }
                op.apply(&mut x, &mut y)?;
                for &(row_node, col_node) in col.pairs(c) {
                    let lb = owned_of[row_node as usize];
                    if lb == usize::MAX || count[col_node as usize] as usize <= k {
                        continue;
                    }
                    let j = first[col_node as usize] + k;
                    for (i, d) in basis[lb].iter().enumerate() {
                        // Kept when exactly zero too: the pattern is the mesh's and the
                        // ties', the same from build to build (`Order`).
                        let v = dot(d, &y[lb]);
                        mine.extend([(first[row_node as usize] + i) as f64, j as f64, v]);
                    }
                }
            }
        }
        // Every rank's triplets in rank order, held once: this rank's own go once gathered
        // (held as well, and the gather split into one list per rank, a rank held 60
        // bytes an entry here where one rank holds 40).
        let all = if comm.size() == 1 {
            mine
        } else {
            let (all, _) = comm.all_gather_f64_flat(&mine);
            drop(mine);
            all
        };
        let mut trip = Vec::with_capacity(all.len() / 3);
        for t in all.chunks_exact(3) {
            trip.push((t[0] as u32, t[1] as u32, t[2]));
        }
        drop(all);
        let a = Csr::from_triplets(m, m, trip).into_symmetric_part();
        let probed = clock.elapsed().as_secs_f64();
        let node_ptr: Vec<usize> = {
            let mut p: Vec<usize> = (0..n).filter(|&g| count[g] > 0).map(|g| first[g]).collect();
            p.push(m);
            p
        };
        let Some(o) = Order::ensure(order, &a, node_ptr) else {
            return Ok(Err(MAX_FACTOR_ENTRIES));
        };
        let analysed = clock.elapsed().as_secs_f64();
        let chol = Factor::new(&a, o.perm.clone(), &o.counts, PIVOT_FLOOR);
        let factored = clock.elapsed().as_secs_f64();
        Ok(Ok(FullTangent {
            seconds: [
                coloured,
                probed - coloured,
                analysed - probed,
                factored - analysed,
            ],
            first,
            basis,
            nnz: chol.nnz(),
            chol,
            x: vec![0.0; m],
            unknowns: m,
        }))
    }

    /// z = T (T^T K T)^-1 T^T r on the owned nodes (collective).
    pub(super) fn apply<C: Comm + ?Sized>(
        &mut self,
        comm: &C,
        node_global: &[u32],
        r: &[Vec3],
        z: &mut [Vec3],
    ) {
        let mut mine = Vec::new();
        for (l, b) in self.basis.iter().enumerate() {
            let f = self.first[node_global[l] as usize];
            for (k, d) in b.iter().enumerate() {
                mine.push((f + k) as f64);
                mine.push(dot(d, &r[l]));
            }
        }
        self.x.iter_mut().for_each(|v| *v = 0.0);
        if comm.size() == 1 {
            for p in mine.chunks_exact(2) {
                self.x[p[0] as usize] = p[1];
            }
        } else {
            for part in comm.all_gather_f64(&mine) {
                for p in part.chunks_exact(2) {
                    self.x[p[0] as usize] = p[1];
                }
            }
        }
        self.chol.solve(&mut self.x);
        for (l, b) in self.basis.iter().enumerate() {
            let f = self.first[node_global[l] as usize];
            let mut v = [0.0; 3];
            for (k, d) in b.iter().enumerate() {
                for i in 0..3 {
                    v[i] += self.x[f + k] * d[i];
                }
            }
            z[l] = v;
        }
    }
}

/// The entries of the owned rows the probes measure: one per owned row and column unknown
/// of every coupled pair of nodes (`owned_of`: the local node of a global one this rank
/// owns, else usize::MAX; `count`: every node's unknowns).
fn owned_entries(col: &Colouring, owned_of: &[usize], basis: &[Vec<Vec3>], count: &[i64]) -> usize {
    (0..col.num_colours)
        .flat_map(|c| col.pairs(c))
        .map(|&(r, c)| match owned_of[r as usize] {
            usize::MAX => 0,
            lb => basis[lb].len() * count[c as usize] as usize,
        })
        .sum()
}

/// The fill-reducing order of the last build and the pattern it was made for: a build whose
/// assembled tangent has the same pattern (and node blocks) keeps it, as its analysis would
/// give the same order and column counts again. Within a run the pattern changes only with
/// the constraint set.
pub(super) struct Order {
    ptr: Vec<usize>,
    idx: Vec<u32>,
    node_ptr: Vec<usize>,
    perm: Vec<usize>,
    counts: Vec<usize>,
}

impl Order {
    /// The order for `a` (node blocks `node_ptr`): the kept one when it was made for the
    /// same pattern, else a new analysis kept in `slot`; None when the factor would hold
    /// more than MAX_FACTOR_ENTRIES.
    fn ensure<'a>(slot: &'a mut Option<Order>, a: &Csr, node_ptr: Vec<usize>) -> Option<&'a Order> {
        let fits = |o: &Order| o.ptr == a.ptr && o.idx == a.idx && o.node_ptr == node_ptr;
        if !slot.as_ref().is_some_and(fits) {
            let (perm, counts) = SparseCholesky::analyse(a, &node_ptr, MAX_FACTOR_ENTRIES)?;
            *slot = Some(Order {
                ptr: a.ptr.clone(),
                idx: a.idx.clone(),
                node_ptr,
                perm,
                counts,
            });
        }
        slot.as_ref()
    }
}

/// The most entries the factor may hold (12 bytes each, on every rank: 1.5 GB); a larger
/// one is not built and block Jacobi preconditions instead, which the log says.
const MAX_FACTOR_ENTRIES: usize = 1 << 27;

/// A pivot of the factor is at least this fraction of its diagonal entry (a modified
/// Cholesky): where the finite-difference tangent is indefinite (points on the kink of the
/// return map) the factor stays positive definite.
const PIVOT_FLOOR: f64 = 1e-2;

/// The colouring of the whole mesh's nodes (one node per aggregate) with the tie rows of
/// every rank, the same on any number of ranks: a build whose constraint set ties the same
/// pairs of nodes keeps the last one (the colouring is a function of the mesh and the
/// ties).
#[derive(Default)]
pub(super) struct Colours {
    last: Option<(Ties, Colouring)>,
}

impl Colours {
    /// The colouring for the ties of `pb` (collective: the ties are gathered).
    fn ensure<C: Comm + ?Sized>(&mut self, pb: &ModelProblem<C>, n: usize) -> &Colouring {
        let ties = Ties::gather(pb.comm, pb.cons, pb.asm.mesh);
        let kept = matches!(&self.last, Some((t, _)) if *t == ties);
        if !kept {
            // Every node its own aggregate: the node graph's colouring, from the ranks'
            // local meshes (`Colouring::of_ranks`).
            let mesh = pb.asm.mesh;
            let identity = NodeAggregates::gather(pb.comm, mesh, &mesh.node_global, &ties);
            let colouring = Colouring::of_ranks(pb.comm, mesh, &identity, n, &ties);
            self.last = Some((ties, colouring));
        }
        match &self.last {
            Some((_, c)) => c,
            None => unreachable!("a colouring was just made"),
        }
    }
}

/// The rule that rebuilds the tangent within a model problem: the residual's reduction over
/// each window of iterations against the first window's after the build. Stale when a
/// window reduces less than half as many orders of magnitude per iteration as that one, or
/// less than a factor of 2 in all.
pub(super) struct RateWatch {
    since: usize,
    start: f64,
    reference: Option<f64>,
}

/// Iterations per window of the rule.
const WINDOW: usize = 10;

impl RateWatch {
    pub(super) fn new(rnorm: f64) -> Self {
        RateWatch {
            since: 0,
            start: rnorm,
            reference: None,
        }
    }

    /// Records one more iteration's residual; the reason when the factor went stale (the
    /// watch then starts over from this residual).
    pub(super) fn stale(&mut self, rnorm: f64) -> Option<String> {
        self.since += 1;
        if self.since < WINDOW {
            return None;
        }
        let orders = (rnorm / self.start).log10();
        let rate = orders / WINDOW as f64;
        self.since = 0;
        self.start = rnorm;
        let why = match self.reference {
            _ if orders > -std::f64::consts::LOG10_2 => format!(
                "the residual fell by {:.2} orders in {WINDOW} iterations",
                -orders
            ),
            Some(r) if rate > 0.5 * r => format!(
                "{:.3} orders per iteration against {:.3} after the build",
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

/// Why a build happens at a model problem's start.
pub(super) const MODEL_START: &str = "model problem start";
