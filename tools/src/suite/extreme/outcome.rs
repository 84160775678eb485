//! A scene's outcome: "pass" (completed and every check passes, or, for a scene that
//! cannot be solved, stopped as it should), "diagnosed stop" (exit code 1, a message naming
//! the step and the time, the completed steps in `.failed.h5`, no NaN) or "FAIL" (a check
//! fails, a crash, a hang, a NaN, a stop without that diagnosis, 2 ranks differing from 1).

use super::checks::Checks;
use super::result::Res;
use super::scenes::{checks_of, generic};
use super::scenes::{MUST_STOP, SCENE_DIR};
use crate::record::{read, read_trim, Record};
use crate::text::n;
use std::path::Path;

/// One run of the extreme suite: its record, the files it left and the result opened.
pub struct Run {
    pub rec: Record,
    /// Which of `.h5`, `.failed.h5`, `.h5.tmp` exist.
    pub files: Vec<&'static str>,
    pub result: Option<Res>,
    pub open_error: Option<String>,
}

/// Which of the step, the time and a place (node, element, body) a message names.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Names {
    pub step: bool,
    pub time: bool,
    pub place: bool,
}

fn is_word(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// Positions where `word` starts at a word boundary in `text`.
fn word_starts<'a>(text: &'a str, word: &'a str) -> impl Iterator<Item = usize> + 'a {
    text.match_indices(word)
        .map(|(i, _)| i)
        .filter(move |&i| !text[..i].chars().next_back().is_some_and(is_word))
}

/// What a stop message names: `step <n>`, `t = <number>`, and a node, element or body
/// followed by something with a digit (or `body '`).
pub fn names(m: &str) -> Names {
    let step =
        word_starts(m, "step ").any(|i| m[i + 5..].starts_with(|c: char| c.is_ascii_digit()));
    let time = word_starts(m, "t = ")
        .any(|i| m[i + 4..].starts_with(|c: char| c.is_ascii_digit() || "+-.e".contains(c)));
    let place = ["node", "element", "body", "nodes", "elements"]
        .iter()
        .any(|w| {
            word_starts(m, w).any(|i| {
                let rest = &m[i + w.len()..];
                if rest.starts_with(is_word) {
                    return false;
                }
                let rest = rest.trim_start_matches([' ', '\'']);
                rest.split(char::is_whitespace)
                    .next()
                    .is_some_and(|t| t.contains(|c: char| c.is_ascii_digit()))
            })
        })
        || m.contains("body '");
    Names { step, time, place }
}

impl Run {
    pub fn load(out: &Path, name: &str, np: usize) -> Run {
        let rec = Record::load(
            &out.join("logs"),
            name,
            np,
            &format!("{SCENE_DIR}/{name}.toml"),
        );
        let stem = out.join(format!("np{np}")).join(name);
        let with = |s: &str| format!("{}{s}", stem.display());
        let files: Vec<&'static str> = [".h5", ".failed.h5", ".h5.tmp"]
            .into_iter()
            .filter(|s| Path::new(&with(s)).exists())
            .collect();
        let (mut result, mut open_error) = (None, None);
        // A crashed run leaves only the .tmp, whose finished steps are readable.
        if let Some(s) = files.first() {
            match Res::open(Path::new(&with(s))) {
                Ok(r) => result = Some(r),
                Err(e) => open_error = Some(format!("{name}{s}: {e}")),
            }
        }
        Run {
            rec,
            files,
            result,
            open_error,
        }
    }

    pub fn completed(&self) -> bool {
        self.rec.rc_is("0") && self.files.contains(&".h5") && !self.files.contains(&".failed.h5")
    }

    pub fn rc(&self) -> &str {
        self.rec.rc.as_deref().unwrap_or("None")
    }

    /// The message a run ended with (a panic's place and text when it panicked).
    pub fn message(&self) -> String {
        let r = &self.rec;
        match r.rc.as_deref() {
            None => return "not run".into(),
            Some("skipped") => return r.stderr.trim().into(),
            Some("124") | Some("137") => return format!("timed out after {} s (killed)", r.limit),
            _ => {}
        }
        let lines: Vec<&str> = r
            .stderr
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty())
            .collect();
        if let Some(i) = lines.iter().position(|l| l.contains("panicked at")) {
            let what = lines.get(i + 1).copied().unwrap_or("");
            let panic = lines[i];
            let place = match (panic.strip_prefix("thread "), panic.find(" panicked at ")) {
                (Some(_), Some(j)) => &panic[j + " panicked at ".len()..],
                _ => panic,
            };
            return format!("panic: {place} {what}").trim().to_string();
        }
        let m = r.error_line();
        if !m.is_empty() {
            m
        } else if r.rc_is("0") {
            String::new()
        } else {
            format!("exit code {}, no message", self.rc())
        }
    }
}

