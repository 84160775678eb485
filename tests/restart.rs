//! Restart: a run killed after a step and continued with `solver run --restart` ends
//! bitwise identical to an uninterrupted run; a restart file of another scene is refused.

use std::path::PathBuf;

use crate::common;
use common::{fresh_dir, paper_scene, repo, restart, solver};

fn dir(name: &str) -> PathBuf {
    fresh_dir(&format!("restart-{name}"))
}

/// Runs the scene uninterrupted, then killed after `kill_after` steps and restarted from
/// the `.tmp` file the killed run left, and demands bitwise-identical results (`solver post
/// compare` with its default tolerance 0: every dataset but wall times).
fn killed_and_restarted_is_identical(name: &str, kill_after: usize) {
    restart::killed_and_restarted_is_identical(&paper_scene(name), &dir(name), kill_after);
}

/// The log (`-v`) of an uninterrupted run of `scene`, which must succeed.
fn logged_run(scene: &std::path::Path, d: &std::path::Path) -> String {
    let log = solver()
        .args(["-v", "run"])
        .arg(scene)
        .arg("-o")
        .arg(d.join("logged.h5"))
        .output()
        .unwrap();
    assert!(log.status.success());
    String::from_utf8_lossy(&log.stderr).into_owned()
}

#[test]
fn stick_slip_mortar_killed_after_step_20_restarts_bitwise() {
    // Mortar friction: the restart state carries the ties (weights, normals, the offsets
    // sticking nodes are held at) besides the constraints.
    killed_and_restarted_is_identical("stick_slip_mortar", 20);
}

#[test]
fn bc_interaction_mu036_mortar_killed_after_step_5_restarts_bitwise() {
    // Mortar ties of slipping nodes, refreshed at every update, carried across the kill.
    killed_and_restarted_is_identical("bc_interaction_mu036_mortar", 5);
}

#[test]
fn stick_slip_killed_after_step_20_restarts_bitwise() {
    // Friction: the restart state carries stick/slip modes, friction forces and the
    // predictor's previous displacement.
    killed_and_restarted_is_identical("stick_slip", 20);
}

#[test]
fn capture_release_killed_after_step_23_restarts_bitwise() {
    // Contact released and captured again after the restart.
    killed_and_restarted_is_identical("capture_release", 23);
}

#[test]
fn normal_smoothing_off_killed_after_step_4_restarts_bitwise() {
    // Nodes 15 and 16 held at the V's bottom edge by both facets (a fold) from the first
    // step on: the restart state carries the second facet, its normal, the edge and the
    // two facets' forces (the fold words of contact/codec.rs).
    killed_and_restarted_is_identical("normal_smoothing_off", 4);
}

