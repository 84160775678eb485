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

use crate::comm::{self, Comm};
use crate::math::{dot, matvec, Mat3, Vec3, IDENTITY};
use crate::mesh::local::LocalMesh;
use std::cell::RefCell;
use std::collections::HashMap;
use std::ops::Range;

/// Chains of constrained nodes deeper than this are circular dependencies.
const MAX_DEPTH: usize = 64;

/// What a row stands for, so forces can be reported per constraint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RowKind {
    /// A prescribed displacement; the index is the scene's Dirichlet entry.
    Dirichlet(usize),
    /// A contact tie; `constraint` indexes the contact state's active list, `component`
    /// is 0 for the normal and 1, 2 for the tangents of a sticking node.
    Contact { constraint: usize, component: u8 },
}

#[derive(Clone, Debug)]
pub struct Row {
    pub dir: Vec3,
    /// Fixed part of the right-hand side.
    pub value: f64,
    /// Master nodes (global ids, on any rank) and weights.
    pub masters: Vec<(u32, f64)>,
    pub kind: RowKind,
}

/// A row as given, before the independent subset is chosen.
pub struct RowSpec {
    /// Local index of the constrained node; it must be owned by this rank.
    pub node: usize,
    pub row: Row,
}

/// Where a master value lives: an owned local node or a slot of the fetched values.
#[derive(Clone, Copy, Debug)]
enum Src {
    Local(u32),
    Remote(u32),
}

struct NodeRows {
    node: usize,
    global: u32,
    rows: Vec<Row>,
    /// Per row, per master: where its value is.
    refs: Vec<Vec<Src>>,
    /// Per row, per master: the slot of the force this tie passes to the master.
    out: Vec<Vec<u32>>,
    /// Slots of the forces this node receives, in key order (a range of `incoming`).
    incoming: Range<usize>,
    /// Inverse of the Gram matrix of the kept rows (leading k x k block).
    ginv: Mat3,
    proj: Mat3,
    /// Index of the node's first row in the flat multiplier array.
    first: usize,
}

/// A point-to-point exchange: entries `send[r]` of a source array go to rank r, which
/// writes them to the entries `recv[r]` of its destination array.
#[derive(Default)]
pub(crate) struct Plan {
    send: Vec<(usize, Vec<u32>)>,
    recv: Vec<(usize, Vec<u32>)>,
}

impl Plan {
    fn is_empty(&self) -> bool {
        self.send.is_empty() && self.recv.is_empty()
    }

    fn messages<const K: usize>(&self, src: &[[f64; K]]) -> Vec<(usize, Vec<f64>)> {
        self.send
            .iter()
            .map(|(r, idx)| (*r, idx.iter().flat_map(|&i| src[i as usize]).collect()))
            .collect()
    }

    fn deliver<const K: usize, C: Comm + ?Sized>(
        &self,
        comm: &C,
        send: Vec<(usize, Vec<f64>)>,
        dst: &mut [[f64; K]],
    ) {
        let mut recv: Vec<(usize, Vec<f64>)> = self
            .recv
            .iter()
            .map(|(r, idx)| (*r, vec![0.0; K * idx.len()]))
            .collect();
        comm.exchange(&send, &mut recv);
        for ((_, idx), (_, buf)) in self.recv.iter().zip(&recv) {
            for (k, &i) in idx.iter().enumerate() {
                dst[i as usize].copy_from_slice(&buf[K * k..K * (k + 1)]);
            }
        }
    }

    pub(crate) fn run<const K: usize, C: Comm + ?Sized>(
        &self,
        comm: &C,
        src: &[[f64; K]],
        dst: &mut [[f64; K]],
    ) {
        if !self.is_empty() {
            let send = self.messages(src);
            self.deliver(comm, send, dst);
        }
    }

    fn run_in_place<const K: usize, C: Comm + ?Sized>(&self, comm: &C, buf: &mut [[f64; K]]) {
        if !self.is_empty() {
            let send = self.messages(buf);
            self.deliver(comm, send, buf);
        }
    }
}

