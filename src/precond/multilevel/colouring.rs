//! Colours of the fine-level aggregates for measuring the first coarse operator
//! Kc = Q^T A Q: one operator application per colour and mode gives, for every aggregate k,
//! its coupling to the one aggregate of that colour it sees. Two aggregates j, j' may share
//! a colour only if no aggregate k couples to both. Coupling follows the constrained
//! operator T^T K T: a probe on aggregate j reaches the slaves tied to its nodes (expand),
//! then their element neighbours (K), then the masters of the constrained nodes among those
//! (reduce). What each aggregate reaches is found by the ranks, each from its owned nodes'
//! elements (`reach_pairs`) and every rank's tie rows, gathered and sorted; the colours
//! are given greedily in aggregate order: the same on any number of ranks. (`reach_of`
//! forms the same sets from a whole node graph: the memory estimate's count before a run.)

use super::aggregation::Graph;
use super::around::NodeElements;
use crate::comm::{message, Comm};
use crate::constraints::Constraints;
use crate::mesh::local::LocalMesh;

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

/// Master and slave lists of every tie, in global node ids: the (slave, master) pairs
/// sorted both ways, searched (their size is the ties', not the mesh's).
#[derive(PartialEq)]
pub struct Ties {
    /// (slave, master), ascending.
    by_slave: Vec<(u32, u32)>,
    /// (master, slave), ascending.
    by_master: Vec<(u32, u32)>,
}

/// The second members of the pairs whose first is `a` (`pairs` ascending).
fn paired(pairs: &[(u32, u32)], a: u32) -> impl Iterator<Item = u32> + '_ {
    let lo = pairs.partition_point(|p| p.0 < a);
    pairs[lo..]
        .iter()
        .take_while(move |p| p.0 == a)
        .map(|p| p.1)
}

impl Ties {
    /// Gathers the tie rows of every rank (collective).
    pub fn gather<C: Comm + ?Sized>(comm: &C, cons: &Constraints, mesh: &LocalMesh) -> Self {
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
        Ties::from_pairs(pairs)
    }

    /// From (slave, master) pairs in any order.
    pub fn from_pairs(mut pairs: Vec<(u32, u32)>) -> Self {
        pairs.sort_unstable();
        pairs.dedup();
        let mut by_master: Vec<(u32, u32)> = pairs.iter().map(|&(s, m)| (m, s)).collect();
        by_master.sort_unstable();
        Ties {
            by_slave: pairs,
            by_master,
        }
    }

    fn masters(&self, a: u32) -> impl Iterator<Item = u32> + '_ {
        paired(&self.by_slave, a)
    }

    fn slaves(&self, a: u32) -> impl Iterator<Item = u32> + '_ {
        paired(&self.by_master, a)
    }

    /// Every node that is a master of some tie, ascending, once each.
    fn master_nodes(&self) -> impl Iterator<Item = u32> + '_ {
        let mut last = None;
        self.by_master
            .iter()
            .map(|&(m, _)| m)
            .filter(move |&m| last.replace(m) != Some(m))
    }
}

/// The aggregate of every node a rank's colouring looks up: its local nodes' (owned, then
/// ghosts, by local index) and the tie masters' wherever they are (gathered from their
/// owners, ascending by global id): not every node of the mesh.
pub struct NodeAggregates<'a> {
    local: &'a [u32],
    masters: Vec<(u32, u32)>,
}

impl<'a> NodeAggregates<'a> {
    /// From the local nodes' aggregates and (master, aggregate) pairs in any order.
    pub fn new(local: &'a [u32], mut masters: Vec<(u32, u32)>) -> Self {
        masters.sort_unstable();
        masters.dedup();
        NodeAggregates { local, masters }
    }

    /// The local nodes' aggregates `local` (of `mesh`) with those of every tie's masters,
    /// each sent by the rank that owns it (collective).
    pub fn gather<C: Comm + ?Sized>(
        comm: &C,
        mesh: &LocalMesh,
        local: &'a [u32],
        ties: &Ties,
    ) -> Self {
        let mine: Vec<(u32, u32)> = ties
            .master_nodes()
            .filter_map(|m| mesh.owned_node(m).map(|l| (m, local[l])))
            .collect();
        let masters = if comm.size() == 1 {
            mine
        } else {
            message::all_gather(comm, &mine)
        };
        Self::new(local, masters)
    }

