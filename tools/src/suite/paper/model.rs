//! What the paper suite knows about each run once it is over: the run's record, its
//! result file, `solver post verify --json` and `solver post info` of it, and the 1- against
//! 2-rank comparison, all read back from `out/paper/`.

use crate::record::{read, read_trim, Record};
use serde_json::Value;
use std::path::Path;

/// A check of `solver post verify`.
#[derive(Clone, Debug, PartialEq)]
pub struct Check {
    pub name: String,
    pub value: Option<f64>,
    pub limit: Option<f64>,
    pub pass: bool,
}

/// `solver post verify --json` of a result.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Verify {
    pub kind: String,
    pub checks: Vec<Check>,
    pub reported: Vec<(String, Option<f64>)>,
    pub notes: Vec<String>,
}

impl Verify {
    pub fn parse(text: &str) -> Option<Verify> {
        let v: Value = serde_json::from_str(text).ok()?;
        let checks = v["checks"]
            .as_array()?
            .iter()
            .map(|c| Check {
                name: c["name"].as_str().unwrap_or("").into(),
                value: c["value"].as_f64(),
                limit: c["limit"].as_f64(),
                pass: c["pass"].as_bool().unwrap_or(false),
            })
            .collect();
        let reported = v["reported"]
            .as_array()?
            .iter()
            .map(|r| (r[0].as_str().unwrap_or("").to_string(), r[1].as_f64()))
            .collect();
        let notes = v["notes"]
            .as_array()
            .map(|a| {
                a.iter()
                    .filter_map(|n| n.as_str().map(str::to_string))
                    .collect()
            })
            .unwrap_or_default();
        Some(Verify {
            kind: v["kind"].as_str().unwrap_or("").into(),
            checks,
            reported,
            notes,
        })
    }

    /// A reported quantity (the last one of that name).
    pub fn reported(&self, name: &str) -> Option<f64> {
        self.reported
            .iter()
            .rev()
            .find(|r| r.0 == name)
            .and_then(|r| r.1)
    }

    pub fn passed(&self) -> usize {
        self.checks.iter().filter(|c| c.pass).count()
    }

    /// The checks as name and value pairs.
    pub fn check_values(&self) -> Vec<(String, Option<f64>)> {
        self.checks
            .iter()
            .map(|c| (c.name.clone(), c.value))
            .collect()
    }
}

/// The value of the first name starting with `prefix` (the last value given that name).
pub fn first(prefix: &str, table: &[(String, Option<f64>)]) -> Option<f64> {
    let name = &table.iter().find(|(k, _)| k.starts_with(prefix))?.0;
    table.iter().rev().find(|(k, _)| k == name)?.1
}

/// One run of the paper suite with everything read back about it.
#[derive(Clone, Debug, Default)]
pub struct PaperRun {
    pub rec: Record,
    /// The result file relative to `out/paper/` (`np1/<name>.h5` or `.failed.h5`).
    pub result: Option<String>,
    pub verify: Option<Verify>,
    pub verify_error: String,
    pub info: String,
}

impl PaperRun {
    pub fn load(out: &Path, name: &str, np: usize, scene: &str) -> PaperRun {
        let logs = out.join("logs");
        let base = |ext: &str| logs.join(format!("{name}.np{np}.{ext}"));
        let result = [".h5", ".failed.h5"]
            .iter()
            .map(|s| format!("np{np}/{name}{s}"))
            .find(|r| out.join(r).exists());
        PaperRun {
            rec: Record::load(&logs, name, np, scene),
            result,
            verify: read(&base("verify.json")).and_then(|t| Verify::parse(&t)),
            verify_error: read_trim(&base("verify.stderr")),
            info: read(&base("info.txt")).unwrap_or_default(),
        }
    }

    pub fn completed(&self) -> bool {
        self.rec.rc_is("0")
            && self
                .result
                .as_deref()
                .is_some_and(|r| r.ends_with(".h5") && !r.ends_with(".failed.h5"))
    }

    pub fn message(&self) -> String {
        self.rec.message()
    }

    pub fn checks(&self) -> &[Check] {
        self.verify.as_ref().map_or(&[], |v| &v.checks)
    }

    pub fn reported(&self, name: &str) -> Option<f64> {
        self.verify.as_ref().and_then(|v| v.reported(name))
    }

    pub fn passed(&self) -> usize {
        self.verify.as_ref().map_or(0, Verify::passed)
    }

    /// The completed load steps, from `solver post info`.
    pub fn steps(&self) -> Option<u64> {
        self.info
            .lines()
            .find_map(|l| l.strip_prefix("steps:"))
            .filter(|s| s.starts_with(char::is_whitespace))
            .and_then(|s| {
                let digits: String = s
                    .trim_start()
                    .chars()
                    .take_while(char::is_ascii_digit)
                    .collect();
                digits.parse().ok()
            })
    }

    /// Contact updates of each step, from `solver post info`'s table.
    pub fn per_step_updates(&self) -> Vec<u64> {
        self.info.lines().filter_map(step_row_updates).collect()
    }
}

/// The contact updates of a row of `solver post info`'s step table (seven columns: step,
/// time, CG iterations, contact updates, cut-backs, residual, wall time).
fn step_row_updates(line: &str) -> Option<u64> {
    let t: Vec<&str> = line.split_whitespace().collect();
    let int = |s: &str| !s.is_empty() && s.chars().all(|c| c.is_ascii_digit());
    (t.len() == 7 && int(t[0]) && int(t[2]) && int(t[3]) && int(t[4]))
        .then(|| t[3].parse().ok())
        .flatten()
}

