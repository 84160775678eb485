//! The robustness table's results (`--robustness`): each problem with every
//! preconditioner's run and CalculiX's. The runner (`robustness/`) produces them and the
//! report (`report/robustness.rs`) reads them.

use crate::block::BLOCK_BASE_N;
use crate::machine::RunInfo;
use crate::peers::calculix::robustness::CcxRun;
use crate::runner::log::SolverLog;
use crate::runner::process::MIB;
use crate::runner::solver::Precond;
use std::path::PathBuf;

/// Ranks of every run of the table.
pub const ROBUSTNESS_RANKS: usize = 2;
/// The preconditioners of the table, in its order.
pub const PRECONDITIONERS: [Precond; 4] = [
    Precond::Jacobi,
    Precond::TwoLevel,
    Precond::Multilevel,
    Precond::Auto,
];

/// Where a problem of the table comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Source {
    /// The Hertz example at this refinement factor of its Gmsh mesh.
    Hertz(usize),
    /// The extreme suite's scene of this name.
    Extreme(&'static str),
    /// The paper's stick/slip bar at 160 x 8 x 1.
    StickSlip,
    /// The block on block refined by this factor.
    Block(usize),
}

impl Source {
    /// The label of the table's rows.
    pub fn label(self) -> String {
        match self {
            Source::Hertz(f) => format!("Hertz x{f}"),
            Source::Extreme(name) => name.to_string(),
            Source::StickSlip => "stick/slip 160 x 8 x 1".into(),
            Source::Block(f) => format!("block on block n = {}", BLOCK_BASE_N * f),
        }
    }

    /// A file-name stem.
    pub fn key(self) -> String {
        match self {
            Source::Hertz(f) => format!("hertz_x{f}"),
            Source::Extreme(name) => name.to_string(),
            Source::StickSlip => "stick_slip_160x8".into(),
            Source::Block(f) => format!("block_n{}", BLOCK_BASE_N * f),
        }
    }
}

/// One problem of the table, measured.
pub struct Case {
    pub source: Source,
    pub scene: PathBuf,
    pub elements: usize,
    pub nodes: usize,
    /// The node set whose largest |u| is compared with CalculiX's.
    pub compare_set: Option<&'static str>,
    pub runs: Vec<Run>,
    /// CalculiX's run, when it runs this problem (`None`: it does not, or is missing).
    pub ccx: Option<CcxRun>,
    /// Why the problem could not be set up (no runs then).
    pub error: Option<String>,
}

/// Everything `--robustness` measured.
pub struct Robustness {
    pub info: RunInfo,
    pub quick: bool,
    pub timeout_s: f64,
    /// CalculiX's time limit.
    pub ccx_timeout_s: f64,
    pub ccx_version: Option<String>,
    pub cases: Vec<Case>,
}

/// How one run ended.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    Finished(SolverLog),
    /// The solver stopped with an error (or used another preconditioner than the one asked
    /// for): the message.
    Failed(String),
    /// Stopped at the time limit.
    OverLimit,
}

/// One run of one scene with one preconditioner.
#[derive(Clone, Debug, PartialEq)]
pub struct Run {
    pub precond: Precond,
    pub outcome: Outcome,
    /// Wall time of the `run/mpirun` process (start-up and mesh reading included), s.
    pub process_wall: f64,
    /// CG iterations and contact updates the log shows when the run did not finish: the
    /// steps it completed and the contact updates of the step it was in (at least what it
    /// did).
    pub partial: (u64, u64),
    /// The solver's `preconditioner:` line (without the prefix), when it printed one.
    pub preconditioner: Option<String>,
    /// Largest |u| over the compared node set and every step, when finished and asked for.
    pub max_u: Option<f64>,
}

impl Run {
    pub fn log(&self) -> Option<&SolverLog> {
        match &self.outcome {
            Outcome::Finished(l) => Some(l),
            _ => None,
        }
    }

    /// Peak memory per element a rank holds, bytes (finished runs).
    pub fn bytes_per_element(&self, ranks: usize) -> Option<f64> {
        let l = self.log()?;
        Some(l.peak_mib * MIB / (l.elements as f64 / ranks as f64))
    }
}