/// A scene judged: its outcome, checks, what makes it FAIL, and the 2-rank verdict.
pub struct Verdict {
    pub kind: &'static str,
    pub checks: Checks,
    pub problems: Vec<String>,
    pub two: String,
}

/// Judges scene `name` from its 1-rank run (and 2-rank run, when there is one).
pub fn judge(name: &str, runs: &[Run], base: Option<&Res>, logs: &Path) -> Verdict {
    let r1 = &runs[0];
    let mut c = Checks::default();
    let mut problems = file_problems(r1);
    let must_stop = MUST_STOP.contains(&name);
    judge_exit(name, r1, base, must_stop, &mut c, &mut problems);
    judge_completed_steps(r1, &mut c, &mut problems);
    let mut kind = if !problems.is_empty() {
        "FAIL"
    } else if r1.completed() || must_stop {
        "pass"
    } else {
        "diagnosed stop"
    };
    let two = match runs.get(1) {
        Some(r2) => two_ranks(name, r1, r2, logs, &mut problems),
        None => "-".into(),
    };
    if !problems.is_empty() {
        kind = "FAIL";
    }
    Verdict {
        kind,
        checks: c,
        problems,
        two,
    }
}

/// What is wrong with the 1-rank run's result file itself: unreadable, or not finite.
fn file_problems(r1: &Run) -> Vec<String> {
    let mut problems = Vec::new();
    if let Some(e) = &r1.open_error {
        problems.push(format!("result file unreadable: {e}"));
    }
    if let Some(res) = r1.result.as_ref() {
        let bad = res.not_finite();
        if !bad.is_empty() {
            problems.push(format!("NaN or infinity in {}", bad.join(", ")));
        }
    }
    problems
}

/// Runs check `f`; a check that cannot be evaluated is a problem.
fn evaluate(
    c: &mut Checks,
    problems: &mut Vec<String>,
    f: &dyn Fn(&mut Checks) -> Result<(), String>,
) {
    if let Err(e) = f(c) {
        problems.push(format!("the check could not be evaluated: {e}"));
    }
}

/// Judges the 1-rank run by how it ended: its exit code, its files and its message.
fn judge_exit(
    name: &str,
    r1: &Run,
    base: Option<&Res>,
    must_stop: bool,
    c: &mut Checks,
    problems: &mut Vec<String>,
) {
    let res = r1.result.as_ref();
    let tmp_only = r1.files == [".h5.tmp"];
    match r1.rec.rc.as_deref() {
        None | Some("skipped") | Some("127") => problems.push(format!("not run: {}", r1.message())),
        Some("124") | Some("137") => problems.push(r1.message()),
        _ if r1.completed() => {
            if must_stop {
                problems.push("completed, though the load cannot be carried".into());
            } else if let Some(res) = res {
                evaluate(c, problems, &|c| checks_of(name, res, c, base));
                if !c.passed() {
                    problems.push("a check fails".into());
                }
            }
        }
        Some("1") => {
            let nm = names(&r1.message());
            if !r1.files.contains(&".failed.h5") {
                problems.push("exit 1 without a .failed.h5".into());
            }
            if r1.files.contains(&".h5") {
                problems.push("a complete-looking .h5 was left".into());
            }
            if !(nm.step && nm.time) {
                problems.push("the message does not name the step and the time".into());
            }
            if must_stop {
                c.check(
                    "clean stop (0: exit 1, step and time named, .failed.h5 kept, no .h5)",
                    if problems.is_empty() { 0.0 } else { 1.0 },
                    0.0,
                );
            }
        }
        Some(rc) => problems.push(format!(
            "exit code {rc}: {}{}",
            r1.message(),
            if tmp_only {
                "; only the .h5.tmp was left"
            } else {
                ""
            }
        )),
    }
}

