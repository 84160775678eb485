//! Contact against exact answers: a frictionless block on a block (matching and
//! non-matching meshes), a block on a rigid plate with Coulomb friction (stick below the
//! limit, slip at mu N beyond it), and a block pressed then lifted off.
//!
//! Tolerances. Every scene solves with a residual tolerance of 1e-12 of the reference force
//! (the larger of the external force and the reaction norms). Where the exact answer is in
//! the finite element space, the remaining error is solver round-off:
//! - a resultant (a sum of nodal constraint forces) differs from the applied load by the
//!   sum of the residual's free components over the body, at most sqrt(number of nodes)
//!   times the residual norm: < 1e-11 of the load for these meshes, asserted at 1e-10;
//! - a stress or displacement differs by at most the condition number of the stiffness
//!   (about 1e2 to 1e3 on these few-element meshes) times the relative residual: < 1e-9,
//!   asserted at 1e-8.

use crate::common;
use common::stacked::{nodes_at_y, pressure_top, stacked};
use common::{problem, run_serial, solve};
use solver::problem::Problem;
use solver::run::GlobalState;

/// Residual tolerance of every scene below.
const TOL: f64 = 1e-12;

/// Two stacked unit cubes (`common::stacked`) of linear elastic blocks (E = 1e6, `nu`),
/// frictionless node-to-face contact, a pressure rising to `p` in one step.
fn stacked_blocks(n_lower: usize, n_upper: usize, nu: f64, p: f64) -> String {
    let material = format!("{{ model = \"linear_elastic\", E = 1.0e6, nu = {nu:?} }}");
    stacked(
        (n_lower, n_upper),
        ("small", &material),
        "node_face",
        &pressure_top(p),
        "{ end = 1.0, steps = 1 }",
    )
}

/// Tributary area of a node of a uniform n x n grid on the unit square (x, z).
fn tributary_area(x: f64, z: f64, n: usize) -> f64 {
    let h = 1.0 / n as f64;
    let w = |c: f64| {
        if c.abs() < 1e-9 || (c - 1.0).abs() < 1e-9 {
            0.5 * h
        } else {
            h
        }
    };
    w(x) * w(z)
}

/// Largest |sigma - diag(0, -p, 0)| / p over the elements of body `b`.
fn uniaxial_stress_error(p: &Problem, state: &GlobalState, b: usize, load: f64) -> f64 {
    let body = &p.mesh.bodies[b];
    let exact = [0.0, -load, 0.0, 0.0, 0.0, 0.0];
    state.stress[body.first_element..body.first_element + body.num_elements]
        .iter()
        .flat_map(|s| s.iter().zip(&exact).map(|(a, e)| (a - e).abs() / load))
        .fold(0.0, f64::max)
}

/// (total slave force in y, largest |f_y / A_trib - p| / p) over the slave nodes.
fn slave_pressure(p: &Problem, state: &GlobalState, n_upper: usize, load: f64) -> (f64, f64) {
    let slaves = nodes_at_y(p, 1, 1.0);
    assert_eq!(slaves.len(), (n_upper + 1) * (n_upper + 1));
    let mut total = 0.0;
    let mut worst: f64 = 0.0;
    for &s in &slaves {
        let f = state.contact_force[s];
        total += f[1];
        let x = p.mesh.coords[s];
        let a = tributary_area(x[0], x[2], n_upper);
        worst = worst.max((f[1] / a - load).abs() / load);
    }
    (total, worst)
}

