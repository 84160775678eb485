//! What a result file's mesh is written from ([`MeshSource`]): the mesh read a range of
//! rows at a time, so that rank 0, which writes the file, holds one round of the mesh in
//! the file's form (64-bit ids) and not a copy of all of it beside the run's own. The
//! copy and the concatenated `all_connectivity` were 22 MB at the block on block n = 40,
//! the largest part of rank 0's peak on 16 ranks.

use std::ops::Range;

use super::data::OutputMesh;
use super::xdmf::Topology;
use super::ElementNodes;

/// A body of the mesh: its name, the node count of its elements and their number.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BodyRows {
    pub name: String,
    pub nodes_per_element: usize,
    pub elements: usize,
}

/// A mesh as the result file records it, read by ranges of rows. Nodes are in global
/// order; a body's elements are counted from 0 within the body, and the bodies' elements
/// concatenated give the global element order.
pub trait MeshSource {
    /// Nodes of the mesh.
    fn num_nodes(&self) -> usize;
    /// The bodies in order.
    fn bodies(&self) -> Vec<BodyRows>;
    /// Undeformed coordinates of the nodes `nodes`.
    fn coordinates(&self, nodes: Range<usize>) -> Vec<[f64; 3]>;
    /// The scene's 1-based ids of the nodes `nodes` (of those it has: see `num_node_ids`).
    fn node_ids(&self, nodes: Range<usize>) -> Vec<u64>;
    /// Node ids it has: one per node, unless the source is inconsistent (an in-memory
    /// mesh), which the writer refuses.
    fn num_node_ids(&self) -> usize {
        self.num_nodes()
    }
    /// The 0-based node indices of the elements `elements` of body `body`, row after row.
    fn connectivity(&self, body: usize, elements: Range<usize>) -> Vec<u64>;
    /// The 1-based global ids of the elements `elements` of body `body` (of those it has).
    fn element_ids(&self, body: usize, elements: Range<usize>) -> Vec<u64>;
    /// Element ids body `body` has: one per element unless the source is inconsistent.
    fn num_element_ids(&self, body: usize) -> usize {
        self.bodies()[body].elements
    }
    /// Number of node sets.
    fn node_sets(&self) -> usize;
    /// Node set `i`: its name and 1-based node ids.
    fn node_set(&self, i: usize) -> (String, Vec<u64>);
    /// Number of side sets.
    fn side_sets(&self) -> usize;
    /// Side set `i`: its name and (1-based element id, local face) pairs.
    fn side_set(&self, i: usize) -> (String, Vec<(u64, u8)>);

    /// Elements of all bodies.
    fn num_elements(&self) -> usize {
        self.bodies().iter().map(|b| b.elements).sum()
    }
}

/// The form of `/mesh/all_connectivity` for `bodies`: rows of one node count while every
/// body with elements has that count, else XDMF's "Mixed" array (a type code before each
/// element's nodes; `super::cells::concatenate`).
pub(super) fn topology(bodies: &[BodyRows]) -> Topology {
    let mut widths = bodies
        .iter()
        .filter(|b| b.elements > 0)
        .map(|b| b.nodes_per_element);
    let first = widths.next().unwrap_or(8);
    if widths.all(|w| w == first) {
        Topology::Uniform {
            nodes_per_element: first,
        }
    } else {
        Topology::Mixed {
            length: bodies
                .iter()
                .map(|b| b.elements * (1 + b.nodes_per_element))
                .sum(),
        }
    }
}

impl MeshSource for OutputMesh {
    fn num_nodes(&self) -> usize {
        self.coordinates.len()
    }
    fn bodies(&self) -> Vec<BodyRows> {
        self.bodies
            .iter()
            .map(|b| BodyRows {
                name: b.name.clone(),
                nodes_per_element: b.connectivity.nodes_per_element,
                elements: b.connectivity.len(),
            })
            .collect()
    }
    fn coordinates(&self, nodes: Range<usize>) -> Vec<[f64; 3]> {
        self.coordinates[nodes].to_vec()
    }
    fn node_ids(&self, nodes: Range<usize>) -> Vec<u64> {
        let end = nodes.end.min(self.node_ids.len());
        self.node_ids[nodes.start.min(end)..end].to_vec()
    }
    fn num_node_ids(&self) -> usize {
        self.node_ids.len()
    }
    fn connectivity(&self, body: usize, elements: Range<usize>) -> Vec<u64> {
        let c = &self.bodies[body].connectivity;
        let n = c.nodes_per_element;
        c.flat[elements.start * n..elements.end * n].to_vec()
    }
    fn element_ids(&self, body: usize, elements: Range<usize>) -> Vec<u64> {
        let ids = &self.bodies[body].element_ids;
        let end = elements.end.min(ids.len());
        ids[elements.start.min(end)..end].to_vec()
    }
    fn num_element_ids(&self, body: usize) -> usize {
        self.bodies[body].element_ids.len()
    }
    fn node_sets(&self) -> usize {
        self.node_sets.len()
    }
    fn node_set(&self, i: usize) -> (String, Vec<u64>) {
        self.node_sets[i].clone()
    }
    fn side_sets(&self) -> usize {
        self.side_sets.len()
    }
    fn side_set(&self, i: usize) -> (String, Vec<(u64, u8)>) {
        self.side_sets[i].clone()
    }
}

impl OutputMesh {
    /// The whole of `source` (what reading the file's mesh back gives).
    pub fn from_source(source: &impl MeshSource) -> OutputMesh {
        let bodies = source.bodies();
        OutputMesh {
            coordinates: source.coordinates(0..source.num_nodes()),
            node_ids: source.node_ids(0..source.num_nodes()),
            bodies: bodies
                .iter()
                .enumerate()
                .map(|(i, b)| super::OutputBody {
                    name: b.name.clone(),
                    connectivity: ElementNodes {
                        nodes_per_element: b.nodes_per_element,
                        flat: source.connectivity(i, 0..b.elements),
                    },
                    element_ids: source.element_ids(i, 0..b.elements),
                })
                .collect(),
            node_sets: (0..source.node_sets())
                .map(|i| source.node_set(i))
                .collect(),
            side_sets: (0..source.side_sets())
                .map(|i| source.side_set(i))
                .collect(),
        }
    }
}
