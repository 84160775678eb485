//! Runs killed and restarted, and results compared with `solver post compare`.

use std::path::{Path, PathBuf};

use super::paths::solver;

/// `solver post compare a b`: whether it exited 0, and its report (standard output).
pub fn post_compare(a: &Path, b: &Path) -> (bool, String) {
    let cmp = solver()
        .args(["post", "compare"])
        .arg(a)
        .arg(b)
        .output()
        .unwrap();
    (
        cmp.status.success(),
        String::from_utf8_lossy(&cmp.stdout).to_string(),
    )
}

/// Runs `scene` uninterrupted to `d/full.h5`, then killed after `kill_after` steps and
/// restarted from the `.tmp` file the killed run left to `d/cut.h5`, and demands
/// bitwise-identical results (`solver post compare` with its default tolerance 0: every
/// dataset but wall times). Returns the uninterrupted result and the comparison's report.
pub fn killed_and_restarted_is_identical(
    scene: &str,
    d: &Path,
    kill_after: usize,
) -> (PathBuf, String) {
    let full = d.join("full.h5");
    let cut = d.join("cut.h5");
    let s = solver()
        .args(["-q", "run", scene, "-o"])
        .arg(&full)
        .status()
        .unwrap();
    assert!(s.success());
    let s = solver()
        .args(["-q", "run", scene, "-o"])
        .arg(&cut)
        .env("SOLVER_TEST_ABORT_AFTER_STEP", kill_after.to_string())
        .status()
        .unwrap();
    assert!(!s.success(), "the killed run must not exit 0");
    let tmp = d.join("cut.h5.tmp");
    assert!(
        tmp.exists() && !cut.exists(),
        "a killed run leaves only the .tmp file"
    );
    let out = solver()
        .args(["run", scene, "--restart"])
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
    let (same, report) = post_compare(&full, &cut);
    assert!(same, "results differ:\n{report}");
    assert!(report.contains("bitwise identical"), "{report}");
    (full, report)
}
