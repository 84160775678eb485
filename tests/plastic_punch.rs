//! A rigid flat punch pressed into an elastic-perfectly plastic block in plane strain: the
//! mean punch pressure approaches Prandtl's limit (2 + pi) sigma_y / sqrt(3) under
//! refinement. Half the problem (symmetry at x = 0), one element through the thickness with
//! u_z = 0; the punch is a prescribed vertical displacement of the top nodes with x <= a
//! (a smooth punch: the limit is the same for a rough one).

mod common;

use partition::Decomposition;
use solver::comm::SerialComm;
use solver::mesh::local::LocalMesh;
use solver::solver::Stepper;

const E: f64 = 200e3;
const NU: f64 = 0.3;
const SY: f64 = 250.0;
/// Half-width of the punch; the block is 6 a wide and 6 a deep.
const A: f64 = 1.0;
const L: f64 = 6.0;

fn scene(n: usize, depth: f64, steps: usize) -> String {
    let t = L / n as f64;
    format!(
        r#"
kinematics = "small"
[[body]]
name = "block"
box = {{ min = [0.0, 0.0, 0.0], max = [{L}, {L}, {t}] }}
divisions = [{n}, {n}, 1]
material = {{ model = "j2_plastic", E = {E}, nu = {NU}, yield_stress = {SY} }}
volumetric = "mean_dilatation"
[[node_set]]
name = "all"
box = {{ min = [0.0, 0.0, 0.0], max = [{L}, {L}, {t}] }}
[[node_set]]
name = "x0"
plane = {{ point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}
[[node_set]]
name = "bottom"
plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}
[[node_set]]
name = "right"
plane = {{ point = [{L}, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}
[[node_set]]
name = "punch"
box = {{ min = [0.0, {L}, 0.0], max = [{A}, {L}, {t}] }}
[[displacement]]
node_set = "all"
components = ["z"]
value = 0.0
[[displacement]]
node_set = "x0"
components = ["x"]
value = 0.0
[[displacement]]
node_set = "bottom"
components = ["x", "y"]
value = 0.0
[[displacement]]
node_set = "right"
components = ["x"]
value = 0.0
[[displacement]]
node_set = "punch"
components = ["y"]
function = [[0.0, 0.0], [1.0, {d}]]
[time]
segments = [{{ end = 1.0, steps = {steps} }}]
[solver]
tolerance = 1e-8
max_iterations = 200000
"#,
        d = -depth
    )
}

/// Mean punch pressure after each step (the punch nodes' reaction over the punch area) and
/// the CG iterations.
pub fn punch_curve(n: usize, depth: f64, steps: usize) -> (Vec<(f64, f64)>, u64) {
    let p = common::problem(&scene(n, depth, steps));
    let comm = SerialComm;
    let d = Decomposition::partition(p.mesh.num_nodes(), &p.mesh.elements, 1).unwrap();
    let local = LocalMesh::new(&p.mesh, &d, 0);
    let mut st = Stepper::new(&comm, &p, &local);
    let punch = &p.node_set("punch").unwrap().nodes;
    let thickness = L / n as f64;
    let mut out = Vec::new();
    let mut cg = 0;
    for (k, &t) in p.step_times.iter().enumerate() {
        cg += st
            .advance(k + 1, t)
            .unwrap_or_else(|f| panic!("n = {n}: {f}"))
            .cg_iterations;
        let (fi, _) = st.forces();
        let force: f64 = punch
            .iter()
            .map(|&g| fi[local.local_node(g).unwrap()][1])
            .sum();
        out.push((depth * t, -force / (A * thickness)));
    }
    (out, cg)
}

#[test]
#[ignore = "measurement: cargo test --release --test plastic_punch curve -- --ignored --nocapture"]
fn curve() {
    let n: usize = std::env::var("PUNCH_N").map_or(24, |v| v.parse().unwrap());
    let depth: f64 = std::env::var("PUNCH_DEPTH").map_or(0.1, |v| v.parse().unwrap());
    let (c, cg) = punch_curve(n, depth * A, 10);
    for (d, p) in c {
        println!("n = {n}: depth {d:.4}: mean pressure {p:.2}");
    }
    println!("{cg} CG iterations");
}

#[test]
fn flat_punch_approaches_prandtl() {
    let prandtl = (2.0 + std::f64::consts::PI) * SY / 3f64.sqrt();
    let mut last = 0.0;
    for n in [12, 24, 48] {
        let (curve, cg) = punch_curve(n, 0.06 * A, 12);
        let pm = curve.last().unwrap().1;
        println!(
            "n = {n}: mean punch pressure at depth {:.3} a: {pm:.2} = {:.4} of Prandtl's {prandtl:.2}; {cg} CG iterations",
            curve.last().unwrap().0,
            pm / prandtl
        );
        last = pm;
    }
    // The issue's acceptance: within 5 % at the finest mesh.
    assert!(
        (last - prandtl).abs() < 0.05 * prandtl,
        "{last} vs {prandtl}"
    );
}

#[test]
#[ignore = "measurement"]
fn plane_strain_compression_limit() {
    // One element, u_z = 0, compressed in y with x free: sigma_yy -> 2 sigma_y / sqrt(3).
    let text =
        scene(1, 0.01, 4).replace(&format!("max = [{A}, {L}, "), &format!("max = [{L}, {L}, "));
    let p = common::problem(&text);
    let comm = SerialComm;
    let d = Decomposition::partition(p.mesh.num_nodes(), &p.mesh.elements, 1).unwrap();
    let local = LocalMesh::new(&p.mesh, &d, 0);
    let mut st = Stepper::new(&comm, &p, &local);
    for (k, &t) in p.step_times.iter().enumerate() {
        st.advance(k + 1, t).unwrap();
        let s = st.assembly().owned_stresses(&st.u).unwrap()[0];
        println!("t {t}: stress {s:?}, 2k = {}", 2.0 * SY / 3f64.sqrt());
    }
}
