//! The block-on-block scene (`run/scenes/bench/block_on_block.toml`) refined to n = 10,
//! 20, 40 elements per edge, run by the solver under `run/mpirun` on 1 and 2 ranks with
//! each preconditioner: CG iterations, contact updates, wall time, peak memory, total
//! contact force, the coarse space; the two-level / Jacobi ratios, the 2-rank speed-up and
//! whether 1 and 2 ranks give bitwise the same file; and `solver check --ranks` of one
//! size (the partition).

use crate::api::{load_scene_refined, norm, sub, Vec3};
use crate::config::Config;
use crate::runner::log::{coarse_info, number_after, CoarseInfo};
use crate::runner::process::{Limits, MIB};
use crate::runner::solver::{
    compare_results, repo_root, solver_check, total_contact_force, Compare, Job, Precond, Runs,
};
use crate::stats::{ratio, Stat};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The benchmark scene; the solver refines it itself (`solver run --refine F`).
pub const BLOCK_SCENE: &str = "run/scenes/bench/block_on_block.toml";
/// Elements per edge of each block in BLOCK_SCENE.
pub const BLOCK_BASE_N: usize = 10;
/// Rank counts of the solver runs; the speed-up is the first over the second.
pub const BLOCK_RANKS: [usize; 2] = [1, 2];
/// Rank counts whose decomposition `solver check --ranks` reports.
pub const PARTITION_RANKS: [usize; 2] = [2, 3];
/// Node sets of BLOCK_SCENE held in y: the upper block's top (pressed down), the lower
/// block's bottom.
pub const BLOCK_TOP_SET: &str = "upper_top";
pub const BLOCK_BOTTOM_SET: &str = "lower_bottom";
/// A solver run still going after this long is stopped (a hang under MPI, not a result).
pub const SOLVER_TIMEOUT_S: f64 = 7200.0;
/// What the two-level preconditioner should reach on n = GOAL_N (the project's issue 9):
/// at most these fractions of Jacobi's CG iterations and wall time.
pub const GOAL_N: usize = 40;
pub const GOAL_ITERATION_RATIO: f64 = 1.0 / 5.0;
pub const GOAL_TIME_RATIO: f64 = 1.0 / 3.0;
/// Every block-on-block size runs with each; ratios are the second over the first.
pub const PRECONDITIONERS: [Precond; 2] = [Precond::Jacobi, Precond::TwoLevel];

/// The block-on-block scene at one size on one rank count with one preconditioner,
/// repeated.
pub struct BlockCase {
    /// Elements per edge of each block.
    pub n: usize,
    pub ranks: usize,
    pub runs: Runs,
    /// Total contact force at the last step (from the last repeat's result file).
    pub contact_force: Result<Vec3, String>,
    pub result: PathBuf,
}

impl BlockCase {
    pub fn elements(&self) -> usize {
        self.runs.log.elements
    }

    pub fn cg_iterations(&self) -> u64 {
        self.runs.log.cg_iterations
    }

    pub fn bytes_per_element(&self) -> f64 {
        self.runs.bytes_per_element(self.ranks)
    }

    pub fn preconditioner_line(&self) -> &str {
        self.runs.log.preconditioner.as_deref().unwrap_or("")
    }

    pub fn coarse(&self) -> Option<CoarseInfo> {
        coarse_info(self.preconditioner_line())
    }
}

/// Growth of the peak memory per rank from `a` to the larger `b` (same rank count), per
/// element added per rank (bytes): the runtime's fixed cost cancels.
pub fn marginal_bytes(a: (usize, f64), b: &BlockCase) -> Option<f64> {
    let (elements, peak_mib) = a;
    let de = (b.elements() as f64 - elements as f64) / b.ranks as f64;
    (de > 0.0).then(|| (b.runs.peak_mib.median - peak_mib) * MIB / de)
}

