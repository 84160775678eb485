//! Coulomb friction where the motion along the master is prescribed: an elastic block on a
//! rigid base inclined at PHI, pressed by a vertical traction on its top, then pushed up the
//! slope, either by a prescribed u_x on its rear face (whose bottom nodes are slave nodes of
//! the base, so the prescribed motion drives them along it) or by a rigid pusher body
//! through frictionless contact. Every slave node slides up the slope, so by global
//! equilibrium (W the vertical load, N the total normal force, F = mu N the friction):
//!   N = W / (cos PHI - mu sin PHI),  push P = W (sin PHI + mu cos PHI) / (cos PHI - mu sin PHI),
//! and the friction force is mu N down the slope.
//!
//! Tolerances. Each scene solves to a residual of 1e-12 of the reference force; a resultant
//! (a sum of nodal forces) then differs from its exact value by at most sqrt(number of
//! nodes) times the residual, below 1e-10 of the load on these meshes (at most 700 nodes).
//! A slipping node's friction force is mu times the normal force of the previous model
//! problem; the last model problem needs no CG iteration, so the two differ by at most the
//! residual tolerance: the sum of friction forces is mu N to about 1e-12 of N. Both are
//! asserted at the acceptance tolerance 1e-8 of the load, well above that round-off.

use crate::common;
use common::{problem, solve};
use solver::problem::Problem;
use solver::run::GlobalState;

/// Slope of the base (degrees), friction coefficient, block length along the slope, height,
/// depth, vertical traction on the top, final push.
const PHI_DEG: f64 = 5.0;
const MU: f64 = 0.3;
const L: f64 = 2.0;
const H: f64 = 1.0;
const D: f64 = 0.2;
const P_TOP: f64 = 1.0e3;
const PUSH: f64 = 2.0e-3;

/// How the block is pushed.
#[derive(Clone, Copy, PartialEq)]
pub enum Push {
    /// u_x prescribed on the whole rear face (its bottom nodes are slave nodes).
    Prescribed,
    /// A rigid pusher body moved by u_x, touching the rear face through frictionless contact.
    Pusher,
}

/// The scene: block `nx` x `ny` x 1 elements (body 0), base (body 1), and for `Push::Pusher`
/// the pusher (body 2). Time 0-1: the traction; 1-2: the push, in two steps.
pub fn scene(nx: usize, ny: usize, push: Push) -> String {
    let (s, c) = PHI_DEG.to_radians().sin_cos();
    let (xe, ye) = (L * c, L * s);
    let (b0x, b0y) = (-0.3 * c, -0.3 * s);
    let (b1x, b1y) = ((L + 0.3) * c, (L + 0.3) * s);
    let block = corners([[0.0, 0.0], [xe, ye], [xe, ye + H], [0.0, H]]);
    let base = corners([[b0x, b0y - 0.5], [b1x, b1y - 0.5], [b1x, b1y], [b0x, b0y]]);
    let mut text = format!(
        r#"
name = "pushed_block"
kinematics = "small"

[[body]]
name = "block"
corners = [{block}]
divisions = [{nx}, {ny}, 1]
material = {{ model = "linear_elastic", E = 1.0e7, nu = 0.3 }}

[[body]]
name = "base"
corners = [{base}]
divisions = [{nb}, 1, 1]
material = {{ model = "linear_elastic", E = 1.0e7, nu = 0.3 }}

[[node_set]]
name = "base_all"
body = "base"
box = {{ min = [-10.0, -10.0, -10.0], max = [10.0, 10.0, 10.0] }}

[[node_set]]
name = "block_all"
body = "block"
box = {{ min = [-10.0, -10.0, -10.0], max = [10.0, 10.0, 10.0] }}

[[side_set]]
name = "base_top"
body = "base"
plane = {{ point = [0.0, 0.0, 0.0], normal = [{ns:?}, {c:?}, 0.0] }}

[[side_set]]
name = "block_bottom"
body = "block"
plane = {{ point = [0.0, 0.0, 0.0], normal = [{ns:?}, {c:?}, 0.0] }}

[[side_set]]
name = "block_top"
body = "block"
plane = {{ point = [0.0, {H:?}, 0.0], normal = [{ns:?}, {c:?}, 0.0] }}

[[displacement]]
node_set = "base_all"
components = ["x", "y", "z"]
value = 0.0

[[displacement]]
node_set = "block_all"
components = ["z"]
value = 0.0

[[traction]]
side_set = "block_top"
vector = [0.0, {mp:?}, 0.0]
function = [[0.0, 0.0], [1.0, 1.0], [2.0, 1.0]]

[[contact]]
master = "base_top"
slave = "block_bottom"
friction = "coulomb"
mu = {MU:?}

[time]
segments = [{{ end = 1.0, steps = 1 }}, {{ end = 2.0, steps = 2 }}]

[solver]
tolerance = 1e-12
"#,
        nb = 2 * nx,
        ns = -s,
        mp = -P_TOP,
    );
    match push {
        Push::Prescribed => text.push_str(&prescribed_push()),
        Push::Pusher => text.push_str(&pusher(ny)),
    }
    text
}

