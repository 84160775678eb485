//! A multilevel preconditioner for the constrained model problem: smoothed aggregation
//! with the rigid-body modes as near-nullspace.
//!
//! - Fine level: the matrix-free constrained operator T^T K T, smoothed by a Chebyshev
//!   polynomial in D^-1 A (D the nodal 3 x 3 blocks of the block-Jacobi preconditioner).
//! - First coarse level: aggregates of a node and its neighbours on the global node graph
//!   (any mesh), six rigid-body modes each (Q, projected on the free directions of
//!   constrained nodes); Kc = Q^T A Q assembled sparse from one operator application per
//!   colour and mode (aggregates coloured so that no aggregate sees two of one colour,
//!   contact ties and their masters included).
//! - Further levels: algebraic smoothed aggregation of the assembled operators within each
//!   body, relaxed with the inverse node blocks (six modes per coarse node), a dense
//!   Cholesky factor on the coarsest.
//!
//! One application is a symmetric V-cycle (the same polynomial before and after the coarse
//! correction): a fixed symmetric positive definite operator for CG. With degree 0 the
//! fine level is additive instead, z = D^-1 r + Q V(Q^T r), and costs no operator
//! application (used for nonlinear bodies, whose operator is a finite difference).
//!
//! Bitwise the same on any number of ranks: aggregates and colours come from global data;
//! restriction sums each aggregate on one rank in global node order; each rank measures
//! and keeps only its rows of the first coarse operator, from which the levels below are
//! built with every sum in the order the whole operator gives it (`first`), each held as
//! every rank's rows too, down to the coarsest, which every rank builds whole; every rank
//! runs the same cycle, applying its rows of each coarse operator above the coarsest
//! (`Split`: every entry the same row sum whoever computes it); fine-level dot products
//! are exact.

pub mod aggregation;
pub mod around;
pub mod block_rows;
pub mod blocks;
pub mod colouring;
pub mod cycle;
pub mod direct;
mod elimination;
pub mod factor_choice;
pub mod first;
pub mod halo;
pub mod measure;
pub mod op;
pub mod prolongation;
pub mod prolongator;
pub mod size;
pub mod smoother;
pub mod sparse;
pub mod sparse_cholesky;
pub mod split;
pub mod supernodal;
pub mod transfer;
pub mod triple;

use crate::comm::{self, message, Comm};
use crate::constraints::Constraints;
use crate::math::{matvec, Mat3, Vec3};
use crate::mesh::local::LocalMesh;
use crate::mesh::whole::Whole;
use colouring::{Colouring, NodeAggregates, Ties};
use cycle::Hierarchy;
use halo::Halo;
use prolongator::MODES;
use smoother::{hash_value, Chebyshev, Space};
use split::Split;
use transfer::Transfer;

/// Chebyshev degree on the coarse levels.
const COARSE_DEGREE: usize = 2;
/// V-cycles on the first coarse level per application. A V-cycle costs that level
/// 2 degree products (4), each sweep after the first one more: at n = 80 (block on
/// block, 2 ranks) its 35 million entries made the 14 products of three sweeps most of a
/// CG iteration. Two sweeps (9 products) keep the iterations within 1.2 times n = 20's
/// (79, 81, 93, 94 at n = 20, 40, 60, 80, against 79, 79, 89, 92 with three); one sweep
/// (4 products) is faster still at n = 80 (103 iterations, CG loops 26-30 s against
/// 39-40 s with three) but takes 1.29 times n = 20's iterations (80).
const COARSE_SWEEPS: usize = 2;
/// Chebyshev degree on the fine level: each degree costs two operator applications per
/// CG iteration (Hertz x2: 756 CG iterations with degree 1, 720 with 2).
pub const FINE_DEGREE: usize = 1;

/// The fine-level operator: y = T^T A T x on the owned nodes (x may be changed).
pub trait FineOperator {
    type Error;
    fn apply(&mut self, x: &mut [Vec3], y: &mut [Vec3]) -> Result<(), Self::Error>;
}

pub struct Multilevel {
    transfer: Transfer,
    hierarchy: Option<Hierarchy>,
    fine: Option<Chebyshev>,
    /// Chebyshev degree on the fine level; 0: additive fine level.
    degree: usize,
    global_ids: Vec<u32>,
    owned: usize,
    coarse: CoarseVectors,
    /// The fine level's work vectors (r and d are the measurement's probes too): none while
    /// the coarse levels are built, the build's highest memory (65 MB per rank at n = 80).
    /// The operator's input is copied into the caller's scratch vector (`tmp` of `apply`),
    /// one that is idle while the preconditioner runs.
    f: FineVectors,
    origin: Vec3,
    length: f64,
    /// Times the hierarchy was built.
    pub builds: usize,
    /// What the last build made, for the log.
    pub summary: String,
}

