//! The results model: everything a normal run measured, in typed structs, which both
//! report writers (`report/`) read. Quantities derived from several measurements are
//! computed here (or on the measurement's own type), once for both files.

pub mod large;
pub mod robustness;

use crate::bandwidth::Stream;
use crate::block::{marginal_bytes, BlockCase, BlockSize, PartitionReport, BLOCK_RANKS};
use crate::cube::CubeResult;
use crate::kernels::KernelResult;
use crate::machine::RunInfo;
use crate::peers::calculix::block::Calculix;
use crate::report::json::J;
use crate::runner::solver::Precond;
use crate::search::ContactResult;

/// The large section of an earlier `--large` run, carried over as it was written: a normal
/// run does not measure it and must not lose it.
pub struct EarlierLarge {
    pub json: J,
    /// Its part of report.md (from its heading to the end).
    pub markdown: String,
}

pub struct Results {
    pub quick: bool,
    pub info: RunInfo,
    /// Elements per edge of the kernel mesh.
    pub kernel_n: usize,
    pub stream: Vec<Stream>,
    pub kernels: Vec<KernelResult>,
    pub cubes: Vec<CubeResult>,
    pub contact: ContactResult,
    pub blocks: Vec<BlockSize>,
    /// The solve tolerance of the block scene.
    pub block_tolerance: Option<f64>,
    pub partitions: Vec<Result<PartitionReport, String>>,
    pub calculix: Calculix,
    pub large: Option<EarlierLarge>,
}

impl Results {
    /// The one-core triad bandwidth, GB/s (median).
    pub fn triad_1core(&self) -> Option<f64> {
        self.stream
            .iter()
            .find(|s| s.kernel == "triad" && s.threads == 1)
            .map(|s| s.gbs.median)
    }

    /// Growth of the peak memory per rank of block size `i` over the next smaller size,
    /// per element added per rank (bytes).
    pub fn marginal_bytes(&self, i: usize, p: Precond, ranks: usize) -> Option<f64> {
        let b = self.blocks.get(i)?.case(p, ranks)?;
        let a = self.blocks.get(i.checked_sub(1)?)?.case(p, ranks)?;
        marginal_bytes((a.elements(), a.runs.peak_mib.median), b)
    }

    /// The run CalculiX is set beside on a size: two-level on 2 ranks.
    pub fn our_case(&self, n: usize) -> Option<&BlockCase> {
        self.blocks
            .iter()
            .find(|b| b.n == n)?
            .case(Precond::TwoLevel, BLOCK_RANKS[1])
    }

    /// Our total contact force (y) on a size: the two-level 2-rank run's, else the
    /// two-level 1-rank run's.
    pub fn our_force(&self, n: usize) -> Option<f64> {
        let size = self.blocks.iter().find(|b| b.n == n)?;
        BLOCK_RANKS.iter().rev().find_map(|&r| {
            let c = size.case(Precond::TwoLevel, r)?;
            c.contact_force.as_ref().ok().map(|f| f[1])
        })
    }

    /// Block-on-block runs that failed.
    pub fn failed_block_runs(&self) -> usize {
        self.blocks
            .iter()
            .flat_map(|b| &b.runs)
            .flat_map(|pr| &pr.cases)
            .filter(|c| c.is_err())
            .count()
    }
}

/// CalculiX's total force over ours, less one.
pub fn relative_difference(ccx: f64, ours: f64) -> f64 {
    (ccx - ours) / ours
}
