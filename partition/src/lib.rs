//! Mesh decomposition for the distributed solver (no MPI in here).
//!
//! The input is a global mesh of elements of any kind ([`Cells`]): `num_nodes`, and
//! `elements.nodes(e)` = the global (0-based) node ids of element `e`. The crate
//!
//! 1. partitions the elements over `nparts` ranks with METIS
//!    ([`partition_elements`]), using the face-adjacency dual graph (two
//!    elements are neighbours when they share at least 4 nodes); or METIS
//!    partitions groups of elements cut from the whole by recursive coordinate
//!    bisection ([`partition_for_ranks`], by default from [`GROUPED_RANKS`]
//!    ranks), so that no rank needs METIS on the whole mesh;
//! 2. derives node ownership, ghost elements, ghost nodes and the halo
//!    send/receive lists per rank ([`Decomposition`]).
//!
//! # Ownership and ghost rules
//!
//! * **Elements**: element `e` is owned by rank `element_part[e]`.
//! * **Nodes**: a node is owned by the *lowest-numbered* part among the parts
//!   of the elements that contain it. Nodes in no element are owned by rank 0.
//!   The rule depends only on the element partition, so every rank computes
//!   the same owner for every node without communication.
//! * **Ghost elements** of rank `r`: every element not owned by `r` that
//!   touches at least one node owned by `r` (exactly one layer).
//! * **Ghost nodes** of rank `r`: every node of an owned or ghost element of
//!   `r` that is not owned by `r`.
//! * **Local node numbering**: owned nodes (ascending global id) followed by
//!   ghost nodes (ascending global id), see [`RankPart::local_nodes`].
//! * **Halo lists**: `recv` = ghost nodes grouped by owner rank; `send` = owned
//!   nodes that are ghosts on another rank. Rank `a`'s send list to `b` is
//!   identical (same ids, same order) to rank `b`'s receive list from `a`.
//!
//! # Why these rules
//!
//! The goal is results that are *bitwise identical regardless of the number
//! of ranks*. Because every element touching an owned node is local (owned or
//! ghost), the owner of a node can evaluate the complete nodal sum (internal
//! force, lumped mass, ...) itself, adding the element contributions in
//! ascending global element order (see [`RankPart::local_elements`]). That is
//! exactly the order a serial run uses, so the floating-point sum is the same
//! for 1, 2 or 64 ranks. Ghost node values are never summed across ranks; they
//! are simply overwritten with the owner's value through the halo exchange
//! (`send`/`recv`). The price is the redundant computation on ghost elements.

use std::collections::HashMap;
use std::fmt;

use metis::Idx;

mod cells;
mod graph;
mod groups;
mod metis_lock;
mod ordering;
pub use cells::Cells;
pub use graph::DualGraph;
use graph::NodeElements;
pub use groups::{grouped, Groups, GROUPED_RANKS, GROUP_PARTS};
use metis_lock::{METIS_LOCK, METIS_SEED};
pub use ordering::nested_dissection;

/// Errors from partitioning or building a decomposition.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PartitionError {
    /// `nparts` was zero.
    NoParts,
    /// An element references a node id `>= num_nodes`.
    NodeOutOfRange {
        element: usize,
        node: u32,
        num_nodes: usize,
    },
    /// `element_part.len()` differs from the number of elements.
    PartLengthMismatch {
        element_part_len: usize,
        num_elements: usize,
    },
    /// `element_part[element] >= nparts`.
    PartOutOfRange {
        element: usize,
        part: u32,
        nparts: usize,
    },
    /// The mesh or the part count does not fit METIS' index type (or `u32`).
    TooLarge,
    /// METIS reported an error.
    Metis(String),
    /// A part ended up without elements.
    EmptyPart { part: usize },
}

impl fmt::Display for PartitionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoParts => write!(f, "number of parts must be at least 1"),
            Self::NodeOutOfRange {
                element,
                node,
                num_nodes,
            } => write!(
                f,
                "element {element} references node {node}, but the mesh has only {num_nodes} nodes"
            ),
            Self::PartLengthMismatch {
                element_part_len,
                num_elements,
            } => write!(
                f,
                "element partition has {element_part_len} entries, but the mesh has {num_elements} elements"
            ),
            Self::PartOutOfRange {
                element,
                part,
                nparts,
            } => write!(
                f,
                "element {element} is assigned to part {part}, but there are only {nparts} parts"
            ),
            Self::TooLarge => write!(f, "mesh too large for the METIS index type"),
            Self::Metis(msg) => write!(f, "METIS failed: {msg}"),
            Self::EmptyPart { part } => write!(f, "part {part} received no elements"),
        }
    }
}