/// The fine level as the smoother sees it (flat vectors, three entries per node).
struct Fine<'a, C: Comm + ?Sized, O: FineOperator> {
    comm: &'a C,
    op: &'a mut O,
    minv: &'a [Mat3],
    owned: usize,
    ids: &'a [u32],
    tmp: &'a mut [Vec3],
}

impl<C: Comm + ?Sized, O: FineOperator> Space for Fine<'_, C, O> {
    type Error = O::Error;
    fn apply(&mut self, x: &[f64], y: &mut [f64]) -> Result<(), O::Error> {
        self.tmp.as_flattened_mut().copy_from_slice(x);
        self.op.apply(self.tmp, y.as_chunks_mut::<3>().0)
    }
    fn inv_diag(&self, r: &[f64], z: &mut [f64]) {
        let (r, z) = (r.as_chunks::<3>().0, z.as_chunks_mut::<3>().0);
        for ((z, r), m) in z.iter_mut().zip(r).zip(self.minv) {
            *z = matvec(m, r);
        }
    }
    fn dot(&self, a: &[f64], b: &[f64]) -> f64 {
        comm::dot(
            self.comm,
            a.as_chunks::<3>().0,
            b.as_chunks::<3>().0,
            self.owned,
        )
    }
    fn start(&self, v: &mut [f64]) {
        for (l, x) in v.as_chunks_mut::<3>().0.iter_mut().enumerate() {
            let g = self.ids[l] as u64;
            *x = std::array::from_fn(|i| hash_value(3 * g + i as u64));
        }
    }
}

impl Multilevel {
    /// The fine-level aggregates and transfer, made on rank 0 from the whole mesh
    /// (`whole`) and sent (collective); the operators come with `setup`.
    pub fn new<C: Comm + ?Sized>(
        comm: &C,
        whole: Option<&Whole>,
        mesh: &LocalMesh,
        degree: usize,
    ) -> Self {
        let transfer = Transfer::new(comm, whole, mesh);
        let dim = transfer.dim();
        // The bounding box's centre and diagonal (the near-nullspace's origin and length).
        let (origin, length): ([f64; 3], f64) = message::broadcast(
            comm,
            whole
                .map(|w| {
                    let mut lo = [f64::INFINITY; 3];
                    let mut hi = [f64::NEG_INFINITY; 3];
                    for x in &w.mesh.coords {
                        for i in 0..3 {
                            lo[i] = lo[i].min(x[i]);
                            hi[i] = hi[i].max(x[i]);
                        }
                    }
                    (
                        std::array::from_fn(|i| 0.5 * (lo[i] + hi[i])),
                        w.mesh.bounding_diagonal().max(f64::MIN_POSITIVE),
                    )
                })
                .as_ref(),
        );
        Multilevel {
            hierarchy: None,
            fine: None,
            degree,
            global_ids: mesh.node_global.clone(),
            owned: mesh.num_owned_nodes,
            coarse: CoarseVectors::new(comm, transfer.num_aggregates),
            f: FineVectors::none(),
            origin,
            length,
            builds: 0,
            summary: format!(
                "multilevel: {} fine aggregates ({dim} unknowns)",
                transfer.num_aggregates
            ),
            transfer,
        }
    }

    pub fn is_set_up(&self) -> bool {
        self.hierarchy.is_some()
    }

    pub fn degree(&self) -> usize {
        self.degree
    }

