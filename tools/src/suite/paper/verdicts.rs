//! The paper suite's judgements: how the 2-rank run compares with the 1-rank one, the key
//! error of each scene, the summary table's cells, and what fails the job.

use super::model::{first, Comparison, PaperRun};
use super::results::{Paper, BASE, CHECKED_VARIANTS, DRAWN_EXAMPLES};
use crate::text::{cell, num, number_between};

/// The number of contact updates a cycling diagnosis names (`after N contact updates`).
pub fn cycle_updates(msg: &str) -> Option<u64> {
    number_between(msg, "after ", " contact updates")
}

impl Paper {
    pub fn pair(&self, name: &str) -> &(PaperRun, PaperRun) {
        &self
            .runs
            .iter()
            .find(|r| r.0 == name)
            .expect("a scene of the suite")
            .1
    }

    pub fn comparison(&self, name: &str) -> Comparison {
        Comparison::load(&self.out.join("logs"), name)
    }

    /// The 2-rank run against the 1-rank run, in words.
    pub fn two_ranks(&self, name: &str) -> String {
        let (r1, r2) = self.pair(name);
        let c = self.comparison(name);
        let rc = c.rc.as_deref();
        if r2.completed() {
            return match rc {
                Some("0") => "bitwise identical".into(),
                Some("1") => c.difference(),
                Some("2") => format!("cannot compare: {}", c.verdict),
                _ => "completed, not compared (no 1-rank result)".into(),
            };
        }
        let mut text = if r2.rec.not_run() {
            r2.message()
        } else if r2.rec.rc_is("1") && r1.rec.rc_is("1") && r1.message() == r2.message() {
            "failed as on 1 rank (exit 1, the same message)".into()
        } else {
            format!(
                "failed (exit {}): {}",
                r2.rec.rc.as_deref().unwrap_or(""),
                r2.message()
            )
        };
        match rc {
            Some("0") => text += "; the finished steps are bitwise identical to 1 rank's",
            Some("1") => text += &format!("; the finished steps: {}", c.difference()),
            _ => {}
        }
        text
    }

    /// The scene's key error, as a table cell.
    pub fn key_error(&self, name: &str) -> String {
        let r1 = &self.pair(name).0;
        let Some(v) = &r1.verify else {
            return "-".into();
        };
        let checks = v.check_values();
        let rep = &v.reported;
        match v.kind.as_str() {
            "bc_interaction" | "bc_interaction_mu037" => format!(
                "max \\|u - exact\\|/d = {}",
                num(first("max |u - exact|", &checks))
            ),
            "bc_interaction_mu036" => format!(
                "{} slave nodes slip",
                num(v.reported("slave nodes slipping at the last step"))
            ),
            "bc_interaction_frictionless" => {
                format!("\\|U_x(0)\\|/d = {}", num(first("|U_x(s = 0)|", &checks)))
            }
            "normal_smoothing" | "normal_smoothing_off" => format!(
                "max \\|u_x\\|/\\|u_y\\| at x = 1: {}",
                num(first("max |u_x|", &checks))
            ),
            "capture_release" => {
                let errs: Vec<f64> = v
                    .checks
                    .iter()
                    .filter(|c| c.name.starts_with('|') || c.name.starts_with("max |"))
                    .filter_map(|c| c.value)
                    .collect();
                match errs.iter().copied().reduce(f64::max) {
                    Some(m) => format!("max rel. error {} ({} checks)", num(Some(m)), errs.len()),
                    None => "-".into(),
                }
            }
            "stick_slip" => match first("difference from the 1-D formula", rep) {
                Some(d) => format!("{:.2}% of u_max from 1-D theory at t = 2", d * 100.0),
                None => "-".into(),
            },
            "multi_constraint" | "multi_constraint_nonmatching" => {
                // Checked (matching meshes, or mortar contact) or reported only.
                let table = if first("max |u - exact|", &checks).is_some() {
                    &checks
                } else {
                    rep
                };
                format!(
                    "u: {}, sigma: {} (relative)",
                    num(first("max |u - exact|", table)),
                    num(first("max |sigma - exact|", table))
                )
            }
            _ => match v.checks.first() {
                Some(c) => format!("{} = {}", cell(&c.name), num(c.value)),
                None => "-".into(),
            },
        }
    }

