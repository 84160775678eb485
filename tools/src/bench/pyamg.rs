//! `bench --pyamg`: PyAMG's smoothed aggregation beside our multilevel preconditioner on the
//! same operators. For each case the solver runs on one rank with `--preconditioner
//! multilevel --export-operator DIR`, which writes the first model problem that needs a CG
//! iteration (the constrained operator in the unknowns CG iterates on, its right-hand side,
//! the rigid-body modes) and our CG iterations on it; `run/pyamg_peer.py` then runs PyAMG
//! (`smoothed_aggregation_solver` with the modes as near-nullspace, as the preconditioner of
//! CG) to the same absolute residual, as the operator comes (scalar) and padded to nodal
//! 3 x 3 blocks. The table puts the two iteration counts side by side; the section goes
//! into `<out>/results.json` (key `pyamg`) and `<out>/report.md` in place of an earlier one.

use crate::block::{BLOCK_BASE_N, BLOCK_SCENE};
use crate::report::json::{Rec, J};
use crate::runner::process::{run_limited, Limits};
use crate::runner::solver::{repo_root, solver_exe};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The heading of the section in report.md.
pub const PYAMG_HEADING: &str = "## PyAMG beside the multilevel preconditioner";
/// The Hertz example remeshed twice as fine (`run/gmsh/make_examples 2` writes it).
const HERTZ_X2: &str = "run/examples/cylinder_on_block_x2.toml";
/// The Python of the virtual environment `run/setup --pyamg` makes.
const VENV_PYTHON: &str = ".venv-pyamg/bin/python";
/// Our iterations may be at most this many times PyAMG's (issue 19's goal).
pub const GOAL_RATIO: f64 = 1.5;
/// Time limits of one solver run and one PyAMG run.
const SOLVER_TIMEOUT_S: f64 = 1800.0;
const PYAMG_TIMEOUT_S: f64 = 1800.0;

/// One operator: the scene and how the solver is asked to refine it.
struct Case {
    name: String,
    scene: PathBuf,
    refine: Option<usize>,
}

/// PyAMG on one operator with one set-up.
#[derive(Clone, Debug)]
pub struct PeerRun {
    pub setup: String,
    pub unknowns: usize,
    pub iterations: usize,
    pub converged: bool,
    pub setup_time: f64,
    pub solve_time: f64,
    pub operator_complexity: f64,
    pub levels: usize,
}

/// One case's numbers.
#[derive(Clone, Debug)]
pub struct PyamgCase {
    pub name: String,
    pub unknowns: usize,
    pub nonzeros: usize,
    pub contact_rows: usize,
    pub ours: usize,
    pub relative_tolerance: f64,
    pub peers: Vec<PeerRun>,
}

impl PyamgCase {
    /// The PyAMG set-up with the fewest iterations among those that converged.
    pub fn best(&self) -> Option<&PeerRun> {
        self.peers
            .iter()
            .filter(|p| p.converged)
            .min_by_key(|p| p.iterations)
    }

    /// Our iterations over the best PyAMG set-up's.
    pub fn ratio(&self) -> Option<f64> {
        self.best()
            .filter(|p| p.iterations > 0)
            .map(|p| self.ours as f64 / p.iterations as f64)
    }
}

/// A case that could not be measured, with the reason.
pub type Outcome = Result<PyamgCase, String>;

fn cases() -> Vec<Case> {
    let block = |refine: usize| Case {
        name: format!("block on block n = {}", BLOCK_BASE_N * refine),
        scene: repo_root().join(BLOCK_SCENE),
        refine: Some(refine),
    };
    vec![
        block(2),
        block(4),
        Case {
            name: "Hertz x2".into(),
            scene: repo_root().join(HERTZ_X2),
            refine: None,
        },
    ]
}

/// The file name of a case's directory.
fn slug(name: &str) -> String {
    name.split_whitespace()
        .filter(|w| *w != "=")
        .collect::<Vec<_>>()
        .join("_")
}

fn number(j: &serde_json::Value, key: &str, file: &Path) -> Result<f64, String> {
    j.get(key)
        .and_then(serde_json::Value::as_f64)
        .ok_or_else(|| format!("{}: key '{key}' missing or not a number", file.display()))
}

fn read_json(path: &Path) -> Result<serde_json::Value, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    serde_json::from_str(&text).map_err(|e| format!("{}: not JSON: {e}", path.display()))
}