impl std::error::Error for PartitionError {}

fn check_mesh(num_nodes: usize, elements: &dyn Cells) -> Result<(), PartitionError> {
    if u32::try_from(elements.count()).is_err() || u32::try_from(num_nodes).is_err() {
        return Err(PartitionError::TooLarge);
    }
    for (e, conn) in (0..elements.count()).map(|e| (e, elements.nodes(e))) {
        if let Some(&node) = conn.iter().find(|&&n| n as usize >= num_nodes) {
            return Err(PartitionError::NodeOutOfRange {
                element: e,
                node,
                num_nodes,
            });
        }
    }
    Ok(())
}

/// Candidate partitions within this imbalance count as "balanced"; among
/// balanced ones the smaller edge cut wins.
const ACCEPTABLE_IMBALANCE: f64 = 1.05;

/// Assigns every element to a part in `0..nparts`.
///
/// `nparts == 1` gives all zeros without calling METIS. Otherwise the
/// face-adjacency dual graph is partitioned with both METIS recursive
/// bisection and k-way (fixed seed, so the result is deterministic); the
/// better one is kept: no empty parts first, then balance within 5 %, then
/// smaller edge cut, then smaller largest part. Disconnected meshes (separate
/// contact bodies) are fine. METIS calls are serialised by a process-wide
/// lock because METIS' random-number state is global (without the lock,
/// concurrent calls from several threads are not reproducible). Should METIS still leave a part empty, elements
/// are moved deterministically (highest id of the largest part) into it.
///
/// With at least as many parts as elements, element e goes to part e and the
/// remaining parts are empty (a rank with nothing to do still takes part).
///
/// Errors: `nparts == 0`, node ids out of range, METIS failures.
pub fn partition_elements(
    num_nodes: usize,
    elements: &dyn Cells,
    nparts: usize,
) -> Result<Vec<u32>, PartitionError> {
    if nparts == 0 {
        return Err(PartitionError::NoParts);
    }
    check_mesh(num_nodes, elements)?;
    let ne = elements.count();
    if nparts == 1 {
        return Ok(vec![0; ne]);
    }
    if nparts >= ne {
        return Ok((0..ne as u32).collect());
    }
    let nparts_idx = Idx::try_from(nparts).map_err(|_| PartitionError::TooLarge)?;

    let graph = DualGraph::new(num_nodes, elements);
    let xadj = to_idx(&graph.xadj)?;
    let adjncy = to_idx(&graph.adjncy)?;
    let run = |kway: bool| metis_partition(&xadj, &adjncy, ne, (nparts, nparts_idx), kway);

    // METIS recommends recursive bisection for small part counts and k-way
    // for larger ones; the preferred method wins ties.
    let (first, second) = if nparts <= 8 {
        (false, true)
    } else {
        (true, false)
    };
    let a = run(first)?;
    let b = run(second)?;
    let key = |p: &[u32]| {
        let sizes = part_sizes(p, nparts);
        let empty = sizes.iter().filter(|&&s| s == 0).count();
        let max = sizes.iter().copied().max().unwrap_or(0);
        let imbalance = max as f64 * nparts as f64 / ne as f64;
        (
            empty,
            imbalance > ACCEPTABLE_IMBALANCE,
            graph.edge_cut(p),
            max,
        )
    };
    let mut part = if key(&b) < key(&a) { b } else { a };

    fill_empty_parts(&mut part, nparts);
    if let Some(p) = part_sizes(&part, nparts).iter().position(|&s| s == 0) {
        return Err(PartitionError::EmptyPart { part: p });
    }
    Ok(part)
}

/// The parts of a group's elements given alone (`elements`, in ascending element order, with
/// their nodes' global ids): the parts [`partition_group`] gives the group, on a rank that
/// holds only the group's elements.
pub fn partition_group_elements(
    elements: &dyn Cells,
    parts: std::ops::Range<usize>,
) -> Result<Vec<u32>, PartitionError> {
    let ids: Vec<u32> = (0..elements.count() as u32).collect();
    partition_ids(elements, &ids, parts)
}

/// The parts of group `g`'s elements (ascending element order): METIS on their dual graph
/// alone ([`partition_elements`], into the group's parts), the parts numbered globally.
pub fn partition_group(
    elements: &dyn Cells,
    groups: &Groups,
    g: usize,
) -> Result<Vec<u32>, PartitionError> {
    partition_ids(elements, &groups.elements(g), groups.parts(g))
}

