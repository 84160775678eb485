//! A small results model with every kind of outcome (failed runs, stopped and skipped
//! CalculiX sizes, an unreadable result file, bitwise differences, an earlier large
//! section, a large run with each outcome), for the report writers' tests.

use crate::bandwidth::Stream;
use crate::block::{BlockCase, BlockSize, PartitionReport, PrecondRuns};
use crate::cube::CubeResult;
use crate::kernels::{model_bytes, Case, KernelResult};
use crate::machine::{Machine, RunInfo};
use crate::peers::calculix::block::{Calculix, CcxSize, Forces};
use crate::peers::calculix::run::{Outcome, Timed};
use crate::report::json::J;
use crate::results::large::{Large, LargeOutcome, LargeRun, MemoryEstimate};
use crate::results::{EarlierLarge, Results};
use crate::runner::log::SolverLog;
use crate::runner::solver::{Compare, Precond, Runs};
use crate::search::ContactResult;
use crate::stats::Stat;
use std::path::PathBuf;

pub fn stat(median: f64, min: f64, max: f64, repeats: usize) -> Stat {
    Stat {
        median,
        min,
        max,
        repeats,
    }
}

fn info() -> RunInfo {
    RunInfo {
        machine: Machine {
            cpu_model: "Test CPU".into(),
            cache: "512 KB".into(),
            logical_cpus: 2,
            physical_cores: None,
            date: "2000-01-02T03:04:05Z".into(),
            git_commit: Some("abc1234".into()),
            git_dirty: Some(true),
            load_start: Some("0.10 0.20 0.30".into()),
            jiffies_start: None,
        },
        total_wall: 123.5,
        load_end: None,
        steal: Some(0.015),
    }
}

/// A run of the block scene at size `n` with `cg` iterations; memory grows with n^3.
pub fn case(n: usize, ranks: usize, p: Precond, cg: u64, force: Result<f64, &str>) -> BlockCase {
    let elements = 2 * n * n * n;
    let log = SolverLog {
        elements,
        nodes: 2 * (n + 1) * (n + 1) * (n + 1),
        steps: 2,
        cg_iterations: cg,
        cg_step_sum: cg,
        contact_updates: 8,
        wall: 0.001 * cg as f64 / ranks as f64,
        peak_mib: 32.0 + elements as f64 / 1000.0,
        preconditioner: Some(match p {
            Precond::Jacobi => "nodal block Jacobi".into(),
            Precond::TwoLevel => format!(
                "two-level; coarse space: {} aggregates ({} unknowns), cell size 5.3621e-1, \
                 54 colours",
                n * 2,
                n * 12
            ),
            Precond::Multilevel | Precond::Auto => "multilevel; 3 levels".into(),
        }),
    };
    let wall = log.wall;
    let peak = log.peak_mib;
    BlockCase {
        n,
        ranks,
        runs: Runs {
            log,
            consistent: cg != 777,
            wall: stat(wall, 0.9 * wall, 1.2 * wall, 3),
            process_wall: stat(wall + 0.4, wall + 0.3, wall + 0.5, 3),
            peak_mib: stat(peak, peak, peak + 1.0, 3),
        },
        contact_force: force.map(|f| [1e-6, f, -1e-6]).map_err(str::to_string),
        result: PathBuf::from(format!("out/n{n}_np{ranks}_{}.h5", p.arg())),
    }
}

fn compare(code: i32) -> Compare {
    Compare {
        code: Some(code),
        summary: if code == 0 {
            "result: identical".into()
        } else {
            "result: 2 datasets differ | bitwise".into()
        },
    }
}

fn precond_runs(
    p: Precond,
    cases: [Result<BlockCase, String>; 2],
    compare: Option<Result<Compare, String>>,
) -> PrecondRuns {
    PrecondRuns {
        precond: p,
        cases: cases.into(),
        compare,
    }
}

fn blocks() -> Vec<BlockSize> {
    use Precond::{Jacobi, TwoLevel};
    let j = Jacobi;
    let t = TwoLevel;
    vec![
        BlockSize {
            n: 10,
            refine: 1,
            runs: vec![
                precond_runs(
                    j,
                    [
                        Ok(case(10, 1, j, 299, Ok(4.37))),
                        Ok(case(10, 2, j, 299, Ok(4.37))),
                    ],
                    Some(Ok(compare(0))),
                ),
                precond_runs(
                    t,
                    [
                        Ok(case(10, 1, t, 187, Ok(4.37))),
                        Ok(case(10, 2, t, 187, Ok(4.37))),
                    ],
                    Some(Ok(compare(0))),
                ),
            ],
        },
        BlockSize {
            n: 20,
            refine: 2,
            runs: vec![
                precond_runs(
                    j,
                    [
                        Ok(case(20, 1, j, 600, Ok(4.4))),
                        Err("exit code 1: step 1 failed | diverged".into()),
                    ],
                    None,
                ),
                precond_runs(
                    t,
                    [
                        Ok(case(20, 1, t, 239, Ok(4.4))),
                        Ok(case(20, 2, t, 777, Ok(4.4))),
                    ],
                    Some(Err("cannot run compare".into())),
                ),
            ],
        },
        BlockSize {
            n: 40,
            refine: 4,
            runs: vec![
                precond_runs(
                    j,
                    [
                        Ok(case(40, 1, j, 1892, Ok(4.41))),
                        Ok(case(40, 2, j, 1892, Err("no steps | none"))),
                    ],
                    Some(Ok(compare(1))),
                ),
                precond_runs(
                    t,
                    [
                        Ok(case(40, 1, t, 377, Ok(4.41))),
                        Ok(case(40, 2, t, 400, Ok(4.41))),
                    ],
                    Some(Ok(compare(0))),
                ),
            ],
        },
    ]
}