/// Runs `cmd` with its output beside `stem`; the error names the log.
fn run_logged(cmd: &mut Command, stem: &Path, timeout_s: f64, what: &str) -> Result<(), String> {
    let log = stem.with_extension("log");
    let f = run_limited(
        cmd,
        &stem.with_extension("out"),
        &log,
        &Limits::timeout(timeout_s),
    )?;
    if let Some(why) = f.stopped {
        return Err(format!("{what}: {why} (log {})", log.display()));
    }
    if f.code != Some(0) {
        let text = std::fs::read_to_string(&log).unwrap_or_default();
        return Err(format!(
            "{what}: exit code {}: {} (log {})",
            f.code.map_or("none (signal)".into(), |c| c.to_string()),
            text.lines().last().unwrap_or(""),
            log.display()
        ));
    }
    Ok(())
}

fn measure(exe: &Path, python: &Path, dir: &Path, case: &Case) -> Outcome {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let export = dir.join("export");
    let _ = std::fs::remove_dir_all(&export);
    let mut cmd = Command::new(repo_root().join("run/mpirun"));
    cmd.args(["-np", "1"])
        .arg(exe)
        .args(["-v", "run"])
        .arg(&case.scene);
    if let Some(f) = case.refine {
        cmd.args(["--refine", &f.to_string()]);
    }
    cmd.args(["--preconditioner", "multilevel", "--export-operator"])
        .arg(&export)
        .arg("-o")
        .arg(dir.join("result.h5"));
    eprintln!(
        "bench: pyamg: {}: solver with the operator export",
        case.name
    );
    run_logged(&mut cmd, &dir.join("solver"), SOLVER_TIMEOUT_S, "solver")?;
    let model_path = export.join("model.json");
    let model = read_json(&model_path)?;
    let ours = number(&model, "cg_iterations", &model_path)? as usize;
    eprintln!(
        "bench: pyamg: {}: ours {ours} CG iterations; PyAMG",
        case.name
    );
    let peer_path = dir.join("pyamg.json");
    let mut cmd = Command::new(python);
    cmd.arg(repo_root().join("run/pyamg_peer.py"))
        .arg(&export)
        .arg("--json")
        .arg(&peer_path);
    run_logged(
        &mut cmd,
        &dir.join("pyamg"),
        PYAMG_TIMEOUT_S,
        "run/pyamg_peer.py",
    )?;
    let peer = read_json(&peer_path)?;
    let runs = peer
        .get("runs")
        .and_then(serde_json::Value::as_array)
        .ok_or_else(|| format!("{}: key 'runs' missing", peer_path.display()))?;
    let mut peers = Vec::new();
    for r in runs {
        peers.push(PeerRun {
            setup: r
                .get("setup")
                .and_then(serde_json::Value::as_str)
                .unwrap_or("?")
                .to_string(),
            unknowns: number(r, "unknowns", &peer_path)? as usize,
            iterations: number(r, "iterations", &peer_path)? as usize,
            converged: r
                .get("converged")
                .and_then(serde_json::Value::as_bool)
                .unwrap_or(false),
            setup_time: number(r, "setup_time", &peer_path)?,
            solve_time: number(r, "solve_time", &peer_path)?,
            operator_complexity: number(r, "operator_complexity", &peer_path)?,
            levels: number(r, "levels", &peer_path)? as usize,
        });
    }
    Ok(PyamgCase {
        name: case.name.clone(),
        unknowns: number(&model, "unknowns", &model_path)? as usize,
        nonzeros: number(&model, "nonzeros", &model_path)? as usize,
        contact_rows: number(&model, "contact_rows", &model_path)? as usize,
        ours,
        relative_tolerance: number(&peer, "relative_tolerance", &peer_path)?,
        peers,
    })
}

/// The section's JSON.
pub fn json(cases: &[(String, Outcome)]) -> J {
    let list = cases
        .iter()
        .map(|(name, o)| match o {
            Err(e) => Rec::default()
                .put("case", name.as_str())
                .put("error", e.as_str())
                .json(),
            Ok(c) => Rec::default()
                .put("case", c.name.as_str())
                .put("unknowns", c.unknowns)
                .put("nonzeros", c.nonzeros)
                .put("contact_rows", c.contact_rows)
                .put("relative_tolerance", c.relative_tolerance)
                .put("ours_cg_iterations", c.ours)
                .put(
                    "pyamg",
                    J::Arr(
                        c.peers
                            .iter()
                            .map(|p| {
                                Rec::default()
                                    .put("setup", p.setup.as_str())
                                    .put("unknowns", p.unknowns)
                                    .put("cg_iterations", p.iterations)
                                    .put("converged", p.converged)
                                    .put("setup_s", p.setup_time)
                                    .put("solve_s", p.solve_time)
                                    .put("operator_complexity", p.operator_complexity)
                                    .put("levels", p.levels)
                                    .json()
                            })
                            .collect(),
                    ),
                )
                .put("ratio_ours_over_pyamg", c.ratio().map_or(J::Null, J::Num))
                .put("goal_ratio", GOAL_RATIO)
                .json(),
        })
        .collect();
    J::Arr(list)
}