#[test]
fn frictionless_block_on_block_matching_meshes_is_uniaxial() {
    let (nu, load, e) = (0.3, 1.0e3, 1.0e6);
    let p = problem(&stacked_blocks(3, 3, nu, load));
    let (_, state) = solve(&p);
    // Exact: uniaxial stress sigma_yy = -p in both bodies (the lateral faces are free and the
    // rollers allow the Poisson expansion, equal on both sides of the matching interface),
    // u = (nu p x / E, -p y / E, nu p z / E): trilinear, so in the element space.
    let stress_lower = uniaxial_stress_error(&p, &state, 0, load);
    let stress_upper = uniaxial_stress_error(&p, &state, 1, load);
    let mut disp: f64 = 0.0;
    for (n, x) in p.mesh.coords.iter().enumerate() {
        let exact = [nu * load * x[0] / e, -load * x[1] / e, nu * load * x[2] / e];
        for d in 0..3 {
            disp = disp.max((state.displacement[n][d] - exact[d]).abs() / (2.0 * load / e));
        }
    }
    // The applied load is p A with A = 1. With matching meshes each slave node carries the
    // consistent nodal force of the uniform pressure, p times its tributary area.
    let (total, pressure) = slave_pressure(&p, &state, 3, load);
    let total_err = (total - load).abs() / load;
    let slaves = nodes_at_y(&p, 1, 1.0);
    let all_active = slaves
        .iter()
        .all(|&s| state.constraints.iter().any(|c| c.slave as usize == s));
    println!(
        "block on block (3x3x3 / 3x3x3, nu = {nu}): max |sigma - exact| / p: lower {stress_lower:.3e}, upper {stress_upper:.3e}; max |u - exact| / |u_max| {disp:.3e}"
    );
    println!(
        "  total contact force {total:.15e} vs p A = {load:e}: rel. error {total_err:.3e}; max |f/A_trib - p| / p {pressure:.3e}; slave nodes all in contact: {all_active}"
    );
    assert!(all_active, "a slave node is not in contact");
    assert!(
        stress_lower <= 1e-8 && stress_upper <= 1e-8,
        "stress not uniaxial"
    );
    assert!(disp <= 1e-8, "displacement error {disp:e}");
    assert!(total_err <= 1e-10, "total contact force {total} vs {load}");
    assert!(
        pressure <= 1e-8,
        "contact pressure not uniform: {pressure:e}"
    );
    // Frictionless: no tangential contact force on any slave node (the contact row is along
    // the master normal, y up to the round-off of its computation).
    for &s in &slaves {
        let f = state.contact_force[s];
        assert!(
            f[0].abs() <= 1e-12 * load && f[2].abs() <= 1e-12 * load,
            "tangential force {f:?} at node {s}"
        );
    }
}

#[test]
fn frictionless_block_on_block_nonmatching_meshes_is_in_equilibrium() {
    let (nu, load) = (0.3, 1.0e3);
    let p = problem(&stacked_blocks(3, 4, nu, load));
    let (_, state) = solve(&p);
    // One-pass node-to-face contact does not pass the contact patch test on non-matching
    // meshes (the slave nodes' forces, passed to the master nodes through the face shape
    // functions, are not the master's consistent nodal forces of a uniform pressure), so the
    // pressure distribution and the stress are only reported. Global equilibrium is exact:
    // the slave forces balance the load on the upper body up to the residual.
    let (total, pressure) = slave_pressure(&p, &state, 4, load);
    let total_err = (total - load).abs() / load;
    let stress_lower = uniaxial_stress_error(&p, &state, 0, load);
    let stress_upper = uniaxial_stress_error(&p, &state, 1, load);
    let slaves = nodes_at_y(&p, 1, 1.0);
    let rms = (slaves
        .iter()
        .map(|&s| {
            let x = p.mesh.coords[s];
            let a = tributary_area(x[0], x[2], 4);
            ((state.contact_force[s][1] / a - load) / load).powi(2)
        })
        .sum::<f64>()
        / slaves.len() as f64)
        .sqrt();
    println!("block on block, non-matching (lower 3x3x3 master, upper 4x4x4 slave, nu = {nu}):");
    println!("  contact pressure f/A_trib vs p: max rel. error {pressure:.3e}, rms {rms:.3e}");
    println!(
        "  stress: max |sigma - exact| / p: lower {stress_lower:.3e}, upper {stress_upper:.3e}"
    );
    println!("  total contact force {total:.15e} vs p A = {load:e}: rel. error {total_err:.3e}");
    let mut rows: Vec<(f64, f64, f64)> = slaves
        .iter()
        .map(|&s| {
            let x = p.mesh.coords[s];
            let a = tributary_area(x[0], x[2], 4);
            (x[0], x[2], state.contact_force[s][1] / a / load)
        })
        .collect();
    rows.sort_by(|a, b| (a.1, a.0).partial_cmp(&(b.1, b.0)).unwrap());
    for z in rows.chunks(5) {
        let line: Vec<String> = z.iter().map(|r| format!("{:.6}", r.2)).collect();
        println!("  z = {:.2}: f/(A_trib p) = {}", z[0].1, line.join("  "));
    }
    assert!(total_err <= 1e-8, "total contact force {total} vs {load}");
}