/// `solver post compare` of the 1- and 2-rank results: its exit code, the counted datasets
/// that differ with their largest relative difference, and its verdict.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Comparison {
    pub rc: Option<String>,
    pub differing: Vec<(String, f64)>,
    pub verdict: String,
}

impl Comparison {
    pub fn load(logs: &Path, name: &str) -> Comparison {
        match read(&logs.join(format!("{name}.compare.txt"))) {
            None => Comparison::default(),
            Some(txt) => {
                Comparison::parse(&txt, &read_trim(&logs.join(format!("{name}.compare.rc"))))
            }
        }
    }

    pub fn parse(txt: &str, rc: &str) -> Comparison {
        let differing = txt
            .lines()
            .filter_map(dataset_row)
            .filter(|(_, _, status)| {
                !status.contains("not counted") && !status.starts_with("identical")
            })
            .map(|(name, rel, _)| (name.to_string(), rel.parse().unwrap_or(f64::NAN)))
            .collect();
        let mut verdict = txt
            .lines()
            .find_map(|l| l.strip_prefix("result: "))
            .unwrap_or("")
            .to_string();
        if rc == "2" {
            if let Some(l) = txt.lines().map(str::trim).find(|l| !l.is_empty()) {
                verdict = l.to_string();
            }
        }
        Comparison {
            rc: Some(rc.to_string()),
            differing,
            verdict,
        }
    }

    /// How the two files differ, in a few words.
    pub fn difference(&self) -> String {
        let results: Vec<&(String, f64)> = self
            .differing
            .iter()
            .filter(|d| d.0.starts_with("/results/"))
            .collect();
        if let Some(worst) = results
            .iter()
            .copied()
            .reduce(|a, b| if b.1 > a.1 { b } else { a })
        {
            return format!(
                "differs (max rel diff {}, in {})",
                crate::text::n(worst.1),
                worst.0
            );
        }
        if !self.differing.is_empty() {
            let names: Vec<&str> = self.differing.iter().map(|d| d.0.as_str()).collect();
            return format!("results identical, differs in {}", names.join(", "));
        }
        format!("differs ({})", self.verdict)
    }
}

/// A dataset row of `solver post compare`: (name, max rel diff, status).
fn dataset_row(line: &str) -> Option<(&str, &str, &str)> {
    if !line.starts_with('/') {
        return None;
    }
    let (name, rest) = line.split_once(char::is_whitespace)?;
    let rest = rest.trim_start().strip_prefix('[')?;
    let (_, rest) = rest.split_once(']')?;
    let rest = rest.strip_prefix(char::is_whitespace)?.trim_start();
    let (_abs, rest) = rest.split_once(char::is_whitespace)?;
    let rest = rest.trim_start();
    let (rel, status) = rest.split_once(char::is_whitespace)?;
    Some((name, rel, status.trim_start()))
}

#[cfg(test)]
mod tests {
    use super::*;

    const COMPARE: &str = "a: x\nb: y\ntolerance: bitwise\n\
dataset                                          shape  max abs diff  max rel diff  status\n\
/results/displacement                         [10, 3]     1.0000e-9     2.5000e-3  3 values differ\n\
/results/stress                               [10, 6]     1.0000e-9     1.0000e-2  4 values differ\n\
/partition/element_rank                           [96]      1.0000e0           inf  48 values differ (not counted)\n\
/stats/residual                                   [60]      0.0000e0      0.0000e0  identical\n\
result: DIFFERENT (2 of 44 counted datasets)\n";

    #[test]
    fn a_comparison_names_the_worst_result_dataset() {
        let c = Comparison::parse(COMPARE, "1");
        assert_eq!(
            c.differing,
            vec![
                ("/results/displacement".to_string(), 2.5e-3),
                ("/results/stress".to_string(), 1e-2)
            ]
        );
        assert_eq!(c.verdict, "DIFFERENT (2 of 44 counted datasets)");
        assert_eq!(
            c.difference(),
            "differs (max rel diff 0.01, in /results/stress)"
        );
        let stats = Comparison {
            differing: vec![("/stats/cg_iterations".into(), 1.0)],
            ..c.clone()
        };
        assert_eq!(
            stats.difference(),
            "results identical, differs in /stats/cg_iterations"
        );
        let cannot = Comparison::parse("error: meshes differ\n", "2");
        assert_eq!(cannot.verdict, "error: meshes differ");
    }

    #[test]
    fn verify_json_is_read_with_missing_values_as_none() {
        let v = Verify::parse(
            r#"{"scene":"s","kind":"k","checks":[{"name":"a","value":1e-9,"limit":1e-8,"pass":true},
            {"name":"b","value":null,"limit":0.0,"pass":false}],"reported":[["r",2.0],["r",3.0]],"notes":["n"]}"#,
        )
        .unwrap();
        assert_eq!(v.passed(), 1);
        assert_eq!(v.checks[1].value, None);
        assert_eq!(v.reported("r"), Some(3.0));
        assert_eq!(first("a", &v.check_values()), Some(1e-9));
        assert_eq!(first("z", &v.check_values()), None);
        assert!(Verify::parse("not json").is_none());
    }

    #[test]
    fn info_gives_steps_and_per_step_updates() {
        let run = PaperRun {
            info: "steps:        3\n\n step  time  CG its  contact  cutback  residual  wall\n    0    5.000000e-2        0        1        0   1.7989e-10      0.002\n    1    1.0e-1   4   7   0   1.0e-10   0.002\n"
                .into(),
            ..PaperRun::default()
        };
        assert_eq!(run.steps(), Some(3));
        assert_eq!(run.per_step_updates(), vec![1, 7]);
    }
}
