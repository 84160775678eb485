//! Colours of the fine-level aggregates for measuring the first coarse operator
//! Kc = Q^T A Q: one operator application per colour and mode gives, for every aggregate k,
//! its coupling to the one aggregate of that colour it sees. Two aggregates j, j' may share
//! a colour only if no aggregate k couples to both. Coupling follows the constrained
//! operator T^T K T: a probe on aggregate j reaches the slaves tied to its nodes (expand),
//! then their element neighbours (K), then the masters of the constrained nodes among those
//! (reduce). Computed from global data (the node graph, every rank's tie rows gathered in
//! global order), greedily in aggregate order: the same on any number of ranks.

use super::aggregation::{Graph, NodeElements};
use crate::comm::{message, Comm};
use crate::constraints::Constraints;
use crate::mesh::local::LocalMesh;
use crate::mesh::Connectivity;

pub struct Colouring {
    pub colour: Vec<u16>,
    pub num_colours: usize,
    /// For aggregate k, the aggregates it couples to, with their colours:
    /// seen[seen_ptr[k]..seen_ptr[k + 1]] as (colour, aggregate), sorted by colour.
    seen_ptr: Vec<usize>,
    seen: Vec<(u16, u32)>,
    /// Per colour, the pairs (k, j): aggregate k sees aggregate j of that colour.
    by_colour: Vec<Vec<(u32, u32)>>,
}

/// Master and slave lists of every tie, in global node ids.
#[derive(PartialEq)]
pub struct Ties {
    /// masters of node a: masters[ptr[a]..ptr[a + 1]].
    m_ptr: Vec<usize>,
    masters: Vec<u32>,
    /// slaves of node a.
    s_ptr: Vec<usize>,
    slaves: Vec<u32>,
}

impl Ties {
    /// Gathers the tie rows of every rank (collective).
    pub fn gather<C: Comm + ?Sized>(
        comm: &C,
        cons: &Constraints,
        mesh: &LocalMesh,
        n: usize,
    ) -> Self {
        let mut mine = Vec::new();
        for l in 0..mesh.num_owned_nodes {
            let gid = mesh.node_global[l];
            for (_, row) in cons.rows(l) {
                for &(m, _) in &row.masters {
                    mine.push((gid, m));
                }
            }
        }
        let pairs: Vec<(u32, u32)> = if comm.size() == 1 {
            mine
        } else {
            message::all_gather(comm, &mine)
        };
        Ties::from_pairs(n, pairs)
    }

    /// From (slave, master) pairs in any order.
    pub fn from_pairs(n: usize, mut pairs: Vec<(u32, u32)>) -> Self {
        pairs.sort_unstable();
        pairs.dedup();
        let csr = |p: &[(u32, u32)]| {
            let mut ptr = vec![0usize; n + 1];
            for &(a, _) in p {
                ptr[a as usize + 1] += 1;
            }
            for i in 0..n {
                ptr[i + 1] += ptr[i];
            }
            (ptr, p.iter().map(|&(_, b)| b).collect::<Vec<u32>>())
        };
        let (m_ptr, masters) = csr(&pairs);
        let mut rev: Vec<(u32, u32)> = pairs.iter().map(|&(s, m)| (m, s)).collect();
        rev.sort_unstable();
        let (s_ptr, slaves) = csr(&rev);
        Ties {
            m_ptr,
            masters,
            s_ptr,
            slaves,
        }
    }

    fn masters(&self, a: usize) -> &[u32] {
        &self.masters[self.m_ptr[a]..self.m_ptr[a + 1]]
    }

    fn slaves(&self, a: usize) -> &[u32] {
        &self.slaves[self.s_ptr[a]..self.s_ptr[a + 1]]
    }
}

/// Adds to `set` (marked in `mark` with `stamp`) every node reachable through `next`,
/// transitively (chains of ties).
fn close(set: &mut Vec<u32>, mark: &mut [u32], stamp: u32, next: impl Fn(usize) -> Vec<u32>) {
    let mut i = 0;
    while i < set.len() {
        for b in next(set[i] as usize) {
            if mark[b as usize] != stamp {
                mark[b as usize] = stamp;
                set.push(b);
            }
        }
        i += 1;
    }
}