/// A 4x4x4 unit block on a rigid plate (one element, every node fixed), Coulomb friction
/// mu = 0.3, nu = 0 (so the pressed state is uniaxial and the in-plane problem has no z
/// coupling). The block top: u_z = 0, u_y from 0 to -d over t in [0, 1]; then over t in
/// [1, 2] either a traction `traction` (force per area, along x) or a prescribed u_x from 0
/// to `push`.
fn block_on_plate(traction: Option<f64>, push: Option<f64>) -> String {
    let mut text = format!(
        r#"
name = "block_on_plate"
kinematics = "small"

[[body]]
name = "plate"
box = {{ min = [-0.5, -0.5, -0.5], max = [1.5, 0.0, 1.5] }}
divisions = [1, 1, 1]
material = {{ model = "linear_elastic", E = 1.0e6, nu = 0.0 }}

[[body]]
name = "block"
box = {{ min = [0.0, 0.0, 0.0], max = [1.0, 1.0, 1.0] }}
divisions = [4, 4, 4]
material = {{ model = "linear_elastic", E = 1.0e6, nu = 0.0 }}

[[node_set]]
name = "plate_all"
body = "plate"
box = {{ min = [-0.5, -0.5, -0.5], max = [1.5, 0.0, 1.5] }}

[[node_set]]
name = "block_top"
body = "block"
plane = {{ point = [0.0, 1.0, 0.0], normal = [0.0, 1.0, 0.0] }}

[[side_set]]
name = "plate_top"
body = "plate"
plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}

[[side_set]]
name = "block_bottom"
body = "block"
plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}

[[side_set]]
name = "block_top"
body = "block"
plane = {{ point = [0.0, 1.0, 0.0], normal = [0.0, 1.0, 0.0] }}

[[displacement]]
node_set = "plate_all"
components = ["x", "y", "z"]
value = 0.0

[[displacement]]
node_set = "block_top"
components = ["z"]
value = 0.0

[[displacement]]
node_set = "block_top"
components = ["y"]
function = [[0.0, 0.0], [1.0, -1.0e-3]]

[[contact]]
master = "plate_top"
slave = "block_bottom"
friction = "coulomb"
mu = 0.3

[time]
segments = [{{ end = 1.0, steps = 2 }}, {{ end = 2.0, steps = 10 }}]

[solver]
tolerance = {TOL:?}
"#
    );
    if let Some(t) = traction {
        text += &format!(
            r#"
[[traction]]
side_set = "block_top"
vector = [{t:?}, 0.0, 0.0]
function = [[0.0, 0.0], [1.0, 0.0], [2.0, 1.0]]
"#
        );
    }
    if let Some(s) = push {
        text += &format!(
            r#"
[[displacement]]
node_set = "block_top"
components = ["x"]
function = [[0.0, 0.0], [1.0, 0.0], [2.0, {s:?}]]
"#
        );
    }
    text
}

const MU: f64 = 0.3;
const PLATE_E: f64 = 1.0e6;
const PRESS: f64 = 1.0e-3;

