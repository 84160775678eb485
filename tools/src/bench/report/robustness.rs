//! The robustness section (`--robustness`): `<out>/robustness/report.md` and
//! `results.json`, a row per problem and preconditioner and one per CalculiX run.

use super::json::{Rec, J};
use super::markdown::{cell, dirty, fmt_opt, fmt_steal};
use crate::peers::calculix::robustness::CcxRun;
use crate::peers::calculix::run::Outcome as CcxOutcome;
use crate::results::robustness::{
    Case, Outcome, Robustness, Run, PRECONDITIONERS, ROBUSTNESS_RANKS,
};
use crate::runner::process::MIB;
use crate::runner::solver::repo_root;
use std::fmt::Write as _;
use std::path::Path;

pub const ROBUSTNESS_HEADING: &str = "## Robustness: hard problems with every preconditioner";
/// Words of a failure message the table keeps (results.json keeps it whole).
const MESSAGE_WORDS: usize = 24;

/// The first `MESSAGE_WORDS` words of `text`.
pub fn first_words(text: &str) -> String {
    let words: Vec<&str> = text.split_whitespace().collect();
    if words.len() <= MESSAGE_WORDS {
        words.join(" ")
    } else {
        format!("{} ...", words[..MESSAGE_WORDS].join(" "))
    }
}

/// The preconditioner a run used, in its first words (before the first ';').
fn used(r: &Run) -> String {
    r.preconditioner.as_deref().map_or("-".into(), |l| {
        l.split(';').next().unwrap_or(l).trim().to_string()
    })
}

/// CalculiX's largest |u| on a case, when it finished.
fn ccx_max_u(c: &Case) -> Option<f64> {
    match &c.ccx.as_ref()?.outcome {
        CcxOutcome::Finished { values, .. } => Some(*values),
        _ => None,
    }
}

/// (ours - CalculiX) / CalculiX of the largest |u|.
fn difference(r: &Run, c: &Case) -> Option<f64> {
    let (ours, peer) = (r.max_u?, ccx_max_u(c)?);
    Some((ours - peer) / peer)
}

/// The fastest finished run of a case (process wall time).
fn fastest(c: &Case) -> Option<&Run> {
    c.runs
        .iter()
        .filter(|r| r.log().is_some())
        .min_by(|a, b| a.process_wall.total_cmp(&b.process_wall))
}

fn shown_path(p: &Path) -> String {
    p.strip_prefix(repo_root())
        .unwrap_or(p)
        .display()
        .to_string()
}

fn run_json(r: &Run, c: &Case) -> J {
    let rec = Rec::default()
        .put("preconditioner", r.precond.arg())
        .put("preconditioner_line", r.preconditioner.clone())
        .put("process_wall_s", r.process_wall);
    match &r.outcome {
        Outcome::Finished(l) => rec
            .put("status", "finished")
            .put("steps", l.steps)
            .put("cg_iterations", l.cg_iterations)
            .put("contact_updates", l.contact_updates)
            .put("wall_s", l.wall)
            .put("peak_mib_per_rank", l.peak_mib)
            .put("bytes_per_element", r.bytes_per_element(ROBUSTNESS_RANKS))
            .put("max_abs_u", r.max_u)
            .put(
                "max_abs_u_relative_difference_to_calculix",
                difference(r, c),
            ),
        Outcome::Failed(why) => rec
            .put("status", "failed")
            .put("message", why.as_str())
            .put("cg_iterations_logged", r.partial.0)
            .put("contact_updates_logged", r.partial.1),
        Outcome::OverLimit => rec
            .put("status", "over_time_limit")
            .put("cg_iterations_logged", r.partial.0)
            .put("contact_updates_logged", r.partial.1),
    }
    .json()
}