/// The neighbours of every node of a graph: a node's neighbours, each at least once, in any
/// order (the colouring uses the sets only).
pub trait Neighbours {
    /// Nodes of the graph.
    fn nodes(&self) -> usize;
    fn each(&self, a: usize, f: impl FnMut(u32));
}

impl Neighbours for Graph {
    fn nodes(&self) -> usize {
        self.len()
    }
    fn each(&self, a: usize, f: impl FnMut(u32)) {
        self.neighbours(a).iter().copied().for_each(f);
    }
}

/// The node graph of a hexahedral mesh from the elements around each node (a node itself
/// comes among its neighbours, and some twice).
pub struct MeshNeighbours<'a> {
    pub around: &'a NodeElements,
    pub elements: &'a Connectivity,
}

impl Neighbours for MeshNeighbours<'_> {
    fn nodes(&self) -> usize {
        self.around.len()
    }
    fn each(&self, a: usize, f: impl FnMut(u32)) {
        self.around.each_neighbour(self.elements, a, f);
    }
}

/// reach[reach_ptr[j]..reach_ptr[j + 1]]: the aggregates a probe on aggregate j reaches.
pub(super) fn reach_of(
    graph: &impl Neighbours,
    agg_of: &[u32],
    num_aggs: usize,
    ties: &Ties,
) -> (Vec<usize>, Vec<u32>) {
    let n = graph.nodes();
    let mut members: Vec<Vec<u32>> = vec![Vec::new(); num_aggs];
    for a in 0..n {
        members[agg_of[a] as usize].push(a as u32);
    }
    let mut mark = vec![u32::MAX; n];
    let mut amark = vec![u32::MAX; num_aggs];
    let mut reach_ptr = vec![0usize];
    let mut reach: Vec<u32> = Vec::new();
    let mut set: Vec<u32> = Vec::new();
    for (j, nodes) in members.iter().enumerate() {
        let stamp = 2 * j as u32;
        set.clear();
        for &a in nodes {
            mark[a as usize] = stamp;
            set.push(a);
        }
        close(&mut set, &mut mark, stamp, |a| ties.slaves(a).to_vec());
        let stamp2 = stamp + 1;
        let mut near: Vec<u32> = Vec::with_capacity(set.len() * 8);
        for &a in &set {
            if mark[a as usize] != stamp2 {
                mark[a as usize] = stamp2;
                near.push(a);
            }
            graph.each(a as usize, |b| {
                if mark[b as usize] != stamp2 {
                    mark[b as usize] = stamp2;
                    near.push(b);
                }
            });
        }
        close(&mut near, &mut mark, stamp2, |a| ties.masters(a).to_vec());
        for &a in &near {
            let k = agg_of[a as usize];
            if amark[k as usize] != j as u32 {
                amark[k as usize] = j as u32;
                reach.push(k);
            }
        }
        reach_ptr.push(reach.len());
    }
    (reach_ptr, reach)
}

/// For each aggregate, the (colour, aggregate) pairs that reach it.
type SeenBy = Vec<Vec<(u16, u32)>>;

/// Greedy colouring: j takes the lowest colour no aggregate it reaches has seen yet.
/// Returns the colours, their number and, for each aggregate, the (colour, aggregate)
/// pairs that reach it.
fn greedy_colours(
    reach_ptr: &[usize],
    reach: &[u32],
    num_aggs: usize,
) -> (Vec<u16>, usize, SeenBy) {
    let mut colour = vec![0u16; num_aggs];
    let mut seen_by: SeenBy = vec![Vec::new(); num_aggs];
    let mut taken: Vec<bool> = Vec::new();
    let mut num_colours = 0usize;
    for j in 0..num_aggs {
        taken.iter_mut().for_each(|t| *t = false);
        let r = &reach[reach_ptr[j]..reach_ptr[j + 1]];
        for &k in r {
            for &(c, _) in &seen_by[k as usize] {
                taken[c as usize] = true;
            }
        }
        let c = taken.iter().position(|&t| !t).unwrap_or(taken.len());
        if c == taken.len() {
            taken.push(false);
            num_colours += 1;
        }
        colour[j] = c as u16;
        for &k in r {
            seen_by[k as usize].push((c as u16, j as u32));
        }
    }
    (colour, num_colours, seen_by)
}