    /// The aggregate of tie master `m`.
    fn master(&self, m: u32) -> u32 {
        let i = self
            .masters
            .binary_search_by_key(&m, |p| p.0)
            .expect("every tie's master has its aggregate gathered");
        self.masters[i].1
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
        close(&mut set, &mut mark, stamp, |a| {
            ties.slaves(a as u32).collect()
        });
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
        close(&mut near, &mut mark, stamp2, |a| {
            ties.masters(a as u32).collect()
        });
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

/// The masters of node `a` closed over chains of ties, `a` first (M*(a)).
fn masters_closure(ties: &Ties, a: u32, out: &mut Vec<u32>) {
    out.clear();
    out.push(a);
    let mut i = 0;
    while i < out.len() {
        for m in ties.masters(out[i]) {
            if !out.contains(&m) {
                out.push(m);
            }
        }
        i += 1;
    }
}

/// The pairs (j, k), aggregate j's probe reaches aggregate k, that this rank's owned nodes
/// give. `reach_of` forms reach(j) = agg(M*(N[S(j)])): S(j) the nodes of j with the slaves
/// tied to them (transitively), N[.] those with their element neighbours, M*(.) those with
/// their masters (transitively). That is the union over b in S(j) of
/// R(b) = agg(M*(N[b])), and b is in S(j) exactly when j is in J(b) = agg(M*(b)) (a tie's
/// slave lists are its master lists reversed). A rank holds every element around its owned
/// nodes (one ghost layer), so it forms R(b) and J(b) for each of them: the ranks' pairs
/// together are every pair of the whole node graph's reach, each at least once.
pub(super) fn reach_pairs(
    mesh: &LocalMesh,
    aggs: &NodeAggregates,
    num_aggs: usize,
    ties: &Ties,
) -> Vec<(u32, u32)> {
    let owned = mesh.num_owned_nodes;
    let gid = |l: usize| mesh.node_global[l];
    let agg_l = aggs.local;
    // The aggregate of closure member i of local node c: c's own first, then masters.
    let agg_in = |c: usize, i: usize, d: u32| if i == 0 { agg_l[c] } else { aggs.master(d) };
    // Owned nodes by aggregate, so that a mark per aggregate keeps each (j, k) once here.
    let mut order: Vec<u32> = (0..owned as u32).collect();
    order.sort_unstable_by_key(|&l| (agg_l[l as usize], l));
    let around = NodeElements::of_connectivity(mesh.num_nodes(), &mesh.elements);
    // The local nodes tied to masters.
    let mut slave = vec![false; mesh.num_nodes()];
    for l in ties
        .by_slave
        .iter()
        .filter_map(|&(s, _)| mesh.local_node(s))
    {
        slave[l] = true;
    }
    let mut mark = vec![u32::MAX; num_aggs];
    let mut pairs = Vec::new();
    let (mut near, mut closed, mut of_b, mut tied_to) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for &l in &order {
        let b = gid(l as usize);
        let j = agg_l[l as usize];
        near.clear();
        near.push(l);
        around.each_neighbour(&mesh.elements, l as usize, |c| near.push(c));
        let tied = slave[l as usize];
        of_b.clear();
        for &c in &near {
            if slave[c as usize] {
                masters_closure(ties, gid(c as usize), &mut closed);
            } else {
                // No masters: the closure is c alone (the search skipped).
                closed.clear();
                closed.push(gid(c as usize));
            }
            for (i, &d) in closed.iter().enumerate() {
                let k = agg_in(c as usize, i, d);
                if mark[k as usize] != j {
                    mark[k as usize] = j;
                    pairs.push((j, k));
                }
                if tied {
                    of_b.push(k);
                }
            }
        }
        if tied {
            // b is tied to masters in other aggregates: their probes reach R(b) too.
            masters_closure(ties, b, &mut closed);
            tied_to.clear();
            let of = |(i, &d): (usize, &u32)| agg_in(l as usize, i, d);
            tied_to.extend(closed.iter().enumerate().map(of));
            tied_to.sort_unstable();
            tied_to.dedup();
            of_b.sort_unstable();
            of_b.dedup();
            for &i in tied_to.iter().filter(|&&i| i != j) {
                pairs.extend(of_b.iter().map(|&k| (i, k)));
            }
        }
    }
    pairs
}

/// reach_ptr and reach (as `reach_of`, each aggregate's list ascending) from pairs (j, k)
/// in any order, repeats included.
pub(super) fn reach_from_pairs(
    num_aggs: usize,
    mut pairs: Vec<(u32, u32)>,
) -> (Vec<usize>, Vec<u32>) {
    pairs.sort_unstable();
    pairs.dedup();
    let mut reach_ptr = vec![0usize; num_aggs + 1];
    for &(j, _) in &pairs {
        reach_ptr[j as usize + 1] += 1;
    }
    for j in 0..num_aggs {
        reach_ptr[j + 1] += reach_ptr[j];
    }
    (reach_ptr, pairs.into_iter().map(|(_, k)| k).collect())
}

/// `reach_of` of the whole node graph from every rank's owned nodes (collective): each
/// rank's `reach_pairs`, gathered, sorted: the same sets on any number of ranks.
pub(super) fn reach_of_ranks<C: Comm + ?Sized>(
    comm: &C,
    mesh: &LocalMesh,
    aggs: &NodeAggregates,
    num_aggs: usize,
    ties: &Ties,
) -> (Vec<usize>, Vec<u32>) {
    let mine = reach_pairs(mesh, aggs, num_aggs, ties);
    let all = if comm.size() == 1 {
        mine
    } else {
        message::all_gather(comm, &mine)
    };
    reach_from_pairs(num_aggs, all)
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
        Self::of_reach(&reach_ptr, &reach, num_aggs)
    }

    /// `new` of the whole node graph, from the ranks' local meshes and the aggregates of
    /// their nodes (collective; see `reach_of_ranks`).
    pub fn of_ranks<C: Comm + ?Sized>(
        comm: &C,
        mesh: &LocalMesh,
        aggs: &NodeAggregates,
        num_aggs: usize,
        ties: &Ties,
    ) -> Self {
        let (reach_ptr, reach) = reach_of_ranks(comm, mesh, aggs, num_aggs, ties);
        Self::of_reach(&reach_ptr, &reach, num_aggs)
    }

    /// The colouring of the aggregates' reach (greedy, in aggregate order: it depends on
    /// the sets only, not on the order within a list).
    fn of_reach(reach_ptr: &[usize], reach: &[u32], num_aggs: usize) -> Self {
        let (colour, num_colours, seen_by) = greedy_colours(reach_ptr, reach, num_aggs);
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
    use partition::Decomposition;

    #[test]
    fn aggregates_sharing_a_colour_are_never_seen_together() {
        // A path of 12 nodes in 6 aggregates of two; a tie makes node 11 a slave of node 0.
        let edges: Vec<(u32, u32)> = (0..11).map(|i| (i, i + 1)).collect();
        let g = Graph::from_edges(12, &edges);
        let agg_of: Vec<u32> = (0..12).map(|a| a / 2).collect();
        for ties in [Ties::from_pairs(vec![]), Ties::from_pairs(vec![(11, 0)])] {
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
        let c = Colouring::new(&g, &agg_of, 6, &Ties::from_pairs(vec![(11, 0)]));
        assert!(c.seen(0).iter().any(|&(_, j)| j == 5));
        assert!(c.seen(5).iter().any(|&(_, j)| j == 0));
    }

    /// reach_of's lists sorted, for comparing sets.
    fn sorted(reach_ptr: &[usize], reach: &[u32]) -> Vec<Vec<u32>> {
        reach_ptr
            .windows(2)
            .map(|w| {
                let mut l = reach[w[0]..w[1]].to_vec();
                l.sort_unstable();
                l
            })
            .collect()
    }

    #[test]
    fn the_ranks_reach_is_the_whole_graphs_on_any_decomposition() {
        // A block of 5 x 4 x 3 elements (120 nodes) in aggregates of seven consecutive
        // nodes; ties that chain (slave 0 on 50 on 119), a slave of four masters, a master
        // of two slaves, nodes of one element's far corners: the pairs every part's owned
        // nodes give, gathered, are the reach of the whole node graph, on one part and on
        // parts that interleave (elements dealt round the parts).
        let corners = crate::mesh::block::box_corners(&[0.0; 3], &[1.0; 3]);
        let b = crate::mesh::block::generate(&corners, 5, 4, 3).unwrap();
        let g = crate::mesh::GlobalMesh {
            coords: b.coords,
            elements: crate::mesh::Connectivity::from_fixed(&b.elements),
            element_body: vec![0; 60],
            bodies: vec![crate::mesh::Body {
                name: "b".into(),
                kind: crate::fem::ElementKind::Hex8,
                first_node: 0,
                num_nodes: 120,
                first_element: 0,
                num_elements: 60,
            }],
            freed: None,
        };
        let n = g.num_nodes();
        let agg_of: Vec<u32> = (0..n as u32).map(|a| a / 7).collect();
        let na = n.div_ceil(7);
        let graph = Graph::of_mesh(&g);
        let tie_sets = [
            vec![],
            vec![(0, 50), (50, 119)],
            vec![
                (0, 50),
                (50, 119),
                (33, 1),
                (33, 2),
                (33, 90),
                (33, 91),
                (60, 7),
                (61, 7),
            ],
        ];
        for pairs in tie_sets {
            let ties = Ties::from_pairs(pairs);
            let (ptr, reach) = reach_of(&graph, &agg_of, na, &ties);
            let whole = sorted(&ptr, &reach);
            for parts in 1..=3usize {
                let element_part: Vec<u32> = (0..60).map(|e| ((e * 7) % parts) as u32).collect();
                let d = Decomposition::try_new(n, &g.elements, &element_part, parts).unwrap();
                let mut all = Vec::new();
                for r in 0..parts {
                    let mesh = LocalMesh::new(&g, &d, r);
                    let local: Vec<u32> = mesh
                        .node_global
                        .iter()
                        .map(|&a| agg_of[a as usize])
                        .collect();
                    let masters = ties.master_nodes().map(|m| (m, agg_of[m as usize]));
                    let aggs = NodeAggregates::new(&local, masters.collect());
                    all.extend(reach_pairs(&mesh, &aggs, na, &ties));
                }
                let (p2, r2) = reach_from_pairs(na, all);
                assert_eq!(sorted(&p2, &r2), whole, "{parts} parts");
                let c = Colouring::of_reach(&p2, &r2, na);
                let c0 = Colouring::new(&graph, &agg_of, na, &ties);
                assert_eq!(
                    (&c.colour, &c.seen_ptr, &c.seen),
                    (&c0.colour, &c0.seen_ptr, &c0.seen)
                );
                assert_eq!(c.by_colour, c0.by_colour);
            }
        }
    }
}
