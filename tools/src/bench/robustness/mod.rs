//! `--robustness`: the robustness table. The hard problems (the Hertz example at x1, x2,
//! x4; the extreme suite's hardest scenes; the paper's stick/slip bar at 160 x 8 x 1; the
//! block on block at n = 20), each run on `ROBUSTNESS_RANKS` ranks with every
//! preconditioner (Jacobi, two-level, multilevel and the default `auto`) under a time
//! limit, and CalculiX on the Hertz meshes and the bar beside them. Writes
//! `<out>/robustness/` (`report.md`, `results.json`, the derived scenes, every log and
//! result file, the CalculiX decks and outputs); what it measured is `results::robustness`,
//! which the report, `report::robustness`, reads.
//!
//! - `scenes`: the scene files of the table (derived ones written into the output);
//! - `run`: one solver run and how it ended.

pub mod run;
pub mod scenes;

use crate::api::load_scene_refined;
use crate::machine::{machine, RunInfo};
use crate::peers::calculix::robustness::{self as ccx, CcxRun};
use crate::peers::calculix::run::version;
use crate::report;
use crate::results::robustness::{
    Case, Outcome, Robustness, Run, Source, PRECONDITIONERS, ROBUSTNESS_RANKS,
};
use crate::runner::process::Limits;
use crate::runner::solver::{repo_root, solver_exe, Job};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Time limit of every run, ours and CalculiX's: a preconditioner that stalls on a problem
/// shows as "> limit" instead of holding the table up (Jacobi and two-level on Hertz x4
/// stall; every other run of the table takes well under a minute on 2 cores).
pub const ROBUSTNESS_TIMEOUT_S: f64 = 240.0;
/// The limit of `--quick` (a smoke test of the mode).
pub const ROBUSTNESS_QUICK_TIMEOUT_S: f64 = 60.0;
/// CalculiX's limit: its time to solution is what the table sets beside ours, and on Hertz
/// x4 it takes about 220 s on 2 cores (it was stopped at 240 s when the machine was
/// busier). `--quick` gives it the quick limit.
pub const ROBUSTNESS_CCX_TIMEOUT_S: f64 = 600.0;
/// Slope of CalculiX's linear pressure-overclosure law on the Hertz example: the peak
/// contact pressure is about 4300 MPa, so the overclosure stays near 4e-5 mm, about 1e-3
/// of the cylinder's approach.
pub const HERTZ_PENALTY: f64 = 1e8;
/// The same on the stick/slip bar: contact pressures of about 5e3 give an overclosure of
/// 5e-8, 0.1% of the plates' 5e-5 squeeze, and the stick slope (a tenth of it) lets a
/// sticking node move 2.5e-7 before it slips. The bar's largest |u| hangs on the normal
/// force the squeeze gives: with 1e10 CalculiX's came out 2.0% above ours, with 1e11 0.2%;
/// with 1e12 ccx does not converge.
pub const STICK_SLIP_PENALTY: f64 = 1e11;