    pub fn checks_cell(&self, name: &str) -> String {
        let r1 = &self.pair(name).0;
        if r1.rec.not_run() {
            return "NOT RUN".into();
        }
        if r1.rec.timed_out() {
            return "TIMED OUT".into();
        }
        if !r1.rec.rc_is("0") {
            return format!("RUN FAILED (exit {})", r1.rec.rc.as_deref().unwrap_or(""));
        }
        if r1.verify.is_none() {
            return "not verified".into();
        }
        let total = r1.checks().len();
        if total == 0 {
            return "0/0 (reported only)".into();
        }
        format!(
            "{}/{total}{}",
            r1.passed(),
            if r1.passed() == total { "" } else { " FAIL" }
        )
    }

    pub fn cg_cell(&self, name: &str) -> String {
        let r1 = &self.pair(name).0;
        if !r1.completed() && r1.steps().unwrap_or(0) == 0 && r1.result.is_some() {
            return "0 (no step completed)".into();
        }
        num(r1.reported("CG iterations (total)"))
    }

    pub fn updates_cell(&self, name: &str) -> String {
        let r1 = &self.pair(name).0;
        let v = r1.reported("contact updates (total)");
        if !r1.completed() && r1.result.is_some() {
            let steps = r1.steps().unwrap_or(0);
            let mut text = format!(
                "{} ({} completed",
                num(v),
                if steps == 0 {
                    "no step".to_string()
                } else {
                    format!("{steps} steps")
                }
            );
            if let Some(n) = cycle_updates(&r1.message()) {
                text += &format!("; cycling after {n} updates");
            }
            return text + ")";
        }
        num(v)
    }

    pub fn wall_cell(&self, name: &str) -> String {
        self.pair(name)
            .0
            .rec
            .time
            .map_or("-".into(), |t| format!("{t:.2} s"))
    }

    /// What fails the job, in the order the report lists it.
    pub fn failures(&self) -> Vec<String> {
        let mut failures = Vec::new();
        for name in &self.scenes {
            self.scene_failures(name, &mut failures);
        }
        self.example_failures(&mut failures);
        failures
    }

    /// What fails scene `name`: its 2-rank verdict, its 1-rank run and, for a base scene,
    /// its verification.
    fn scene_failures(&self, name: &str, failures: &mut Vec<String>) {
        let (r1, r2) = self.pair(name);
        let verdict2 = self.two_ranks(name);
        if verdict2 != "bitwise identical" {
            failures.push(format!("{name}: 2 ranks: {verdict2}"));
        }
        if !r1.completed() {
            failures.push(format!(
                "{name}: the 1-rank run did not complete: {}",
                r1.message()
            ));
        }
        // The base scenes' checks must pass, and so must every mortar variant's (mortar
        // contact passes each test it applies to, the non-matching patch test included).
        if BASE.contains(&name) || CHECKED_VARIANTS.contains(&name) || name.ends_with("_mortar") {
            for r in [r1, r2] {
                verification_failures(name, r, failures);
            }
        }
    }

    /// What fails the Gmsh example and the drawn examples (plastic, tetrahedral): incomplete
    /// runs, 2 ranks differing, the Hertz comparison failing.
    fn example_failures(&self, failures: &mut Vec<String>) {
        let (ex1, _) = self.pair(&self.example);
        if !ex1.completed() {
            failures.push(format!(
                "{}: the 1-rank run did not complete: {}",
                self.example,
                ex1.message()
            ));
        }
        let two = self.two_ranks(&self.example);
        if two != "bitwise identical" {
            failures.push(format!("{}: 2 ranks: {two}", self.example));
        }
        for (name, _) in DRAWN_EXAMPLES {
            if !self.runs.iter().any(|r| r.0 == name) {
                continue;
            }
            let (p1, _) = self.pair(name);
            if !p1.completed() {
                failures.push(format!(
                    "{name}: the 1-rank run did not complete: {}",
                    p1.message()
                ));
            }
            let two = self.two_ranks(name);
            if two != "bitwise identical" {
                failures.push(format!("{name}: 2 ranks: {two}"));
            }
        }
        if ex1.completed() && self.hertz_rc != "0" {
            failures.push(format!(
                "{}: solver post hertz failed (exit {}): {}",
                self.example,
                self.hertz_rc,
                self.hertz_txt.lines().last().unwrap_or("no output")
            ));
        }
    }
}

