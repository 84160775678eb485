//! Our side of a plasticity case: `solver -v run SCENE -o OUT` under `run/mpirun` on 2
//! ranks with the default (`auto`) preconditioner, its log read back (the preconditioner
//! line, the CG iterations of every increment) and the punch's final mean pressure from the
//! result file.

use super::results::{Ours, RANKS};
use crate::api::ResultFile;
use crate::runner::log::{last_line, number_after, number_before};
use crate::runner::process::{run_limited, Limits};
use crate::runner::solver::{repo_root, solver_exe};
use std::path::{Path, PathBuf};
use std::process::Command;

/// What `solver -v run` printed on standard error (rank 0), read back.
#[derive(Clone, Debug, PartialEq)]
pub struct RunLog {
    /// CG iterations of every `step k/N ... CG n ...` line, in order.
    pub cg_per_step: Vec<u64>,
    /// From the `done:` line; the sum of `cg_per_step`.
    pub cg_total: u64,
    /// The run's wall time as the `done:` line gives it.
    pub solver_wall: f64,
    /// Sum of the steps' `contact updates n` (a scene without contact prints none).
    pub contact_updates: u64,
    /// The `preconditioner: ..` line without its prefix.
    pub preconditioner: Option<String>,
}

/// The CG iterations of every step line of a solver log, in order.
pub fn cg_per_step(log: &str) -> Result<Vec<u64>, String> {
    step_lines(log)
        .map(|l| number_after(l, " CG ").ok_or_else(|| format!("cannot read CG from '{l}'")))
        .collect()
}

fn step_lines(log: &str) -> impl Iterator<Item = &str> {
    log.lines().filter(|l| l.starts_with("step "))
}

/// The log of a finished run: its step lines and its `done:` line.
pub fn parse_log(text: &str) -> Result<RunLog, String> {
    let done = text
        .lines()
        .find(|l| l.starts_with("done: "))
        .ok_or("no 'done: ..' line")?;
    let bad = |what: &str| format!("cannot read {what} from '{done}'");
    let log = RunLog {
        cg_per_step: cg_per_step(text)?,
        cg_total: number_before(done, " CG iterations").ok_or_else(|| bad("CG"))?,
        solver_wall: number_before(done, " s, peak memory").ok_or_else(|| bad("seconds"))?,
        contact_updates: step_lines(text)
            .filter_map(|l| number_after::<u64>(l, "contact updates "))
            .sum(),
        preconditioner: text
            .lines()
            .find_map(|l| l.strip_prefix("preconditioner: "))
            .map(|l| l.trim().to_string()),
    };
    let sum: u64 = log.cg_per_step.iter().sum();
    if sum != log.cg_total {
        return Err(format!(
            "the steps' CG iterations add up to {sum}, the done line says {}",
            log.cg_total
        ));
    }
    Ok(log)
}

/// Our run of `scene` into `dir` (`ours.h5`, `ours.log`, `ours.out`), stopped after
/// `timeout_s`; the mean pressure is the y reaction of the node set `punch_set` over
/// `area`, positive pressing.
pub fn run(
    scene: &Path,
    dir: &Path,
    punch_set: &str,
    area: f64,
    timeout_s: f64,
) -> Result<Ours, String> {
    let (wall, log, h5) = solve(scene, dir, timeout_s)?;
    Ok(Ours {
        wall,
        solver_wall: log.solver_wall,
        cg_total: log.cg_total,
        cg_per_step: log.cg_per_step,
        contact_updates: log.contact_updates,
        preconditioner: log.preconditioner.unwrap_or_else(|| "(no line)".into()),
        pressure: pressure(&h5, punch_set, area)?,
    })
}

/// `solver -v run scene` on `RANKS` ranks into `dir` (`ours.h5`, `ours.log`, `ours.out`),
/// stopped after `timeout_s`: the process's wall time, its log read back (checked against
/// the result file's CG counts) and the result file's path.
pub fn solve(scene: &Path, dir: &Path, timeout_s: f64) -> Result<(f64, RunLog, PathBuf), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let h5 = dir.join("ours.h5");
    let log_path = dir.join("ours.log");
    let _ = std::fs::remove_file(&h5);
    let mut cmd = Command::new(repo_root().join("run/mpirun"));
    cmd.args(["-np", &RANKS.to_string()])
        .arg(solver_exe()?)
        .args(["-v", "run"])
        .arg(scene)
        .arg("-o")
        .arg(&h5);
    let f = run_limited(
        &mut cmd,
        &dir.join("ours.out"),
        &log_path,
        &Limits::timeout(timeout_s),
    )?;
    let text = std::fs::read_to_string(&log_path).unwrap_or_default();
    let steps_done = cg_per_step(&text).map(|c| c.len()).unwrap_or(0);
    if let Some(why) = f.stopped {
        return Err(format!(
            "{why}, after {steps_done} increments (log {})",
            log_path.display()
        ));
    }
    if f.code != Some(0) {
        return Err(format!(
            "exit code {:?} after {steps_done} increments: {} (log {})",
            f.code,
            last_line(&text),
            log_path.display()
        ));
    }
    let log = parse_log(&text).map_err(|e| format!("{}: {e}", log_path.display()))?;
    let stored = stored_cg(&h5)?;
    if stored != log.cg_per_step {
        return Err(format!(
            "the log's CG per increment ({} increments) differ from the result file's ({})",
            log.cg_per_step.len(),
            stored.len()
        ));
    }
    Ok((f.wall, log, h5))
}

