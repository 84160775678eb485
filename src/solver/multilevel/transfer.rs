//! The fine level's transfer: Q, whose columns are the six rigid-body modes of every
//! fine-level aggregate of nodes (projected on the free directions of constrained nodes).
//! Restriction Q^T r sums each aggregate on one rank, over its nodes in global node order
//! (values of nodes owned elsewhere fetched first), and every rank gathers all aggregates:
//! the coarse vector is the same on every rank and on any number of ranks.

use super::aggregation::{aggregate, Graph};
use super::prolongator::MODES;
use crate::comm::{message, Comm, ExchangePlan};
use crate::constraints::Constraints;
use crate::math::{matvec, Vec3};
use crate::mesh::local::LocalMesh;
use crate::mesh::GlobalMesh;
use std::collections::HashMap;

/// Mesh neighbours farther apart than this times the shortest distance from either to a
/// neighbour are weakly coupled and not aggregated together (Graph::strong). Measured on
/// the Hertz example x2 (one element thick, graded): 3233 CG iterations with every
/// neighbour aggregated, 756 with this ratio; cubes (diagonals 1.41 and 1.73) keep all.
const STRONG_RATIO: f64 = 2.0;

/// Meshes of at most this many nodes get one aggregate per node: the first coarse level
/// is then the fine operator itself, factored directly (its rotation modes have no
/// stiffness and are left out), and CG converges in a few iterations per model problem.
pub const SINGLETON_NODES: usize = 300;

/// Where a node value comes from when an aggregate's coefficients are summed.
#[derive(Clone, Copy)]
enum Src {
    Local(u32),
    Remote(u32),
}

pub struct Transfer {
    pub num_aggregates: usize,
    /// Aggregate of every global node.
    pub agg_of: Vec<u32>,
    /// Per local node: (aggregate, offset (x - centre) / scale of its aggregate).
    node: Vec<(u32, Vec3)>,
    /// Aggregates this rank sums: (aggregate, sources in global node order with offsets).
    sums: Vec<(u32, Vec<(Src, Vec3)>)>,
    fetch: ExchangePlan,
    far: Vec<Vec3>,
    mine: Vec<f64>,
    pub centre: Vec<Vec3>,
    pub scale: Vec<f64>,
}

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

impl Transfer {
    /// Aggregates the global node graph and plans the sums (collective).
    pub fn new<C: Comm + ?Sized>(
        comm: &C,
        g: &GlobalMesh,
        graph: &Graph,
        mesh: &LocalMesh,
    ) -> Self {
        let n = g.num_nodes();
        let (agg_of, na) = if n <= SINGLETON_NODES {
            ((0..n as u32).collect(), n)
        } else {
            aggregate(&graph.strong(&g.coords, STRONG_RATIO), &vec![true; n])
        };
        let mut centre = vec![[0.0; 3]; na];
        let mut count = vec![0usize; na];
        for a in 0..n {
            let k = agg_of[a] as usize;
            for i in 0..3 {
                centre[k][i] += g.coords[a][i];
            }
            count[k] += 1;
        }
        for k in 0..na {
            for i in 0..3 {
                centre[k][i] /= count[k] as f64;
            }
        }
        let mut scale = vec![0.0f64; na];
        for a in 0..n {
            let k = agg_of[a] as usize;
            let d = crate::math::sub(&g.coords[a], &centre[k]);
            scale[k] = scale[k].max(crate::math::dot(&d, &d).sqrt());
        }
        let floor = g.bounding_diagonal() * 1e-12;
        scale
            .iter_mut()
            .for_each(|s| *s = s.max(floor).max(f64::MIN_POSITIVE));
        let offset = |a: usize| -> Vec3 {
            let k = agg_of[a] as usize;
            std::array::from_fn(|i| (g.coords[a][i] - centre[k][i]) / scale[k])
        };
        let node = mesh
            .node_global
            .iter()
            .map(|&gid| (agg_of[gid as usize], offset(gid as usize)))
            .collect();
        let mut members: Vec<Vec<u32>> = vec![Vec::new(); na];
        for a in 0..n {
            members[agg_of[a] as usize].push(a as u32);
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
        let mine = Vec::with_capacity(sums.len() * (MODES + 1));
        Transfer {
            num_aggregates: na,
            agg_of,
            node,
            sums,
            fetch,
            far: vec![[0.0; 3]; wanted.len()],
            mine,
            centre,
            scale,
        }
    }

    pub fn dim(&self) -> usize {
        MODES * self.num_aggregates
    }

    /// The coarse near-nullspace: the coefficients of the six global rigid-body modes
    /// (rotations about `origin`, divided by `length`) in every aggregate's modes.
    pub fn nullspace(&self, origin: &Vec3, length: f64) -> Vec<[f64; MODES]> {
        let mut b = vec![[0.0; MODES]; self.dim()];
        for k in 0..self.num_aggregates {
            let c = crate::math::sub(&self.centre[k], origin);
            for i in 0..3 {
                b[MODES * k + i][i] = 1.0;
                // e_i x (c - origin) / length in the translations, scale / length in the
                // rotation about axis i.
                let mut e = [0.0; 3];
                e[i] = 1.0;
                let t = crate::math::cross(&e, &c);
                for j in 0..3 {
                    b[MODES * k + j][3 + i] = t[j] / length;
                }
                b[MODES * k + 3 + i][3 + i] = self.scale[k] / length;
            }
        }
        b
    }

    /// Q^T r: every aggregate's six coefficients, the same on every rank. Collective.
    pub fn restrict<C: Comm + ?Sized>(&mut self, comm: &C, r: &[Vec3], out: &mut [f64]) {
        self.fetch.run(comm, r, &mut self.far);
        self.mine.clear();
        let single = comm.size() == 1;
        if single {
            out.iter_mut().for_each(|v| *v = 0.0);
        }
        for (k, src) in &self.sums {
            let mut acc = [0.0; MODES];
            for (s, d) in src {
                let v = match *s {
                    Src::Local(l) => &r[l as usize],
                    Src::Remote(q) => &self.far[q as usize],
                };
                for (m, phi) in modes(d).iter().enumerate() {
                    acc[m] += phi[0] * v[0] + phi[1] * v[1] + phi[2] * v[2];
                }
            }
            if single {
                out[MODES * *k as usize..MODES * (*k as usize + 1)].copy_from_slice(&acc);
            } else {
                message::push(&mut self.mine, &(*k, acc));
            }
        }
        if single {
            return;
        }
        for part in comm.all_gather_f64(&self.mine) {
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
    /// of that colour (projected on the free directions of constrained nodes); zero on the
    /// other nodes and the ghosts.
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