/// What fails a completed base-scene run: no verification, or a failed check.
fn verification_failures(name: &str, r: &PaperRun, failures: &mut Vec<String>) {
    if r.completed() && r.verify.is_none() {
        failures.push(format!(
            "{name}: {}-rank result could not be verified: {}",
            r.rec.np, r.verify_error
        ));
    }
    if r.completed() {
        for c in r.checks().iter().filter(|c| !c.pass) {
            failures.push(format!(
                "{name}: {} rank(s): check failed: {} = {} (limit {})",
                r.rec.np,
                c.name,
                num(c.value),
                num(c.limit)
            ));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cycling_diagnosis_is_read() {
        let msg = "step 1 failed after 3 cut-backs: contact did not settle after 4 contact \
                   updates: the constraint set cycles between two states: slave nodes 15, 16 \
                   (between master faces)";
        assert_eq!(cycle_updates(msg), Some(4));
        assert_eq!(cycle_updates("no number"), None);
    }
}

#[cfg(test)]
mod judgement {
    use super::super::model::{Check, Verify};
    use super::*;
    use crate::record::Record;

    fn run(np: usize, pass: bool) -> PaperRun {
        PaperRun {
            rec: Record {
                np,
                scene: "run/scenes/paper/bc_interaction.toml".into(),
                rc: Some("0".into()),
                ..Record::default()
            },
            result: Some(format!("np{np}/bc_interaction.h5")),
            verify: Some(Verify {
                kind: "bc_interaction".into(),
                checks: vec![Check {
                    name: "max |u - exact| / d".into(),
                    value: Some(if pass { 1e-13 } else { 1e-3 }),
                    limit: Some(1e-8),
                    pass,
                }],
                ..Verify::default()
            }),
            ..PaperRun::default()
        }
    }

    /// A paper whose comparisons all say "bitwise identical" (exit 0) and whose Hertz
    /// comparison ran.
    fn paper(pass: bool) -> (Paper, std::path::PathBuf) {
        let out = std::env::temp_dir().join(format!("suite-paper-{}-{pass}", std::process::id()));
        std::fs::create_dir_all(out.join("logs")).unwrap();
        for n in ["bc_interaction", "cylinder_on_block"] {
            std::fs::write(
                out.join(format!("logs/{n}.compare.txt")),
                "result: bitwise identical\n",
            )
            .unwrap();
            std::fs::write(out.join(format!("logs/{n}.compare.rc")), "0\n").unwrap();
        }
        let p = Paper {
            out: out.clone(),
            scenes: vec!["bc_interaction".into()],
            example: "cylinder_on_block".into(),
            example_scene: "run/examples/cylinder_on_block.toml".into(),
            runs: vec![
                ("bc_interaction".into(), (run(1, pass), run(2, pass))),
                ("cylinder_on_block".into(), (run(1, true), run(2, true))),
            ],
            hertz_rc: "0".into(),
            hertz_txt: String::new(),
            render_rc: "3".into(),
            render_log: String::new(),
        };
        (p, out)
    }

    /// A failing check of a base scene fails the job (on each rank it fails on); passing
    /// checks, bitwise identical ranks and a completed example do not.
    #[test]
    fn a_failing_check_of_a_base_scene_fails_the_job() {
        let (good, dir) = paper(true);
        assert_eq!(good.failures(), Vec::<String>::new());
        assert_eq!(good.checks_cell("bc_interaction"), "1/1");
        assert_eq!(
            good.key_error("bc_interaction"),
            "max \\|u - exact\\|/d = 1.000e-13"
        );
        let (bad, dir2) = paper(false);
        assert_eq!(
            bad.failures(),
            [
                "bc_interaction: 1 rank(s): check failed: max |u - exact| / d = 0.001 (limit 1.000e-08)",
                "bc_interaction: 2 rank(s): check failed: max |u - exact| / d = 0.001 (limit 1.000e-08)",
            ]
        );
        assert_eq!(bad.checks_cell("bc_interaction"), "0/1 FAIL");
        let facts = crate::facts::Facts {
            date: String::new(),
            commit: String::new(),
            cores: String::new(),
            cpu: String::new(),
            mem: String::new(),
            os: String::new(),
            kernel: String::new(),
            rustc: String::new(),
            mpi: String::new(),
            solver: String::new(),
            paraview: String::new(),
            elapsed: 0,
        };
        assert_eq!(super::super::report::write(&good, &facts), Ok(0));
        assert_eq!(
            super::super::report::write(&bad, &facts),
            Ok(1),
            "a failure gives exit code 1"
        );
        let report = std::fs::read_to_string(dir2.join("report.md")).unwrap();
        assert!(report.contains("**Failures:**\n\n- bc_interaction: 1 rank(s): check failed"));
        std::fs::remove_dir_all(dir).unwrap();
        std::fs::remove_dir_all(dir2).unwrap();
    }
}
