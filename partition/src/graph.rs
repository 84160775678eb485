//! The element dual graph (METIS's input) and the node -> elements incidence, both in CSR
//! form.

use crate::Cells;

/// Element dual graph in CSR form: elements `e` and `f` are adjacent when they
/// share at least [`DualGraph::NCOMMON`] nodes (a hex face; a 6-node triangle's too, never an edge's three).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DualGraph {
    /// Row pointers, length `num_elements + 1`.
    pub xadj: Vec<usize>,
    /// Neighbour element ids, ascending within each row.
    pub adjncy: Vec<u32>,
}

impl DualGraph {
    /// Number of shared nodes that makes two elements neighbours.
    pub const NCOMMON: u32 = 4;

    /// Builds the face-adjacency graph. Node ids must be `< num_nodes`
    /// (checked by the public entry points before calling this).
    pub fn new(num_nodes: usize, elements: &dyn Cells) -> DualGraph {
        let n2e = NodeElements::new(num_nodes, elements);
        let ne = elements.count();
        let mut count = vec![0u32; ne];
        let mut touched: Vec<u32> = Vec::new();
        let mut xadj = Vec::with_capacity(ne + 1);
        let mut adjncy = Vec::new();
        xadj.push(0);
        for (e, conn) in (0..elements.count()).map(|e| (e, elements.nodes(e))) {
            for node in distinct_nodes(conn) {
                for &f in n2e.of(node) {
                    if f as usize != e {
                        if count[f as usize] == 0 {
                            touched.push(f);
                        }
                        count[f as usize] += 1;
                    }
                }
            }
            touched.sort_unstable();
            for &f in &touched {
                if count[f as usize] >= Self::NCOMMON {
                    adjncy.push(f);
                }
                count[f as usize] = 0;
            }
            touched.clear();
            xadj.push(adjncy.len());
        }
        DualGraph { xadj, adjncy }
    }

    /// Number of vertices (elements).
    pub fn num_vertices(&self) -> usize {
        self.xadj.len() - 1
    }

    /// Neighbours of element `e`.
    pub fn neighbours(&self, e: usize) -> &[u32] {
        &self.adjncy[self.xadj[e]..self.xadj[e + 1]]
    }

    /// Number of graph edges whose end points lie in different parts.
    pub fn edge_cut(&self, element_part: &[u32]) -> usize {
        (0..self.num_vertices())
            .map(|e| {
                self.neighbours(e)
                    .iter()
                    .filter(|&&f| (f as usize) > e && element_part[f as usize] != element_part[e])
                    .count()
            })
            .sum()
    }
}

/// The edge cut of `element_part` (`DualGraph::edge_cut`) from the elements around each
/// node, without the dual graph held.
pub(crate) fn edge_cut(n2e: &NodeElements, elements: &dyn Cells, element_part: &[u32]) -> usize {
    let mut count = vec![0u32; elements.count()];
    let mut touched: Vec<u32> = Vec::new();
    let mut cut = 0;
    for e in 0..elements.count() {
        for node in distinct_nodes(elements.nodes(e)) {
            for &f in n2e.of(node) {
                if f as usize > e {
                    if count[f as usize] == 0 {
                        touched.push(f);
                    }
                    count[f as usize] += 1;
                }
            }
        }
        for &f in &touched {
            if count[f as usize] >= DualGraph::NCOMMON
                && element_part[f as usize] != element_part[e]
            {
                cut += 1;
            }
            count[f as usize] = 0;
        }
        touched.clear();
    }
    cut
}

/// Node -> elements incidence in CSR form (element ids ascending per node).
pub(crate) struct NodeElements {
    ptr: Vec<usize>,
    elems: Vec<u32>,
}

impl NodeElements {
    pub(crate) fn new(num_nodes: usize, elements: &dyn Cells) -> NodeElements {
        let mut ptr = vec![0usize; num_nodes + 1];
        for conn in (0..elements.count()).map(|e| elements.nodes(e)) {
            for node in distinct_nodes(conn) {
                ptr[node as usize + 1] += 1;
            }
        }
        for i in 0..num_nodes {
            ptr[i + 1] += ptr[i];
        }
        let mut fill = ptr.clone();
        let mut elems = vec![0u32; ptr[num_nodes]];
        // Elements are visited in ascending order, so each row is ascending.
        for (e, conn) in (0..elements.count()).map(|e| (e, elements.nodes(e))) {
            for node in distinct_nodes(conn) {
                elems[fill[node as usize]] = e as u32;
                fill[node as usize] += 1;
            }
        }
        NodeElements { ptr, elems }
    }

    pub(crate) fn of(&self, node: u32) -> &[u32] {
        &self.elems[self.ptr[node as usize]..self.ptr[node as usize + 1]]
    }
}

/// The distinct node ids of an element (degenerate hexes may repeat nodes).
fn distinct_nodes(conn: &[u32]) -> impl Iterator<Item = u32> + '_ {
    conn.iter()
        .enumerate()
        .filter(|(i, n)| !conn[..*i].contains(n))
        .map(|(_, &n)| n)
}