/// (sum of slave contact forces, slave node ids) of the block-on-plate scene.
fn slave_resultant(p: &Problem, state: &GlobalState) -> ([f64; 3], Vec<usize>) {
    let slaves = nodes_at_y(p, 1, 0.0);
    assert_eq!(slaves.len(), 25);
    let mut f = [0.0; 3];
    for &s in &slaves {
        for d in 0..3 {
            f[d] += state.contact_force[s][d];
        }
    }
    (f, slaves)
}

#[test]
fn coulomb_block_sticks_below_the_friction_limit() {
    // Pressed by d = 1e-3 with nu = 0 and every slave node stuck: uniaxial, N = E d A / H
    // = 1e3 exactly (in the element space). Then a tangential force T = 0.5 mu N on the top.
    let n_exact = PLATE_E * PRESS;
    let t = 0.5 * MU * n_exact;
    let p = problem(&block_on_plate(Some(t), None));
    let (_, state) = solve(&p);
    let (f, slaves) = slave_resultant(&p, &state);
    // Stuck slave nodes are tied to their master points on the fixed plate: u = 0 up to
    // round-off of the constraint projection, measured against the pressing displacement d.
    let slip = slaves
        .iter()
        .map(|&s| {
            let u = state.displacement[s];
            u[0].hypot(u[2]) / PRESS
        })
        .fold(0.0, f64::max);
    let statuses: Vec<u8> = slaves.iter().map(|&s| state.contact_status[s]).collect();
    // The largest local tangential / (mu normal) ratio: the margin of the stick state.
    let ratio = slaves
        .iter()
        .map(|&s| {
            let c = state.contact_force[s];
            c[0].hypot(c[2]) / (MU * c[1])
        })
        .fold(0.0, f64::max);
    println!(
        "stick (T = 0.5 mu N = {t}): N = {:.15e} (exact {n_exact:e}), friction force {:.15e} (applied {t}), max |u_t| / d {slip:.3e}, max |f_t| / (mu f_n) at a node {ratio:.4}, statuses {statuses:?}",
        f[1], f[0]
    );
    // N: the uniaxial pressed state is exact, the traction adds no net normal force (the
    // shear problem is antisymmetric about x = 1/2); the friction balances T (resultants,
    // 1e-10, see the top of the file).
    assert!((f[1] - n_exact).abs() <= 1e-10 * n_exact, "N = {}", f[1]);
    assert!(
        (f[0] + t).abs() <= 1e-10 * t,
        "friction force {} vs {t}",
        f[0]
    );
    assert!(
        slip <= 1e-12,
        "a stuck slave node moved tangentially: {slip:e}"
    );
    assert!(
        statuses.iter().all(|&s| s == 1),
        "every slave node must stick: {statuses:?}"
    );
}

#[test]
fn coulomb_block_slides_at_mu_n_beyond_the_friction_limit() {
    // Pressed by d, then the top pushed along x by 5 d: the stick limit is near
    // mu N H / (G A) = 0.6 d (shear stiffness G A / H, G = E / 2), so the block slides and
    // every slave node carries mu times its normal force against the motion.
    let push = 5.0 * PRESS;
    let p = problem(&block_on_plate(None, Some(push)));
    let (_, state) = solve(&p);
    let (f, slaves) = slave_resultant(&p, &state);
    let statuses: Vec<u8> = slaves.iter().map(|&s| state.contact_status[s]).collect();
    let slide = slaves
        .iter()
        .map(|&s| state.displacement[s][0])
        .fold(f64::INFINITY, f64::min);
    let n = f[1];
    let err = (f[0] + MU * n).abs() / (MU * n);
    println!(
        "slip (top pushed {push:e}): N = {n:.15e} (pressed E d A / H = {:e}), friction force {:.15e}, mu N = {:.15e}, rel. error {err:.3e}, z force {:.3e}, slave u_x >= {slide:.4e}, statuses {statuses:?}",
        PLATE_E * PRESS,
        f[0],
        MU * n,
        f[2]
    );
    assert!(n > 0.0, "no normal force");
    assert!(
        statuses.iter().all(|&s| s == 2),
        "every slave node must slip: {statuses:?}"
    );
    assert!(slide > 0.0, "the block did not slide");
    // Each slipping node's friction force is mu times the normal force of the converged
    // model problem; the sum differs from mu N by the residual (1e-8 leaves a wide margin
    // over the 1e-10 of a resultant).
    assert!(err <= 1e-8, "friction force {} vs mu N = {}", f[0], MU * n);
    assert!(f[2].abs() <= 1e-8 * MU * n, "z friction {}", f[2]);
}