/// The section's Markdown.
pub fn markdown(cases: &[(String, Outcome)]) -> String {
    let mut s = format!("{PYAMG_HEADING}\n\n");
    s.push_str(
        "The first model problem that needs a CG iteration, exported by `solver run \
         --export-operator` (one rank, `--preconditioner multilevel`): the constrained operator \
         in the unknowns CG iterates on, the rigid-body modes as near-nullspace. PyAMG \
         (`smoothed_aggregation_solver`, symmetric strength with theta 0, defaults otherwise) \
         preconditions CG from x = 0 to the absolute residual ours stopped at; *scalar* is the \
         operator as exported, *nodal* the same padded to 3 x 3 node blocks. The ratio is ours \
         over the better PyAMG set-up; the goal is at most 1.5.\n\n",
    );
    s.push_str(
        "| case | unknowns | contact rows | ours (multilevel) | PyAMG scalar | PyAMG nodal | ours / PyAMG | PyAMG setup / solve (s) | operator complexity |\n",
    );
    s.push_str("|---|---:|---:|---:|---:|---:|---:|---|---|\n");
    for (name, o) in cases {
        match o {
            Err(e) => {
                let _ = writeln!(s, "| {name} | failed: {e} | | | | | | | |");
            }
            Ok(c) => {
                let it = |setup: &str| {
                    c.peers
                        .iter()
                        .find(|p| p.setup == setup)
                        .map_or("-".into(), |p| {
                            format!(
                                "{}{}",
                                p.iterations,
                                if p.converged { "" } else { " (not converged)" }
                            )
                        })
                };
                let times: Vec<String> = c
                    .peers
                    .iter()
                    .map(|p| format!("{:.2} / {:.2}", p.setup_time, p.solve_time))
                    .collect();
                let oc: Vec<String> = c
                    .peers
                    .iter()
                    .map(|p| format!("{:.2}", p.operator_complexity))
                    .collect();
                let ratio = c.ratio().map_or("-".into(), |r| {
                    format!(
                        "{r:.2}{}",
                        if r <= GOAL_RATIO { "" } else { " (above 1.5)" }
                    )
                });
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                    c.name,
                    c.unknowns,
                    c.contact_rows,
                    c.ours,
                    it("scalar"),
                    it("nodal"),
                    ratio,
                    times.join(", "),
                    oc.join(", ")
                );
            }
        }
    }
    s
}

/// Puts the section into `<out>/results.json` (key `pyamg`) and `<out>/report.md` (in
/// place of an earlier one, up to the next section).
fn merge(out: &Path, j: J, section: &str) -> Result<(PathBuf, PathBuf), String> {
    let jpath = out.join("results.json");
    let rpath = out.join("report.md");
    let mut root = std::fs::read_to_string(&jpath)
        .ok()
        .and_then(|t| serde_json::from_str::<J>(&t).ok())
        .filter(|j| matches!(j, J::Obj(_)))
        .unwrap_or_else(|| J::Obj(Vec::new()));
    root.set("pyamg", j);
    let mut report = std::fs::read_to_string(&rpath)
        .unwrap_or_else(|_| "# Solver performance benchmark\n\n".to_string());
    if let Some(i) = report.find(PYAMG_HEADING) {
        let rest = &report[i + PYAMG_HEADING.len()..];
        let tail = rest.find("\n## ").map(|k| rest[k + 1..].to_string());
        report.truncate(i);
        report.push_str(section);
        if let Some(t) = tail {
            report.push('\n');
            report.push_str(&t);
        }
    } else {
        if !report.ends_with("\n\n") {
            report.push('\n');
        }
        report.push_str(section);
    }
    let text = serde_json::to_string_pretty(&root)
        .map_err(|e| format!("cannot serialise the results: {e}"))?;
    std::fs::write(&jpath, text + "\n")
        .map_err(|e| format!("cannot write {}: {e}", jpath.display()))?;
    std::fs::write(&rpath, &report)
        .map_err(|e| format!("cannot write {}: {e}", rpath.display()))?;
    Ok((jpath, rpath))
}