#[test]
fn overhang_killed_after_step_1_restarts_bitwise() {
    // run/scenes/friction/overhang.toml: six bottom nodes stick beyond the edges of the
    // plate's faces, held at their offsets; the restart state carries the offsets (the
    // longer layout of contact/codec.rs). Read back without them, the restarted run pulls
    // those nodes onto the edges and differs.
    let scene = format!(
        "{}/run/scenes/friction/overhang.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    restart::killed_and_restarted_is_identical(&scene, &dir("overhang"), 1);
}

#[test]
fn a_restart_file_of_another_scene_is_refused() {
    let d = dir("other");
    let bar = d.join("bar.h5");
    let s = solver()
        .args(["-q", "run"])
        .arg(format!(
            "{}/run/examples/bar.toml",
            env!("CARGO_MANIFEST_DIR")
        ))
        .arg("-o")
        .arg(&bar)
        .status()
        .unwrap();
    assert!(s.success());
    let out = solver()
        .args(["run", &paper_scene("capture_release"), "--restart"])
        .arg(&bar)
        .arg("-o")
        .arg(d.join("x.h5"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("written by a different scene"), "{err}");
    assert!(!d.join("x.h5").exists() && !d.join("x.h5.tmp").exists());
}

/// A run continued from a file written before the contact pressure was recorded (here: the
/// killed run's file with that dataset removed) writes none either, says so, and is
/// otherwise bitwise the uninterrupted run.
#[test]
fn a_restart_from_a_file_without_contact_pressure_writes_none() {
    let d = dir("no_pressure");
    let scene = paper_scene("capture_release");
    let (full, cut) = (d.join("full.h5"), d.join("cut.h5"));
    let s = solver()
        .args(["-q", "run", &scene, "-o"])
        .arg(&full)
        .status()
        .unwrap();
    assert!(s.success());
    let s = solver()
        .args(["-q", "run", &scene, "-o"])
        .arg(&cut)
        .env("SOLVER_TEST_ABORT_AFTER_STEP", "23")
        .status()
        .unwrap();
    assert!(!s.success(), "the killed run must not exit 0");
    let tmp = d.join("cut.h5.tmp");
    hdf5::File::open_rw(&tmp)
        .unwrap()
        .unlink("/results/contact/pressure")
        .unwrap();
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
        log.contains("continuing from step 23 ") && log.contains("has no contact pressure"),
        "{log}"
    );
    let f = solver::output::ResultFile::open(&cut).unwrap();
    assert!(!f.has_contact_pressure());
    assert_eq!(f.num_steps(), 50);
    let (same, report) = restart::post_compare(&full, &cut);
    assert!(same, "results differ:\n{report}");
    assert!(
        report.contains("bitwise identical")
            && report.contains("only in a: /results/contact/pressure"),
        "{report}"
    );
}

#[test]
fn a_run_whose_preconditioner_switched_restarts_bitwise() {
    // The block on block at n = 20 (18522 nodes): under `auto`, Jacobi with multilevel on
    // standby; its first model problem reaches 300 CG iterations and multilevel takes over
    // for the rest of the run. The restart file records the switch, so step 2 of the
    // continued run is solved with multilevel as in the uninterrupted run.
    let d = dir("switched");
    let base = std::fs::read_to_string(format!(
        "{}/run/scenes/bench/block_on_block.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    assert_eq!(base.matches("divisions = [10, 10, 10]").count(), 2);
    let scene = d.join("block_on_block_n20.toml");
    std::fs::write(
        &scene,
        base.replace("divisions = [10, 10, 10]", "divisions = [20, 20, 20]"),
    )
    .unwrap();
    // The uninterrupted run does switch (else this test would not test the switch).
    let text = logged_run(&scene, &d);
    assert!(
        text.contains("switched to the multilevel preconditioner"),
        "{text}"
    );
    restart::killed_and_restarted_is_identical(scene.to_str().unwrap(), &d, 1);
}

#[test]
fn a_run_that_kept_its_multilevel_hierarchy_restarts_bitwise() {
    // The paper's stick/slip bar at 80 x 4 x 1 (auto: multilevel, the bar being held by
    // contact alone). While the bar is squeezed (steps 1-20) every node sticks and the
    // constrained operator is the same bit for bit at every increment: the hierarchy built
    // at step 1 serves to step 20 and is not built again. Killed after step 10, the
    // continued run builds it at step 11 from that increment's own constraint set, which
    // must give the very hierarchy the uninterrupted run kept.
    let d = dir("kept_hierarchy");
    let base = std::fs::read_to_string(paper_scene("stick_slip")).unwrap();
    assert_eq!(base.matches("divisions = [40, 2, 1]").count(), 1);
    assert_eq!(base.matches("divisions = [10, 1, 1]").count(), 2);
    let scene = d.join("stick_slip_80x4.toml");
    std::fs::write(
        &scene,
        base.replace("divisions = [40, 2, 1]", "divisions = [80, 4, 1]")
            .replace("divisions = [10, 1, 1]", "divisions = [20, 1, 1]"),
    )
    .unwrap();
    let text = logged_run(&scene, &d);
    assert!(text.contains("preconditioner: multilevel"), "{text}");
    // Built once for the squeeze (the next build comes when the bar begins to slip, in
    // step 21 or later), so the kill below falls between two uses of a kept hierarchy.
    let builds: Vec<&str> = text.lines().filter(|l| l.contains("(build ")).collect();
    assert!(builds[0].contains("(build 1: first use"), "{text}");
    let second = text.find("(build 2: ").expect("a second build");
    let before = &text[..second];
    assert!(
        before.contains("step 20/60"),
        "the hierarchy was built again before step 21:\n{text}"
    );
    assert!(builds.len() < 60, "{} builds in 60 steps", builds.len());
    restart::killed_and_restarted_is_identical(scene.to_str().unwrap(), &d, 10);
    // Killed while the bar slips: the hierarchy built at step 29 (its contact rows fell
    // by more than a tenth) is kept by steps 30 to 35 on constraint sets that differ
    // from its own, so the continued run must build it from the rows the restart file
    // keeps (built from step 31's own rows, the results differ).
    let d = dir("kept_hierarchy_slipping");
    restart::killed_and_restarted_is_identical(scene.to_str().unwrap(), &d, 30);
}

/// A mixed mesh: a tet10 cube on a hex8 cube through mortar contact under large kinematics
/// (the tet faces' sub-triangles the slave), killed after its first of two steps.
#[test]
fn a_tet_on_hex_contact_run_restarts_bitwise() {
    let scene = repo("mpi-tests/tet_on_hex_mortar.toml")
        .display()
        .to_string();
    restart::killed_and_restarted_is_identical(&scene, &dir("tet_on_hex_mortar"), 1);
}

#[test]
fn a_hierarchy_kept_across_increments_is_rebuilt_from_the_restart_file() {
    // The block on block with the multilevel preconditioner (mpi-tests' scene, n = 10):
    // the contact ties' weights move a little from step 1 to step 2 (so the constrained
    // operator differs and its fingerprint too), their master faces do not, and step 2
    // keeps the hierarchy step 1 built. The continued run holds no hierarchy; it must
    // build it from the rows step 1 built it on, which the restart file keeps (built
    // from step 2's own rows instead, the results differed by up to 3e-14 of the
    // displacement and 2.8e-10 of the stress).
    let d = dir("kept_across_increments");
    let scene = repo("mpi-tests/block_on_block_multilevel.toml");
    let text = logged_run(&scene, &d);
    assert!(
        text.contains("multilevel builds 1 (kept at 0 new increments)")
            && text.contains("multilevel builds 0 (kept at 1 new increments)"),
        "{text}"
    );
    let (full, _) = restart::killed_and_restarted_is_identical(scene.to_str().unwrap(), &d, 1);
    let f = hdf5::File::open(&full).unwrap();
    assert!(f.link_exists("/restart/slot1/hierarchy"));
    // Words that do not parse (a node count with no nodes after it), written with a valid
    // checksum: refused by name, not misread and not a panic.
    let tmp = d.join("cut.h5.tmp");
    let ds = hdf5::File::open_rw(&tmp)
        .unwrap()
        .dataset("/restart/slot1/hierarchy")
        .unwrap();
    ds.resize((2,)).unwrap();
    ds.write_raw(&[1.0, 5.0]).unwrap();
    drop(ds);
    let out = solver()
        .args(["run", scene.to_str().unwrap(), "--restart"])
        .arg(&tmp)
        .arg("-o")
        .arg(d.join("refused.h5"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("the restart state's preconditioner rows (dataset `hierarchy`) do not fit"),
        "{err}"
    );
}
