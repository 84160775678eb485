//! One analysis from a validated problem to a result file: decompose, build the rank's
//! local mesh, step through time, gather each step's results on rank 0 and write them.

use crate::comm::Comm;
use crate::problem::Problem;
use partition::Decomposition;

mod decompose;
mod driver;
mod export;
mod fields;
mod gather;
mod mesh;
mod outcome;
mod plastic;
mod restart;
pub use decompose::Partition;
pub use driver::{run_from, run_from_root, run_owned};
use gather::Gather;
pub use mesh::output_mesh;
pub use outcome::{peak_memory, ActiveConstraint, GlobalState, RunOptions, RunSummary};
pub use restart::check_restart;

/// How a scene splits over `ranks` ranks: the decomposition's balance, edge cut and per-rank
/// element and node counts, and the master faces each rank holds for its slave nodes at the
/// reference configuration (the ghosted faces of the contact search).
pub fn decomposition_report(
    problem: &Problem,
    ranks: usize,
    method: Partition,
) -> Result<String, String> {
    use std::fmt::Write;
    let mesh = &problem.mesh;
    let centres = decompose::centres(mesh);
    let groups = method.groups(ranks);
    let d =
        partition::partition_for_ranks(mesh.num_nodes(), &mesh.elements, &centres, ranks, groups)
            .and_then(|parts| {
                Decomposition::try_new(mesh.num_nodes(), &mesh.elements, &parts, ranks)
            })
            .map_err(|e| {
                format!(
                    "{}: cannot partition the mesh over {ranks} ranks: {e}",
                    problem.file
                )
            })?;
    let mut s = d.stats().to_string();
    if !problem.contacts.is_empty() {
        let counts = crate::contact::ghost::face_counts(problem, &d);
        let owned = |r: usize, p: usize| {
            problem.contacts[p]
                .master_faces
                .iter()
                .filter(|(e, _)| d.element_part()[*e as usize] as usize == r)
                .count()
        };
        let _ = writeln!(
            s,
            "contact: master faces per rank (owned / held for the rank's slave nodes)"
        );
        for (p, pair) in problem.contacts.iter().enumerate() {
            let per: Vec<String> = (0..ranks)
                .map(|r| format!("rank {r}: {} / {}", owned(r, p), counts[r][p]))
                .collect();
            let _ = writeln!(
                s,
                "  {} ({} faces, {} slave nodes): {}",
                pair.name,
                pair.master_faces.len(),
                pair.slave_nodes.len(),
                per.join(", ")
            );
        }
    }
    Ok(s)
}

pub fn run<C: Comm + ?Sized>(
    comm: &C,
    problem: &Problem,
    opts: &RunOptions,
) -> Result<(RunSummary, GlobalState), String> {
    run_from(comm, problem, opts, None)
}
