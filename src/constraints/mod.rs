//! Node-local constraint rows: prescribed displacements (any direction) and contact ties,
//! enforced together as a change of variables u = T v + g.
//!
//! A constrained node s carries rows c_i . (u_s - sum_j w_ij u_mj) = b_i: a Dirichlet row
//! has no master terms; a contact row ties the node to a point of a master face (weights
//! w_ij = face shape functions at the contact point). Rows on one node need not be
//! orthogonal (a skew Dirichlet condition and a contact normal at 20 degrees, or three
//! master faces meeting at a corner): they are enforced at once through the Gram system
//! G l = (b + B u_m), G_ij = c_i . c_j, so the node lands on the intersection of all of
//! them, and a residual splits into the row forces G^-1 C r plus a free part P r. A row that
//! adds nothing to the span of the node's earlier rows is dropped (Dirichlet rows come
//! first, so a node fixed in every direction by Dirichlet conditions carries no contact
//! force and cannot slip).
//!
//! Every rank holds the rows of the constrained nodes it owns; a master node may be owned
//! by another rank. Nodes are processed in levels of dependency depth (a master node that
//! is itself constrained is resolved first), so T is a product of node-local maps and T^T
//! applies their transposes in reverse order. Between levels, master values are fetched
//! from their owners (T) and the force each tie passes to a master node is pushed to the
//! master's owner (T^T). A node sums the forces it receives in the order of (slave node,
//! row, master) global keys, whichever rank they come from: the result is bitwise the same
//! on any number of ranks.

mod build;
mod rows;
mod untied;

pub use rows::{CircularDependency, Row, RowKind, RowSpec};
use rows::{Level, NodeRows, Src};
use untied::{Shape, Untied};

use crate::comm::{self, Comm};
use crate::math::{dot, matvec, Mat3, Vec3, IDENTITY};
use crate::mesh::local::LocalMesh;
use std::cell::RefCell;
use std::ops::Range;

#[derive(Default)]
struct Scratch {
    remote: Vec<Vec3>,
    force: Vec<Vec3>,
    block: Vec<[f64; 9]>,
}

pub struct Constraints {
    /// Owned constrained nodes in dependency order (level, then global id).
    nodes: Vec<NodeRows>,
    /// Position in `nodes` by local node, u32::MAX when free or not owned (4 bytes per
    /// local node, not 8).
    slot: Vec<u32>,
    num_rows: usize,
    levels: Vec<Level>,
    /// Force slots received by each node, grouped by node in key order.
    incoming: Vec<u32>,
    /// Owned unconstrained nodes that receive forces, with their range of `incoming`.
    free_incoming: Vec<(usize, Range<usize>)>,
    /// The first level's nodes whose rows have no masters, packed (`untied`), their
    /// shapes, and the indices in `nodes` of that level's other nodes.
    untied: Vec<Untied>,
    shapes: Vec<Shape>,
    tied0: Vec<u32>,
    num_remote: usize,
    num_slots: usize,
    scratch: RefCell<Scratch>,
    /// Rows dropped as redundant with earlier rows on their node.
    pub dropped: Vec<(usize, RowKind)>,
}

impl Constraints {
    /// No constraints on this mesh. Collective only in name: no communication.
    pub fn none(mesh: &LocalMesh) -> Self {
        Constraints {
            nodes: Vec::new(),
            slot: vec![u32::MAX; mesh.num_nodes()],
            num_rows: 0,
            levels: Vec::new(),
            incoming: Vec::new(),
            free_incoming: Vec::new(),
            untied: Vec::new(),
            shapes: Vec::new(),
            tied0: Vec::new(),
            num_remote: 0,
            num_slots: 0,
            scratch: RefCell::new(Scratch::default()),
            dropped: Vec::new(),
        }
    }