/// A problem of the table: where it comes from, and CalculiX's contact slope and the node
/// set whose largest |u| both codes report, when CalculiX runs it.
pub struct Spec {
    pub source: Source,
    pub ccx: Option<(f64, &'static str)>,
}

/// The problems of a full run, or of `--quick`.
pub fn specs(quick: bool) -> Vec<Spec> {
    let hertz = |f| Spec {
        source: Source::Hertz(f),
        ccx: Some((HERTZ_PENALTY, "cylinder_axis")),
    };
    let plain = |source| Spec { source, ccx: None };
    let mut v = vec![hertz(1), hertz(2)];
    if !quick {
        v.push(hertz(4));
    }
    for name in ["incompressible_mean", "aspect100", "drag_deformable"] {
        v.push(plain(Source::Extreme(name)));
    }
    if !quick {
        v.push(Spec {
            source: Source::StickSlip,
            ccx: Some((STICK_SLIP_PENALTY, "bar_top")),
        });
    }
    v.push(plain(Source::Block(if quick { 1 } else { 2 })));
    v
}

/// The scene file of `source` and `--refine`, derived scenes written into `dir`.
fn scene_file(source: Source, dir: &Path) -> Result<(PathBuf, Option<usize>), String> {
    Ok(match source {
        Source::Hertz(f) => (scenes::hertz(dir, f)?, None),
        Source::Extreme(name) => (scenes::extreme(name)?, None),
        Source::StickSlip => (scenes::stick_slip(dir)?, None),
        Source::Block(f) => (repo_root().join(crate::block::BLOCK_SCENE), Some(f)),
    })
}

/// A problem with every preconditioner, then CalculiX.
/// `ccx_timeout_s`: CalculiX's time limit, `None` when it is not installed.
fn case(exe: &Path, dir: &Path, spec: &Spec, limits: &Limits, ccx_timeout_s: Option<f64>) -> Case {
    let source = spec.source;
    let mut c = Case {
        source,
        scene: PathBuf::new(),
        elements: 0,
        nodes: 0,
        compare_set: spec.ccx.map(|(_, set)| set),
        runs: Vec::new(),
        ccx: None,
        error: None,
    };
    let setup = scene_file(source, &dir.join("scenes")).and_then(|(scene, refine)| {
        let problem =
            load_scene_refined(&scene, refine.unwrap_or(1) as u32).map_err(|e| e.to_string())?;
        Ok((scene, refine, problem))
    });
    let (scene, refine, problem) = match setup {
        Ok(s) => s,
        Err(e) => {
            eprintln!("bench: robustness: {}: {e}", source.label());
            c.error = Some(e);
            return c;
        }
    };
    c.scene = scene.clone();
    c.elements = problem.mesh.num_elements();
    c.nodes = problem.mesh.num_nodes();
    let compare: Option<Vec<u32>> = c
        .compare_set
        .and_then(|s| problem.node_set(s))
        .map(|s| s.nodes.clone());
    eprintln!(
        "bench: robustness: {} ({} elements, {} nodes)",
        source.label(),
        c.elements,
        c.nodes
    );
    for p in PRECONDITIONERS {
        let job = Job {
            scene: scene.clone(),
            refine,
            ranks: ROBUSTNESS_RANKS,
            preconditioner: p,
            result: dir
                .join("runs")
                .join(format!("{}_{}.h5", source.key(), p.arg())),
        };
        let r = run::run(exe, &job, limits, compare.as_deref());
        match r {
            Ok(r) => {
                eprintln!(
                    "bench:   {:<10} {}",
                    p.label(),
                    outcome_line(&r, limits.timeout_s)
                );
                c.runs.push(r);
            }
            Err(e) => {
                eprintln!("bench:   {:<10} could not run: {e}", p.label());
                c.runs.push(Run {
                    precond: p,
                    outcome: Outcome::Failed(format!("could not run: {e}")),
                    process_wall: 0.0,
                    partial: (0, 0),
                    preconditioner: None,
                    max_u: None,
                });
            }
        }
    }
    if let (Some((penalty, set)), Some(timeout_s)) = (spec.ccx, ccx_timeout_s) {
        let ccx_dir = dir.join("calculix").join(source.key());
        let r = ccx::run(&problem, &ccx_dir, &source.key(), penalty, timeout_s, set);
        eprintln!("bench:   CalculiX   {}", ccx_line(&r));
        c.ccx = Some(r);
    }
    c
}

/// How a run ended, in one line of progress.
fn outcome_line(r: &Run, limit: f64) -> String {
    match &r.outcome {
        Outcome::Finished(l) => format!(
            "{} CG iterations, {} contact updates, {:.1} s ({:.1} s process), {:.1} MiB per rank",
            l.cg_iterations, l.contact_updates, l.wall, r.process_wall, l.peak_mib
        ),
        Outcome::Failed(why) => format!(
            "failed after {:.1} s ({} CG iterations logged): {why}",
            r.process_wall, r.partial.0
        ),
        Outcome::OverLimit => format!(
            "stopped at the limit of {limit:.0} s ({} CG iterations logged)",
            r.partial.0
        ),
    }
}

fn ccx_line(r: &CcxRun) -> String {
    use crate::peers::calculix::run::Outcome;
    match &r.outcome {
        Outcome::Finished { timed, values } => format!(
            "{:.1} s, {} iterations, max |u| {values:.6e}",
            timed.wall.median, timed.iterations
        ),
        Outcome::Stopped(why) => format!("stopped: {why}"),
        Outcome::Failed(why) | Outcome::Skipped(why) => format!("failed: {why}"),
    }
}

/// `bench --robustness [--quick]`: the table into `<out>/robustness/`.
pub fn run(out: &Path, quick: bool) -> Result<(), String> {
    let start = Instant::now();
    let dir = report_dir(out);
    std::fs::create_dir_all(dir.join("runs"))
        .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let machine = machine();
    let exe = solver_exe()?;
    let timeout_s = if quick {
        ROBUSTNESS_QUICK_TIMEOUT_S
    } else {
        ROBUSTNESS_TIMEOUT_S
    };
    let limits = Limits::timeout(timeout_s);
    let ccx_version = version();
    match &ccx_version {
        Some(v) => eprintln!("bench: robustness: CalculiX {v}"),
        None => eprintln!(
            "bench: robustness: CalculiX not available (no ccx on PATH; `run/setup --calculix` installs it)"
        ),
    }
    let ccx_timeout_s = if quick {
        ROBUSTNESS_QUICK_TIMEOUT_S
    } else {
        ROBUSTNESS_CCX_TIMEOUT_S
    };
    let ccx_limit = ccx_version.as_ref().map(|_| ccx_timeout_s);
    let cases: Vec<Case> = specs(quick)
        .iter()
        .map(|s| case(&exe, &dir, s, &limits, ccx_limit))
        .collect();
    let r = Robustness {
        info: RunInfo::finish(machine, start),
        quick,
        timeout_s,
        ccx_timeout_s,
        ccx_version,
        cases,
    };
    let md = report::robustness::markdown(&r, &dir);
    let json = serde_json::to_string_pretty(&report::robustness::json(&r))
        .map_err(|e| format!("cannot serialise the results: {e}"))?;
    let (rpath, jpath) = (dir.join("report.md"), dir.join("results.json"));
    std::fs::write(&rpath, &md).map_err(|e| format!("cannot write {}: {e}", rpath.display()))?;
    std::fs::write(&jpath, json + "\n")
        .map_err(|e| format!("cannot write {}: {e}", jpath.display()))?;
    println!("{md}");
    eprintln!("bench: wrote {} and {}", jpath.display(), rpath.display());
    let unset = r.cases.iter().filter(|c| c.error.is_some()).count();
    if unset > 0 {
        return Err(format!(
            "{unset} problem(s) of the table could not be set up; see the report"
        ));
    }
    Ok(())
}

/// Where `bench --robustness` writes.
pub fn report_dir(out: &Path) -> PathBuf {
    out.join("robustness")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The full table: Hertz x1, x2, x4, three extreme scenes, the bar and the block at
    /// n = 20, CalculiX beside the Hertz meshes and the bar; quick drops x4 and the bar.
    #[test]
    fn problems_of_the_table() {
        let full: Vec<String> = specs(false).iter().map(|s| s.source.label()).collect();
        assert_eq!(
            full,
            [
                "Hertz x1",
                "Hertz x2",
                "Hertz x4",
                "incompressible_mean",
                "aspect100",
                "drag_deformable",
                "stick/slip 160 x 8 x 1",
                "block on block n = 20"
            ]
        );
        let with_ccx = specs(false).iter().filter(|s| s.ccx.is_some()).count();
        assert_eq!(with_ccx, 4);
        assert_eq!(specs(true).len(), 6);
        for s in specs(false) {
            if let Source::Extreme(name) = s.source {
                assert!(scenes::extreme(name).is_ok(), "{name}");
            }
        }
    }
}