impl Colouring {
    /// Colours the aggregates `agg_of` (of every global node) of the node graph with ties.
    pub fn new(graph: &impl Neighbours, agg_of: &[u32], num_aggs: usize, ties: &Ties) -> Self {
        let (reach_ptr, reach) = reach_of(graph, agg_of, num_aggs, ties);
        let (colour, num_colours, seen_by) = greedy_colours(&reach_ptr, &reach, num_aggs);
        let mut seen_ptr = vec![0usize];
        let mut seen = Vec::new();
        let mut by_colour = vec![Vec::new(); num_colours];
        for (k, mut s) in seen_by.into_iter().enumerate() {
            s.sort_unstable();
            for &(c, j) in &s {
                by_colour[c as usize].push((k as u32, j));
            }
            seen.extend(s);
            seen_ptr.push(seen.len());
        }
        Colouring {
            colour,
            num_colours,
            seen_ptr,
            seen,
            by_colour,
        }
    }

    /// The pairs (k, j) of colour c: aggregate k sees aggregate j.
    pub fn pairs(&self, c: usize) -> &[(u32, u32)] {
        &self.by_colour[c]
    }

    /// The aggregates k couples to: (colour, aggregate).
    pub fn seen(&self, k: usize) -> &[(u16, u32)] {
        &self.seen[self.seen_ptr[k]..self.seen_ptr[k + 1]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aggregates_sharing_a_colour_are_never_seen_together() {
        // A path of 12 nodes in 6 aggregates of two; a tie makes node 11 a slave of node 0.
        let edges: Vec<(u32, u32)> = (0..11).map(|i| (i, i + 1)).collect();
        let g = Graph::from_edges(12, &edges);
        let agg_of: Vec<u32> = (0..12).map(|a| a / 2).collect();
        for ties in [
            Ties::from_pairs(12, vec![]),
            Ties::from_pairs(12, vec![(11, 0)]),
        ] {
            let c = Colouring::new(&g, &agg_of, 6, &ties);
            for k in 0..6 {
                let s = c.seen(k);
                for w in s.windows(2) {
                    assert_ne!(w[0].0, w[1].0, "aggregate {k} sees two of one colour");
                }
                for &(col, j) in s {
                    assert_eq!(c.colour[j as usize], col);
                }
            }
            // Without the tie: aggregates j and j+1 are neighbours; j sees j-1, j, j+1.
            assert!(c.num_colours >= 3);
        }
        // With the tie, aggregate 0 sees aggregate 5 (the slave's aggregate) and the
        // slave's neighbours; aggregate 5's probe reaches aggregate 0 through the master.
        let c = Colouring::new(&g, &agg_of, 6, &Ties::from_pairs(12, vec![(11, 0)]));
        assert!(c.seen(0).iter().any(|&(_, j)| j == 5));
        assert!(c.seen(5).iter().any(|&(_, j)| j == 0));
    }

    #[test]
    fn the_mesh_neighbours_colour_as_the_node_graph_does() {
        // Three elements in a row (16 nodes), aggregates of four nodes, a tie from the far
        // end's node to the first: the colouring from the elements around each node is
        // the one from the node graph.
        let mesh = crate::mesh::hexahedra_in_a_row(vec![[0.0; 3]; 16]);
        let around = NodeElements::of_mesh(&mesh);
        let by_elements = MeshNeighbours {
            around: &around,
            elements: &mesh.elements,
        };
        let graph = Graph::of_mesh(&mesh);
        let agg_of: Vec<u32> = (0..16).map(|a| a / 4).collect();
        for ties in [vec![], vec![(15, 0)], vec![(15, 0), (12, 3)]] {
            let a = Colouring::new(&graph, &agg_of, 4, &Ties::from_pairs(16, ties.clone()));
            let b = Colouring::new(&by_elements, &agg_of, 4, &Ties::from_pairs(16, ties));
            assert_eq!((&a.colour, a.num_colours), (&b.colour, b.num_colours));
            assert_eq!((&a.seen_ptr, &a.seen), (&b.seen_ptr, &b.seen));
            assert_eq!(a.by_colour, b.by_colour);
        }
    }
}