fn ccx_json(r: &CcxRun, elements: usize) -> J {
    let rec = Rec::default().put("deck", shown_path(&r.deck));
    match &r.outcome {
        CcxOutcome::Finished { timed, values } => rec
            .put("status", "finished")
            .put("wall_s", timed.wall.median)
            .put("ccx_time_s", timed.own_time)
            .put("iterations", timed.iterations)
            .put("peak_mib", timed.peak_mib)
            .put(
                "bytes_per_element",
                timed.peak_mib.map(|p| p * MIB / elements as f64),
            )
            .put("max_abs_u", *values),
        CcxOutcome::Stopped(why) => rec.put("status", "stopped").put("message", why.as_str()),
        CcxOutcome::Failed(why) | CcxOutcome::Skipped(why) => {
            rec.put("status", "failed").put("message", why.as_str())
        }
    }
    .json()
}

fn case_json(c: &Case) -> J {
    let rec = Rec::default()
        .put("problem", c.source.label())
        .put("scene", shown_path(&c.scene))
        .put("elements", c.elements)
        .put("nodes", c.nodes)
        .put("compared_node_set", c.compare_set)
        .put("error", c.error.clone())
        .put(
            "runs",
            J::Arr(c.runs.iter().map(|r| run_json(r, c)).collect()),
        );
    match &c.ccx {
        Some(x) => rec.put("calculix", ccx_json(x, c.elements)),
        None => rec.put("calculix", J::Null),
    }
    .json()
}

/// results.json of `--robustness`.
pub fn json(r: &Robustness) -> J {
    let m = &r.info.machine;
    let meta = Rec::default()
        .put("date", m.date.as_str())
        .put("git_commit", m.git_commit.clone())
        .put("git_dirty", m.git_dirty)
        .put("cpu_model", m.cpu_model.as_str())
        .put("logical_cpus", m.logical_cpus)
        .put("quick", r.quick)
        .put("total_wall_s", r.info.total_wall)
        .put("load_average_start", m.load_start.clone())
        .put("load_average_end", r.info.load_end.clone())
        .put("cpu_steal_fraction", r.info.steal)
        .json();
    Rec::default()
        .put("schema", "solver-bench-robustness/1")
        .put("doc", DOC)
        .put("meta", meta)
        .put("ranks", ROBUSTNESS_RANKS)
        .put("timeout_s", r.timeout_s)
        .put("calculix_timeout_s", r.ccx_timeout_s)
        .put(
            "preconditioners",
            J::Arr(PRECONDITIONERS.iter().map(|p| J::from(p.arg())).collect()),
        )
        .put("calculix_version", r.ccx_version.clone())
        .put("problems", J::Arr(r.cases.iter().map(case_json).collect()))
        .json()
}

const DOC: &str = "Each problem run as `run/mpirun -np 2 target/release/solver -vv run SCENE \
[--refine F] --preconditioner P -o runs/KEY_P.h5` for P = jacobi, two_level, multilevel, auto \
(the default), stopped after timeout_s. status: finished, failed (the solver's error message, or \
it used another preconditioner than the one asked for: preconditioner_line) or over_time_limit; \
cg_iterations and contact_updates summed over the steps; *_logged: what the log of an unfinished \
run shows (its completed steps and the contact updates of the step it was in: at least what it \
did); wall_s = the solver's own time, process_wall_s = the mpirun process; peak_mib_per_rank = \
largest VmHWM over the ranks, bytes_per_element = peak / (elements / ranks); max_abs_u = largest \
|u| over compared_node_set and every step. calculix: ccx (2 threads, OMP_NUM_THREADS) on the \
deck written from the scene (node-to-surface penalty contact, *DLOAD pressures), stopped after \
calculix_timeout_s, wall_s of the process, ccx_time_s its own, iterations = Newton iterations, bytes_per_element = its peak / \
elements, max_abs_u over the same set from *NODE PRINT U at every increment; \
max_abs_u_relative_difference_to_calculix = (ours - ccx) / ccx.";

