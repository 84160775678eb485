//! The nodal contact pressure of the result file (`/results/contact/pressure`) against
//! exact answers: a block pressed uniformly onto a block carries the applied pressure at
//! every slave node (matching meshes: either contact discretization, small and large
//! kinematics; non-matching meshes: mortar), nodes not in contact carry none, and a block
//! lifted off carries none. Read back from the HDF5 file.
//!
//! Tolerance: the scenes solve to a residual of 1e-12 of the reference force; a nodal
//! force differs from its exact value by at most the condition number of the stiffness
//! (1e2 to 1e3 on these meshes) times that (see tests/contact.rs): asserted at 1e-8.

use crate::common;
use common::stacked::{nodes_at_y, pressure_top, stacked, TWO_STEPS};
use common::{fresh_dir, problem, run_serial};
use solver::output::ResultFile;
use solver::problem::Problem;

/// Runs `scene` to `<dir>/<name>.h5` and returns the problem and the open result file.
fn run_to_file(name: &str, scene: &str) -> (Problem, ResultFile) {
    let dir = fresh_dir(&format!("contact-pressure-tests/{name}"));
    let p = problem(scene);
    let (summary, state) = run_serial(&p, Some(dir.join(format!("{name}.h5"))));
    if let Some(f) = &summary.failure {
        panic!("{name}: run failed: {f}");
    }
    let f = ResultFile::open(&summary.output.expect("a result file")).unwrap();
    let last = f.num_steps() - 1;
    // The file holds what the run computed.
    assert_eq!(
        f.contact_pressure(last).unwrap().as_ref(),
        Some(&state.contact_pressure)
    );
    (p, f)
}

/// Every step: each slave node's pressure is the applied one at that step (relative
/// error), and every other node's is exactly zero. Returns the largest relative error.
fn check_uniform(name: &str, p: &Problem, f: &ResultFile, load: f64) -> f64 {
    let slaves = nodes_at_y(p, 1, 1.0);
    let times = f.time().unwrap();
    let mut worst: f64 = 0.0;
    for (k, t) in times.iter().enumerate() {
        let applied = load * t;
        let pressure = f
            .contact_pressure(k)
            .unwrap()
            .expect("the file has pressures");
        let status = f.contact_status(k).unwrap();
        assert_eq!(pressure.len(), p.mesh.num_nodes());
        for (n, &v) in pressure.iter().enumerate() {
            if slaves.contains(&n) {
                assert_eq!(status[n], 2, "{name}: slave node {n} not in contact");
                worst = worst.max((v - applied).abs() / applied);
            } else {
                assert_eq!(v, 0.0, "{name}: step {k}, node {n} is not a slave node");
            }
        }
    }
    println!(
        "{name}: {} slave nodes, {} steps: max |pressure - p| / p = {worst:.3e}",
        slaves.len(),
        times.len()
    );
    worst
}

/// Uniaxial stress sigma_yy = -p in both bodies is in the element space (see
/// tests/contact.rs); with matching meshes every slave node, corners and edges included,
/// carries the consistent nodal force of the uniform pressure, p times its area.
#[test]
fn matching_blocks_carry_the_applied_pressure_for_either_discretization() {
    let load = 1.0e3;
    let elastic = r#"{ model = "linear_elastic", E = 1.0e6, nu = 0.3 }"#;
    for discretization in ["node_face", "mortar"] {
        let name = format!("small_{discretization}");
        let (p, f) = run_to_file(
            &name,
            &stacked(
                (3, 3),
                ("small", elastic),
                discretization,
                &pressure_top(load),
                TWO_STEPS,
            ),
        );
        let worst = check_uniform(&name, &p, &f, load);
        assert!(worst <= 1e-8, "{name}: {worst:e}");
    }
}

/// Non-matching meshes (lower 3 x 3 x 3 master, upper 4 x 4 x 4 slave): mortar contact
/// passes the patch test, so the slave nodes carry the consistent nodal forces of the
/// uniform pressure and the nodal pressure is exact again; node-to-face contact does not
/// (tests/contact.rs), and its nodal pressure only balances the load on the whole.
#[test]
fn nonmatching_blocks_with_mortar_contact_carry_the_applied_pressure() {
    let load = 1.0e3;
    let elastic = r#"{ model = "linear_elastic", E = 1.0e6, nu = 0.3 }"#;
    let scene = stacked(
        (3, 4),
        ("small", elastic),
        "mortar",
        &pressure_top(load),
        TWO_STEPS,
    );
    let (p, f) = run_to_file("nonmatching_mortar", &scene);
    let worst = check_uniform("nonmatching_mortar", &p, &f, load);
    assert!(worst <= 1e-8, "nonmatching_mortar: {worst:e}");
}