    /// Measures Kc, builds the coarse levels and the fine smoother (collective; `tmp` a
    /// scratch vector of the local nodes, as for `apply`: freed while the coarse levels are
    /// built and given back zeroed).
    #[allow(clippy::too_many_arguments)]
    pub fn setup<C: Comm + ?Sized, O: FineOperator>(
        &mut self,
        comm: &C,
        cons: &Constraints,
        mesh: &LocalMesh,
        minv: &[Mat3],
        op: &mut O,
        linear: bool,
        tmp: &mut Vec<Vec3>,
    ) -> Result<(), O::Error> {
        // The old hierarchy goes first: held through the build, it doubled the peak memory
        // of a rebuild (block on block n = 80: 4761 MiB per rank instead of the estimated
        // 3489). Nothing below uses it; a build that fails leaves none, and the next use
        // builds one.
        self.hierarchy = None;
        crate::memory::guard::give_back_freed();
        let clock = std::time::Instant::now();
        let mut phases = [0.0f64; 4];
        let mut lap =
            |i: usize| phases[i] = clock.elapsed().as_secs_f64() - phases.iter().sum::<f64>();
        let ties = Ties::gather(comm, cons, mesh);
        let local = self.transfer.aggregates.of_local_nodes();
        let aggs = NodeAggregates::gather(comm, mesh, local, &ties);
        let na = self.transfer.num_aggregates;
        // Each rank finds what its owned nodes reach in its local mesh; the colouring of the
        // gathered sets is every rank's (`colouring::reach_of_ranks`).
        let col = Colouring::of_ranks(comm, mesh, &aggs, na, &ties);
        drop(aggs);
        lap(0);
        self.f.ensure_probes(mesh.num_nodes());
        let mut coeff = self.coarse.take_whole(na);
        let buf = measure::Probe {
            v: &mut self.f.r,
            av: &mut self.f.d,
            coeff: &mut coeff,
        };
        let held = first::held(comm, na);
        let kc = measure::measure(
            comm,
            &mut self.transfer,
            &col,
            cons,
            (self.owned, &mesh.coords),
            buf,
            held.clone(),
            |v, av| op.apply(v, av),
        );
        self.coarse.give_back(coeff);
        let kc = kc?;
        lap(1);
        // Only the measurement needs the colours and the ties: not held through the build
        // (42 MB per rank at n = 80).
        let num_colours = col.num_colours;
        drop((col, ties));
        self.f = FineVectors::none();
        let tmp_len = tmp.len();
        *tmp = Vec::new();
        let b = first::Modes::Rigid(self.transfer.nullspace(&self.origin, self.length));
        let body = self.transfer.body.clone();
        let mut h = first::build(comm, kc, held, na, b, body, COARSE_DEGREE, COARSE_SWEEPS);
        let local = (self.transfer.aggregates.of_local_nodes(), self.owned);
        self.coarse.finish(comm, &mut h, self.transfer.dim(), local);
        lap(2);
        *tmp = vec![[0.0; 3]; tmp_len];
        self.f.ensure(mesh.num_nodes(), self.degree);
        self.fine = None;
        if self.degree > 0 && linear {
            self.estimate_smoother(comm, minv, op, tmp)?;
        }
        lap(3);
        self.builds += 1;
        self.summary = format!(
            "multilevel: {} fine aggregates, {} colours, coarse levels of {:?} unknowns ({:?} non-zeros), {}, {}; colouring {:.3} s, measuring ({} operator applications) {:.3} s, coarse levels {:.3} s, fine smoother {:.3} s",
            na,
            num_colours,
            h.sizes,
            h.nonzeros,
            h.describe(),
            match self.fine {
                Some(c) => format!("fine Chebyshev degree {}", c.degree),
                None => "additive fine level".to_string(),
            },
            phases[0],
            num_colours * MODES,
            phases[1],
            phases[2],
            phases[3]
        );
        self.hierarchy = Some(h);
        Ok(())
    }

    /// The fine Chebyshev smoother for the operator and diagonal blocks as they are now
    /// (collective): its bound on the spectrum of D^-1 A is measured again (`tmp` as for
    /// `apply`).
    pub fn estimate_smoother<C: Comm + ?Sized, O: FineOperator>(
        &mut self,
        comm: &C,
        minv: &[Mat3],
        op: &mut O,
        tmp: &mut [Vec3],
    ) -> Result<(), O::Error> {
        // The power iteration's third vector only while it runs: the cycle uses four.
        let mut x = vec![[0.0; 3]; self.f.r.len()];
        let mut f = Fine {
            comm,
            op,
            minv,
            owned: self.owned,
            ids: &self.global_ids,
            tmp,
        };
        self.fine = Some(Chebyshev::estimate(
            &mut f,
            self.degree,
            x.as_flattened_mut(),
            self.f.r.as_flattened_mut(),
            self.f.d.as_flattened_mut(),
        )?);
        Ok(())
    }

    /// Whether the cycle smooths the fine level with Chebyshev (linear bodies): only then
    /// can it lose positive definiteness, when D^-1 A outgrows the smoother's bound.
    pub fn smooths_fine(&self) -> bool {
        self.fine.is_some()
    }

