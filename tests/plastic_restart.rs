//! Restart mid-yield: a plastic run killed after a step in which elements are yielding and
//! continued with `solver run --restart` ends bitwise identical to an uninterrupted run (the
//! restart file carries the committed integration-point history).

use std::path::{Path, PathBuf};

use crate::common;
use common::{fresh_dir, repo, restart, solver};

fn dir(name: &str) -> PathBuf {
    fresh_dir(&format!("plastic-restart-{name}"))
}

fn killed_and_restarted_is_identical(scene: &str, kill_after: usize) {
    let scene = repo(scene).display().to_string();
    let name = Path::new(&scene)
        .file_stem()
        .unwrap()
        .to_string_lossy()
        .to_string();
    let (full, report) =
        restart::killed_and_restarted_is_identical(&scene, &dir(&name), kill_after);
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

#[test]
fn plastic_indent_with_the_full_tangent_restarts_bitwise() {
    // The factor is built at every increment's first model problem from that state (and
    // kept within the increment while its unknowns fit), so a restart repeats the
    // uninterrupted run's factors.
    killed_and_restarted_is_identical("mpi-tests/plastic_indent_tangent.toml", 3);
}

#[test]
fn plastic_indent_by_newton_restarts_bitwise() {
    killed_and_restarted_is_identical("mpi-tests/plastic_indent_newton.toml", 3);
}

#[test]
fn plastic_indent_with_mean_elements_killed_mid_yield_restarts_bitwise() {
    // The hourglass state of the plastic one-point elements is committed history too.
    killed_and_restarted_is_identical("mpi-tests/plastic_indent_mean.toml", 3);
}

#[test]
fn bolted_clamp_killed_while_slipping_restarts_bitwise() {
    // Plastic plates with friction: the coupled (friction) solves keep the full tangent
    // within an increment, never across one, so a restart repeats the run. Killed after
    // step 3 of 12: the head is pressed on, the upper plate yielding under its edges (it
    // first yields in step 2) and most of the contact nodes slipping.
    killed_and_restarted_is_identical("run/examples/bolted_clamp.toml", 3);
}

#[test]
fn a_plastic_tet10_cube_restarts_bitwise() {
    // Composite tetrahedra, small kinematics, the full tangent from their assembled
    // consistent tangents: the history of their four points per element is committed.
    killed_and_restarted_is_identical("mpi-tests/tet_punch.toml", 3);
}

#[test]
fn a_tet10_cube_under_large_kinematics_restarts_bitwise() {
    killed_and_restarted_is_identical("mpi-tests/tet_cube.toml", 2);
}