/// capture_release with 2x2x2 meshes and nu = 0.3: the upper top (u_x = u_z = 0) moves
/// down by 0.01 at t = 1 and up to +0.01 at t = 2; `steps` are the time segments.
fn lift_off(steps: &str) -> String {
    format!(
        r#"
name = "lift_off"
kinematics = "small"

[[body]]
name = "lower"
box = {{ min = [0.0, 0.0, 0.0], max = [1.0, 1.0, 1.0] }}
divisions = [2, 2, 2]
material = {{ model = "linear_elastic", E = 10.0e6, nu = 0.3 }}

[[body]]
name = "upper"
box = {{ min = [0.0, 1.0, 0.0], max = [1.0, 2.0, 1.0] }}
divisions = [2, 2, 2]
material = {{ model = "linear_elastic", E = 10.0e6, nu = 0.3 }}

[[node_set]]
name = "lower_bottom"
body = "lower"
plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}

[[node_set]]
name = "upper_top"
body = "upper"
plane = {{ point = [0.0, 2.0, 0.0], normal = [0.0, 1.0, 0.0] }}

[[side_set]]
name = "lower_top"
body = "lower"
plane = {{ point = [0.0, 1.0, 0.0], normal = [0.0, 1.0, 0.0] }}

[[side_set]]
name = "upper_bottom"
body = "upper"
plane = {{ point = [0.0, 1.0, 0.0], normal = [0.0, 1.0, 0.0] }}

[[displacement]]
node_set = "lower_bottom"
components = ["x", "y", "z"]
value = 0.0

[[displacement]]
node_set = "upper_top"
components = ["x", "z"]
value = 0.0

[[displacement]]
node_set = "upper_top"
components = ["y"]
function = [[0.0, 0.0], [1.0, -0.01], [2.0, 0.01]]

[[contact]]
master = "lower_top"
slave = "upper_bottom"
friction = "frictionless"

[time]
segments = [{steps}]

[solver]
tolerance = {TOL:?}
"#
    )
}