    /// Doubles the fine smoother's bound on the spectrum of D^-1 A: the cycle is positive
    /// definite again once the bound covers the largest eigenvalue (a power iteration's
    /// estimate can miss a mode that lives on a few nodes).
    pub fn widen_smoother(&mut self) {
        if let Some(c) = self.fine.as_mut() {
            c.widen(2.0);
        }
    }

    /// z = M^-1 r on the owned nodes (collective; `x` the local mesh's positions; `tmp` a
    /// scratch vector of the local nodes, overwritten: the copy of the operator's input,
    /// which the operator changes). Requires `setup`.
    #[allow(clippy::too_many_arguments)]
    pub fn apply<C: Comm + ?Sized, O: FineOperator>(
        &mut self,
        comm: &C,
        (cons, x): (&Constraints, &[Vec3]),
        minv: &[Mat3],
        op: &mut O,
        (r, tmp): (&[Vec3], &mut [Vec3]),
        z: &mut [Vec3],
    ) -> Result<(), O::Error> {
        let h = self.hierarchy.as_mut().expect("multilevel set up");
        let owned = self.owned;
        let Some(cheb) = self.fine else {
            for (z, (m, r)) in z.iter_mut().zip(minv.iter().zip(r)) {
                *z = matvec(m, r);
            }
            self.coarse
                .correct(comm, h, &self.transfer, (cons, owned, x), r, z);
            return Ok(());
        };
        let v = &mut self.f;
        let mut f = Fine {
            comm,
            op,
            minv,
            owned,
            ids: &self.global_ids,
            tmp,
        };
        z.iter_mut().for_each(|v| *v = [0.0; 3]);
        v.r.copy_from_slice(r);
        let (zf, rf) = (z.as_flattened_mut(), v.r.as_flattened_mut());
        let (df, tf) = (v.d.as_flattened_mut(), v.t.as_flattened_mut());
        cheb.smooth(&mut f, rf, zf, df, tf)?;
        residual(&mut f, r, zf, rf)?;
        self.coarse
            .correct(comm, h, &self.transfer, (cons, owned, x), &v.r, z);
        let (zf, rf) = (z.as_flattened_mut(), v.r.as_flattened_mut());
        residual(&mut f, r, zf, rf)?;
        let (df, tf) = (v.d.as_flattened_mut(), v.t.as_flattened_mut());
        cheb.smooth(&mut f, rf, zf, df, tf)
    }
}

/// The fine level's work vectors, one entry per local node (or none).
struct FineVectors {
    r: Vec<Vec3>,
    d: Vec<Vec3>,
    /// The Chebyshev iteration's product, for a degree of 2 or more only (degree 1 applies
    /// no operator, and the residual is formed in r).
    t: Vec<Vec3>,
}

impl FineVectors {
    /// For `nodes` nodes and a fine smoother of `degree`.
    fn new(nodes: usize, degree: usize) -> Self {
        let v = |n: usize| vec![[0.0; 3]; n];
        FineVectors {
            r: v(nodes),
            d: v(nodes),
            t: v(if degree > 1 { nodes } else { 0 }),
        }
    }

    fn none() -> Self {
        FineVectors::new(0, 0)
    }

    /// Allocates those that were freed (outside CG: its iterations allocate nothing).
    fn ensure(&mut self, nodes: usize, degree: usize) {
        let t = if degree > 1 { nodes } else { 0 };
        for (v, n) in [(&mut self.r, nodes), (&mut self.d, nodes), (&mut self.t, t)] {
            if v.len() != n {
                *v = vec![[0.0; 3]; n];
            }
        }
    }

    /// The two the measurement's probes use, the third (if any) freed: while the first
    /// coarse level's entries arrive.
    fn ensure_probes(&mut self, nodes: usize) {
        for v in [&mut self.r, &mut self.d] {
            if v.len() != nodes {
                *v = vec![[0.0; 3]; nodes];
            }
        }
        self.t = Vec::new();
    }
}

/// The first coarse level's vectors: the restricted residual `b`, the correction `x`, and
/// the buffers of its products split over the ranks (`Split`: this rank's rows and every
/// rank's, gathered; empty on one rank). On more ranks than one, `b` holds this rank's
/// rows only (`Aggregates::restrict_held`) and the correction is read from the gathered
/// buffer (`Hierarchy::solve_rows`): `x` is empty. Whole, the two were 0.5 MB on every rank
/// at n = 40.
struct CoarseVectors {
    b: Vec<f64>,
    x: Vec<f64>,
    split_rows: Vec<f64>,
    split_all: Vec<f64>,
    /// Aggregates per rank where split (`first::held`).
    per: usize,
    /// Where split: the other ranks' unknowns of the aggregates of this rank's owned
    /// nodes, which the correction's prolongation reads (fetched, not the whole level
    /// gathered: 263 kB a CG iteration per rank at n = 40).
    halo: Option<Halo>,
}

