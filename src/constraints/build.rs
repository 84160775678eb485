//! Building a constraint set, phase by phase: the rows of each node, where each master's
//! value lives, the dependency depth of every node, the order by level, and per level the
//! exchanges of master values and of the forces the ties pass on.

use super::rows::{
    invert_small, CircularDependency, Level, NodeRows, RowKind, RowSpec, Src, MAX_DEPTH,
};
use crate::comm::{self, message, plan, Comm, ExchangePlan};
use crate::math::{dot, Vec3, IDENTITY};
use crate::mesh::local::LocalMesh;
use std::collections::HashMap;

/// Each owned node's rows in the order given, with an orthonormal basis of their
/// directions; a row in the span of the node's earlier ones is dropped (listed with its
/// node). Also the slot of each local node in the list (usize::MAX when it has no rows).
#[allow(clippy::type_complexity)]
pub(super) fn node_rows(
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
                // Most constrained nodes have one row (a plane-strain slab's every node):
                // the default first growth to 4 rows took 288 bytes for its 72.
                rows: Vec::with_capacity(1),
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
pub(super) fn locate_masters(
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
pub(super) fn depths<C: Comm + ?Sized>(
    comm: &C,
    mesh: &LocalMesh,
    nodes: &[NodeRows],
    (remote_global, remote_owner): (&[u32], &[usize]),
) -> Result<Vec<usize>, CircularDependency> {
    let everything: Vec<(u32, u32)> = remote_global
        .iter()
        .enumerate()
        .map(|(k, &g)| (g, k as u32))
        .collect();
    let all = ExchangePlan::fetch(comm, &everything, remote_owner, |g| mesh.owned_node(g));
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
pub(super) fn order_by_level(
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

/// A row entry: (slave node's global id, row of the node, master of the row).
pub(super) type Key = (u32, u32, u32);

/// A force a tie passes to a master node: (target local node, key of the row entry, force
/// slot).
pub(super) type Arrival = (usize, Key, u32);

/// Per level: the remote masters it reads, and the forces its ties pass on. A force slot
/// per (node, row, master); a received force gets a slot of its own. `remote_owner`: the
/// owner of each remote master (by its index in the node rows' `Src::Remote`). Returns
/// the levels, the number of slots and every force's arrival. Collective.
pub(super) fn force_routes<C: Comm + ?Sized>(
    comm: &C,
    mesh: &LocalMesh,
    nodes: &mut [NodeRows],
    (level_of, num_levels): (&[usize], usize),
    remote_owner: &[usize],
) -> (Vec<Level>, usize, Vec<Arrival>) {
    let mut levels = Vec::with_capacity(num_levels);
    let mut num_slots = 0usize;
    let mut arrivals: Vec<Arrival> = Vec::new();
    for level in 0..num_levels {
        let start = level_of.partition_point(|&d| d < level);
        let end = level_of.partition_point(|&d| d <= level);
        let mut wanted: Vec<(u32, u32)> = Vec::new();
        // (master node, key of the row entry) to the master's owner.
        let mut push: Vec<Vec<(u32, Key)>> = vec![Vec::new(); comm.size()];
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
                            let r = remote_owner[q as usize];
                            push[r].push((m, key));
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
        let owners: Vec<usize> = wanted
            .iter()
            .map(|&(_, q)| remote_owner[q as usize])
            .collect();
        let fetch = ExchangePlan::fetch(comm, &wanted, &owners, |g| mesh.owned_node(g));
        let received = message::all_to_all(comm, &push);
        let mut plan = ExchangePlan {
            send: plan::nonempty(push_slots),
            recv: Vec::new(),
        };
        for (r, msg) in received.into_iter().enumerate() {
            if msg.is_empty() {
                continue;
            }
            let mut slots = Vec::with_capacity(msg.len());
            for (master, key) in msg {
                let target = mesh
                    .owned_node(master)
                    .expect("a force is pushed to the master's owner");
                let k = num_slots as u32;
                num_slots += 1;
                slots.push(k);
                arrivals.push((target, key, k));
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
pub(super) fn incoming(
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
