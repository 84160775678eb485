//! The paper suite's post-processing of the results, each into its log file under
//! `out/paper/logs/`: `solver post verify --json` and `info`, `solver post compare` of 1
//! against 2 ranks, the figures, `solver post hertz` of the cylinder, and run/render's
//! ParaView pictures.

use super::results::{DRAWN_EXAMPLES, EXAMPLE};
use crate::record::{read, read_trim};
use crate::runner::{run_merged, Suite};
use std::path::{Path, PathBuf};
use std::process::Command;

fn s(p: &Path) -> &str {
    p.to_str().expect("the suite's paths are UTF-8")
}

/// Verify (and, on 1 rank, info) of every result; 1 against 2 ranks.
pub fn checks(suite: &Suite, scenes: &[String]) {
    let logs = suite.logs();
    for n in scenes {
        for np in [1, 2] {
            let Some(r) = suite.result_of(n, np) else {
                continue;
            };
            let base = |ext: &str| logs.join(format!("{n}.np{np}.{ext}"));
            suite.solver_to(
                &["post", "verify", "--json", s(&r)],
                &base("verify.json"),
                Some(&base("verify.stderr")),
                Some(&base("verify.rc")),
            );
            if read(&base("verify.stderr")).is_some_and(|t| t.is_empty()) {
                let _ = std::fs::remove_file(base("verify.stderr"));
            }
            if np == 1 {
                suite.solver_to(&["post", "info", s(&r)], &base("info.txt"), None, None);
            }
        }
        compare(suite, n);
    }
}

/// `solver post compare` of the 1- and 2-rank results, when both exist.
fn compare(suite: &Suite, name: &str) {
    if let (Some(a), Some(b)) = (suite.result_of(name, 1), suite.result_of(name, 2)) {
        let logs = suite.logs();
        suite.solver_to(
            &["post", "compare", s(&a), s(&b)],
            &logs.join(format!("{name}.compare.txt")),
            None,
            Some(&logs.join(format!("{name}.compare.rc"))),
        );
    }
}

/// The paper's figures, each from the 1-rank result of its scene.
pub fn figures(suite: &Suite) {
    let logs = suite.logs();
    for (fig, scene) in [
        ("fig2", "bc_interaction_frictionless"),
        ("fig5", "capture_release"),
        ("fig6", "stick_slip"),
        ("fig_smoothing", "normal_smoothing"),
    ] {
        let log = logs.join(format!("{fig}.log"));
        let rc = logs.join(format!("{fig}.rc"));
        match suite.result_of(scene, 1) {
            None => {
                let _ = std::fs::write(
                    &log,
                    format!("no 1-rank result of {scene} to draw {fig} from\n"),
                );
                let _ = std::fs::write(&rc, "2\n");
            }
            Some(r) => {
                let png = suite.out.join(format!("{fig}.png"));
                suite.solver_to(
                    &["post", "figure", fig, s(&r), "-o", s(&png)],
                    &log,
                    None,
                    Some(&rc),
                );
            }
        }
        let text = read(&log).unwrap_or_default();
        suite.say(text.lines().last().unwrap_or(""));
    }
}

/// The cylinder against Hertz, and its 1- against 2-rank comparison.
pub fn hertz(suite: &Suite) {
    let logs = suite.logs();
    let txt = logs.join("hertz.txt");
    match suite.result_of(EXAMPLE, 1) {
        Some(a) => {
            suite.solver_to(
                &["post", "info", s(&a)],
                &logs.join(format!("{EXAMPLE}.np1.info.txt")),
                None,
                None,
            );
            let png = suite.out.join("hertz.png");
            suite.solver_to(
                &["post", "hertz", s(&a), "-o", s(&png)],
                &txt,
                None,
                Some(&logs.join("hertz.rc")),
            );
        }
        None => {
            let _ = std::fs::write(&txt, format!("no 1-rank result of {EXAMPLE}\n"));
            let _ = std::fs::write(logs.join("hertz.rc"), "2\n");
        }
    }
    compare(suite, EXAMPLE);
    for (name, _) in DRAWN_EXAMPLES {
        compare(suite, name);
    }
    let text = read(&txt).unwrap_or_default();
    let line = text
        .lines()
        .find(|l| l.contains("RMS error"))
        .map(|l| l.trim_start())
        .or_else(|| text.lines().last())
        .unwrap_or("");
    suite.say(&format!("hertz: {line}"));
}

/// ParaView pictures of the last step (run/render), when ParaView is installed.
pub fn render(suite: &Suite) {
    let logs = suite.logs();
    let (log, rc) = (logs.join("render.log"), logs.join("render.rc"));
    let xmfs: Vec<PathBuf> = ["capture_release", "stick_slip", "multi_constraint", EXAMPLE]
        .iter()
        .filter_map(|n| suite.result_of(n, 1))
        .map(|r| PathBuf::from(s(&r).strip_suffix(".h5").unwrap_or(s(&r)).to_string() + ".xmf"))
        .filter(|x| x.is_file())
        .collect();
    if xmfs.is_empty() {
        let _ = std::fs::write(&log, "no result to draw\n");
        let _ = std::fs::write(&rc, "2\n");
    } else {
        let mut cmd = Command::new("timeout");
        cmd.args(["-k", "10", "300", "run/render"])
            .args(&xmfs)
            .arg("-o")
            .arg(&suite.out);
        let code = run_merged(&mut cmd, &log);
        let _ = std::fs::write(&rc, format!("{code}\n"));
    }
    for (name, _) in DRAWN_EXAMPLES {
        render_oblique(suite, name);
    }
    let text = read(&log).unwrap_or_default();
    let last = text.lines().last().unwrap_or("");
    match read_trim(&rc).as_str() {
        "0" => {
            let n = text
                .lines()
                .filter(|l| l.starts_with("render: ") && l.contains(".png"))
                .count();
            suite.say(&format!("ParaView pictures: {n} written (run/render)"))
        }
        "3" => suite.say(&format!(
            "ParaView pictures: not drawn, {}",
            last.strip_prefix("run/render: ").unwrap_or(last)
        )),
        code => suite.say(&format!(
            "ParaView pictures: run/render failed (exit {code}), see {}",
            log.display()
        )),
    }
}

/// An example drawn on its own, from an oblique view: seen from the front, the plastic
/// example's yielded zone under the bolt head is hidden by the plates' elastic faces, and
/// the bracket's bolt hole and bend are edge-on.
fn render_oblique(suite: &Suite, name: &str) {
    let logs = suite.logs();
    let log = logs.join(format!("render_{name}.log"));
    let Some(r) = suite.result_of(name, 1) else {
        return;
    };
    let xmf = PathBuf::from(s(&r).strip_suffix(".h5").unwrap_or(s(&r)).to_string() + ".xmf");
    if !xmf.is_file() {
        return;
    }
    let mut cmd = Command::new("timeout");
    cmd.args(["-k", "10", "300", "run/render", "--view", "iso"])
        .arg(&xmf)
        .arg("-o")
        .arg(&suite.out);
    let code = run_merged(&mut cmd, &log);
    let _ = std::fs::write(logs.join(format!("render_{name}.rc")), format!("{code}\n"));
}