struct Level {
    /// Range of `Constraints::nodes`.
    nodes: Range<usize>,
    /// Master values this level reads from other ranks.
    fetch: Plan,
    /// Forces this level's ties pass to masters on other ranks.
    push: Plan,
}

#[derive(Default)]
struct Scratch {
    remote: Vec<Vec3>,
    force: Vec<Vec3>,
    block: Vec<[f64; 9]>,
}

pub struct Constraints {
    /// Owned constrained nodes in dependency order (level, then global id).
    nodes: Vec<NodeRows>,
    /// Position in `nodes` by local node, usize::MAX when free or not owned.
    slot: Vec<usize>,
    num_rows: usize,
    levels: Vec<Level>,
    /// Force slots received by each node, grouped by node in key order.
    incoming: Vec<u32>,
    /// Owned unconstrained nodes that receive forces, with their range of `incoming`.
    free_incoming: Vec<(usize, Range<usize>)>,
    num_remote: usize,
    num_slots: usize,
    scratch: RefCell<Scratch>,
    /// Rows dropped as redundant with earlier rows on their node.
    pub dropped: Vec<(usize, RowKind)>,
}

/// A circular master/slave dependency between constrained nodes (a global node id).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CircularDependency(pub u32);

/// Asks the owners of the given remote nodes for their values: returns the plan that
/// fetches them into `slots`. Collective.
pub(crate) fn fetch_plan<C: Comm + ?Sized>(
    comm: &C,
    mesh: &LocalMesh,
    wanted: &[(u32, u32)],
) -> Plan {
    let size = comm.size();
    let mut by_rank: Vec<Vec<u32>> = vec![Vec::new(); size];
    let mut request: Vec<Vec<f64>> = vec![Vec::new(); size];
    for &(global, slot) in wanted {
        let r = mesh.owner(global);
        by_rank[r].push(slot);
        request[r].push(global as f64);
    }
    let asked = comm.all_to_all_f64(&request);
    let mut plan = Plan::default();
    for (r, ids) in asked.into_iter().enumerate() {
        if !ids.is_empty() {
            let local = ids
                .iter()
                .map(|&g| {
                    mesh.owned_node(g as u32)
                        .expect("a node is requested from its owner") as u32
                })
                .collect();
            plan.send.push((r, local));
        }
    }
    for (r, slots) in by_rank.into_iter().enumerate() {
        if !slots.is_empty() {
            plan.recv.push((r, slots));
        }
    }
    plan
}