/// run/scenes/friction/overhang.toml: a block 1.04 wide on a plate 1 wide (every plate node
/// fixed; nu = 0, mu = 0.3): its
/// bottom edges overhang the plate's edges by 0.02, within the tangential tolerance (0.05),
/// so the bottom nodes there touch the plate's edge and stick to the point of the edge
/// their projection is clamped to. Pressed by d = 1e-3 (top: u_y = -d, u_x = u_z = 0), the
/// exact answer is uniaxial: every bottom node stays where it is (u = 0: the plate does not
/// move and a stuck node does not slide), every contact force is normal, and the normal
/// resultant is E d A / H with A = 1.04 (in the element space, so exact to round-off).
/// A stick tie that held the node on the edge point itself pulled those nodes 0.02 in x.
#[test]
fn a_node_stuck_beyond_the_edge_of_its_master_face_stays_where_it_is() {
    let text = std::fs::read_to_string(format!(
        "{}/run/scenes/friction/overhang.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .expect("the scene is in the repository");
    let p = problem(&text);
    let (_, state) = solve(&p);
    let bottom = nodes_at_y(&p, 1, 0.0);
    assert_eq!(bottom.len(), 15);
    let overhanging = bottom
        .iter()
        .filter(|&&s| p.mesh.coords[s][0] < 0.0 || p.mesh.coords[s][0] > 1.0)
        .count();
    assert_eq!(overhanging, 6, "two rows of three bottom nodes overhang");
    let statuses: Vec<u8> = bottom.iter().map(|&s| state.contact_status[s]).collect();
    assert!(
        statuses.iter().all(|&s| s == 1),
        "every bottom node must stick: {statuses:?}"
    );
    // Stuck on the fixed plate: u = 0 to round-off of the constraint projection, measured
    // against the pressing displacement d (as in coulomb_block_sticks_below_the_friction_limit).
    let moved = bottom
        .iter()
        .map(|&s| {
            let u = state.displacement[s];
            (u[0].hypot(u[1]).hypot(u[2]) / PRESS, s)
        })
        .fold((0.0, 0), |a, b| if b.0 > a.0 { b } else { a });
    assert!(
        moved.0 <= 1e-12,
        "bottom node {} at x = {} moved by {:.3e} d",
        moved.1 + 1,
        p.mesh.coords[moved.1][0],
        moved.0
    );
    // Uniaxial: N = E d A / H, the friction resultant zero (resultants, 1e-10, see the top
    // of the file).
    let mut f = [0.0; 3];
    for &s in &bottom {
        for d in 0..3 {
            f[d] += state.contact_force[s][d];
        }
    }
    let n_exact = 1.0e6 * PRESS * 1.04;
    assert!(
        (f[1] - n_exact).abs() <= 1e-10 * n_exact,
        "N = {} (exact {n_exact})",
        f[1]
    );
    assert!(
        f[0].hypot(f[2]) <= 1e-10 * n_exact,
        "tangential resultant {f:?}"
    );
}

#[test]
fn block_pressed_then_lifted_off_carries_nothing() {
    let press = "{ end = 1.0, steps = 5 }";
    let both = "{ end = 1.0, steps = 5 }, { end = 2.0, steps = 10 }";
    let pressed_problem = problem(&lift_off(press));
    let (_, pressed) = solve(&pressed_problem);
    let p = problem(&lift_off(both));
    let (summary, state) = solve(&p);
    assert_eq!(summary.steps.len(), 15);
    let slaves = nodes_at_y(&p, 1, 1.0);
    assert_eq!(slaves.len(), 9);
    let max_abs = |v: &mut dyn Iterator<Item = f64>| v.fold(0.0, |m: f64, x| m.max(x.abs()));
    let pressed_force = max_abs(&mut pressed.contact_force.iter().flatten().copied());
    let pressed_stress = max_abs(&mut pressed.stress.iter().flatten().copied());
    let pressed_total: f64 = slaves.iter().map(|&s| pressed.contact_force[s][1]).sum();
    let pressed_status: Vec<u8> = slaves.iter().map(|&s| pressed.contact_status[s]).collect();
    let force = max_abs(&mut state.contact_force.iter().flatten().copied()) / pressed_force;
    let stress = max_abs(&mut state.stress.iter().flatten().copied()) / pressed_stress;
    let statuses: Vec<u8> = slaves.iter().map(|&s| state.contact_status[s]).collect();
    // The upper body, held only at its top, translates rigidly by +0.01 (gap 0.01).
    let gap_err = slaves
        .iter()
        .map(|&s| (state.displacement[s][1] - 0.01).abs() / 0.01)
        .fold(0.0, f64::max);
    println!(
        "pressed (t = 1): total contact force {pressed_total:.6e}, max |contact force| {pressed_force:.6e}, max |stress| {pressed_stress:.6e}, statuses {pressed_status:?}"
    );
    println!(
        "lifted (t = 2): max |contact force| / pressed {force:.3e}, max |stress| / pressed {stress:.3e}, max |u_y - 0.01| / 0.01 at the slave nodes {gap_err:.3e}, statuses {statuses:?}, active constraints {}",
        state.constraints.len()
    );
    let released: Vec<usize> = summary
        .steps
        .iter()
        .filter(|r| r.contact.released > 0)
        .map(|r| r.step)
        .collect();
    println!("  steps that released slave nodes: {released:?}");
    assert!(
        pressed_status.iter().all(|&s| s == 2),
        "pressed: {pressed_status:?}"
    );
    assert!(pressed_total > 0.0);
    // After lift-off the exact contact forces and stresses are zero; the solver leaves
    // round-off of the residual tolerance (1e-12 of the largest force seen), amplified by
    // the condition number (see the top of the file): 1e-10 of the pressed values.
    assert!(force <= 1e-10, "contact force after lift-off {force:e}");
    assert!(stress <= 1e-10, "stress after lift-off {stress:e}");
    assert!(
        gap_err <= 1e-8,
        "upper body not rigidly lifted: {gap_err:e}"
    );
    assert!(
        statuses.iter().all(|&s| s == 0 || s == 3),
        "slave nodes not released: {statuses:?}"
    );
    assert!(state.constraints.is_empty(), "{:?}", state.constraints);
}

/// A block on the rigid plate of `block_on_plate`, free but for contact (no Dirichlet
/// condition on it), pressed by a pressure of 1e3 on its top (N = 1e3) and then, over
/// t in [1, 2], pushed by a traction `tx` along x on its top.
fn free_block_on_plate(divisions: usize, nu: f64, friction: &str, tx: f64) -> String {
    format!(
        r#"
name = "free_block_on_plate"
kinematics = "small"

[[body]]
name = "plate"
box = {{ min = [-0.5, -0.5, -0.5], max = [1.5, 0.0, 1.5] }}
divisions = [1, 1, 1]
material = {{ model = "linear_elastic", E = 1.0e6, nu = 0.0 }}

[[body]]
name = "block"
box = {{ min = [0.0, 0.0, 0.0], max = [1.0, 1.0, 1.0] }}
divisions = [{divisions}, {divisions}, {divisions}]
material = {{ model = "linear_elastic", E = 1.0e6, nu = {nu:?} }}

[[node_set]]
name = "plate_all"
body = "plate"
box = {{ min = [-0.5, -0.5, -0.5], max = [1.5, 0.0, 1.5] }}

[[side_set]]
name = "plate_top"
body = "plate"
plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}

[[side_set]]
name = "block_bottom"
body = "block"
plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}

[[side_set]]
name = "block_top"
body = "block"
plane = {{ point = [0.0, 1.0, 0.0], normal = [0.0, 1.0, 0.0] }}

[[displacement]]
node_set = "plate_all"
components = ["x", "y", "z"]
value = 0.0

[[pressure]]
side_set = "block_top"
function = [[0.0, 0.0], [1.0, 1.0e3]]

[[traction]]
side_set = "block_top"
vector = [{tx:?}, 0.0, 0.0]
function = [[0.0, 0.0], [1.0, 0.0], [2.0, 1.0]]

[[contact]]
master = "plate_top"
slave = "block_bottom"
{friction}

[time]
segments = [{{ end = 1.0, steps = 2 }}, {{ end = 2.0, steps = 1 }}]

[solver]
tolerance = {TOL:?}
"#
    )
}