/// `bench --pyamg`: every case, then the section merged into `<out>`'s files and printed.
/// A case that fails is reported in its row; the run fails only when every case did.
pub fn run(out: &Path) -> Result<(), String> {
    let exe = solver_exe()?;
    let python = repo_root().join(VENV_PYTHON);
    if !python.is_file() {
        return Err(format!(
            "{} not found: install PyAMG with run/setup --pyamg (run/bench --pyamg does)",
            python.display()
        ));
    }
    let hertz = repo_root().join(HERTZ_X2);
    if !hertz.is_file() {
        eprintln!("bench: pyamg: {HERTZ_X2} missing; run/gmsh/make_examples 2");
        let mut cmd = Command::new(repo_root().join("run/gmsh/make_examples"));
        cmd.arg("2");
        std::fs::create_dir_all(out.join("pyamg"))
            .map_err(|e| format!("cannot create {}: {e}", out.join("pyamg").display()))?;
        run_logged(
            &mut cmd,
            &out.join("pyamg/make_examples"),
            600.0,
            "run/gmsh/make_examples 2",
        )?;
    }
    let mut results = Vec::new();
    for case in cases() {
        let dir = out.join("pyamg").join(slug(&case.name));
        let o = measure(&exe, &python, &dir, &case);
        match &o {
            Ok(c) => eprintln!(
                "bench: pyamg: {}: {} unknowns, ours {}, PyAMG {}",
                c.name,
                c.unknowns,
                c.ours,
                c.peers
                    .iter()
                    .map(|p| format!("{} {}", p.setup, p.iterations))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            Err(e) => eprintln!("bench: pyamg: {}: {e}", case.name),
        }
        results.push((case.name, o));
    }
    let section = markdown(&results);
    let (jpath, rpath) = merge(out, json(&results), &section)?;
    println!("{section}");
    eprintln!("bench: wrote {} and {}", jpath.display(), rpath.display());
    if results.iter().all(|(_, o)| o.is_err()) {
        return Err("no PyAMG case could be measured".into());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn case(ours: usize, scalar: usize, nodal: usize, nodal_converged: bool) -> PyamgCase {
        let peer = |setup: &str, iterations, converged| PeerRun {
            setup: setup.into(),
            unknowns: 10,
            iterations,
            converged,
            setup_time: 0.1,
            solve_time: 0.2,
            operator_complexity: 1.2,
            levels: 3,
        };
        PyamgCase {
            name: "c".into(),
            unknowns: 10,
            nonzeros: 100,
            contact_rows: 2,
            ours,
            relative_tolerance: 1e-9,
            peers: vec![
                peer("scalar", scalar, true),
                peer("nodal", nodal, nodal_converged),
            ],
        }
    }

    #[test]
    fn ratio_uses_the_better_converged_setup() {
        assert_eq!(case(30, 20, 15, true).ratio(), Some(2.0));
        assert_eq!(case(30, 20, 15, false).ratio(), Some(1.5));
        let md = markdown(&[
            ("c".into(), Ok(case(30, 20, 15, true))),
            ("d".into(), Err("solver: exit code 1".into())),
        ]);
        assert!(md.starts_with(PYAMG_HEADING));
        assert!(
            md.contains("| c | 10 | 2 | 30 | 20 | 15 | 2.00 (above 1.5) |"),
            "{md}"
        );
        assert!(md.contains("| d | failed: solver: exit code 1 |"));
        assert_eq!(slug("block on block n = 20"), "block_on_block_n_20");
    }

    #[test]
    fn command_line() {
        let parse = |a: &[&str]| crate::parse_args(a.iter().map(|s| s.to_string()));
        let ok = parse(&["--pyamg", "--out", "d"]).unwrap().unwrap();
        assert_eq!(ok.mode, crate::Mode::Pyamg);
        assert_eq!(ok.out, PathBuf::from("d"));
        for bad in [
            &["--pyamg", "--quick"][..],
            &["--large", "--pyamg"],
            &["--pyamg", "--ironing"],
        ] {
            assert_eq!(
                parse(bad),
                Err("--pyamg goes with --out only".into()),
                "{bad:?}"
            );
        }
    }
}