impl CoarseVectors {
    fn new<C: Comm + ?Sized>(comm: &C, aggregates: usize) -> Self {
        let dim = MODES * aggregates;
        if comm.size() == 1 {
            return CoarseVectors {
                b: vec![0.0; dim],
                x: vec![0.0; dim],
                split_rows: Vec::new(),
                split_all: Vec::new(),
                per: aggregates,
                halo: None,
            };
        }
        let rows = first::rows_per_rank(comm, aggregates);
        CoarseVectors {
            b: vec![0.0; MODES * first::held(comm, aggregates).len()],
            x: Vec::new(),
            split_rows: vec![0.0; rows],
            split_all: vec![0.0; rows * comm.size()],
            per: rows / MODES,
            halo: None,
        }
    }

    /// Completes the hierarchy's build (`Hierarchy::finish`) on this rank's rows of the
    /// first level (`Split`), or all `dim` of them on one rank, and where split the
    /// exchange of the correction's prolongation to the `owned` nodes of `agg` (the
    /// aggregate of each local node; collective).
    fn finish<C: Comm + ?Sized>(
        &mut self,
        comm: &C,
        h: &mut Hierarchy,
        dim: usize,
        (agg, owned): (&[u32], usize),
    ) {
        let rows = self.split_rows.len();
        if rows > 0 {
            let first = comm.rank() * rows;
            let mut reached = vec![false; dim];
            for &k in &agg[..owned] {
                let k = k as usize;
                reached[MODES * k..MODES * (k + 1)].fill(true);
            }
            self.halo = Some(Halo::new(comm, &reached, first..first + self.b.len(), rows));
            let split = &mut Split {
                comm,
                rows: &mut self.split_rows,
                all: &mut self.split_all,
            };
            h.finish(split, first, rows, |own| first::gather_rows(comm, &own));
        } else {
            h.finish(&mut cycle::Whole, 0, dim, |own| own);
        }
    }

    /// A whole coarse vector for the measurement's probes, whose responses are restricted
    /// whole (each rank's rows read every aggregate's coefficients): `b` on one rank, else
    /// a buffer of its own (`b` holds only this rank's rows). Given back by `give_back`.
    fn take_whole(&mut self, aggregates: usize) -> Vec<f64> {
        if self.split_rows.is_empty() {
            std::mem::take(&mut self.b)
        } else {
            vec![0.0; MODES * aggregates]
        }
    }

    /// Takes back what `take_whole` gave (`b` on one rank; else it goes).
    fn give_back(&mut self, whole: Vec<f64>) {
        if self.split_rows.is_empty() {
            self.b = whole;
        }
    }

    /// z += Q V(Q^T r) on the owned nodes (`cons` and `owned` as `prolong_add` takes them):
    /// the coarse correction, the first level's products split over the ranks when there
    /// are several. Collective.
    fn correct<C: Comm + ?Sized>(
        &mut self,
        comm: &C,
        h: &mut Hierarchy,
        transfer: &Transfer,
        (cons, owned, x): (&Constraints, usize, &[Vec3]),
        r: &[Vec3],
        z: &mut [Vec3],
    ) {
        let aggregates = &transfer.aggregates;
        if self.split_rows.is_empty() {
            aggregates.restrict(comm, x, r, &mut self.b);
            h.solve(&self.b, &mut self.x);
            aggregates.prolong_add(cons, (owned, x), &self.x, z);
        } else {
            aggregates.restrict_held(comm, x, r, self.per, &mut self.b);
            let rows = &mut self.split_rows;
            let all = &mut self.split_all;
            let halo = self.halo.as_ref();
            h.solve_rows(&self.b, &mut Split { comm, rows, all }, halo, |xc| {
                aggregates.prolong_add(cons, (owned, x), xc, z);
            });
        }
    }
}

/// rf = r - A z (A z formed in rf).
fn residual<S: Space>(f: &mut S, r: &[Vec3], z: &[f64], rf: &mut [f64]) -> Result<(), S::Error> {
    f.apply(z, rf)?;
    for (a, b) in rf.iter_mut().zip(r.as_flattened()) {
        *a = b - *a;
    }
    Ok(())
}