/// Checks the steps a stopped run did complete: they must still be right.
fn judge_completed_steps(r1: &Run, c: &mut Checks, problems: &mut Vec<String>) {
    if let Some(res) = r1.result.as_ref().filter(|r| !r1.completed() && r.n > 0) {
        // The steps that did complete must still be right.
        c.notes.push(format!(
            "{} step(s) completed before the stop (t = {}); the force balance below is that of the last of them",
            res.n,
            n(res.times[res.n - 1])
        ));
        evaluate(c, problems, &|c| generic(res, c));
        if !c.passed() {
            problems.push("a check of the completed steps fails".into());
        }
    }
}

/// The 2-rank run against the 1-rank run; what differs goes into `problems`.
fn two_ranks(name: &str, r1: &Run, r2: &Run, logs: &Path, problems: &mut Vec<String>) -> String {
    let crc = read_trim(&logs.join(format!("{name}.compare.rc")));
    let ctxt = read(&logs.join(format!("{name}.compare.txt"))).unwrap_or_default();
    let same_msg = r1.message() == r2.message();
    let (rc1, rc2) = (r1.rc(), r2.rc());
    if r2.rec.not_run() {
        return r2.message();
    }
    let mut problem = |two: String| {
        problems.push(format!("2 ranks: {two}"));
        two
    };
    if rc2 != rc1 && !(rc1 == "101" && !(rc2 == "0" || rc2 == "1")) {
        return problem(format!("exit {rc2} (1 rank: exit {rc1}): {}", r2.message()));
    }
    match crc.as_str() {
        "0" => {
            let two = format!(
                "bitwise identical{}",
                if rc1 == "0" {
                    ""
                } else if same_msg {
                    " (the completed steps; same message)"
                } else {
                    " (the completed steps; the message differs)"
                }
            );
            if rc1 == "1" && !same_msg {
                problems.push(format!("2 ranks: the message differs: {}", r2.message()));
            }
            two
        }
        "1" => {
            let worst = ctxt
                .lines()
                .find(|l| l.starts_with("/results/") && !l.contains("identical"))
                .and_then(|l| l.split_whitespace().next());
            problem(format!(
                "DIFFERS{}",
                worst.map_or(String::new(), |w| format!(": {w}"))
            ))
        }
        "2" => {
            let first = ctxt.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
            problem(format!("cannot compare: {first}"))
        }
        _ => format!("exit {rc2}, no result to compare"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stop_message_names_step_time_and_place() {
        let m = "step 3 (to t = 0.5) failed at t = 0.375 after 2 cut-backs: CG did not converge; \
                 body 'block' is not held";
        assert_eq!(
            names(m),
            Names {
                step: true,
                time: true,
                place: true
            }
        );
        let m = "CG did not converge in 5000 iterations at node 17";
        assert_eq!(
            names(m),
            Names {
                step: false,
                time: false,
                place: true
            }
        );
        assert_eq!(
            names("substep 3 at t=1 nodes"),
            Names {
                step: false,
                time: false,
                place: false
            }
        );
        assert!(names("the elements 'e12' invert").place);
        assert!(!names("the elementsx 12").place);
    }

    fn run(rc: &str, stderr: &str, files: Vec<&'static str>) -> Run {
        Run {
            rec: Record {
                np: 1,
                scene: format!("{SCENE_DIR}/s.toml"),
                rc: Some(rc.into()),
                limit: "120".into(),
                stderr: stderr.into(),
                ..Record::default()
            },
            files,
            result: None,
            open_error: None,
        }
    }

    #[test]
    fn a_panic_is_reported_with_its_place() {
        let r = run(
            "101",
            "thread 'main' panicked at src/x.rs:3:5:\nindex out of bounds\n",
            vec![],
        );
        assert_eq!(r.message(), "panic: src/x.rs:3:5: index out of bounds");
        assert_eq!(
            run("124", "", vec![]).message(),
            "timed out after 120 s (killed)"
        );
        assert_eq!(run("0", "", vec![".h5"]).message(), "");
    }

    /// The judgement without result files: a stop that names step and time is a diagnosed
    /// stop; one that does not, or without its .failed.h5, FAILs; a crash FAILs.
    #[test]
    fn stops_are_judged_by_their_diagnosis() {
        let logs = std::env::temp_dir();
        let good = "error: step 2 (to t = 1) failed at t = 0.75 after 3 cut-backs: CG stalled\n";
        let v = judge("x", &[run("1", good, vec![".failed.h5"])], None, &logs);
        assert_eq!((v.kind, v.problems.len()), ("diagnosed stop", 0));
        let v = judge(
            "x",
            &[run("1", "error: CG stalled\n", vec![".failed.h5"])],
            None,
            &logs,
        );
        assert_eq!(v.kind, "FAIL");
        assert_eq!(
            v.problems,
            ["the message does not name the step and the time"]
        );
        let v = judge("x", &[run("1", good, vec![])], None, &logs);
        assert_eq!(v.problems, ["exit 1 without a .failed.h5"]);
        let v = judge(
            "off_edge",
            &[run("1", good, vec![".failed.h5"])],
            None,
            &logs,
        );
        assert_eq!(
            v.kind, "pass",
            "a scene that must stop passes when it stops cleanly"
        );
        assert_eq!(v.checks.checks[0].value, 0.0);
        let v = judge("x", &[run("139", "", vec![".h5.tmp"])], None, &logs);
        assert_eq!(
            v.problems,
            ["exit code 139: exit code 139, no message; only the .h5.tmp was left"]
        );
        let v = judge("off_edge", &[run("0", "", vec![".h5"])], None, &logs);
        assert_eq!(v.problems, ["completed, though the load cannot be carried"]);
    }

    #[test]
    fn two_ranks_must_end_as_one_rank_did() {
        let logs = std::env::temp_dir().join(format!("suite-two-ranks-{}", std::process::id()));
        std::fs::create_dir_all(&logs).unwrap();
        let good = "error: step 2 (to t = 1) failed at t = 0.75: CG stalled\n";
        let a = run("1", good, vec![".failed.h5"]);
        let b = run("0", "", vec![".h5"]);
        let v = judge("y", &[a, b], None, &logs);
        assert_eq!(v.kind, "FAIL");
        assert!(v.two.starts_with("exit 0 (1 rank: exit 1)"), "{}", v.two);
        std::fs::write(logs.join("z.compare.rc"), "1\n").unwrap();
        std::fs::write(
            logs.join("z.compare.txt"),
            "/results/stress  [2, 6]  1e-9  1e-3  2 values differ\n",
        )
        .unwrap();
        let v = judge(
            "z",
            &[
                run("1", good, vec![".failed.h5"]),
                run("1", good, vec![".failed.h5"]),
            ],
            None,
            &logs,
        );
        assert_eq!(v.two, "DIFFERS: /results/stress");
        assert_eq!(v.kind, "FAIL");
        std::fs::remove_dir_all(&logs).unwrap();
    }
}