/// The parts `parts` of the elements `ids` (ascending), by METIS on their dual graph.
fn partition_ids(
    elements: &dyn Cells,
    ids: &[u32],
    parts: std::ops::Range<usize>,
) -> Result<Vec<u32>, PartitionError> {
    let (nodes, sub) = groups::local_mesh(elements, ids);
    let local = partition_elements(nodes, &sub, parts.len())?;
    Ok(local.iter().map(|&p| p + parts.start as u32).collect())
}

/// The partition over `nparts` ranks as a run makes it: by `groups` of the centres, each
/// partitioned by METIS ([`partition_group`]; all of them here, a run partitions only its
/// own group on each rank, the same parts), or METIS on the whole mesh (also with groups
/// for at most GROUP_PARTS parts, or at least as many parts as elements: element e to
/// part e).
pub fn partition_for_ranks(
    num_nodes: usize,
    elements: &dyn Cells,
    centres: &[[f64; 3]],
    nparts: usize,
    groups: bool,
) -> Result<Vec<u32>, PartitionError> {
    if !(groups && grouped(elements.count(), nparts)) {
        return partition_elements(num_nodes, elements, nparts);
    }
    check_mesh(num_nodes, elements)?;
    let groups = Groups::new(centres, nparts);
    let lists = groups
        .members()
        .iter()
        .enumerate()
        .map(|(g, ids)| partition_ids(elements, ids, groups.parts(g)))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(groups.assemble(|g| &lists[g]))
}

/// Node owner: lowest part among the node's elements; orphans -> 0.
fn node_owners(num_nodes: usize, elements: &dyn Cells, element_part: &[u32]) -> Vec<u32> {
    let mut node_owner = vec![u32::MAX; num_nodes];
    for (conn, &p) in (0..elements.count())
        .map(|e| elements.nodes(e))
        .zip(element_part)
    {
        for &n in conn {
            let o = &mut node_owner[n as usize];
            *o = (*o).min(p);
        }
    }
    for o in &mut node_owner {
        if *o == u32::MAX {
            *o = 0;
        }
    }
    node_owner
}

/// What finding a rank's ghosts needs: the mesh, the ownership and scratch marks.
struct Halo<'a> {
    elements: &'a dyn Cells,
    element_part: &'a [u32],
    node_owner: &'a [u32],
    n2e: NodeElements,
    elem_mark: Vec<bool>,
    node_mark: Vec<bool>,
}

impl Halo<'_> {
    /// Rank `rank`'s part: its ghost elements (touching its owned nodes), ghost nodes (of
    /// its owned and ghost elements) and the receive lists, grouped by owner.
    fn rank_part(
        &mut self,
        rank: usize,
        owned_elements: Vec<u32>,
        owned_nodes: Vec<u32>,
    ) -> RankPart {
        let r = rank as u32;
        let (element_part, node_owner) = (self.element_part, self.node_owner);
        let mut ghost_elements = Vec::new();
        for &n in &owned_nodes {
            for &e in self.n2e.of(n) {
                if element_part[e as usize] != r && !self.elem_mark[e as usize] {
                    self.elem_mark[e as usize] = true;
                    ghost_elements.push(e);
                }
            }
        }
        for &e in &ghost_elements {
            self.elem_mark[e as usize] = false;
        }
        ghost_elements.sort_unstable();

        let mut ghost_nodes = Vec::new();
        for &e in owned_elements.iter().chain(&ghost_elements) {
            for &n in self.elements.nodes(e as usize) {
                if node_owner[n as usize] != r && !self.node_mark[n as usize] {
                    self.node_mark[n as usize] = true;
                    ghost_nodes.push(n);
                }
            }
        }
        for &n in &ghost_nodes {
            self.node_mark[n as usize] = false;
        }
        ghost_nodes.sort_unstable();

        // Group ghosts by owner rank, ids ascending within each group.
        let mut by_owner: Vec<(usize, Vec<u32>)> = Vec::new();
        let mut sorted_by_owner = ghost_nodes.clone();
        sorted_by_owner.sort_by_key(|&n| (node_owner[n as usize], n));
        for n in sorted_by_owner {
            let o = node_owner[n as usize] as usize;
            match by_owner.last_mut() {
                Some((last, list)) if *last == o => list.push(n),
                _ => by_owner.push((o, vec![n])),
            }
        }

        RankPart {
            rank,
            owned_elements,
            ghost_elements,
            owned_nodes,
            ghost_nodes,
            recv: by_owner,
            send: Vec::new(),
        }
    }
}

