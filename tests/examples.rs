//! Every example command the user is shown runs as shown: the block under "Using it" in the
//! README and the examples of `solver --help`, in that order, each exiting 0. They run in a
//! fresh directory that holds a link to the repository's `run/`, so the relative paths of
//! the examples resolve and their `out/` is the test's own.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common;
use common::repo;

/// The commands of the first fenced block after `heading`: `\` continuations joined, `#`
/// comments dropped, the build command skipped (this test's binary is built already).
fn readme_block(heading: &str) -> Vec<String> {
    let text = std::fs::read_to_string(repo("README.md")).unwrap();
    let after = &text[text.find(heading).expect("the README has the heading")..];
    let start = after.find("```\n").expect("a fenced block") + 4;
    let block = &after[start..start + after[start..].find("```").unwrap()];
    let joined = block.replace("\\\n", " ");
    joined
        .lines()
        .map(|l| l.split(" #").next().unwrap().trim().to_string())
        .filter(|l| !l.is_empty() && !l.starts_with("cargo build"))
        .collect()
}

/// The lines after "Examples:" in `solver --help`.
fn help_examples() -> Vec<String> {
    let o = Command::new(env!("CARGO_BIN_EXE_solver"))
        .arg("--help")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0));
    let text = String::from_utf8(o.stdout).unwrap();
    let after = &text[text.find("Examples:").expect("--help has examples") + 9..];
    after
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .map(str::to_string)
        .collect()
}

/// Runs one example line in `dir` with this build's solver in place of `solver` and
/// `target/release/solver`.
fn run_line(dir: &Path, line: &str) {
    let bin = env!("CARGO_BIN_EXE_solver");
    let words: Vec<&str> = line
        .split_whitespace()
        .enumerate()
        .map(|(i, w)| match w {
            "target/release/solver" => bin,
            "solver" if i == 0 => bin,
            w => w,
        })
        .collect();
    let t = std::time::Instant::now();
    let o = Command::new(words[0])
        .args(&words[1..])
        .current_dir(dir)
        .output()
        .unwrap_or_else(|e| panic!("{line}: {e}"));
    println!(
        "{:6.2} s  exit {:?}  {line}",
        t.elapsed().as_secs_f64(),
        o.status.code()
    );
    assert_eq!(
        o.status.code(),
        Some(0),
        "{line}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

fn fresh_dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("examples-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    std::os::unix::fs::symlink(repo("run"), d.join("run")).unwrap();
    d
}

#[test]
fn the_readme_using_it_block_runs_as_shown() {
    let lines = readme_block("## Using it");
    assert!(lines.len() >= 10, "{lines:?}");
    let d = fresh_dir("readme");
    for line in &lines {
        run_line(&d, line);
    }
    // What the block says it writes is there.
    for f in [
        "out/bar.h5",
        "out/bar.xmf",
        "out/bar-np2.h5",
        "out/bar.png",
        "out/hertz.png",
    ] {
        assert!(d.join(f).is_file(), "{f}");
    }
}

#[test]
fn the_help_examples_run_as_shown() {
    let lines = help_examples();
    assert!(lines.len() >= 5, "{lines:?}");
    let d = fresh_dir("help");
    for line in &lines {
        run_line(&d, line);
    }
}
