//! The mesh of a result file, from the validated problem: read by the writer a round of
//! rows at a time (`RunMesh`), or whole (`output_mesh`).

use std::ops::Range;

use crate::mesh::GlobalMesh;
use crate::output::{BodyRows, MeshSource, OutputMesh};
use crate::problem::Problem;

/// The whole mesh `m` of `problem` as the result file records it, read where it is: node
/// ids are 1-based global indices, element ids likewise, a body's elements the mesh's
/// range of it.
pub struct RunMesh<'a> {
    pub problem: &'a Problem,
    pub mesh: &'a GlobalMesh,
}

impl MeshSource for RunMesh<'_> {
    fn num_nodes(&self) -> usize {
        self.mesh.coords.len()
    }
    fn bodies(&self) -> Vec<BodyRows> {
        self.mesh
            .bodies
            .iter()
            .map(|b| BodyRows {
                name: b.name.clone(),
                nodes_per_element: b.kind.nodes(),
                elements: b.num_elements,
            })
            .collect()
    }
    fn coordinates(&self, nodes: Range<usize>) -> Vec<[f64; 3]> {
        self.mesh.coords[nodes].to_vec()
    }
    fn node_ids(&self, nodes: Range<usize>) -> Vec<u64> {
        (nodes.start as u64 + 1..=nodes.end as u64).collect()
    }
    fn connectivity(&self, body: usize, elements: Range<usize>) -> Vec<u64> {
        let first = self.mesh.bodies[body].first_element;
        (first + elements.start..first + elements.end)
            .flat_map(|e| self.mesh.elements.element(e).iter().map(|&n| u64::from(n)))
            .collect()
    }
    fn element_ids(&self, body: usize, elements: Range<usize>) -> Vec<u64> {
        let first = self.mesh.bodies[body].first_element as u64;
        (first + elements.start as u64 + 1..=first + elements.end as u64).collect()
    }
    fn node_sets(&self) -> usize {
        self.problem.node_sets.len()
    }
    fn node_set(&self, i: usize) -> (String, Vec<u64>) {
        let s = &self.problem.node_sets[i];
        (
            s.name.clone(),
            s.nodes.iter().map(|&n| n as u64 + 1).collect(),
        )
    }
    fn side_sets(&self) -> usize {
        self.problem.side_sets.len()
    }
    fn side_set(&self, i: usize) -> (String, Vec<(u64, u8)>) {
        let s = &self.problem.side_sets[i];
        (
            s.name.clone(),
            s.faces.iter().map(|&(e, f)| (e as u64 + 1, f)).collect(),
        )
    }
}

/// The whole mesh `m` of `problem` as the result file records it, held whole.
pub fn output_mesh(problem: &Problem, m: &GlobalMesh) -> OutputMesh {
    OutputMesh::from_source(&RunMesh { problem, mesh: m })
}