/// A body held only by slipping nodes: after the Poisson expansion makes every bottom corner
/// slip radially, the step that adds a small sideways load starts with all four corners
/// slipping, so with friction forces as fixed loads the block would have no tangential
/// support and the model problem would be singular. Slipping nodes then carry a tangential
/// spring in the model problem (`springs`), the contact update re-sticks the corners
/// that the load unloads, and the step converges.
#[test]
fn coulomb_block_resists_a_small_tangential_load_after_radial_slip() {
    // One element, nu = 0.3: while it is pressed, the bottom's Poisson expansion gives each
    // bottom corner a radial tangential force 0.42 of its normal force, above mu = 0.3, so
    // all four slip radially (correctly). Then a traction T = 20 = mu N / 15 on the top:
    // far below the sliding limit mu N = 300, so an equilibrium exists with the block in
    // contact, and whatever the stick/slip pattern, the block is held by contact alone:
    // sum of contact forces = (-T, N, 0) exactly (resultant tolerance, here 1e-8 of N), and
    // the displacements stay of elastic size (p H / E = 1e-3; asserted below 1e-2).
    let (n, t) = (1.0e3, 20.0);
    let p = problem(&free_block_on_plate(
        1,
        0.3,
        "friction = \"coulomb\"\nmu = 0.3",
        t,
    ));
    let (summary, state) = solve(&p);
    let slaves = nodes_at_y(&p, 1, 0.0);
    let mut f = [0.0; 3];
    for &s in &slaves {
        for d in 0..3 {
            f[d] += state.contact_force[s][d];
        }
    }
    let umax = state
        .displacement
        .iter()
        .flatten()
        .fold(0.0, |m: f64, x| m.max(x.abs()));
    let last = summary.steps.last().unwrap();
    let statuses: Vec<u8> = slaves.iter().map(|&s| state.contact_status[s]).collect();
    println!(
        "radial slip then T = {t}: contact force sum {f:?} (exact [-{t}, {n}, 0]), max |u| {umax:.3e}, statuses {statuses:?}, last step residual {:.3e} / reference {:.3e}",
        last.residual, last.reference
    );
    assert!(umax <= 1e-2, "the block ran away: max |u| = {umax:e}");
    assert!(
        (f[0] + t).abs() <= 1e-8 * n && (f[1] - n).abs() <= 1e-8 * n && f[2].abs() <= 1e-8 * n,
        "contact forces {f:?} do not balance the load (-{t}, {n}, 0)"
    );
    assert!(
        statuses.iter().all(|&s| s == 1 || s == 2),
        "a slave node left contact: {statuses:?}"
    );
}

