//! The mesh of a result file, from the validated problem.

use crate::fem::ElementKind;
use crate::output::{OutputBody, OutputMesh};
use crate::problem::Problem;

/// The whole mesh as the result file records it. The file's connectivity is hexahedral
/// (`[elements, 8]`): a body of another kind is refused with a message until the file
/// records each body with its own node count (issue 41, item 5).
pub fn output_mesh(problem: &Problem) -> Result<OutputMesh, String> {
    let m = &problem.mesh;
    if let Some(b) = m.bodies.iter().find(|b| b.kind != ElementKind::Hex8) {
        return Err(format!(
            "body '{}' is made of {} elements: writing them to a result file is not supported              yet (run without -o)",
            b.name,
            b.kind.name()
        ));
    }
    Ok(OutputMesh {
        coordinates: m.coords.clone(),
        node_ids: (1..=m.num_nodes() as u64).collect(),
        bodies: m
            .bodies
            .iter()
            .map(|b| OutputBody {
                name: b.name.clone(),
                connectivity: (b.first_element..b.first_element + b.num_elements)
                    .map(|e| m.elements.fixed::<8>(e).map(|n| n as u64))
                    .collect(),
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
    })
}
