//! `suite`: the verification suites the `run/` scripts start (they install, build, and call
//! this).
//!
//! - `suite paper` (run/paper): the paper's five tests on 1 and 2 ranks, verified, compared,
//!   drawn, and `out/paper/report.md` (module `paper`);
//! - `suite extreme [--one-rank]` (run/extreme): the hard scenes, each solved and checked or
//!   stopped with a diagnosis, and `out/extreme/report.md` (module `extreme`, whose checks
//!   use the library's `post::balance`);
//! - `suite study [--quick] [--out DIR]` (run/study): error against run time (module
//!   `study`).
//!
//! Shared: `runner` (the solver under `timeout` and `run/mpirun` within a budget, its log
//! files), `record` (a run read back from its logs), `facts` (date, commit, machine),
//! `text` (the reports' number formats and tables).
//!
//! Run from the repository's root (the scripts change there first): scenes, `run/mpirun`
//! and `target/release/solver` are found by relative paths, which the reports quote.
//!
//! Environment: `SUITE_STARTED` (seconds since the epoch when the calling script started,
//! so that budgets and reported times include the build), `PAPER_BUDGET` (510),
//! `PAPER_RUN_LIMIT` (120), `EXTREME_BUDGET` (540), `EXTREME_RUN_LIMIT` (120).

mod extreme;
mod facts;
mod paper;
mod record;
mod runner;
mod study;
mod text;

use runner::Suite;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

const USAGE: &str = "usage: suite paper\n       suite extreme [--one-rank]\n       suite study [--quick] [--out DIR]";

/// When the calling script started (`SUITE_STARTED`), else now.
fn started() -> Result<Instant, String> {
    let now = Instant::now();
    let Ok(text) = std::env::var("SUITE_STARTED") else {
        return Ok(now);
    };
    let t: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("SUITE_STARTED: expected seconds since the epoch, got '{text}'"))?;
    let epoch = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_err(|e| e.to_string())?
        .as_secs_f64();
    let ago = (epoch - t).max(0.0);
    Ok(now.checked_sub(Duration::from_secs_f64(ago)).unwrap_or(now))
}

/// An integer setting from the environment, or its default.
fn setting(key: &str, default: i64) -> Result<i64, String> {
    match std::env::var(key) {
        Ok(v) if !v.is_empty() => v
            .trim()
            .parse()
            .map_err(|_| format!("{key}: expected a whole number of seconds, got '{v}'")),
        _ => Ok(default),
    }
}

fn suite(
    name: &'static str,
    budget: i64,
    run_limit: i64,
    widths: (usize, usize),
) -> Result<Suite, String> {
    Ok(Suite {
        name,
        solver: PathBuf::from("target/release/solver"),
        out: PathBuf::from(format!("out/{name}")),
        budget,
        run_limit,
        start: started()?,
        name_width: widths.0,
        time_width: widths.1,
    })
}

fn run(args: &[String]) -> Result<i32, (i32, String)> {
    let usage = |m: String| (2, format!("{m}\n{USAGE}"));
    let fail = |m: String| (2, m);
    let help = matches!(
        args.first().map(String::as_str),
        Some("-h" | "--help") | None
    );
    if !help && !std::path::Path::new("run/scenes").is_dir() {
        return Err(fail(
            "suite: run/scenes not found: run from the repository's root (as run/paper, \
             run/extreme and run/study do)"
                .into(),
        ));
    }
    match args.first().map(String::as_str) {
        Some("paper") => {
            if let Some(a) = args.get(1) {
                return Err(usage(format!("suite paper: unknown option '{a}'")));
            }
            let s = suite(
                "paper",
                setting("PAPER_BUDGET", 510).map_err(fail)?,
                setting("PAPER_RUN_LIMIT", 120).map_err(fail)?,
                (30, 6),
            )
            .map_err(fail)?;
            paper::run(&s).map_err(|e| (1, format!("run/paper: {e}")))
        }
        Some("extreme") => {
            let mut one_rank = false;
            for a in &args[1..] {
                match a.as_str() {
                    "--one-rank" => one_rank = true,
                    other => {
                        return Err(fail(format!(
                            "run/extreme: unknown option '{other}' (expected --one-rank)"
                        )))
                    }
                }
            }
            let s = suite(
                "extreme",
                setting("EXTREME_BUDGET", 540).map_err(fail)?,
                setting("EXTREME_RUN_LIMIT", 120).map_err(fail)?,
                (24, 7),
            )
            .map_err(fail)?;
            extreme::run(&s, one_rank).map_err(|e| (1, format!("run/extreme: {e}")))
        }
        Some("study") => study::main(&args[1..])
            .map(|()| 0)
            .map_err(|e| (2, format!("study: {e}"))),
        Some("-h") | Some("--help") => {
            println!("{USAGE}");
            Ok(0)
        }
        Some(other) => Err(usage(format!("suite: unknown suite '{other}'"))),
        None => Err(usage("suite: which suite?".into())),
    }
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match run(&args) {
        Ok(code) => ExitCode::from(code as u8),
        Err((code, msg)) => {
            eprintln!("{msg}");
            ExitCode::from(code as u8)
        }
    }
}
