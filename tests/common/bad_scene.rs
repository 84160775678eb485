//! A scene that must be refused: `solver check` and `solver run` agree on it, say the same,
//! never panic, and write no result.

use super::paths::solver;

/// Writes `text` to `<name>.toml` in a directory of `suite`, runs `solver check` and
/// `solver run` on it and returns the exit code and the run's standard error.
pub fn check_and_run(suite: &str, name: &str, text: &str) -> (i32, String) {
    // Under cargo's directory for integration tests' files: a later run overwrites them.
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("bad-scenes-{suite}"));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    let result = dir.join(format!("{name}.h5"));
    let check = solver()
        .args(["check", path.to_str().unwrap()])
        .output()
        .expect("solver runs");
    let check_err = String::from_utf8_lossy(&check.stderr).to_string();
    let run = solver()
        .args(["-q", "run", path.to_str().unwrap(), "-o"])
        .arg(&result)
        .output()
        .expect("solver runs");
    let run_err = String::from_utf8_lossy(&run.stderr).to_string();
    assert_eq!(
        check.status.code(),
        run.status.code(),
        "check and run disagree on {name}: {check_err} / {run_err}"
    );
    if !check.status.success() {
        assert_eq!(
            check_err, run_err,
            "check and run report {name} differently"
        );
    }
    assert!(
        !check_err.contains("panicked"),
        "{name}: panic: {check_err}"
    );
    assert!(!run_err.contains("panicked"), "{name}: panic: {run_err}");
    let code = run.status.code().unwrap_or(-1);
    if code != 0 {
        assert!(
            !result.exists(),
            "{name}: a result file was written for a bad scene"
        );
    }
    (code, run_err)
}

/// The scene is refused with exit code 2 by a message naming its file and each of `needles`.
pub fn expect_error(suite: &str, name: &str, text: &str, needles: &[&str]) {
    let (code, err) = check_and_run(suite, name, text);
    println!("{name}: exit {code}: {}", err.trim());
    assert_eq!(code, 2, "{name}: exit code ({err})");
    assert!(
        err.contains(&format!("{name}.toml")),
        "{name}: message does not name the file: {err}"
    );
    for n in needles {
        assert!(err.contains(n), "{name}: message lacks '{n}': {err}");
    }
}
