//! Restart mid-yield: a plastic run killed after a step in which elements are yielding and
//! continued with `solver run --restart` ends bitwise identical to an uninterrupted run (the
//! restart file carries the committed integration-point history).

use std::path::{Path, PathBuf};
use std::process::Command;

fn solver() -> Command {
    Command::new(env!("CARGO_BIN_EXE_solver"))
}

fn dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("plastic-restart-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn killed_and_restarted_is_identical(scene: &str, kill_after: usize) {
    let scene = format!("{}/{scene}", env!("CARGO_MANIFEST_DIR"));
    let name = Path::new(&scene)
        .file_stem()
        .unwrap()
        .to_string_lossy()
        .to_string();
    let d = dir(&name);
    let full = d.join("full.h5");
    let cut = d.join("cut.h5");
    let s = solver()
        .args(["-q", "run", &scene, "-o"])
        .arg(&full)
        .status()
        .unwrap();
    assert!(s.success());
    let s = solver()
        .args(["-q", "run", &scene, "-o"])
        .arg(&cut)
        .env("SOLVER_TEST_ABORT_AFTER_STEP", kill_after.to_string())
        .status()
        .unwrap();
    assert!(!s.success(), "the killed run must not exit 0");
    let tmp = d.join("cut.h5.tmp");
    assert!(tmp.exists() && !cut.exists());
    let out = solver()
        .args(["run", &scene, "--restart"])
        .arg(&tmp)
        .arg("-o")
        .arg(&cut)
        .output()
        .unwrap();
    let log = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "restart failed: {log}");
    assert!(
        log.contains(&format!("continuing from step {kill_after} ")),
        "{log}"
    );
    let cmp = solver()
        .args(["post", "compare"])
        .arg(&full)
        .arg(&cut)
        .output()
        .unwrap();
    let report = String::from_utf8_lossy(&cmp.stdout);
    assert!(cmp.status.success(), "results differ:\n{report}");
    assert!(report.contains("bitwise identical"), "{report}");
    assert!(report.contains("/results/plastic_strain"), "{report}");
    // The file holds yielded elements before and after the kill: mid-yield.
    let info = solver().args(["post", "info"]).arg(&full).output().unwrap();
    let info = String::from_utf8_lossy(&info.stdout);
    let yielded: Vec<usize> = info
        .lines()
        .skip_while(|l| !l.contains("max plastic eps"))
        .skip(1)
        .filter_map(|l| l.split_whitespace().nth(2)?.parse().ok())
        .collect();
    assert!(yielded[kill_after - 1] > 0, "{info}");
    assert!(yielded.last() > Some(&yielded[kill_after - 1]), "{info}");
}

#[test]
fn plastic_indent_killed_mid_yield_restarts_bitwise() {
    killed_and_restarted_is_identical("mpi-tests/plastic_indent.toml", 3);
}