/// The CG iterations of every step the result file stores.
fn stored_cg(h5: &Path) -> Result<Vec<u64>, String> {
    let f = ResultFile::open(h5).map_err(|e| e.to_string())?;
    let stats = f.stats().map_err(|e| e.to_string())?;
    Ok(stats.iter().map(|s| s.cg_iterations).collect())
}

/// Minus the y reaction of the set's nodes at the last step, over `area`.
fn pressure(h5: &Path, set: &str, area: f64) -> Result<f64, String> {
    let f = ResultFile::open(h5).map_err(|e| e.to_string())?;
    let last = f
        .num_steps()
        .checked_sub(1)
        .ok_or_else(|| format!("{}: no steps", h5.display()))?;
    let nodes = f
        .node_set(set)
        .map_err(|e| e.to_string())?
        .ok_or_else(|| format!("{}: no node set '{set}'", h5.display()))?;
    let r = f.reaction(last).map_err(|e| e.to_string())?;
    // The file's ids are 1-based.
    let fy: f64 = nodes.iter().map(|&n| r[n as usize - 1][1]).sum();
    Ok(-fy / area)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Lines as `solver -v run` printed them (punch_40 and contact_punch_48 of the smoke
    /// run, shortened to three steps; one step cut back).
    const LOG: &str = "\
punch_40: 1 bodies, 1600 elements, 3362 nodes, 50 steps, 2 rank(s)
preconditioner: full tangent (plastic: body 'block'; 3362 nodes, below 20000)
step 1/50  t = 0.020000    CG     98  residual 2.126e-9 (reference 2.190e1)  cut-backs 0  9.027 s  ~443 s left
CG trace: 1 model problem(s), 16 iterations, 47 force evaluations; restarts: Polak-Ribiere 1, descent 0, Jacobi rebuilds 0; halvings 0, secants 15 (refused 0); multilevel builds 0, coarse builds 0
step 2/50  t = 0.040000    CG    112  residual 3.9e-11 (reference 2.1e0)  cut-backs 1  0.954 s  ~100 s left
step 50/50  t = 1.000000    CG     16  residual 6.412e-9 (reference 7.304e1)  cut-backs 0  1.354 s  ~0 s left
done: 3 steps, 226 CG iterations, 115.145 s, peak memory 60.9 MiB per rank (estimated 64.7 MiB); results in o.h5
";

    const CONTACT_STEPS: &str = "\
step 1/12  t = 0.083333    CG     80  residual 4.036e-7 (reference 4.683e1)  cut-backs 0  5.949 s  contact updates 1, in contact 18 (stick 0, slip 18), released 0, max penetration 0.00e0  ~66 s left
step 12/12  t = 1.000000    CG      5  residual 3.779e-7 (reference 1.630e2)  cut-backs 0  2.375 s  contact updates 3, in contact 16 (stick 0, slip 16), released 0, max penetration 8.88e-16  ~0 s left
done: 2 steps, 85 CG iterations, 37.223 s, peak memory 70.0 MiB per rank (estimated 79.9 MiB); results in c.h5
";

    #[test]
    fn a_log_is_read() {
        let log = parse_log(LOG).unwrap();
        assert_eq!(
            log,
            RunLog {
                cg_per_step: vec![98, 112, 16],
                cg_total: 226,
                solver_wall: 115.145,
                contact_updates: 0,
                preconditioner: Some(
                    "full tangent (plastic: body 'block'; 3362 nodes, below 20000)".into()
                ),
            }
        );
        let ours = Ours {
            wall: 116.0,
            solver_wall: log.solver_wall,
            cg_total: log.cg_total,
            cg_per_step: log.cg_per_step,
            contact_updates: 0,
            preconditioner: String::new(),
            pressure: 0.0,
        };
        assert_eq!(ours.cg_max(), (112, 2));
        let contact = parse_log(CONTACT_STEPS).unwrap();
        assert_eq!(
            (
                contact.cg_per_step,
                contact.contact_updates,
                contact.preconditioner
            ),
            (vec![80, 5], 4, None)
        );
    }

    #[test]
    fn a_log_that_does_not_add_up_is_refused() {
        let bad = LOG.replace("CG     16", "CG x");
        assert!(parse_log(&bad)
            .unwrap_err()
            .starts_with("cannot read CG from 'step 50/50"));
        let odd = LOG.replace("226 CG iterations", "227 CG iterations");
        assert_eq!(
            parse_log(&odd).unwrap_err(),
            "the steps' CG iterations add up to 226, the done line says 227"
        );
        assert_eq!(parse_log("step 1/2").unwrap_err(), "no 'done: ..' line");
        assert_eq!(cg_per_step("no steps"), Ok(vec![]));
    }
}