#[test]
fn frictionless_block_pushed_sideways_cannot_converge() {
    // Frictionless contact cannot resist the tangential traction: the block has no
    // equilibrium (a rigid-body mode under a net load), so the step must fail (the run
    // reports a failure, exit code 1), not converge to a runaway displacement.
    let p = problem(&free_block_on_plate(
        1,
        0.0,
        "friction = \"frictionless\"",
        100.0,
    ));
    let (summary, state) = run_serial(&p, None);
    let umax = state
        .displacement
        .iter()
        .flatten()
        .fold(0.0, |m: f64, x| m.max(x.abs()));
    for r in &summary.steps {
        println!(
            "frictionless push: step {} t = {}: residual {:.3e}, reference {:.3e}, in contact {}, released {}",
            r.step, r.time, r.residual, r.reference, r.contact.active, r.contact.released
        );
    }
    println!(
        "  failure: {:?}; max |u| at the end {umax:.3e}",
        summary.failure
    );
    assert!(
        summary.failure.is_some(),
        "a block with no equilibrium was reported converged (max |u| = {umax:e}, last reference force {:e} for a load of 1e3)",
        summary.steps.last().map_or(0.0, |r| r.reference)
    );
}

/// The block held only by slipping nodes (the test above) is kept as a scene file for the
/// multi-rank runs (mpi-tests/scenes.txt); it must be the scene tested here.
/// FRICTION_WRITE_SCENES=1 rewrites it.
#[test]
fn slipping_corners_scene_file_is_the_tested_scene() {
    let path = format!(
        "{}/run/scenes/friction/slipping_corners.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = "# A block whose four corners slip radially, then a small sideways load: held only by\n# slipping nodes when the load starts (tests/contact.rs).\n".to_string()
        + &free_block_on_plate(1, 0.3, "friction = \"coulomb\"\nmu = 0.3", 20.0)
            .replace("name = \"free_block_on_plate\"", "name = \"slipping_corners\"");
    if std::env::var_os("FRICTION_WRITE_SCENES").is_some() {
        std::fs::write(&path, &text).unwrap();
    }
    let stored = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(stored == text, "{path} differs from the tested scene");
}