/// Large kinematics: the follower pressure acts on the deformed top, and the slave area is
/// the deformed one. p = E/20 stretches the blocks laterally by about 1.5 %, so measuring the
/// area in the reference configuration would be 3 % off.
#[test]
fn matching_blocks_carry_the_applied_pressure_under_large_kinematics() {
    let load = 50.0;
    let rubber = r#"{ model = "neo_hookean", E = 1000.0, nu = 0.3 }"#;
    let (p, f) = run_to_file(
        "large",
        &stacked(
            (2, 2),
            ("large", rubber),
            "node_face",
            &pressure_top(load),
            TWO_STEPS,
        ),
    );
    let last = f.num_steps() - 1;
    let u = f.displacement(last).unwrap();
    let corner = nodes_at_y(&p, 1, 1.0)
        .into_iter()
        .find(|&n| p.mesh.coords[n][0] == 1.0 && p.mesh.coords[n][2] == 1.0)
        .unwrap();
    let stretch = 1.0 + u[corner][0];
    println!("large: lateral stretch {stretch:.6}");
    assert!(stretch > 1.01, "the blocks should widen: {stretch}");
    let worst = check_uniform("large", &p, &f, load);
    assert!(worst <= 1e-8, "large: {worst:e}");
}

/// Pressed by moving the upper top down by 0.002 (uniaxial stress E 0.002 / 2 = 1000), then
/// up to +0.01: while pressed each slave node's pressure is its normal force over its area,
/// here its tributary area, and equals the uniaxial stress; once the bodies part (when the
/// top passes its start, at t = 1 + 1/6), no node has a pressure.
#[test]
fn a_block_lifted_off_has_no_contact_pressure() {
    let elastic = r#"{ model = "linear_elastic", E = 1.0e6, nu = 0.3 }"#;
    let top = r#"[[node_set]]
name = "upper_top_nodes"
body = "upper"
plane = { point = [0.0, 2.0, 0.0], normal = [0.0, 1.0, 0.0] }

[[displacement]]
node_set = "upper_top_nodes"
components = ["y"]
function = [[0.0, 0.0], [1.0, -0.002], [2.0, 0.01]]"#;
    let segments = "{ end = 1.0, steps = 2 }, { end = 2.0, steps = 2 }";
    let scene = stacked((2, 2), ("small", elastic), "node_face", top, segments);
    let (p, f) = run_to_file("lift_off", &scene);
    let slaves = nodes_at_y(&p, 1, 1.0);
    let tributary = |x: f64| if x == 0.0 || x == 1.0 { 0.25 } else { 0.5 };
    let times = f.time().unwrap();
    assert_eq!(times, [0.5, 1.0, 1.5, 2.0]);
    for (k, &t) in times.iter().enumerate() {
        let pressure = f.contact_pressure(k).unwrap().unwrap();
        let force = f.contact_force(k).unwrap();
        let status = f.contact_status(k).unwrap();
        for (n, &v) in pressure.iter().enumerate() {
            if t <= 1.0 && slaves.contains(&n) {
                let x = p.mesh.coords[n];
                let a = tributary(x[0]) * tributary(x[2]);
                let want = force[n][1] / a;
                assert!(
                    (v - want).abs() <= 1e-12 * want,
                    "node {n}, t = {t}: pressure {v} vs force / area {want}"
                );
                let exact = 1.0e6 * 0.002 * t / 2.0;
                assert!(
                    (v - exact).abs() <= 1e-8 * exact,
                    "node {n}, t = {t}: pressure {v} vs {exact}"
                );
            } else {
                assert_eq!(v, 0.0, "node {n}, t = {t}, status {}", status[n]);
            }
        }
        if t > 1.0 {
            assert!(
                slaves.iter().all(|&n| status[n] != 2),
                "t = {t}: {status:?}"
            );
        }
    }
}