/// Send lists mirror the receive lists: iterate receivers in ascending rank so every send
/// list ends up sorted by destination rank.
fn mirror_sends(parts: &mut [RankPart]) {
    let mut sends: Vec<Vec<(usize, Vec<u32>)>> = vec![Vec::new(); parts.len()];
    for part in parts.iter() {
        for (owner, list) in &part.recv {
            sends[*owner].push((part.rank, list.clone()));
        }
    }
    for (part, send) in parts.iter_mut().zip(sends) {
        part.send = send;
    }
}

/// Graph indices as METIS' integer type.
fn to_idx<T: Copy>(v: &[T]) -> Result<Vec<Idx>, PartitionError>
where
    Idx: TryFrom<T>,
{
    v.iter()
        .map(|&x| Idx::try_from(x))
        .collect::<Result<Vec<Idx>, _>>()
        .map_err(|_| PartitionError::TooLarge)
}

/// One METIS partition of the graph (xadj, adjncy) into `nparts` parts, by k-way or by
/// recursive bisection, with the fixed seed and under the process-wide lock.
fn metis_partition(
    xadj: &[Idx],
    adjncy: &[Idx],
    ne: usize,
    (nparts, nparts_idx): (usize, Idx),
    kway: bool,
) -> Result<Vec<u32>, PartitionError> {
    let mut part: Vec<Idx> = vec![0; ne];
    // A poisoned lock only means another METIS call panicked; the global
    // state is re-seeded by every call, so carry on.
    let _guard = METIS_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let g = metis::Graph::new(1, nparts_idx, xadj, adjncy)
        .map_err(|e| PartitionError::Metis(e.to_string()))?
        .set_option(metis::option::Seed(METIS_SEED));
    if kway {
        g.part_kway(&mut part)
    } else {
        g.part_recursive(&mut part)
    }
    .map_err(|e| PartitionError::Metis(e.to_string()))?;
    part.into_iter()
        .map(|p| match u32::try_from(p) {
            Ok(p) if (p as usize) < nparts => Ok(p),
            _ => Err(PartitionError::Metis(format!(
                "returned part {p} outside 0..{nparts}"
            ))),
        })
        .collect()
}

fn part_sizes(element_part: &[u32], nparts: usize) -> Vec<usize> {
    let mut sizes = vec![0usize; nparts];
    for &p in element_part {
        sizes[p as usize] += 1;
    }
    sizes
}

/// Deterministic repair: while a part is empty, move the highest-id element
/// of the largest part (lowest index on ties) into it.
fn fill_empty_parts(element_part: &mut [u32], nparts: usize) {
    let mut sizes = part_sizes(element_part, nparts);
    while let Some(empty) = sizes.iter().position(|&s| s == 0) {
        let (largest, &size) = sizes
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.cmp(b.1).then(b.0.cmp(&a.0)))
            .expect("nparts >= 1");
        if size < 2 {
            return; // more parts than elements: caller reports the error
        }
        let e = element_part
            .iter()
            .rposition(|&p| p as usize == largest)
            .expect("largest part is non-empty");
        element_part[e] = empty as u32;
        sizes[largest] -= 1;
        sizes[empty] += 1;
    }
}

/// What one rank holds. All id lists are global ids in ascending order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RankPart {
    /// This rank.
    pub rank: usize,
    /// Elements assigned to this rank.
    pub owned_elements: Vec<u32>,
    /// Elements of other ranks touching at least one node owned here.
    pub ghost_elements: Vec<u32>,
    /// Nodes owned by this rank.
    pub owned_nodes: Vec<u32>,
    /// Nodes of owned or ghost elements that are owned elsewhere.
    pub ghost_nodes: Vec<u32>,
    /// `(owner rank, ghost nodes owned by it)`, ascending rank, non-empty lists.
    pub recv: Vec<(usize, Vec<u32>)>,
    /// `(rank, owned nodes that are ghosts there)`, ascending rank, non-empty lists.
    pub send: Vec<(usize, Vec<u32>)>,
}

impl RankPart {
    /// Number of owned nodes; local indices `0..num_owned_nodes()` are owned.
    pub fn num_owned_nodes(&self) -> usize {
        self.owned_nodes.len()
    }