/// The block scene refined by `refine` on `ranks` ranks with `precond`, repeated, its
/// result file in `dir`.
pub fn block_case(
    exe: &Path,
    dir: &Path,
    refine: usize,
    ranks: usize,
    precond: Precond,
    repeats: usize,
    limits: &Limits,
) -> Result<BlockCase, String> {
    let n = BLOCK_BASE_N * refine;
    let job = Job {
        scene: repo_root().join(BLOCK_SCENE),
        refine: Some(refine),
        ranks,
        preconditioner: precond,
        result: dir.join(format!("n{n}_np{ranks}_{}.h5", precond.arg())),
    };
    let label = format!("n = {n}, {}, {ranks} rank(s)", precond.label());
    let runs = job.run_repeated(exe, repeats, limits, &label)?;
    Ok(BlockCase {
        n,
        ranks,
        runs,
        contact_force: total_contact_force(&job.result),
        result: job.result,
    })
}

/// The speed-up of the first rank count over the second: (median, min, max) of the
/// first's wall time over the second's.
pub fn speedup(a: &BlockCase, b: &BlockCase) -> Stat {
    ratio(&a.runs.wall, &b.runs.wall)
}

/// One size with one preconditioner on every rank count of BLOCK_RANKS.
pub struct PrecondRuns {
    pub precond: Precond,
    /// In the order of BLOCK_RANKS.
    pub cases: Vec<Result<BlockCase, String>>,
    /// The first rank count's result file against the second's.
    pub compare: Option<Result<Compare, String>>,
}

impl PrecondRuns {
    pub fn case(&self, ranks: usize) -> Option<&BlockCase> {
        self.cases.iter().flatten().find(|c| c.ranks == ranks)
    }

    pub fn speedup(&self) -> Option<Stat> {
        Some(speedup(
            self.case(BLOCK_RANKS[0])?,
            self.case(BLOCK_RANKS[1])?,
        ))
    }
}

/// One size of the block-on-block scene with every preconditioner on every rank count.
pub struct BlockSize {
    pub n: usize,
    pub refine: usize,
    /// In the order of PRECONDITIONERS.
    pub runs: Vec<PrecondRuns>,
}

impl BlockSize {
    pub fn runs(&self, p: Precond) -> Option<&PrecondRuns> {
        self.runs.iter().find(|r| r.precond == p)
    }

    pub fn case(&self, p: Precond, ranks: usize) -> Option<&BlockCase> {
        self.runs(p)?.case(ranks)
    }

    pub fn elements(&self) -> Option<usize> {
        self.runs
            .iter()
            .flat_map(|r| r.cases.iter().flatten())
            .map(BlockCase::elements)
            .next()
    }

    /// The most repeats any run of this size had.
    pub fn repeats(&self) -> usize {
        self.runs
            .iter()
            .flat_map(|pr| pr.cases.iter().flatten())
            .map(|c| c.runs.wall.repeats)
            .max()
            .unwrap_or(0)
    }

    /// The two runs compared on a rank count: (Jacobi, two-level).
    pub fn pair(&self, ranks: usize) -> Option<(&BlockCase, &BlockCase)> {
        Some((
            self.case(PRECONDITIONERS[0], ranks)?,
            self.case(PRECONDITIONERS[1], ranks)?,
        ))
    }

    /// Two-level CG iterations over Jacobi's.
    pub fn iteration_ratio(&self, ranks: usize) -> Option<f64> {
        let (j, t) = self.pair(ranks)?;
        Some(t.cg_iterations() as f64 / j.cg_iterations() as f64)
    }

    /// Two-level wall time over Jacobi's.
    pub fn time_ratio(&self, ranks: usize) -> Option<Stat> {
        let (j, t) = self.pair(ranks)?;
        Some(ratio(&t.runs.wall, &j.runs.wall))
    }

    /// |F_two-level - F_Jacobi| / |F_Jacobi| of the total contact force vectors.
    pub fn force_difference(&self, ranks: usize) -> Option<f64> {
        let (j, t) = self.pair(ranks)?;
        let (fj, ft) = (
            j.contact_force.as_ref().ok()?,
            t.contact_force.as_ref().ok()?,
        );
        Some(norm(&sub(ft, fj)) / norm(fj))
    }

