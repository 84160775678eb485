//! Aggregation: groups of neighbouring nodes (on the fine level) or of neighbouring
//! aggregates (on the coarse levels) that become one coarse node carrying the rigid-body
//! modes. Greedy, in index order (Vanek, Mandel and Brezina's three phases), on a graph
//! built from global data only, so the aggregates are the same on any number of ranks and
//! follow any mesh, structured or from Gmsh.

use super::around::{Around, NodeElements};
use crate::math::Vec3;
use crate::mesh::{Connectivity, GlobalMesh};

/// An undirected graph in CSR form (no self loops, neighbours sorted).
pub struct Graph {
    pub ptr: Vec<usize>,
    pub adj: Vec<u32>,
}

impl Graph {
    pub fn len(&self) -> usize {
        self.ptr.len() - 1
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    #[inline]
    pub fn neighbours(&self, i: usize) -> &[u32] {
        &self.adj[self.ptr[i]..self.ptr[i + 1]]
    }

    /// Builds a graph from a list of edges (both directions are added).
    pub fn from_edges(n: usize, edges: &[(u32, u32)]) -> Self {
        let mut count = vec![0usize; n + 1];
        for &(a, b) in edges {
            if a != b {
                count[a as usize + 1] += 1;
                count[b as usize + 1] += 1;
            }
        }
        for i in 0..n {
            count[i + 1] += count[i];
        }
        let mut next = count.clone();
        let mut adj = vec![0u32; count[n]];
        for &(a, b) in edges {
            if a != b {
                adj[next[a as usize]] = b;
                next[a as usize] += 1;
                adj[next[b as usize]] = a;
                next[b as usize] += 1;
            }
        }
        // Sort and remove duplicates row by row.
        let mut ptr = vec![0usize; n + 1];
        let mut out = Vec::with_capacity(adj.len());
        for i in 0..n {
            let row = &mut adj[count[i]..count[i + 1]];
            row.sort_unstable();
            let start = out.len();
            for &j in row.iter() {
                if out.len() == start || *out.last().expect("non-empty") != j {
                    out.push(j);
                }
            }
            ptr[i + 1] = out.len();
        }
        Graph { ptr, adj: out }
    }

    /// The node graph of a hexahedral mesh: two nodes are neighbours when they share an
    /// element (the graph `from_edges` makes of every element's 28 node pairs, built node
    /// by node from the elements of each: those pairs and their sort were 570 MB at 10^6
    /// elements).
    pub fn of_mesh(mesh: &GlobalMesh) -> Self {
        Graph::around(&NodeElements::of_mesh(mesh), &mesh.elements)
    }

    /// `of_mesh` from the elements around every node.
    pub fn around(around: &NodeElements, elements: &Connectivity) -> Self {
        let n = around.len();
        let mut mark = vec![u32::MAX; n];
        let mut ptr = Vec::with_capacity(n + 1);
        ptr.push(0);
        let mut adj = Vec::new();
        let mut row: Vec<u32> = Vec::new();
        for a in 0..n {
            row.clear();
            mark[a] = a as u32;
            around.each_neighbour(elements, a, |b| {
                if mark[b as usize] != a as u32 {
                    mark[b as usize] = a as u32;
                    row.push(b);
                }
            });
            row.sort_unstable();
            adj.extend_from_slice(&row);
            ptr.push(adj.len());
        }
        adj.shrink_to_fit();
        Graph { ptr, adj }
    }
}

impl Graph {
    /// The edge graph of a hexahedral mesh: two nodes are neighbours when they share an
    /// element edge (aggregates of a node and these neighbours are about two elements
    /// wide instead of three).
    pub fn of_mesh_edges(mesh: &GlobalMesh) -> Self {
        let mut edges = Vec::with_capacity(mesh.num_elements() * 12);
        for (k, e) in mesh.elements.iter().enumerate() {
            for &(a, b) in mesh.kind(k).edges() {
                edges.push((e[a], e[b]));
            }
        }
        Graph::from_edges(mesh.num_nodes(), &edges)
    }
}

/// Sorted neighbour lists without the node itself, held (`Graph`) or formed row by row
/// (`StrongMesh`): what aggregation reads.
pub trait Rows {
    /// The number of nodes.
    fn nodes(&self) -> usize;
    /// Node i's neighbours, sorted, in `out` (cleared first).
    fn row(&mut self, i: usize, out: &mut Vec<u32>);
}

impl Rows for Graph {
    fn nodes(&self) -> usize {
        self.len()
    }
    fn row(&mut self, i: usize, out: &mut Vec<u32>) {
        out.clear();
        out.extend_from_slice(self.neighbours(i));
    }
}

/// The strong part of a mesh's node graph: neighbours a, b (nodes of one element) stay
/// linked when their distance is at most `ratio` times the shortest distance from either
/// of them to a neighbour. On elements much longer in one direction than in another (a
/// one-element-thick plane-strain slab, stretched elements of a graded mesh) the long
/// direction is weakly coupled and aggregates do not cross it, so each side gets its own
/// rigid-body modes (smoothed aggregation's strength of connection, measured on the
/// geometry: the stiffness between two nodes of an element goes like 1/distance^2).
///
/// Formed row by row from the elements around each node as aggregation reads it
/// (`Around`: a window of nodes where the numbering allows): the node graph and its strong
/// part held whole were about 450 B per node of the whole mesh on every rank (60 MB at
/// n = 40, the largest part of a rank's peak from 4 ranks up); the elements around every
/// node 36 B per node more (5.2 MB at n = 40); this holds 12 B per node (the shortest
/// distances, the marks) and 4 B per node and per element for the window's plan.
pub struct StrongMesh<'a> {
    around: Around,
    elements: &'a Connectivity,
    coords: &'a [Vec3],
    ratio: f64,
    dmin: Vec<f64>,
    /// `stamp` at the nodes of the row being formed.
    mark: Vec<u32>,
    stamp: u32,
}

