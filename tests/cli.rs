//! The command line on bad input: a clear message naming the file and the key, a non-zero
//! exit code, never a panic.

use crate::common;
use common::{bad_scene, solver};

/// Refused with exit code 2 naming the file and each of `needles`.
fn expect_error(name: &str, text: &str, needles: &[&str]) {
    bad_scene::expect_error("cli", name, text, needles);
}

fn run_bad(name: &str, text: &str) -> (i32, String) {
    bad_scene::check_and_run("cli", name, text)
}

const GOOD: &str = r#"
[[body]]
name = "b"
box = { min = [0.0, 0.0, 0.0], max = [1.0, 1.0, 1.0] }
divisions = [1, 1, 1]
material = { model = "linear_elastic", E = 1000.0, nu = 0.3 }
[[node_set]]
name = "bottom"
plane = { point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }
[[displacement]]
node_set = "bottom"
components = ["x", "y", "z"]
value = 0.0
[time]
segments = [{ end = 1.0, steps = 1 }]
"#;

#[test]
fn good_scene_passes_check() {
    let (code, err) = run_bad("good", GOOD);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn unknown_key() {
    expect_error(
        "unknown_key",
        &GOOD.replace("divisions =", "divisons = [1, 1, 1]\ndivisions ="),
        &["unknown field `divisons`", "line"],
    );
}

#[test]
fn missing_set_name() {
    expect_error(
        "missing_set",
        &GOOD.replace("node_set = \"bottom\"", "node_set = \"botom\""),
        &["displacement[0].node_set", "'botom'", "bottom"],
    );
}

#[test]
fn non_positive_young_modulus() {
    expect_error(
        "bad_e",
        &GOOD.replace("E = 1000.0", "E = -5.0"),
        &["body[0].material.E", "> 0", "-5"],
    );
    expect_error(
        "zero_e",
        &GOOD.replace("E = 1000.0", "E = 0.0"),
        &["body[0].material.E"],
    );
}

#[test]
fn poisson_ratio_at_half() {
    expect_error(
        "bad_nu",
        &GOOD.replace("nu = 0.3", "nu = 0.5"),
        &["body[0].material.nu", "(-1, 0.5)"],
    );
}

/// Two entries prescribing one direction of the same nodes with other values: the second
/// would be dropped silently (a node's rows in the span of its earlier ones are), so the
/// scene is refused naming both entries, the node and the values; the same values twice
/// (an edge node in two held faces) and a skew direction in the span of held components
/// with consistent values are accepted.
#[test]
fn contradicting_prescribed_displacements() {
    let side = "[[node_set]]\nname = \"left\"\nplane = { point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }\n";
    let pulled = format!(
        "{side}[[displacement]]\nnode_set = \"left\"\ncomponents = [\"x\"]\nfunction = [[0.0, 0.0], [1.0, -0.1]]\n"
    );
    let text = GOOD.replace("[time]", &format!("{pulled}[time]"));
    expect_error(
        "contradicting",
        &text,
        &[
            "displacement[1]",
            "displacement[0]",
            "node 1 ",
            "as 0 at t = 1, and here as -0.1",
        ],
    );
    let same = format!(
        "{side}[[displacement]]\nnode_set = \"left\"\ncomponents = [\"x\"]\nvalue = 0.0\n[[displacement]]\nnode_set = \"left\"\ndirection = [1.0, 1.0, 0.0]\nvalue = 0.0\n"
    );
    let (code, err) = run_bad(
        "same_twice",
        &GOOD.replace("[time]", &format!("{same}[time]")),
    );
    assert_eq!(code, 0, "{err}");
}

#[test]
fn inverted_element() {
    // Top and bottom corners swapped: every Jacobian is negative.
    let corners = "corners = [[0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 1.0, 1.0], [1.0, 1.0, 1.0], [1.0, 0.0, 1.0], [0.0, 0.0, 1.0]]";
    let text = GOOD.replace(
        "box = { min = [0.0, 0.0, 0.0], max = [1.0, 1.0, 1.0] }",
        corners,
    );
    expect_error("inverted", &text, &["body[0]", "element 1", "inverted"]);
}

#[test]
fn non_numeric_value() {
    expect_error(
        "non_numeric",
        &GOOD.replace("E = 1000.0", "E = \"stiff\""),
        &["invalid type: string \"stiff\"", "line"],
    );
}

#[test]
fn missing_file_and_bad_command_line() {
    let out = solver()
        .args(["run", "/nonexistent/scene.toml"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        err.contains("/nonexistent/scene.toml") && err.contains("cannot read"),
        "{err}"
    );
    let out = solver().args(["frobnicate"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("unrecognized subcommand"));
}

/// Every scene under run/ and mpi-tests/ passes `solver check` and its summary names its
/// bodies, elements and steps (the summary analysts read before a run).
#[test]
fn every_shipped_scene_passes_check() {
    fn scenes(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                scenes(&p, out);
            } else if p.extension().is_some_and(|x| x == "toml") {
                out.push(p);
            }
        }
    }
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut found = Vec::new();
    scenes(&root.join("run"), &mut found);
    scenes(&root.join("mpi-tests"), &mut found);
    found.sort();
    assert!(found.len() >= 14, "only {} scenes found", found.len());
    for p in &found {
        let out = solver().arg("check").arg(p).output().expect("solver runs");
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{}: {}",
            p.display(),
            String::from_utf8_lossy(&out.stderr)
        );
        for needle in ["bodies", "elements", "steps"] {
            assert!(
                text.contains(needle),
                "{}: summary lacks '{needle}':\n{text}",
                p.display()
            );
        }
    }
}

/// A reader that closes standard output early (`solver check scene | head -1`) ends the
/// command quietly by SIGPIPE, as other command-line tools end, not with a panic.
#[test]
fn a_closed_standard_output_is_no_panic() {
    use std::os::unix::process::ExitStatusExt;
    let mut child = solver()
        .args(["check"])
        .arg(common::repo("run/scenes/bench/block_on_block.toml"))
        .args(["--ranks", "2"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(
        out.status.signal(),
        Some(libc::SIGPIPE),
        "{:?}: {err}",
        out.status
    );
}
