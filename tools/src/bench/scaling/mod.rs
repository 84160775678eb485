//! `--scaling`: the block on block at n = 40 with the multilevel preconditioner on 1, 2, 4,
//! 8 and 16 ranks (oversubscribed beyond the machine's cores: memory and message counts
//! are what these runs measure, not time), and the paper's two-element capture/release scene on 8 ranks (the runtime's
//! own peak: MPI, HDF5 and the binary). Per rank count: the peak memory per rank, the CG
//! iterations and what the busiest rank sent per CG iteration (the solver's
//! `communication` line). From them: the fit peak = a + b / P and a's replicated part (a
//! less the runtime) against the 1-rank peak; and from the measured compute rate (1 and 2
//! ranks, the machine's two cores) and the counted messages a latency-bandwidth model of
//! strong and weak scaling to 1024 ranks (`model`), drawn in `scaling.png`.
//! `bench --scaling [--out DIR]` writes `<out>/scaling/`: report.md, results.json,
//! scaling.png and each run's log and result file.

pub mod measured;
pub mod model;
mod report;

use crate::block::{block_case, SOLVER_TIMEOUT_S};
use crate::runner::process::Limits;
use crate::runner::solver::{repo_root, solver_exe, Job, Precond};
use measured::{
    iteration_of, sent_per_iteration, Point, Scaling, RUNTIME_RANKS, RUNTIME_SCENE, SCALING_RANKS,
    SCALING_REFINE,
};
use model::fit_inverse;
use std::path::{Path, PathBuf};

/// Runs the points and the runtime scene and writes the report.
pub fn run(out: &Path) -> Result<(), String> {
    let exe = solver_exe()?;
    let dir = out.join("scaling");
    std::fs::create_dir_all(&dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let limits = Limits::timeout(SOLVER_TIMEOUT_S);
    let mut points = Vec::new();
    let mut failures = Vec::new();
    for ranks in SCALING_RANKS {
        eprintln!("bench: scaling: block on block n = 40, multilevel, {ranks} rank(s)");
        let case = block_case(
            &exe,
            &dir,
            SCALING_REFINE,
            ranks,
            Precond::Multilevel,
            1,
            &limits,
        );
        match case {
            Ok(case) => {
                let log =
                    std::fs::read_to_string(case.result.with_extension("log")).unwrap_or_default();
                points.push(Point {
                    sent: sent_per_iteration(&log),
                    case,
                });
            }
            Err(e) => failures.push(format!("{ranks} rank(s): {e}")),
        }
    }
    let runtime = Job {
        scene: repo_root().join(RUNTIME_SCENE),
        refine: None,
        ranks: RUNTIME_RANKS,
        preconditioner: Precond::Auto,
        result: dir.join(PathBuf::from(format!("runtime_np{RUNTIME_RANKS}.h5"))),
    }
    .run_repeated(&exe, 1, &limits, "capture_release, 8 ranks (the runtime)");
    let runtime_mib = match runtime {
        Ok(r) => Some(r.peak_mib.median),
        Err(e) => {
            failures.push(format!("the runtime scene: {e}"));
            None
        }
    };
    let pts: Vec<(f64, f64)> = points
        .iter()
        .map(|p| (p.ranks() as f64, p.peak_mib()))
        .collect();
    let scaling = Scaling {
        fit: fit_inverse(&pts),
        iteration: iteration_of(&points),
        points,
        runtime_mib,
        failures,
    };
    report::write(&dir, &scaling)?;
    println!("{}", report::markdown(&scaling));
    Ok(())
}
