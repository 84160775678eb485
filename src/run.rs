//! One analysis from a validated problem to a result file: decompose, build the rank's
//! local mesh, step through time, gather each step's results on rank 0 and write them.

use crate::comm::Comm;
use crate::math::Vec3;
use crate::output::{OutputBody, OutputMesh};
use crate::problem::Problem;
use crate::solver::StepRecord;
use partition::Decomposition;
use std::path::PathBuf;

mod driver;
mod export;
mod fields;
mod gather;
mod plastic;
mod restart;
pub use driver::run_from;
use fields::{write_fields, LocalFields};
use gather::Gather;
pub use restart::check_restart;

#[derive(Clone, Debug)]
pub struct RunOptions {
    /// Result file; None writes nothing (tests that only need the numbers).
    pub output: Option<PathBuf>,
    /// 0 quiet, 1 step lines, 2 more.
    pub verbosity: u8,
    /// Where the first model problem that needs a CG iteration goes, assembled
    /// (`export`); one rank only.
    pub export_operator: Option<PathBuf>,
    /// Keep the last step's fields on rank 0 for the returned [`GlobalState`]; without, the
    /// state comes back empty and rank 0 frees each step's gathered fields as soon as they
    /// are written (the command line, which has the result file).
    pub final_state: bool,
}

/// The run's outcome as every rank sees it.
#[derive(Clone, Debug)]
pub struct RunSummary {
    pub steps: Vec<StepRecord>,
    pub wall_time: f64,
    pub output: Option<PathBuf>,
    /// Set when a step failed: the diagnostic (the result file then holds the steps before).
    pub failure: Option<String>,
    /// Largest peak resident memory of any rank, bytes (0 where the system does not say).
    pub peak_memory: f64,
}

/// This process's peak resident memory in bytes (Linux: VmHWM), if known.
pub fn peak_memory() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0)
}

/// The final state on rank 0 in global order (for tests and the verification checks).
#[derive(Clone, Debug, Default)]
pub struct GlobalState {
    pub displacement: Vec<Vec3>,
    pub stress: Vec<[f64; 6]>,
    pub reaction: Vec<Vec3>,
    pub contact_force: Vec<Vec3>,
    pub contact_status: Vec<u8>,
    /// Per node: contact pressure (compressive > 0), see `contact::area`.
    pub contact_pressure: Vec<f64>,
    /// Per element: equivalent plastic strain (empty without plastic bodies).
    pub plastic_strain: Vec<f64>,
    /// Active contact constraints at the end (one-rank runs): (slave node, pair, master
    /// body, stick).
    pub constraints: Vec<ActiveConstraint>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ActiveConstraint {
    /// 0-based global node id of the slave node.
    pub slave: u32,
    pub pair: usize,
    /// Index of the body the master face belongs to.
    pub master_body: usize,
    pub stick: bool,
    pub normal: Vec3,
    pub normal_force: f64,
}

/// How a scene splits over `ranks` ranks: the decomposition's balance, edge cut and per-rank
/// element and node counts, and the master faces each rank holds for its slave nodes at the
/// reference configuration (the ghosted faces of the contact search).
pub fn decomposition_report(problem: &Problem, ranks: usize) -> Result<String, String> {
    use std::fmt::Write;
    let mesh = &problem.mesh;
    let d = Decomposition::partition(mesh.num_nodes(), &mesh.elements, ranks).map_err(|e| {
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

/// The whole mesh as the result file records it.
pub fn output_mesh(problem: &Problem) -> OutputMesh {
    let m = &problem.mesh;
    OutputMesh {
        coordinates: m.coords.clone(),
        node_ids: (1..=m.num_nodes() as u64).collect(),
        bodies: m
            .bodies
            .iter()
            .map(|b| OutputBody {
                name: b.name.clone(),
                connectivity: m.elements[b.first_element..b.first_element + b.num_elements]
                    .iter()
                    .map(|el| el.map(|n| n as u64))
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
    }
}

pub fn run<C: Comm + ?Sized>(
    comm: &C,
    problem: &Problem,
    opts: &RunOptions,
) -> Result<(RunSummary, GlobalState), String> {
    run_from(comm, problem, opts, None)
}