    /// Builds the constraint set from the rows of this rank's owned nodes; rows are taken
    /// per node in the order given. Collective: every rank calls it together. The phases:
    /// the rows of each node (a row in the span of earlier ones dropped), where each
    /// master's value lives, the dependency depth of every node (ties on tied masters come
    /// later), the order (level, then global id), and per level the exchanges of master
    /// values and of the forces the ties pass on.
    pub fn new<C: Comm + ?Sized>(
        comm: &C,
        mesh: &LocalMesh,
        specs: Vec<RowSpec>,
    ) -> Result<Self, CircularDependency> {
        use build::{depths, force_routes, incoming, locate_masters, node_rows, order_by_level};
        let (nodes, bases, mut slot, dropped) = node_rows(mesh, specs);
        let (nodes, remote_global) = locate_masters(mesh, nodes, &bases);
        let num_remote = remote_global.len();
        // Each remote master's owner, asked once for the depths and every level's plans.
        let remote_owner = mesh.owners(comm, &remote_global);
        let depth = depths(comm, mesh, &nodes, (&remote_global, &remote_owner))?;
        let local_levels = depth.iter().map(|&d| d + 1).max().unwrap_or(0);
        let num_levels = comm::max_f64(comm, local_levels as f64) as usize;
        let (mut nodes, level_of, num_rows) = order_by_level(nodes, &depth, &mut slot);
        let (levels, num_slots, arrivals) = force_routes(
            comm,
            mesh,
            &mut nodes,
            (&level_of, num_levels),
            &remote_owner,
        );
        let (incoming, free_incoming) = incoming(arrivals, &slot, &mut nodes);
        let level0 = levels.first().map_or(0..0, |l| l.nodes.clone());
        let (untied, shapes, tied0) = untied::split(&nodes, level0);
        Ok(Constraints {
            nodes,
            slot: slot
                .iter()
                .map(|&s| if s == usize::MAX { u32::MAX } else { s as u32 })
                .collect(),
            num_rows,
            levels,
            incoming,
            free_incoming,
            untied,
            shapes,
            tied0,
            num_remote,
            num_slots,
            scratch: RefCell::new(Scratch::default()),
            dropped,
        })
    }

    pub fn num_rows(&self) -> usize {
        self.num_rows
    }

    pub fn is_constrained(&self, local: usize) -> bool {
        self.slot[local] != u32::MAX
    }

    /// Projector onto the free directions of an owned constrained node.
    pub fn projector(&self, local: usize) -> Option<&Mat3> {
        let s = self.slot[local];
        (s != u32::MAX).then(|| &self.nodes[s as usize].proj)
    }

    /// Rows of an owned node with their flat indices.
    pub fn rows(&self, local: usize) -> impl Iterator<Item = (usize, &Row)> {
        let s = self.slot[local];
        let nr = (s != u32::MAX).then(|| &self.nodes[s as usize]);
        nr.into_iter().flat_map(|nr| {
            nr.rows
                .iter()
                .enumerate()
                .map(move |(i, r)| (nr.first + i, r))
        })
    }

    /// u <- T u + g on the owned nodes (gap removal included), then the halo exchange:
    /// every constrained node put on all of its rows. Collective.
    pub fn impose<C: Comm + ?Sized>(&self, comm: &C, mesh: &LocalMesh, u: &mut [Vec3]) {
        self.apply(comm, u, true);
        mesh.exchange(comm, u);
    }

    /// p <- T p on the owned nodes: the homogeneous map, for search directions. Ghost
    /// values are left for the caller's halo exchange. Collective.
    pub fn expand<C: Comm + ?Sized>(&self, comm: &C, p: &mut [Vec3]) {
        self.apply(comm, p, false);
    }

    fn apply<C: Comm + ?Sized>(&self, comm: &C, u: &mut [Vec3], with_values: bool) {
        let mut scratch = self.scratch.borrow_mut();
        scratch.remote.resize(self.num_remote, [0.0; 3]);
        for (depth, level) in self.levels.iter().enumerate() {
            level.fetch.run(comm, u, &mut scratch.remote);
            if depth == 0 {
                untied::apply(&self.untied, &self.shapes, u, with_values);
            }
            for nr in self.level_nodes(depth, level) {
                let k = nr.rows.len();
                let mut b = [0.0; 3];
                for (i, (row, refs)) in nr.rows.iter().zip(&nr.refs).enumerate() {
                    let mut v = if with_values { row.value } else { 0.0 };
                    for (&(_, w), src) in row.masters.iter().zip(refs) {
                        let um = match *src {
                            Src::Local(l) => &u[l as usize],
                            Src::Remote(q) => &scratch.remote[q as usize],
                        };
                        v += w * dot(&row.dir, um);
                    }
                    b[i] = v;
                }
                let l = matvec(&nr.ginv, &b);
                let mut x = matvec(&nr.proj, &u[nr.node]);
                for i in 0..k {
                    for d in 0..3 {
                        x[d] += l[i] * nr.rows[i].dir[d];
                    }
                }
                u[nr.node] = x;
            }
        }
    }