impl<'a> StrongMesh<'a> {
    pub fn new(mesh: &'a GlobalMesh, ratio: f64) -> Self {
        let n = mesh.num_nodes();
        let coords = &mesh.coords[..];
        // The shortest distance from each node to another of its elements' nodes.
        let mut dmin = vec![f64::INFINITY; n];
        for e in mesh.elements.iter() {
            for (i, &a) in e.iter().enumerate() {
                for &b in &e[i + 1..] {
                    if a != b {
                        let d = distance(coords, a as usize, b as usize);
                        dmin[a as usize] = dmin[a as usize].min(d);
                        dmin[b as usize] = dmin[b as usize].min(d);
                    }
                }
            }
        }
        StrongMesh {
            around: Around::new(n, &mesh.elements),
            mark: vec![0; n],
            elements: &mesh.elements,
            coords,
            ratio,
            dmin,
            stamp: 0,
        }
    }
}

/// The distance between nodes a and b, the same bits either way round.
fn distance(coords: &[Vec3], a: usize, b: usize) -> f64 {
    let (p, q) = (a.min(b), a.max(b));
    let d = crate::math::sub(&coords[p], &coords[q]);
    crate::math::dot(&d, &d).sqrt()
}

impl Rows for StrongMesh<'_> {
    fn nodes(&self) -> usize {
        self.dmin.len()
    }
    fn row(&mut self, a: usize, out: &mut Vec<u32>) {
        if self.stamp == u32::MAX {
            self.mark.fill(0);
            self.stamp = 0;
        }
        self.stamp += 1;
        let stamp = self.stamp;
        self.mark[a] = stamp;
        out.clear();
        let (mark, dmin, coords, ratio) = (&mut self.mark, &self.dmin, self.coords, self.ratio);
        for &e in self.around.of(self.elements, a) {
            for &b in self.elements.element(e as usize) {
                let b = b as usize;
                if mark[b] != stamp {
                    mark[b] = stamp;
                    if distance(coords, a, b) <= ratio * dmin[a].min(dmin[b]) {
                        out.push(b as u32);
                    }
                }
            }
        }
        out.sort_unstable();
    }
}