/// report.md of `--robustness`; `dir` holds the logs, result files and decks.
pub fn markdown(r: &Robustness, dir: &Path) -> String {
    let mut s = String::new();
    let w = &mut s;
    let m = &r.info.machine;
    let _ = writeln!(w, "{ROBUSTNESS_HEADING}\n");
    let _ = writeln!(
        w,
        "{} on {}, commit {}{}; load average {} at the start, {} at the end; hypervisor \
         steal {}; {:.0} s in all{}. Every problem on {ROBUSTNESS_RANKS} MPI ranks with \
         `--preconditioner` jacobi, two_level, multilevel and auto (the default), each run \
         stopped after **{:.0} s** (\"> {:.0} s\"). CG iterations and contact updates are \
         summed over the steps (\">= n\": what the log of a run that did not finish shows); \
         time = the solver's own, process = the mpirun process (start-up and mesh reading \
         included); B/element = peak memory per rank / (elements / ranks); \"used\" = the \
         solver's `preconditioner:` line up to its first ';'. CalculiX {} (2 threads, direct \
         solver, node-to-surface penalty contact; deck written from the scene) beside the \
         Hertz meshes and the stick/slip bar, stopped after {:.0} s: its B/element is its \
         peak / elements; max |u| = the largest displacement over the named node set and \
         every step, \"vs ccx\" = (ours - CalculiX) / CalculiX. Logs and result files in \
         `{}`.\n",
        m.date,
        m.cpu_model,
        m.git_commit.as_deref().unwrap_or("unknown"),
        dirty(m.git_dirty),
        m.load_start.as_deref().unwrap_or("unknown"),
        r.info.load_end.as_deref().unwrap_or("unknown"),
        fmt_steal(r.info.steal),
        r.info.total_wall,
        if r.quick { " (quick: a subset)" } else { "" },
        r.timeout_s,
        r.timeout_s,
        r.ccx_version.as_deref().unwrap_or("(not installed)"),
        r.ccx_timeout_s,
        dir.display()
    );
    let _ = writeln!(
        w,
        "| problem | elements | preconditioner | outcome | CG iterations | contact updates | time s | process s | B/element | used | max abs(u) | vs ccx |"
    );
    let _ = writeln!(
        w,
        "|---|---:|---|---|---:|---:|---:|---:|---:|---|---:|---:|"
    );
    for c in &r.cases {
        let label = c.source.label();
        if let Some(e) = &c.error {
            let _ = writeln!(w, "| {label} | - | - | not set up: {} ||||||||", cell(e));
            continue;
        }
        for run in &c.runs {
            let _ = writeln!(w, "{}", run_row(&label, c, run, r.timeout_s));
        }
        if let Some(x) = &c.ccx {
            let _ = writeln!(w, "{}", ccx_row(&label, c, x));
        }
    }
    let _ = writeln!(w);
    for c in r.cases.iter().filter(|c| c.ccx.is_some()) {
        let _ = writeln!(w, "- {}", time_to_solution(c));
    }
    s
}

fn run_row(label: &str, c: &Case, r: &Run, limit: f64) -> String {
    let head = format!("| {label} | {} | {} |", c.elements, r.precond.label());
    let used = cell(&used(r));
    match &r.outcome {
        Outcome::Finished(l) => format!(
            "{head} finished | {} | {} | {:.1} | {:.1} | {} | {used} | {} | {} |",
            l.cg_iterations,
            l.contact_updates,
            l.wall,
            r.process_wall,
            fmt_opt(r.bytes_per_element(ROBUSTNESS_RANKS), 0),
            r.max_u.map_or("-".into(), |u| format!("{u:.6e}")),
            difference(r, c).map_or("-".into(), |d| format!("{:+.2}%", 100.0 * d)),
        ),
        Outcome::Failed(why) => format!(
            "{head} failed: {} | >= {} | >= {} | - | {:.1} | - | {used} | - | - |",
            cell(&first_words(why)),
            r.partial.0,
            r.partial.1,
            r.process_wall
        ),
        Outcome::OverLimit => format!(
            "{head} > {limit:.0} s | >= {} | >= {} | - | > {limit:.0} | - | {used} | - | - |",
            r.partial.0, r.partial.1
        ),
    }
}