    /// Number of local (owned + ghost) nodes.
    pub fn num_local_nodes(&self) -> usize {
        self.owned_nodes.len() + self.ghost_nodes.len()
    }

    /// Local nodes in local index order: owned (ascending) then ghost (ascending).
    pub fn local_nodes(&self) -> Vec<u32> {
        let mut v = Vec::with_capacity(self.num_local_nodes());
        v.extend_from_slice(&self.owned_nodes);
        v.extend_from_slice(&self.ghost_nodes);
        v
    }

    /// Local index of a global node, `None` if the node is not local.
    /// Binary search on the two sorted lists; no map needed.
    pub fn local_node_index(&self, global: u32) -> Option<u32> {
        if let Ok(i) = self.owned_nodes.binary_search(&global) {
            return Some(i as u32);
        }
        self.ghost_nodes
            .binary_search(&global)
            .ok()
            .map(|i| (self.owned_nodes.len() + i) as u32)
    }

    /// Global -> local node index map (same result as [`Self::local_node_index`]).
    pub fn global_to_local(&self) -> HashMap<u32, u32> {
        self.owned_nodes
            .iter()
            .chain(&self.ghost_nodes)
            .enumerate()
            .map(|(i, &g)| (g, i as u32))
            .collect()
    }

    /// Owned and ghost elements merged in ascending global id: the order in
    /// which element contributions must be summed for rank-count-independent
    /// results.
    pub fn local_elements(&self) -> Vec<u32> {
        let (a, b) = (&self.owned_elements, &self.ghost_elements);
        let mut v = Vec::with_capacity(a.len() + b.len());
        let (mut i, mut j) = (0, 0);
        while i < a.len() && j < b.len() {
            if a[i] < b[j] {
                v.push(a[i]);
                i += 1;
            } else {
                v.push(b[j]);
                j += 1;
            }
        }
        v.extend_from_slice(&a[i..]);
        v.extend_from_slice(&b[j..]);
        v
    }

    /// Whether global element `e` is owned by this rank.
    pub fn owns_element(&self, e: u32) -> bool {
        self.owned_elements.binary_search(&e).is_ok()
    }

    /// Whether global node `n` is owned by this rank.
    pub fn owns_node(&self, n: u32) -> bool {
        self.owned_nodes.binary_search(&n).is_ok()
    }
}

/// The decomposition of the whole mesh: every rank's [`RankPart`], the
/// element partition and the node owners. Identical on every rank when built
/// from the same input.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Decomposition {
    nparts: usize,
    element_part: Vec<u32>,
    node_owner: Vec<u32>,
    parts: Vec<RankPart>,
    edge_cut: usize,
}

impl Decomposition {
    /// Builds the decomposition from an element partition.
    ///
    /// # Panics
    /// On invalid input (see [`Decomposition::try_new`] for the conditions).
    pub fn new(
        num_nodes: usize,
        elements: &dyn Cells,
        element_part: &[u32],
        nparts: usize,
    ) -> Decomposition {
        Self::try_new(num_nodes, elements, element_part, nparts)
            .unwrap_or_else(|e| panic!("invalid decomposition input: {e}"))
    }

    /// Builds the decomposition from an element partition. Errors if
    /// `nparts == 0`, a node id is out of range, `element_part` has the wrong
    /// length or contains a part `>= nparts`. Empty parts are allowed here
    /// (such a rank just has empty lists, plus orphan nodes on rank 0).
    pub fn try_new(
        num_nodes: usize,
        elements: &dyn Cells,
        element_part: &[u32],
        nparts: usize,
    ) -> Result<Decomposition, PartitionError> {
        if nparts == 0 {
            return Err(PartitionError::NoParts);
        }
        if u32::try_from(nparts).is_err() {
            return Err(PartitionError::TooLarge);
        }
        check_mesh(num_nodes, elements)?;
        if element_part.len() != elements.count() {
            return Err(PartitionError::PartLengthMismatch {
                element_part_len: element_part.len(),
                num_elements: elements.count(),
            });
        }
        if let Some((e, &p)) = element_part
            .iter()
            .enumerate()
            .find(|(_, &p)| p as usize >= nparts)
        {
            return Err(PartitionError::PartOutOfRange {
                element: e,
                part: p,
                nparts,
            });
        }

        let node_owner = node_owners(num_nodes, elements, element_part);
        let mut owned_elements = vec![Vec::new(); nparts];
        for (e, &p) in element_part.iter().enumerate() {
            owned_elements[p as usize].push(e as u32);
        }
        let mut owned_nodes = vec![Vec::new(); nparts];
        for (n, &o) in node_owner.iter().enumerate() {
            owned_nodes[o as usize].push(n as u32);
        }

        let mut halo = Halo {
            elements,
            element_part,
            node_owner: &node_owner,
            n2e: NodeElements::new(num_nodes, elements),
            elem_mark: vec![false; elements.count()],
            node_mark: vec![false; num_nodes],
        };
        let mut parts: Vec<RankPart> = owned_elements
            .into_iter()
            .zip(owned_nodes)
            .enumerate()
            .map(|(rank, (owned_elements, owned_nodes))| {
                halo.rank_part(rank, owned_elements, owned_nodes)
            })
            .collect();
        mirror_sends(&mut parts);

        let edge_cut = graph::edge_cut(&halo.n2e, elements, element_part);
        drop(halo);
        Ok(Decomposition {
            nparts,
            element_part: element_part.to_vec(),
            node_owner,
            parts,
            edge_cut,
        })
    }