/// The 8 corners of a prism of depth D over the quadrilateral `p` (x, y), as scene text.
fn corners(p: [[f64; 2]; 4]) -> String {
    let mut out = Vec::new();
    for z in [0.0, D] {
        for q in p {
            out.push(format!("[{:?}, {:?}, {z:?}]", q[0], q[1]));
        }
    }
    out.join(", ")
}

/// `Push::Prescribed`: u_x prescribed on the block's rear face from t = 1.
fn prescribed_push() -> String {
    format!(
        r#"
[[node_set]]
name = "block_rear"
body = "block"
plane = {{ point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}

[[displacement]]
node_set = "block_rear"
components = ["x"]
function = [[0.0, 0.0], [1.0, 0.0], [2.0, {PUSH:?}]]
"#
    )
}

/// `Push::Pusher`: the pusher body (1 x `ny` x 1 elements), moved by u_x from t = 1,
/// touching the block's rear face through frictionless contact.
fn pusher(ny: usize) -> String {
    let pusher = corners([[-0.2, 0.0], [0.0, 0.0], [0.0, H], [-0.2, H]]);
    format!(
        r#"
[[body]]
name = "pusher"
corners = [{pusher}]
divisions = [1, {ny}, 1]
material = {{ model = "linear_elastic", E = 1.0e7, nu = 0.3 }}

[[node_set]]
name = "pusher_all"
body = "pusher"
box = {{ min = [-10.0, -10.0, -10.0], max = [10.0, 10.0, 10.0] }}

[[side_set]]
name = "pusher_front"
body = "pusher"
plane = {{ point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}

[[side_set]]
name = "block_rear"
body = "block"
plane = {{ point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}

[[displacement]]
node_set = "pusher_all"
components = ["y", "z"]
value = 0.0

[[displacement]]
node_set = "pusher_all"
components = ["x"]
function = [[0.0, 0.0], [1.0, 0.0], [2.0, {PUSH:?}]]

[[contact]]
master = "pusher_front"
slave = "block_rear"
friction = "frictionless"
"#
    )
}

/// Totals over the base contact: (normal force N, friction vector on the block, push P),
/// and the status of every base slave node.
fn totals(p: &Problem, state: &GlobalState, nx: usize, ny: usize) -> (f64, [f64; 3], f64, Vec<u8>) {
    let (s, c) = PHI_DEG.to_radians().sin_cos();
    let n = [-s, c, 0.0];
    let block_nodes = 2 * (nx + 1) * (ny + 1);
    // Normal force and contact force of the base pair (pair 0); a node also touching the
    // pusher (pair 1) has the pusher's normal force taken out of its contact force.
    let mut normal = 0.0;
    let mut force = [0.0; 3];
    let mut push = 0.0;
    let mut statuses = Vec::new();
    for a in &state.constraints {
        let f = state.contact_force[a.slave as usize];
        if a.pair == 0 {
            assert_eq!(a.master_body, 1);
            normal += a.normal_force;
            for d in 0..3 {
                force[d] += f[d];
            }
            statuses.push(state.contact_status[a.slave as usize]);
        } else {
            push += a.normal_force * a.normal[0];
            if state
                .constraints
                .iter()
                .any(|b| b.pair == 0 && b.slave == a.slave)
            {
                for d in 0..3 {
                    force[d] -= a.normal_force * a.normal[d];
                }
            }
        }
    }
    // The prescribed push: the x reactions on the block's nodes.
    if p.contacts.len() == 1 {
        push = state.reaction[..block_nodes].iter().map(|r| r[0]).sum();
    }
    let friction: Vec<f64> = (0..3).map(|d| force[d] - normal * n[d]).collect();
    (
        normal,
        [friction[0], friction[1], friction[2]],
        push,
        statuses,
    )
}

fn check(nx: usize, ny: usize, push: Push) {
    check_text(nx, ny, &scene(nx, ny, push));
}

/// The scene with the block/base pair switched to mortar contact (the base is meshed
/// 2 nx along a longer slope: the meshes do not match).
fn check_mortar(nx: usize, ny: usize, push: Push) {
    let text = scene(nx, ny, push).replace(
        "friction = \"coulomb\"",
        "discretization = \"mortar\"\nfriction = \"coulomb\"",
    );
    assert!(text.contains("mortar"));
    check_text(nx, ny, &text);
}

fn check_text(nx: usize, ny: usize, text: &str) {
    let p = problem(text);
    let (_, state) = solve(&p);
    let (s, c) = PHI_DEG.to_radians().sin_cos();
    let w = P_TOP * L * D;
    let n_exact = w / (c - MU * s);
    let p_exact = w * (s + MU * c) / (c - MU * s);
    let (normal, friction, pushed, statuses) = totals(&p, &state, nx, ny);
    let down = [-c, -s, 0.0];
    let along: f64 = (0..3).map(|d| friction[d] * down[d]).sum();
    let across: f64 = (0..3)
        .map(|d| (friction[d] - along * down[d]).powi(2))
        .sum::<f64>()
        .sqrt();
    println!(
        "{nx} x {ny}: N {normal:.12e} (exact {n_exact:.12e}), friction down the slope {along:.12e} (mu N {:.12e}), across {across:.3e}, push {pushed:.12e} (exact {p_exact:.12e}), statuses {statuses:?}",
        MU * normal
    );
    assert_eq!(
        statuses.len(),
        2 * (nx + 1),
        "every bottom node is in contact"
    );
    assert!(
        statuses.iter().all(|&st| st == 2),
        "a sliding node does not report slip: {statuses:?}"
    );
    let tol = 1e-8 * w;
    assert!(
        (along - MU * normal).abs() <= tol,
        "friction {along} vs mu N {}",
        MU * normal
    );
    assert!(across <= tol, "friction not along the slope: {friction:?}");
    assert!((normal - n_exact).abs() <= tol, "N {normal} vs {n_exact}");
    assert!(
        (pushed - p_exact).abs() <= tol,
        "push {pushed} vs {p_exact}"
    );
}

#[test]
fn prescribed_push_slides_with_friction_coarse() {
    check(10, 5, Push::Prescribed);
}

#[test]
fn prescribed_push_slides_with_friction_fine() {
    check(20, 10, Push::Prescribed);
}

#[test]
fn pusher_body_slides_the_block_with_friction_coarse() {
    check(10, 5, Push::Pusher);
}

#[test]
fn pusher_body_slides_the_block_with_friction_fine() {
    check(20, 10, Push::Pusher);
}

#[test]
fn mortar_prescribed_push_slides_with_friction() {
    check_mortar(10, 5, Push::Prescribed);
}

#[test]
fn mortar_pusher_body_slides_the_block_with_friction() {
    check_mortar(10, 5, Push::Pusher);
}

/// The coarse scenes are kept as files for the multi-rank runs (mpi-tests/scenes.txt); they
/// must be the scenes tested here. FRICTION_WRITE_SCENES=1 rewrites them.
#[test]
fn scene_files_are_the_tested_scenes() {
    for (push, name) in [
        (Push::Prescribed, "pushed_block_prescribed"),
        (Push::Pusher, "pushed_block_pusher"),
    ] {
        let path = format!(
            "{}/run/scenes/friction/{name}.toml",
            env!("CARGO_MANIFEST_DIR")
        );
        let header = format!(
            "# The block pushed up a slope with Coulomb friction (tests/friction_dirichlet.rs, 10 x 5),\n# the push {}.\n",
            if push == Push::Prescribed {
                "prescribed on the rear face"
            } else {
                "by a rigid pusher through frictionless contact"
            }
        );
        let text = header
            + &scene(10, 5, push).replace("name = \"pushed_block\"", &format!("name = \"{name}\""));
        if std::env::var_os("FRICTION_WRITE_SCENES").is_some() {
            std::fs::create_dir_all(std::path::Path::new(&path).parent().unwrap()).unwrap();
            std::fs::write(&path, &text).unwrap();
        }
        let stored = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(stored == text, "{path} differs from the tested scene");
    }
}
