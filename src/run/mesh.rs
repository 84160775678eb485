//! The mesh of a result file, from the validated problem.

use crate::mesh::GlobalMesh;
use crate::output::{ElementNodes, OutputBody, OutputMesh};
use crate::problem::Problem;

/// The whole mesh `m` of `problem` as the result file records it.
pub fn output_mesh(problem: &Problem, m: &GlobalMesh) -> OutputMesh {
    OutputMesh {
        coordinates: m.coords.clone(),
        node_ids: (1..=m.num_nodes() as u64).collect(),
        bodies: m
            .bodies
            .iter()
            .map(|b| OutputBody {
                name: b.name.clone(),
                connectivity: ElementNodes {
                    nodes_per_element: b.kind.nodes(),
                    flat: (b.first_element..b.first_element + b.num_elements)
                        .flat_map(|e| m.elements.element(e).iter().map(|&n| u64::from(n)))
                        .collect(),
                },
                element_ids: (b.first_element as u64 + 1
                    ..=(b.first_element + b.num_elements) as u64)
                    .collect(),
            })
            .collect(),
        node_sets: problem
            .node_sets
            .iter()
            .map(|s| {
                (
                    s.name.clone(),
                    s.nodes.iter().map(|&n| n as u64 + 1).collect(),
                )
            })
            .collect(),
        side_sets: problem
            .side_sets
            .iter()
            .map(|s| {
                (
                    s.name.clone(),
                    s.faces.iter().map(|&(e, f)| (e as u64 + 1, f)).collect(),
                )
            })
            .collect(),
    }
}