fn ccx_row(label: &str, c: &Case, x: &CcxRun) -> String {
    let head = format!("| {label} | {} | CalculiX |", c.elements);
    match &x.outcome {
        CcxOutcome::Finished { timed, values } => format!(
            "{head} finished | - ({} Newton) | - | {} | {:.1} | {} | direct | {values:.6e} | - |",
            timed.iterations,
            fmt_opt(timed.own_time, 1),
            timed.wall.median,
            fmt_opt(timed.peak_mib.map(|p| p * MIB / c.elements as f64), 0),
        ),
        CcxOutcome::Stopped(why) => format!("{head} {} |||||||||", cell(&first_words(why))),
        CcxOutcome::Failed(why) | CcxOutcome::Skipped(why) => {
            format!("{head} failed: {} |||||||||", cell(&first_words(why)))
        }
    }
}

/// Time to solution of a problem: CalculiX's, ours at the default and our fastest.
fn time_to_solution(c: &Case) -> String {
    let label = c.source.label();
    let ccx = c.ccx.as_ref().and_then(|x| match &x.outcome {
        CcxOutcome::Finished { timed, .. } => Some(timed.wall.median),
        _ => None,
    });
    let auto = c
        .runs
        .iter()
        .find(|r| r.precond == crate::runner::solver::Precond::Auto && r.log().is_some());
    let mut s = format!(
        "{label}: CalculiX {}",
        ccx.map_or("did not finish".into(), |t| format!("{t:.1} s"))
    );
    let ours = |s: &mut String, what: &str, r: &Run| {
        let _ = write!(s, "; ours {what} {:.1} s", r.process_wall);
        if let Some(t) = ccx {
            let _ = write!(s, " ({:.2} x CalculiX's time)", r.process_wall / t);
        }
    };
    match auto {
        Some(r) => ours(&mut s, "at the default (auto)", r),
        None => s.push_str("; ours at the default (auto) did not finish"),
    }
    if let Some(f) = fastest(c) {
        ours(&mut s, &format!("fastest ({})", f.precond.label()), f);
    }
    s.push_str(" (process wall times)");
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::fixture::robustness;

    /// Every kind of row: finished with the difference to CalculiX, failed with the first
    /// words of its message and what it logged, over the limit, CalculiX's own row and the
    /// time-to-solution line.
    #[test]
    fn robustness_rows() {
        let r = robustness();
        let md = markdown(&r, Path::new("out/bench/robustness"));
        assert!(md.starts_with(ROBUSTNESS_HEADING));
        assert!(
            md.contains("| Hertz x2 | 2940 | multilevel | finished | 300 | 4 | 6.0 | 8.0 | 1783 | multilevel | 6.250000e-1 | +25.00% |"),
            "{md}"
        );
        assert!(md.contains("| Hertz x2 | 2940 | Jacobi | failed: step 1 (to t = 1) failed at t = 0.015625 after 6 cut-backs: CG did not converge in 20000 iterations | >= 0 | >= 2 | - | 95.0 | - | nodal block Jacobi | - | - |"), "{md}");
        assert!(md.contains("| Hertz x2 | 2940 | two-level | > 240 s | >= 1500 | >= 3 | - | > 240 | - | two-level | - | - |"), "{md}");
        assert!(md.contains("| Hertz x2 | 2940 | CalculiX | finished | - (12 Newton) | - | 11.5 | 12.0 | 7133 | direct | 5.000000e-1 | - |"), "{md}");
        assert!(md.contains("- Hertz x2: CalculiX 12.0 s; ours at the default (auto) 8.0 s (0.67 x CalculiX's time); ours fastest (multilevel) 8.0 s (0.67 x CalculiX's time) (process wall times)"), "{md}");
        let j = serde_json::to_string(&json(&r)).unwrap();
        assert!(j.contains("\"status\":\"over_time_limit\""));
        assert!(j.contains("\"max_abs_u_relative_difference_to_calculix\":0.25"));
        for text in [j, md] {
            let mut words = text.split(|c: char| !c.is_ascii_alphanumeric());
            assert!(!words.any(|w| w == "NaN" || w == "inf"));
        }
        assert_eq!(first_words("a b"), "a b");
        assert_eq!(
            first_words(&"w ".repeat(30)),
            format!("{} ...", ["w"; 24].join(" "))
        );
    }
}