/// Greedy aggregation of the active nodes of a graph. Phase 1: a node whose active
/// neighbours are all free starts an aggregate with them (in index order). Phase 2: a node
/// left over joins the aggregate of its first neighbour aggregated in phase 1. Phase 3:
/// nodes still left start aggregates with their free neighbours. Returns the aggregate of
/// every node (u32::MAX for inactive nodes) and the number of aggregates.
pub fn aggregate(g: &mut impl Rows, active: &[bool]) -> (Vec<u32>, usize) {
    const FREE: u32 = u32::MAX;
    let n = g.nodes();
    let mut agg = vec![FREE; n];
    let mut count = 0u32;
    let mut nb = Vec::new();
    for i in 0..n {
        if !active[i] || agg[i] != FREE {
            continue;
        }
        g.row(i, &mut nb);
        if nb
            .iter()
            .all(|&j| !active[j as usize] || agg[j as usize] == FREE)
        {
            agg[i] = count;
            for &j in &nb {
                if active[j as usize] {
                    agg[j as usize] = count;
                }
            }
            count += 1;
        }
    }
    let phase1 = agg.clone();
    for i in 0..n {
        if !active[i] || agg[i] != FREE {
            continue;
        }
        g.row(i, &mut nb);
        if let Some(&j) = nb.iter().find(|&&j| phase1[j as usize] != FREE) {
            agg[i] = phase1[j as usize];
        }
    }
    for i in 0..n {
        if !active[i] || agg[i] != FREE {
            continue;
        }
        agg[i] = count;
        g.row(i, &mut nb);
        for &j in &nb {
            if active[j as usize] && agg[j as usize] == FREE {
                agg[j as usize] = count;
            }
        }
        count += 1;
    }
    (agg, count as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The node graph of an nx x ny x nz grid of points with 27-point connectivity.
    fn grid(nx: usize, ny: usize, nz: usize) -> Graph {
        let id = |i: usize, j: usize, k: usize| (i + nx * (j + ny * k)) as u32;
        let mut edges = Vec::new();
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    for dk in 0..2 {
                        for dj in 0..2 {
                            for di in 0..2 {
                                let (a, b, c) = (i + di, j + dj, k + dk);
                                if a < nx && b < ny && c < nz {
                                    edges.push((id(i, j, k), id(a, b, c)));
                                }
                                // The other diagonals of the cell.
                                if di == 1 && i + 1 < nx && j + dj < ny && k + dk < nz {
                                    edges.push((id(i + 1, j, k), id(i, j + dj, k + dk)));
                                }
                                if dj == 1 && j + 1 < ny && i + di < nx && k + dk < nz {
                                    edges.push((id(i, j + 1, k), id(i + di, j, k + dk)));
                                }
                            }
                        }
                    }
                }
            }
        }
        Graph::from_edges(nx * ny * nz, &edges)
    }

    /// The strong part of a graph held whole: the rows `StrongMesh` forms one by one.
    fn strong(g: &Graph, coords: &[Vec3], ratio: f64) -> Graph {
        let dist = |a: usize, b: usize| {
            let d = crate::math::sub(&coords[a], &coords[b]);
            crate::math::dot(&d, &d).sqrt()
        };
        let dmin: Vec<f64> = (0..g.len())
            .map(|a| {
                g.neighbours(a)
                    .iter()
                    .map(|&b| dist(a, b as usize))
                    .fold(f64::INFINITY, f64::min)
            })
            .collect();
        let mut edges = Vec::new();
        for a in 0..g.len() {
            for &b in g.neighbours(a) {
                let b = b as usize;
                if a < b && dist(a, b) <= ratio * dmin[a].min(dmin[b]) {
                    edges.push((a as u32, b as u32));
                }
            }
        }
        Graph::from_edges(g.len(), &edges)
    }

    #[test]
    fn strong_rows_formed_one_by_one_are_those_of_the_whole_graph() {
        // A graded, sheared block: element lengths from 0.05 to 1.7 along x, so the strong
        // part drops links (ratio 2) where a short element meets a long one; every row and
        // the aggregates must be those of the graph held whole, in any order of reading.
        let block = crate::mesh::block::generate(
            &[
                [0.0, 0.0, 0.0],
                [6.0, 0.0, 0.0],
                [6.0, 1.0, 0.3],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
                [6.0, 0.2, 1.0],
                [6.0, 1.0, 1.0],
                [0.0, 1.0, 1.0],
            ],
            6,
            4,
            3,
        )
        .expect("memory");
        let coords: Vec<Vec3> = block
            .coords
            .iter()
            .map(|x| [x[0] * x[0] * x[0] / 36.0 + 0.05 * x[0], x[1], x[2]])
            .collect();
        let n = coords.len();
        let mesh = GlobalMesh {
            coords,
            elements: Connectivity::from_fixed(&block.elements),
            element_body: vec![0; block.elements.len()],
            bodies: vec![crate::mesh::Body {
                name: "b".into(),
                kind: crate::fem::ElementKind::Hex8,
                first_node: 0,
                num_nodes: n,
                first_element: 0,
                num_elements: block.elements.len(),
            }],
            freed: None,
        };
        let mut whole = strong(&Graph::of_mesh(&mesh), &mesh.coords, 2.0);
        assert!(
            whole.adj.len() < Graph::of_mesh(&mesh).adj.len(),
            "no link dropped"
        );
        let mut rows = StrongMesh::new(&mesh, 2.0);
        let mut row = Vec::new();
        for a in (0..n).rev().chain(0..n) {
            rows.row(a, &mut row);
            assert_eq!(row, whole.neighbours(a), "node {a}");
        }
        let active = vec![true; n];
        assert_eq!(
            aggregate(&mut rows, &active),
            aggregate(&mut whole, &active)
        );
    }

    #[test]
    fn a_line_is_cut_into_triples() {
        // A path of 9 nodes: phase 1 gives {0,1} (node 0 and its neighbour), skips 2 (its
        // neighbour 1 is taken), takes {2,3,4} around 3 and {5,6,7} around 6; phase 2 puts
        // 8 into 7's aggregate.
        let edges: Vec<(u32, u32)> = (0..8).map(|i| (i, i + 1)).collect();
        let mut g = Graph::from_edges(9, &edges);
        let (agg, n) = aggregate(&mut g, &[true; 9]);
        assert_eq!(n, 3);
        assert_eq!(agg, vec![0, 0, 1, 1, 1, 2, 2, 2, 2]);
    }

    #[test]
    fn every_active_node_is_aggregated_with_a_neighbour() {
        let mut g = grid(7, 6, 5);
        let mut active = vec![true; g.len()];
        active[10] = false;
        active[57] = false;
        let (agg, n) = aggregate(&mut g, &active);
        for i in 0..g.len() {
            if !active[i] {
                assert_eq!(agg[i], u32::MAX);
                continue;
            }
            assert!((agg[i] as usize) < n);
            // Every aggregate is connected: each node has a neighbour in its aggregate
            // unless it is alone.
            let size = agg.iter().filter(|&&a| a == agg[i]).count();
            if size > 1 {
                assert!(g.neighbours(i).iter().any(|&j| agg[j as usize] == agg[i]));
            }
        }
        // 210 nodes in aggregates of up to 27 (one node and its neighbours) and at least
        // 2 (phase 3 only starts an aggregate around a node whose neighbours are taken,
        // which phase 2 prevents for nodes next to a phase-1 aggregate).
        assert!((210 / 27..=105).contains(&n), "{n} aggregates");
    }

    #[test]
    fn mesh_graph_links_the_nodes_of_an_element() {
        let mesh = GlobalMesh {
            coords: vec![[0.0; 3]; 12],
            elements: Connectivity::from_fixed(&[
                [0, 1, 2, 3, 4, 5, 6, 7],
                [1, 8, 9, 2, 5, 10, 11, 6],
            ]),
            element_body: vec![0, 0],
            bodies: vec![crate::mesh::Body {
                name: "b".into(),
                kind: crate::fem::ElementKind::Hex8,
                first_node: 0,
                num_nodes: 12,
                first_element: 0,
                num_elements: 2,
            }],
            freed: None,
        };
        let g = Graph::of_mesh(&mesh);
        // The graph of every element's node pairs, as it was built before.
        let mut pairs = Vec::new();
        for e in &mesh.elements {
            for a in 0..8 {
                for b in a + 1..8 {
                    pairs.push((e[a], e[b]));
                }
            }
        }
        let by_pairs = Graph::from_edges(12, &pairs);
        assert_eq!((&g.ptr, &g.adj), (&by_pairs.ptr, &by_pairs.adj));
        assert_eq!(g.neighbours(0), &[1, 2, 3, 4, 5, 6, 7]);
        assert_eq!(g.neighbours(1).len(), 11);
        assert_eq!(g.neighbours(8), &[1, 2, 5, 6, 9, 10, 11]);
    }
}
