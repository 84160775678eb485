//! One run of the robustness table: `solver run` under `run/mpirun` with one
//! preconditioner and a time limit, and how it ended. A run that fails or is stopped is a
//! result, not an error: its message and the CG iterations it logged before it ended are
//! kept.

use crate::api::ResultFile;
use crate::results::robustness::{Outcome, Run};
use crate::runner::log::{last_line, number_after, parse_solver_log};
use crate::runner::process::{run_limited, Limits};
use crate::runner::solver::Job;
use std::path::Path;

/// CG iterations and contact updates in a log that has no `done:` line: every `step` line
/// and the contact-update lines after the last of them (the step in progress).
pub fn partial_counts(text: &str) -> (u64, u64) {
    let (mut cg, mut updates) = (0u64, 0u64);
    let (mut step_cg, mut step_updates) = (0u64, 0u64);
    for l in text.lines() {
        if l.starts_with("step ") {
            cg += number_after::<u64>(l, " CG ").unwrap_or(0);
            updates += number_after::<u64>(l, "contact updates ").unwrap_or(0);
            (step_cg, step_updates) = (0, 0);
        } else if l.trim_start().starts_with("t = ") && l.contains(": contact update ") {
            step_cg += number_after::<u64>(l, ": CG ").unwrap_or(0);
            step_updates += 1;
        }
    }
    (cg + step_cg, updates + step_updates)
}

/// The solver's last `error: ` line without the prefix (it may be followed by where the
/// completed steps went), else its last line.
pub fn failure_message(text: &str) -> &str {
    text.lines()
        .rev()
        .find_map(|l| l.strip_prefix("error: "))
        .unwrap_or_else(|| last_line(text))
        .trim()
}

/// Largest |u| over `nodes` (global ids) and every step of a result file.
pub fn max_displacement(path: &Path, nodes: &[u32]) -> Result<f64, String> {
    let file = ResultFile::open(path).map_err(|e| e.to_string())?;
    let mut max = 0.0f64;
    for k in 0..file.num_steps() {
        let u = file.displacement(k).map_err(|e| e.to_string())?;
        for &n in nodes {
            let v = u
                .get(n as usize)
                .ok_or_else(|| format!("{}: no node {n}", path.display()))?;
            max = max.max((v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt());
        }
    }
    Ok(max)
}

/// Runs `job` once under `limits`; `compare` is the node set whose largest |u| is read
/// from the result file of a finished run.
pub fn run(exe: &Path, job: &Job, limits: &Limits, compare: Option<&[u32]>) -> Result<Run, String> {
    let log_path = job.result.with_extension("log");
    let _ = std::fs::remove_file(&job.result);
    let f = run_limited(
        &mut job.command(exe),
        &job.result.with_extension("out"),
        &log_path,
        limits,
    )?;
    let text = std::fs::read_to_string(&log_path)
        .map_err(|e| format!("cannot read {}: {e}", log_path.display()))?;
    let preconditioner = text
        .lines()
        .find_map(|l| l.strip_prefix("preconditioner: "))
        .map(|l| l.trim().to_string());
    let outcome = if f.stopped.is_some() {
        Outcome::OverLimit
    } else if f.code != Some(0) {
        Outcome::Failed(failure_message(&text).to_string())
    } else {
        match parse_solver_log(&text) {
            Err(e) => Outcome::Failed(format!("log not read: {e}")),
            Ok(l) => match &preconditioner {
                Some(line) if !job.preconditioner.used(line) => {
                    Outcome::Failed(format!("used {line}"))
                }
                _ => Outcome::Finished(l),
            },
        }
    };
    let max_u = match (&outcome, compare) {
        (Outcome::Finished(_), Some(nodes)) => Some(max_displacement(&job.result, nodes)?),
        _ => None,
    };
    let partial = match &outcome {
        Outcome::Finished(l) => (l.cg_iterations, l.contact_updates),
        _ => partial_counts(&text),
    };
    Ok(Run {
        precond: job.preconditioner,
        outcome,
        process_wall: f.wall,
        partial,
        preconditioner,
        max_u,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two steps done, the third stopped in its second contact update: the steps' counts
    /// and the contact updates of the step in progress.
    #[test]
    fn counts_of_a_run_that_did_not_finish() {
        let log = "\
preconditioner: nodal block Jacobi
step 1/3  t = 0.1    CG    100  residual 1e-9  cut-backs 0  1.0 s  contact updates 2, in contact 4
step 2/3  t = 0.2    CG     50  residual 1e-9  cut-backs 0  1.0 s  contact updates 1, in contact 4
  t = 0.3: contact update 1: CG 70 iterations, in contact 4 (stick 0, slip 4), set changed, 0.5 s into the step
  t = 0.3: contact update 2: CG 30 iterations, in contact 4 (stick 0, slip 4), set changed, 0.9 s into the step
error: step 3 (to t = 0.3) failed at t = 0.25 after 6 cut-backs: CG did not converge
";
        assert_eq!(partial_counts(log), (250, 5));
        let with_file = format!("{log}the completed steps are in out/x.failed.h5\n");
        assert_eq!(
            failure_message(&with_file),
            "step 3 (to t = 0.3) failed at t = 0.25 after 6 cut-backs: CG did not converge"
        );
        assert_eq!(failure_message("killed\n"), "killed");
        assert_eq!(partial_counts(""), (0, 0));
    }
}