fn kernels() -> Vec<KernelResult> {
    let case = Case {
        label: "full, linear elastic (small)",
        integration: "full",
        volumetric: "standard",
        large: false,
        tet: false,
    };
    ["internal_force", "diagonal"]
        .iter()
        .enumerate()
        .map(|(i, &operation)| KernelResult {
            case,
            operation,
            elements: 27000,
            nodes: 29791,
            seconds: stat(0.01 * (i + 1) as f64, 0.009, 0.03, 5),
            cpu_share: 0.98,
            model_bytes: model_bytes(3 + 6 * i),
            checksum: 12.5,
        })
        .collect()
}

fn cubes() -> Vec<CubeResult> {
    [(10, 3509, 97), (20, 26019, 241), (40, 199_000, 480)]
        .iter()
        .map(|&(n, unknowns, cg)| CubeResult {
            n,
            elements: n * n * n,
            nodes: (n + 1) * (n + 1) * (n + 1),
            unknowns,
            cg_iterations: cg,
            iterations_consistent: n != 20,
            run_wall: stat(0.05 * n as f64, 0.04 * n as f64, 0.06 * n as f64, 3),
            solve_wall: stat(0.04 * n as f64, 0.03 * n as f64, 0.05 * n as f64, 3),
            cpu_share: 0.99,
            force_call: stat(1e-4, 9e-5, 2e-4, 5),
            max_error: 3.6e-9,
        })
        .collect()
}

fn contact() -> ContactResult {
    ContactResult {
        m: 100,
        master_faces: 10000,
        slave_nodes: 10000,
        face_size: 0.01,
        normal_tolerance: 0.005,
        tangential_tolerance: 0.001,
        max_offset: 0.0025,
        parse_s: 0.05,
        perturb_s: 0.0001,
        build: stat(0.003, 0.0029, 0.0035, 5),
        search: stat(0.0145, 0.0144, 0.015, 5),
        total: stat(0.018, 0.0177, 0.0185, 5),
        cpu_share: 1.0,
        found: 9999,
        expected: 10000,
        expected_found: 9999,
        consistent: false,
        max_gap_error: 3e-17,
        max_point_error: 3e-16,
        mortar: stat(0.09, 0.088, 0.095, 5),
        mortar_ties: 10000,
        mortar_weight_error: 4e-16,
    }
}

fn calculix() -> Calculix {
    let size = |n: usize, outcome| CcxSize {
        n,
        elements: if n == 80 { 0 } else { 2 * n * n * n },
        nodes: 2 * (n + 1) * (n + 1) * (n + 1),
        deck: PathBuf::from(format!("out/calculix/n{n}/block_on_block_n{n}.inp")),
        outcome,
    };
    let finished = Outcome::Finished {
        timed: Timed {
            wall: stat(0.63, 0.6, 0.7, 3),
            own_time: Some(0.62),
            peak_mib: Some(64.2),
            iterations: 3,
        },
        values: Forces {
            top: [1e-5, -4.374205, -1e-5],
            bottom: [-1e-5, 4.374205, 1e-5],
        },
    };
    Calculix {
        version: Some("2.20".into()),
        sizes: vec![
            size(10, finished),
            size(20, Outcome::Stopped("stopped after 300 s".into())),
            size(
                40,
                Outcome::Skipped("n = 20 did not finish (stopped after 300 s)".into()),
            ),
            size(
                80,
                Outcome::Failed("exit code Some(0); *ERROR in | deck (log x)".into()),
            ),
        ],
    }
}

/// A full (not quick) run with every kind of outcome.
pub fn results() -> Results {
    Results {
        quick: false,
        info: info(),
        kernel_n: 30,
        stream: vec![
            Stream {
                kernel: "copy",
                threads: 1,
                array_bytes: 67_108_864,
                bytes_per_pass: 2 * 67_108_864,
                gbs: stat(20.5, 19.0, 21.0, 3),
            },
            Stream {
                kernel: "triad",
                threads: 1,
                array_bytes: 67_108_864,
                bytes_per_pass: 3 * 67_108_864,
                gbs: stat(22.25, 21.0, 23.0, 3),
            },
        ],
        kernels: kernels(),
        cubes: cubes(),
        contact: contact(),
        blocks: blocks(),
        block_tolerance: Some(1e-9),
        partitions: vec![
            Ok(PartitionReport {
                n: 40,
                ranks: 2,
                imbalance: Some(1.0),
                edge_cut: Some(0),
                text: "decomposition: 2 part(s), element imbalance 1.000 (max/mean), edge cut 0"
                    .into(),
            }),
            Err("solver check --refine 4 --ranks 3: error".into()),
        ],
        calculix: calculix(),
        large: Some(EarlierLarge {
            json: J::Obj(vec![("n".into(), J::Int(80))]),
            markdown: "## Large block on block (n = 80, `run/bench --large`)\n\nearlier\n".into(),
        }),
    }
}

