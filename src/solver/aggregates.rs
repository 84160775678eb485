//! Aggregates of nodes with the six rigid-body modes of each: the space Q that the two-level
//! coarse space (coarse.rs) and the multilevel preconditioner's fine-level transfer
//! (multilevel/transfer.rs) restrict to and prolong from. A column of Q is one mode of one
//! aggregate, projected on the free directions of constrained nodes.
//!
//! Restriction Q^T r sums each aggregate on the rank that owns its lowest node, over its
//! nodes in global node order (values of nodes owned elsewhere fetched first), and every
//! rank gathers every aggregate's coefficients: the coarse vector is bitwise the same on
//! every rank and on any number of ranks.

use crate::comm::{message, Comm, ExchangePlan};
use crate::constraints::Constraints;
use crate::math::{matvec, Vec3};
use crate::mesh::local::LocalMesh;
use std::cell::RefCell;
use std::collections::HashMap;

/// Rigid-body modes per aggregate.
pub const MODES: usize = 6;

/// Values of the six modes of an aggregate at a node with scaled offset d.
#[inline]
pub fn modes(d: &Vec3) -> [Vec3; MODES] {
    [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, -d[2], d[1]],
        [d[2], 0.0, -d[0]],
        [-d[1], d[0], 0.0],
    ]
}

/// Where a node value comes from when an aggregate's coefficients are summed.
#[derive(Clone, Copy)]
enum Src {
    Local(u32),
    Remote(u32),
}

pub struct Aggregates {
    /// Per local node: (aggregate, scaled offset of the node from its aggregate's centre).
    node: Vec<(u32, Vec3)>,
    /// Aggregates this rank sums: (aggregate, sources in global node order with offsets).
    sums: Vec<(u32, Vec<(Src, Vec3)>)>,
    fetch: ExchangePlan,
    /// Fetched node values and this rank's coefficients as a message, reused.
    scratch: RefCell<(Vec<Vec3>, Vec<f64>)>,
}

impl Aggregates {
    /// The plan for `na` aggregates: `agg` is the aggregate of every global node, `offset`
    /// a global node's scaled offset from its aggregate's centre. Collective.
    pub fn new<C: Comm + ?Sized>(
        comm: &C,
        mesh: &LocalMesh,
        agg: &[u32],
        na: usize,
        offset: impl Fn(usize) -> Vec3,
    ) -> Self {
        let node = mesh
            .node_global
            .iter()
            .map(|&gid| (agg[gid as usize], offset(gid as usize)))
            .collect();
        let mut members: Vec<Vec<u32>> = vec![Vec::new(); na];
        for (a, &k) in agg.iter().enumerate() {
            members[k as usize].push(a as u32);
        }
        let mut remote: HashMap<u32, u32> = HashMap::new();
        let mut wanted = Vec::new();
        let mut sums = Vec::new();
        for (k, nodes) in members.iter().enumerate() {
            if mesh.owner(nodes[0]) != comm.rank() {
                continue;
            }
            let src = nodes
                .iter()
                .map(|&gid| {
                    let s = match mesh.owned_node(gid) {
                        Some(l) => Src::Local(l as u32),
                        None => Src::Remote(*remote.entry(gid).or_insert_with(|| {
                            wanted.push((gid, wanted.len() as u32));
                            wanted.len() as u32 - 1
                        })),
                    };
                    (s, offset(gid as usize))
                })
                .collect();
            sums.push((k as u32, src));
        }
        let fetch = mesh.fetch_plan(comm, &wanted);
        let scratch = (
            vec![[0.0; 3]; wanted.len()],
            Vec::with_capacity(sums.len() * (MODES + 1)),
        );
        Aggregates {
            node,
            sums,
            fetch,
            scratch: RefCell::new(scratch),
        }
    }

    /// The aggregate of each local node.
    pub fn aggregate_of(&self, local: usize) -> u32 {
        self.node[local].0
    }

    /// out = Q^T r: every aggregate's six coefficients (`out` holds MODES per aggregate),
    /// the same on every rank. Collective.
    pub fn restrict<C: Comm + ?Sized>(&self, comm: &C, r: &[Vec3], out: &mut [f64]) {
        let (far, mine) = &mut *self.scratch.borrow_mut();
        self.fetch.run(comm, r, far);
        mine.clear();
        let single = comm.size() == 1;
        for (k, src) in &self.sums {
            let mut acc = [0.0; MODES];
            for (s, d) in src {
                let v = match *s {
                    Src::Local(l) => &r[l as usize],
                    Src::Remote(q) => &far[q as usize],
                };
                for (m, phi) in modes(d).iter().enumerate() {
                    acc[m] += phi[0] * v[0] + phi[1] * v[1] + phi[2] * v[2];
                }
            }
            if single {
                out[MODES * *k as usize..MODES * (*k as usize + 1)].copy_from_slice(&acc);
            } else {
                message::push(mine, &(*k, acc));
            }
        }
        if single {
            return;
        }
        for part in comm.all_gather_f64(mine) {
            for (k, coefficients) in message::items::<(u32, [f64; MODES])>(&part) {
                let k = k as usize;
                out[MODES * k..MODES * (k + 1)].copy_from_slice(&coefficients);
            }
        }
    }

    /// z += Q y on the owned nodes.
    pub fn prolong_add(&self, cons: &Constraints, owned: usize, y: &[f64], z: &mut [Vec3]) {
        for (l, (k, d)) in self.node.iter().enumerate().take(owned) {
            let yk = &y[MODES * *k as usize..MODES * (*k as usize + 1)];
            let mut v = [0.0; 3];
            for (m, phi) in modes(d).iter().enumerate() {
                for i in 0..3 {
                    v[i] += phi[i] * yk[m];
                }
            }
            if let Some(p) = cons.projector(l) {
                v = matvec(p, &v);
            }
            for i in 0..3 {
                z[l][i] += v[i];
            }
        }
    }

    /// The probe of colour `c` and mode `m` on the owned nodes: mode m of every aggregate
    /// of that colour (`colour` of each aggregate; projected on the free directions of
    /// constrained nodes); zero on the other nodes and the ghosts.
    #[allow(clippy::too_many_arguments)]
    pub fn probe(
        &self,
        cons: &Constraints,
        colour: &[u16],
        c: usize,
        m: usize,
        owned: usize,
        v: &mut [Vec3],
    ) {
        v.iter_mut().for_each(|x| *x = [0.0; 3]);
        for (l, (k, d)) in self.node.iter().enumerate().take(owned) {
            if colour[*k as usize] as usize == c {
                let phi = modes(d)[m];
                v[l] = match cons.projector(l) {
                    Some(p) => matvec(p, &phi),
                    None => phi,
                };
            }
        }
    }
}