    /// r <- T^T r on the owned nodes. When `multipliers` is given, row i's force
    /// coefficient is written to it: the force the constraint exerts on its node is
    /// sum_i m_i c_i (positive along c_i). Collective.
    pub fn reduce<C: Comm + ?Sized>(
        &self,
        comm: &C,
        r: &mut [Vec3],
        mut multipliers: Option<&mut [f64]>,
    ) {
        let mut scratch = self.scratch.borrow_mut();
        scratch.force.resize(self.num_slots, [0.0; 3]);
        let force = &mut scratch.force;
        for (depth, level) in self.levels.iter().enumerate().rev() {
            if depth == 0 {
                let packed = (&self.untied[..], &self.shapes[..]);
                let out = multipliers.as_deref_mut();
                untied::reduce(packed, &self.incoming, force, r, out);
            }
            for nr in self.level_nodes(depth, level) {
                for &k in &self.incoming[nr.incoming.clone()] {
                    let f = force[k as usize];
                    for d in 0..3 {
                        r[nr.node][d] += f[d];
                    }
                }
                let k = nr.rows.len();
                let rs = r[nr.node];
                let mut c = [0.0; 3];
                for i in 0..k {
                    c[i] = dot(&nr.rows[i].dir, &rs);
                }
                let mu = matvec(&nr.ginv, &c);
                for (i, row) in nr.rows.iter().enumerate() {
                    for (&(_, w), &k) in row.masters.iter().zip(&nr.out[i]) {
                        force[k as usize] = std::array::from_fn(|d| w * mu[i] * row.dir[d]);
                    }
                }
                if let Some(out) = multipliers.as_deref_mut() {
                    for i in 0..k {
                        out[nr.first + i] = -mu[i];
                    }
                }
                r[nr.node] = matvec(&nr.proj, &rs);
            }
            level.push.run_in_place(comm, force);
        }
        for (t, range) in &self.free_incoming {
            for &k in &self.incoming[range.clone()] {
                let f = force[k as usize];
                for d in 0..3 {
                    r[*t][d] += f[d];
                }
            }
        }
    }

    /// The nodes of a level that `apply` and `reduce` take one by one: on the first level
    /// those with masters (the others are packed in `untied`), on the others all.
    fn level_nodes<'a>(
        &'a self,
        depth: usize,
        level: &Level,
    ) -> Box<dyn Iterator<Item = &'a NodeRows> + 'a> {
        if depth == 0 {
            Box::new(self.tied0.iter().map(|&s| &self.nodes[s as usize]))
        } else {
            Box::new(self.nodes[level.nodes.clone()].iter())
        }
    }

    /// Block-Jacobi preconditioner blocks in the constrained space, in place: each tie
    /// adds the slave's stiffness along its row to the master nodes (weighted by w^2),
    /// which the masters feel through T^T K T, and a constrained node's block becomes
    /// P D P + (I - P) d. Collective.
    pub fn precondition_blocks<C: Comm + ?Sized>(&self, comm: &C, d: &mut [Mat3]) {
        let mut scratch = self.scratch.borrow_mut();
        scratch.block.resize(self.num_slots, [0.0; 9]);
        let block = &mut scratch.block;
        let add = |m: &mut Mat3, b: &[f64; 9]| {
            for i in 0..3 {
                for j in 0..3 {
                    m[i][j] += b[3 * i + j];
                }
            }
        };
        for level in self.levels.iter().rev() {
            for nr in &self.nodes[level.nodes.clone()] {
                for &k in &self.incoming[nr.incoming.clone()] {
                    add(&mut d[nr.node], &block[k as usize]);
                }
                let ds = d[nr.node];
                for (i, row) in nr.rows.iter().enumerate() {
                    if row.masters.is_empty() {
                        continue;
                    }
                    let kc = dot(&row.dir, &matvec(&ds, &row.dir));
                    for (&(_, w), &k) in row.masters.iter().zip(&nr.out[i]) {
                        block[k as usize] = std::array::from_fn(|ij| {
                            w * w * kc * row.dir[ij / 3] * row.dir[ij % 3]
                        });
                    }
                }
            }
            level.push.run_in_place(comm, block);
        }
        for (t, range) in &self.free_incoming {
            for &k in &self.incoming[range.clone()] {
                add(&mut d[*t], &block[k as usize]);
            }
        }
        for nr in &self.nodes {
            let p = &nr.proj;
            let dn = d[nr.node];
            let pdp = crate::math::matmul(p, &crate::math::matmul(&dn, p));
            let s = (dn[0][0] + dn[1][1] + dn[2][2]).abs() / 3.0;
            let mut m = pdp;
            for i in 0..3 {
                for j in 0..3 {
                    m[i][j] += s * (IDENTITY[i][j] - p[i][j]);
                }
            }
            d[nr.node] = m;
        }
    }

    /// After inverting the blocks: z = P M^-1 P r on constrained nodes.
    pub fn project_inverse_blocks(&self, minv: &mut [Mat3]) {
        for nr in &self.nodes {
            let p = &nr.proj;
            minv[nr.node] = crate::math::matmul(p, &crate::math::matmul(&minv[nr.node], p));
        }
    }
}

#[cfg(test)]
mod tests;