impl Constraints {
    /// No constraints on this mesh. Collective only in name: no communication.
    pub fn none(mesh: &LocalMesh) -> Self {
        Constraints {
            nodes: Vec::new(),
            slot: vec![usize::MAX; mesh.num_nodes()],
            num_rows: 0,
            levels: Vec::new(),
            incoming: Vec::new(),
            free_incoming: Vec::new(),
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
        let (nodes, bases, mut slot, dropped) = node_rows(mesh, specs);
        let (nodes, remote_global) = locate_masters(mesh, nodes, &bases);
        let num_remote = remote_global.len();
        let depth = depths(comm, mesh, &nodes, &remote_global)?;
        let local_levels = depth.iter().map(|&d| d + 1).max().unwrap_or(0);
        let num_levels = comm::max_f64(comm, local_levels as f64) as usize;
        let (mut nodes, level_of, num_rows) = order_by_level(nodes, &depth, &mut slot);
        let (levels, num_slots, arrivals) =
            force_routes(comm, mesh, &mut nodes, &level_of, num_levels);
        let (incoming, free_incoming) = incoming(arrivals, &slot, &mut nodes);
        Ok(Constraints {
            nodes,
            slot,
            num_rows,
            levels,
            incoming,
            free_incoming,
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
        self.slot[local] != usize::MAX
    }

    /// Projector onto the free directions of an owned constrained node.
    pub fn projector(&self, local: usize) -> Option<&Mat3> {
        let s = self.slot[local];
        (s != usize::MAX).then(|| &self.nodes[s].proj)
    }

    /// Rows of an owned node with their flat indices.
    pub fn rows(&self, local: usize) -> impl Iterator<Item = (usize, &Row)> {
        let s = self.slot[local];
        let nr = (s != usize::MAX).then(|| &self.nodes[s]);
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
        for level in &self.levels {
            level.fetch.run(comm, u, &mut scratch.remote);
            for nr in &self.nodes[level.nodes.clone()] {
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
        for level in self.levels.iter().rev() {
            for nr in &self.nodes[level.nodes.clone()] {
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

/// Inverse of the leading k x k block (k <= 3) of a symmetric positive definite matrix.
fn invert_small(g: &Mat3, k: usize) -> Mat3 {
    let mut out = [[0.0; 3]; 3];
    match k {
        0 => {}
        1 => out[0][0] = 1.0 / g[0][0],
        2 => {
            let det = g[0][0] * g[1][1] - g[0][1] * g[1][0];
            out[0][0] = g[1][1] / det;
            out[1][1] = g[0][0] / det;
            out[0][1] = -g[0][1] / det;
            out[1][0] = -g[1][0] / det;
        }
        _ => out = crate::math::inverse(g).0,
    }
    out
}

/// Each owned node's rows in the order given, with an orthonormal basis of their
/// directions; a row in the span of the node's earlier ones is dropped (listed with its
/// node). Also the slot of each local node in the list (usize::MAX when it has no rows).
#[allow(clippy::type_complexity)]
fn node_rows(
    mesh: &LocalMesh,
    specs: Vec<RowSpec>,
) -> (
    Vec<NodeRows>,
    Vec<Vec<Vec3>>,
    Vec<usize>,
    Vec<(usize, RowKind)>,
) {
    let mut slot = vec![usize::MAX; mesh.num_nodes()];
    let mut nodes: Vec<NodeRows> = Vec::new();
    let mut bases: Vec<Vec<Vec3>> = Vec::new();
    let mut dropped = Vec::new();
    for spec in specs {
        let l = spec.node;
        assert!(
            l < mesh.num_owned_nodes,
            "constraint rows are given on owned nodes"
        );
        if slot[l] == usize::MAX {
            slot[l] = nodes.len();
            nodes.push(NodeRows {
                node: l,
                global: mesh.node_global[l],
                rows: Vec::new(),
                refs: Vec::new(),
                out: Vec::new(),
                incoming: 0..0,
                ginv: [[0.0; 3]; 3],
                proj: IDENTITY,
                first: 0,
            });
            bases.push(Vec::new());
        }
        let s = slot[l];
        let mut r = spec.row.dir;
        let n0 = dot(&r, &r).sqrt();
        for q in &bases[s] {
            let c = dot(&r, q);
            for i in 0..3 {
                r[i] -= c * q[i];
            }
        }
        let n = dot(&r, &r).sqrt();
        if n > 1e-8 * n0 && bases[s].len() < 3 {
            bases[s].push([r[0] / n, r[1] / n, r[2] / n]);
            nodes[s].rows.push(spec.row);
        } else {
            dropped.push((l, spec.row.kind));
        }
    }
    (nodes, bases, slot, dropped)
}

/// Each node's projection onto the directions its rows leave free, the inverse Gram
/// matrix of its row directions, and where each of its rows' masters lives (owned here,
/// or the index of a remote master); returns the remote masters' global ids.
fn locate_masters(
    mesh: &LocalMesh,
    mut nodes: Vec<NodeRows>,
    bases: &[Vec<Vec3>],
) -> (Vec<NodeRows>, Vec<u32>) {
    let mut remote: HashMap<u32, u32> = HashMap::new();
    let mut remote_global: Vec<u32> = Vec::new();
    for (s, nr) in nodes.iter_mut().enumerate() {
        let mut p = IDENTITY;
        for q in &bases[s] {
            for i in 0..3 {
                for j in 0..3 {
                    p[i][j] -= q[i] * q[j];
                }
            }
        }
        nr.proj = p;
        let k = nr.rows.len();
        let mut g = [[0.0; 3]; 3];
        for i in 0..k {
            for j in 0..k {
                g[i][j] = dot(&nr.rows[i].dir, &nr.rows[j].dir);
            }
        }
        nr.ginv = invert_small(&g, k);
        nr.refs = nr
            .rows
            .iter()
            .map(|row| {
                row.masters
                    .iter()
                    .map(|&(m, _)| match mesh.owned_node(m) {
                        Some(l) => Src::Local(l as u32),
                        None => Src::Remote(*remote.entry(m).or_insert_with(|| {
                            remote_global.push(m);
                            remote_global.len() as u32 - 1
                        })),
                    })
                    .collect()
            })
            .collect();
    }
    (nodes, remote_global)
}

/// Dependency depth: a node tied to masters that are themselves constrained comes after
/// them. Each owner publishes its nodes' depths (-1 when free) and the slaves read their
/// masters' until nothing changes anywhere; nodes on a cycle keep deepening, and the
/// lowest of them is named. Collective.
fn depths<C: Comm + ?Sized>(
    comm: &C,
    mesh: &LocalMesh,
    nodes: &[NodeRows],
    remote_global: &[u32],
) -> Result<Vec<usize>, CircularDependency> {
    let everything: Vec<(u32, u32)> = remote_global
        .iter()
        .enumerate()
        .map(|(k, &g)| (g, k as u32))
        .collect();
    let all = fetch_plan(comm, mesh, &everything);
    let mut depth = vec![0usize; nodes.len()];
    let mut own = vec![[-1.0f64]; mesh.num_owned_nodes];
    let mut far = vec![[-1.0f64]; remote_global.len()];
    for iteration in 0.. {
        for (s, nr) in nodes.iter().enumerate() {
            own[nr.node] = [depth[s] as f64];
        }
        all.run(comm, &own, &mut far);
        let mut changed = false;
        for (s, nr) in nodes.iter().enumerate() {
            let mut d = 0usize;
            for refs in &nr.refs {
                for src in refs {
                    let v = match *src {
                        Src::Local(l) if l as usize == nr.node => -1.0,
                        Src::Local(l) => own[l as usize][0],
                        Src::Remote(k) => far[k as usize][0],
                    };
                    if v >= 0.0 {
                        d = d.max(v as usize + 1);
                    }
                }
            }
            if d != depth[s] {
                depth[s] = d;
                changed = true;
            }
        }
        if !comm::any(comm, changed) {
            break;
        }
        if iteration >= MAX_DEPTH {
            let deep = nodes
                .iter()
                .zip(&depth)
                .filter(|(_, &d)| d > MAX_DEPTH / 2)
                .map(|(nr, _)| nr.global as i64)
                .min()
                .unwrap_or(i64::MAX);
            let mut key = [deep];
            comm.min_i64(&mut key);
            return Err(CircularDependency(key[0] as u32));
        }
    }
    Ok(depth)
}

/// The nodes in order of level, then global id, with the flat row numbering that follows
/// (each node's first row) and their slots updated; also each node's level and the
/// number of rows.
fn order_by_level(
    nodes: Vec<NodeRows>,
    depth: &[usize],
    slot: &mut [usize],
) -> (Vec<NodeRows>, Vec<usize>, usize) {
    let mut order: Vec<usize> = (0..nodes.len()).collect();
    order.sort_by_key(|&s| (depth[s], nodes[s].global));
    let mut taken: Vec<Option<NodeRows>> = nodes.into_iter().map(Some).collect();
    let mut sorted = Vec::with_capacity(order.len());
    let mut first = 0;
    let mut level_of = Vec::with_capacity(order.len());
    for &s in &order {
        let mut nr = taken[s].take().expect("each node once");
        nr.first = first;
        first += nr.rows.len();
        slot[nr.node] = sorted.len();
        level_of.push(depth[s]);
        sorted.push(nr);
    }
    (sorted, level_of, first)
}

/// (target local node, (slave global id, row, master), force slot) of a force a tie
/// passes to a master node.
type Arrival = (usize, (u32, u32, u32), u32);

/// Per level: the remote masters it reads, and the forces its ties pass on. A force slot
/// per (node, row, master); a received force gets a slot of its own. Returns the levels,
/// the number of slots and every force's arrival. Collective.
fn force_routes<C: Comm + ?Sized>(
    comm: &C,
    mesh: &LocalMesh,
    nodes: &mut [NodeRows],
    level_of: &[usize],
    num_levels: usize,
) -> (Vec<Level>, usize, Vec<Arrival>) {
    let mut levels = Vec::with_capacity(num_levels);
    let mut num_slots = 0usize;
    let mut arrivals: Vec<Arrival> = Vec::new();
    for level in 0..num_levels {
        let start = level_of.partition_point(|&d| d < level);
        let end = level_of.partition_point(|&d| d <= level);
        let mut wanted: Vec<(u32, u32)> = Vec::new();
        let mut push: Vec<Vec<f64>> = vec![Vec::new(); comm.size()];
        let mut push_slots: Vec<Vec<u32>> = vec![Vec::new(); comm.size()];
        for nr in &mut nodes[start..end] {
            let mut out = Vec::with_capacity(nr.rows.len());
            for (i, (row, refs)) in nr.rows.iter().zip(&nr.refs).enumerate() {
                let mut row_out = Vec::with_capacity(refs.len());
                for (j, (&(m, _), src)) in row.masters.iter().zip(refs).enumerate() {
                    let k = num_slots as u32;
                    num_slots += 1;
                    row_out.push(k);
                    let key = (nr.global, i as u32, j as u32);
                    match *src {
                        Src::Local(l) => arrivals.push((l as usize, key, k)),
                        Src::Remote(q) => {
                            wanted.push((m, q));
                            let r = mesh.owner(m);
                            push[r].extend([m as f64, key.0 as f64, key.1 as f64, key.2 as f64]);
                            push_slots[r].push(k);
                        }
                    }
                }
                out.push(row_out);
            }
            nr.out = out;
        }
        wanted.sort_unstable_by_key(|&(_, q)| q);
        wanted.dedup();
        let fetch = fetch_plan(comm, mesh, &wanted);
        let received = comm.all_to_all_f64(&push);
        let mut plan = Plan::default();
        for (r, slots) in push_slots.into_iter().enumerate() {
            if !slots.is_empty() {
                plan.send.push((r, slots));
            }
        }
        for (r, msg) in received.into_iter().enumerate() {
            if msg.is_empty() {
                continue;
            }
            let mut slots = Vec::with_capacity(msg.len() / 4);
            for e in msg.chunks_exact(4) {
                let target = mesh
                    .owned_node(e[0] as u32)
                    .expect("a force is pushed to the master's owner");
                let k = num_slots as u32;
                num_slots += 1;
                slots.push(k);
                arrivals.push((target, (e[1] as u32, e[2] as u32, e[3] as u32), k));
            }
            plan.recv.push((r, slots));
        }
        levels.push(Level {
            nodes: start..end,
            fetch,
            push: plan,
        });
    }
    (levels, num_slots, arrivals)
}

/// The force slots arriving at each node, in (target, key) order: a constrained node's
/// range in its `incoming`, a free node's in the returned list.
#[allow(clippy::type_complexity)]
fn incoming(
    mut arrivals: Vec<Arrival>,
    slot: &[usize],
    nodes: &mut [NodeRows],
) -> (Vec<u32>, Vec<(usize, std::ops::Range<usize>)>) {
    arrivals.sort_unstable_by_key(|&(t, key, _)| (t, key));
    let incoming: Vec<u32> = arrivals.iter().map(|&(_, _, k)| k).collect();
    let mut free_incoming = Vec::new();
    let mut a = 0;
    while a < arrivals.len() {
        let t = arrivals[a].0;
        let mut b = a;
        while b < arrivals.len() && arrivals[b].0 == t {
            b += 1;
        }
        match slot[t] {
            usize::MAX => free_incoming.push((t, a..b)),
            s => nodes[s].incoming = a..b,
        }
        a = b;
    }
    (incoming, free_incoming)
}

#[cfg(test)]
mod tests;