    /// The preconditioner lines of the two-level runs, one per distinct line, with the
    /// rank counts that printed it.
    pub fn coarse_lines(&self) -> Vec<(Vec<usize>, String)> {
        let mut lines: Vec<(Vec<usize>, String)> = Vec::new();
        let Some(runs) = self.runs(Precond::TwoLevel) else {
            return lines;
        };
        for c in runs.cases.iter().flatten() {
            let line = c.preconditioner_line().to_string();
            match lines.iter_mut().find(|(_, l)| *l == line) {
                Some((ranks, _)) => ranks.push(c.ranks),
                None => lines.push((vec![c.ranks], line)),
            }
        }
        lines
    }
}

fn block_size(exe: &Path, dir: &Path, refine: usize, repeats: usize) -> BlockSize {
    let n = BLOCK_BASE_N * refine;
    let limits = Limits::timeout(SOLVER_TIMEOUT_S);
    let runs = PRECONDITIONERS
        .iter()
        .map(|&precond| {
            let cases: Vec<Result<BlockCase, String>> = BLOCK_RANKS
                .iter()
                .map(|&ranks| {
                    let c = block_case(exe, dir, refine, ranks, precond, repeats, &limits);
                    if let Err(e) = &c {
                        eprintln!(
                            "bench:   n = {n}, {}, {ranks} rank(s) failed: {e}",
                            precond.label()
                        );
                    }
                    c
                })
                .collect();
            let compare = match (&cases[0], &cases[1]) {
                (Ok(a), Ok(b)) => Some(compare_results(exe, &a.result, &b.result)),
                _ => None,
            };
            PrecondRuns {
                precond,
                cases,
                compare,
            }
        })
        .collect();
    BlockSize { n, refine, runs }
}

/// Every configured size, reported on standard error as it finishes.
pub fn run(cfg: &Config, exe: &Path) -> Result<Vec<BlockSize>, String> {
    let block_dir = cfg.out.join("block");
    std::fs::create_dir_all(&block_dir)
        .map_err(|e| format!("cannot create {}: {e}", block_dir.display()))?;
    let mut blocks = Vec::new();
    for &(refine, repeats) in &cfg.block {
        let t = Instant::now();
        let n = BLOCK_BASE_N * refine;
        eprintln!(
            "bench: block on block n = {n} on {BLOCK_RANKS:?} ranks, {} ({repeats} repeat(s))",
            PRECONDITIONERS.map(Precond::label).join(" and ")
        );
        let b = block_size(exe, &block_dir, refine, repeats);
        progress(&b);
        eprintln!(
            "bench:   n = {n}: {:.1} s in all",
            t.elapsed().as_secs_f64()
        );
        blocks.push(b);
    }
    Ok(blocks)
}

fn progress(b: &BlockSize) {
    let n = b.n;
    for pr in &b.runs {
        eprintln!(
            "bench:   n = {n}, {}: speed-up {}, 1 and 2 ranks {}",
            pr.precond.label(),
            pr.speedup()
                .map_or("-".into(), |s| format!("{:.2}", s.median)),
            match &pr.compare {
                Some(Ok(c)) if c.identical() => "bitwise identical".to_string(),
                Some(Ok(c)) => format!("differ ({})", c.summary),
                Some(Err(e)) => format!("not compared: {e}"),
                None => "not compared".to_string(),
            }
        );
    }
    for r in BLOCK_RANKS {
        if let (Some(it), Some(tr), Some(df)) =
            (b.iteration_ratio(r), b.time_ratio(r), b.force_difference(r))
        {
            eprintln!(
                "bench:   n = {n}, {r} rank(s): two-level / Jacobi: CG {it:.3}, time {:.3}; contact forces differ by {df:.1e}",
                tr.median
            );
        }
    }
}

/// The solve tolerance of BLOCK_SCENE (`solver.tolerance`).
pub fn block_tolerance() -> Option<f64> {
    load_scene_refined(&repo_root().join(BLOCK_SCENE), 1)
        .ok()
        .map(|p| p.solver.tolerance)
}

