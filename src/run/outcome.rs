//! What a run is asked for and what it gives back: its options, the summary every rank
//! sees, the final state on rank 0, and the peak memory of this process.

use crate::math::Vec3;
use crate::solver::StepRecord;
use std::path::PathBuf;

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
    /// How the elements are partitioned over the ranks.
    pub partition: super::Partition,
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
    /// What the ranks sent during the steps (from the first step's start to the last
    /// step's end: CG, contact updates, preconditioner builds, the step output): each
    /// count's largest over the ranks, and its sum over them.
    pub traffic_max: crate::comm::Traffic,
    pub traffic_sum: crate::comm::Traffic,
    /// The same for the CG loops alone (each model problem's iterations after its setup),
    /// and the iterations of those loops.
    pub cg_traffic_max: crate::comm::Traffic,
    pub cg_traffic_sum: crate::comm::Traffic,
    pub cg_loop_iterations: u64,
    /// Wall time in those loops (the largest over the ranks), s.
    pub cg_loop_seconds: f64,
    /// Contact updates between model problems (`CgTrace::contact_update`) and their wall
    /// time (the largest over the ranks), s.
    pub contact_updates: u64,
    pub contact_seconds: f64,
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