    /// Convenience: [`partition_elements`] followed by [`Decomposition::try_new`].
    pub fn partition(
        num_nodes: usize,
        elements: &dyn Cells,
        nparts: usize,
    ) -> Result<Decomposition, PartitionError> {
        let element_part = partition_elements(num_nodes, elements, nparts)?;
        Self::try_new(num_nodes, elements, &element_part, nparts)
    }

    /// Number of parts (ranks).
    pub fn nparts(&self) -> usize {
        self.nparts
    }

    /// The part of rank `rank`.
    pub fn part(&self, rank: usize) -> &RankPart {
        &self.parts[rank]
    }

    /// All parts, indexed by rank.
    pub fn parts(&self) -> &[RankPart] {
        &self.parts
    }

    /// Element -> owning rank.
    pub fn element_part(&self) -> &[u32] {
        &self.element_part
    }

    /// Node -> owning rank.
    pub fn node_owner(&self) -> &[u32] {
        &self.node_owner
    }

    /// Number of face-adjacency (dual graph) edges between different parts.
    pub fn edge_cut(&self) -> usize {
        self.edge_cut
    }

    /// Load-balance and halo statistics.
    pub fn stats(&self) -> DecompositionStats {
        let owned_elements: Vec<usize> =
            self.parts.iter().map(|p| p.owned_elements.len()).collect();
        let total: usize = owned_elements.iter().sum();
        let max = owned_elements.iter().copied().max().unwrap_or(0);
        let imbalance = if total == 0 {
            1.0
        } else {
            max as f64 * self.nparts as f64 / total as f64
        };
        DecompositionStats {
            nparts: self.nparts,
            imbalance,
            edge_cut: self.edge_cut,
            owned_elements,
            ghost_elements: self.parts.iter().map(|p| p.ghost_elements.len()).collect(),
            owned_nodes: self.parts.iter().map(|p| p.owned_nodes.len()).collect(),
            ghost_nodes: self.parts.iter().map(|p| p.ghost_nodes.len()).collect(),
        }
    }
}

/// Summary of a [`Decomposition`]; per-rank vectors are indexed by rank.
#[derive(Debug, Clone, PartialEq)]
pub struct DecompositionStats {
    pub nparts: usize,
    /// max owned elements / mean owned elements (1.0 = perfect).
    pub imbalance: f64,
    /// Dual-graph edges between different parts.
    pub edge_cut: usize,
    pub owned_elements: Vec<usize>,
    pub ghost_elements: Vec<usize>,
    pub owned_nodes: Vec<usize>,
    pub ghost_nodes: Vec<usize>,
}

impl fmt::Display for DecompositionStats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "decomposition: {} part(s), element imbalance {:.3} (max/mean), edge cut {}",
            self.nparts, self.imbalance, self.edge_cut
        )?;
        writeln!(
            f,
            "{:>6} {:>12} {:>12} {:>12} {:>12}",
            "rank", "own elems", "ghost elems", "own nodes", "ghost nodes"
        )?;
        for r in 0..self.nparts {
            writeln!(
                f,
                "{:>6} {:>12} {:>12} {:>12} {:>12}",
                r,
                self.owned_elements[r],
                self.ghost_elements[r],
                self.owned_nodes[r],
                self.ghost_nodes[r]
            )?;
        }
        Ok(())
    }
}

impl fmt::Display for Decomposition {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.stats().fmt(f)
    }
}

#[cfg(test)]
mod tests;