/// `solver check SCENE --refine F --ranks R`: the decomposition part of its output.
pub struct PartitionReport {
    pub n: usize,
    pub ranks: usize,
    pub imbalance: Option<f64>,
    pub edge_cut: Option<u64>,
    /// From the `decomposition:` line to the end.
    pub text: String,
}

fn partition_report(exe: &Path, refine: usize, ranks: usize) -> Result<PartitionReport, String> {
    let stdout = solver_check(exe, &repo_root().join(BLOCK_SCENE), refine, ranks)?;
    let start = stdout
        .find("decomposition:")
        .ok_or("solver check printed no 'decomposition:' line")?;
    let text = stdout[start..].trim_end().to_string();
    Ok(PartitionReport {
        n: BLOCK_BASE_N * refine,
        ranks,
        imbalance: number_after(&text, "element imbalance "),
        edge_cut: number_after(&text, "edge cut "),
        text,
    })
}

/// The decomposition of the configured size over every rank count of PARTITION_RANKS.
pub fn partitions(cfg: &Config, exe: &Path) -> Vec<Result<PartitionReport, String>> {
    PARTITION_RANKS
        .iter()
        .map(|&r| partition_report(exe, cfg.partition_refine, r))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::fixture::{case, results};

    #[test]
    fn ratios_of_a_size() {
        let r = results();
        let (n10, n20) = (&r.blocks[0], &r.blocks[1]);
        assert_eq!(n10.iteration_ratio(1), Some(187.0 / 299.0));
        // The fixture's forces are equal: no difference.
        assert_eq!(n10.force_difference(2), Some(0.0));
        // The 2-rank Jacobi run at n = 20 failed: nothing to compare on 2 ranks.
        assert!(n20.pair(2).is_none() && n20.iteration_ratio(2).is_none());
        assert!(n20.runs(Precond::Jacobi).unwrap().speedup().is_none());
        assert_eq!(n20.elements(), Some(16000));
        assert_eq!(n20.repeats(), 3);
        // One coarse line per distinct line, with the rank counts that printed it.
        assert_eq!(n10.coarse_lines().len(), 1);
        assert_eq!(n10.coarse_lines()[0].0, [1, 2]);
    }

    /// The speed-up's extremes pair the fastest with the slowest repeat; bytes per
    /// element divide the peak by the elements one rank holds.
    #[test]
    fn speedup_and_memory_per_element() {
        let t = Precond::TwoLevel;
        let (one, two) = (case(10, 1, t, 200, Ok(1.0)), case(10, 2, t, 200, Ok(1.0)));
        let s = speedup(&one, &two);
        assert_eq!(s.median, 2.0);
        assert!((s.min - 2.0 * 0.9 / 1.2).abs() < 1e-15 && (s.max - 2.0 * 1.2 / 0.9).abs() < 1e-15);
        // 34 MiB over 1000 elements per rank.
        assert!((two.bytes_per_element() - 34.0 * MIB / 1000.0).abs() < 1e-9);
        let c = two.coarse().unwrap();
        assert_eq!((c.aggregates, c.unknowns), (20, 120));
    }

    /// The forces' difference is relative to Jacobi's force vector.
    #[test]
    fn force_difference_is_relative() {
        let j = Precond::Jacobi;
        let t = Precond::TwoLevel;
        let size = BlockSize {
            n: 10,
            refine: 1,
            runs: vec![
                PrecondRuns {
                    precond: j,
                    cases: vec![Ok(case(10, 1, j, 299, Ok(4.0))), Err("x".into())],
                    compare: None,
                },
                PrecondRuns {
                    precond: t,
                    cases: vec![Ok(case(10, 1, t, 187, Ok(4.004))), Err("x".into())],
                    compare: None,
                },
            ],
        };
        // |(0, 0.004, 0)| / |(1e-6, 4, -1e-6)|, the x and z components cancelling.
        let d = size.force_difference(1).unwrap();
        assert!((d - 0.001).abs() < 1e-12, "{d}");
    }
}