fn estimate(fits: bool) -> MemoryEstimate {
    MemoryEstimate {
        pilot: vec![(20, 16000, 60.0), (40, 128_000, 200.0)],
        marginal_bytes: 1310.72,
        elements: 1_024_000,
        predicted_mib_per_rank: 900.0,
        available_mib: fits.then_some(20000.0),
        fits,
    }
}

/// A `--large` run on 1, 2, 3 and 4 ranks: finished, finished, not run, failed.
pub fn large() -> Large {
    let t = Precond::TwoLevel;
    Large {
        info: info(),
        precond: t,
        runs: vec![
            LargeRun {
                ranks: 1,
                precond: t,
                estimate: Ok(estimate(true)),
                outcome: LargeOutcome::Finished(Box::new(case(80, 1, t, 716, Ok(4.42)))),
            },
            LargeRun {
                ranks: 2,
                precond: t,
                estimate: Ok(estimate(true)),
                outcome: LargeOutcome::Finished(Box::new(case(80, 2, t, 716, Ok(4.42)))),
            },
            LargeRun {
                ranks: 3,
                precond: t,
                estimate: Err("exit code 1: x".into()),
                outcome: LargeOutcome::NotRun("memory estimate failed: exit code 1: x".into()),
            },
            LargeRun {
                ranks: 4,
                precond: t,
                estimate: Ok(estimate(false)),
                outcome: LargeOutcome::Failed("stopped | after 21600 s".into()),
            },
        ],
        compare: Some(Ok(compare(0))),
    }
}

/// The robustness table of one Hertz mesh with every outcome: Jacobi failed, two-level
/// over the time limit, multilevel and auto finished, CalculiX finished.
pub fn robustness() -> crate::results::robustness::Robustness {
    use crate::peers::calculix::robustness::CcxRun;
    use crate::results::robustness::Source;
    use crate::results::robustness::{Case as RCase, Outcome as RunOutcome, Robustness, Run};
    let log = SolverLog {
        elements: 2940,
        nodes: 6218,
        steps: 1,
        cg_iterations: 300,
        cg_step_sum: 300,
        contact_updates: 4,
        wall: 6.0,
        peak_mib: 2.5,
        preconditioner: Some("multilevel; 3 levels".into()),
    };
    let run = |precond, outcome, process_wall, partial, line: &str, max_u| Run {
        precond,
        outcome,
        process_wall,
        partial,
        preconditioner: Some(line.into()),
        max_u,
    };
    let runs = vec![
        run(
            Precond::Jacobi,
            RunOutcome::Failed(
                "step 1 (to t = 1) failed at t = 0.015625 after 6 cut-backs: CG did not \
                 converge in 20000 iterations"
                    .into(),
            ),
            95.0,
            (0, 2),
            "nodal block Jacobi",
            None,
        ),
        run(
            Precond::TwoLevel,
            RunOutcome::OverLimit,
            240.5,
            (1500, 3),
            "two-level; coarse space: 40 aggregates",
            None,
        ),
        run(
            Precond::Multilevel,
            RunOutcome::Finished(log.clone()),
            8.0,
            (300, 4),
            "multilevel; 3 levels",
            Some(0.625),
        ),
        run(
            Precond::Auto,
            RunOutcome::Finished(log),
            8.0,
            (300, 4),
            "two-level, multilevel from CG iteration 400 of a model problem on; x",
            Some(0.625),
        ),
    ];
    let ccx = CcxRun {
        deck: PathBuf::from("out/bench/robustness/calculix/hertz_x2/hertz_x2.inp"),
        outcome: Outcome::Finished {
            timed: Timed {
                wall: stat(12.0, 12.0, 12.0, 1),
                own_time: Some(11.5),
                peak_mib: Some(20.0),
                iterations: 12,
            },
            values: 0.5,
        },
    };
    Robustness {
        info: info(),
        quick: false,
        timeout_s: 240.0,
        ccx_timeout_s: 600.0,
        ccx_version: Some("2.20".into()),
        cases: vec![RCase {
            source: Source::Hertz(2),
            scene: PathBuf::from("out/bench/robustness/scenes/cylinder_on_block_x2.toml"),
            elements: 2940,
            nodes: 6218,
            compare_set: Some("cylinder_axis"),
            runs,
            ccx: Some(ccx),
            error: None,
        }],
    }
}
