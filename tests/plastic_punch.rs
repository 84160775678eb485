//! A rigid flat punch pressed into an elastic-perfectly plastic block in plane strain: the
//! mean punch pressure approaches Prandtl's limit (2 + pi) sigma_y / sqrt(3) under
//! refinement. Half the problem (symmetry at x = 0), one element through the thickness with
//! u_z = 0, the base and the far side held. The punch is a rigid plate (every node
//! prescribed) in frictionless contact with the block (a smooth punch: the limit is the same
//! for a rough one); the same punch as a prescribed displacement of the block's top nodes
//! gives the same curve, and that one is compared with CalculiX.

use crate::common;
use partition::Decomposition;
use solver::comm::SerialComm;
use solver::mesh::local::LocalMesh;
use solver::solver::Stepper;

use common::punch::{self, A, L};

const E: f64 = 200e3;
const NU: f64 = 0.3;
const SY: f64 = 250.0;

fn scene(n: usize, depth: f64, steps: usize, volumetric: &str) -> String {
    scene_with(
        n,
        depth,
        steps,
        &format!("volumetric = \"{volumetric}\""),
        SY,
    )
}

/// The prescribed punch with the block's element line (`volumetric = ...` or
/// `integration = ...`) and yield stress given.
fn scene_with(n: usize, depth: f64, steps: usize, element: &str, sy: f64) -> String {
    format!(
        "{}{}[time]\nsegments = [{{ end = 1.0, steps = {steps} }}]\n[solver]\ntolerance = 1e-8\nmax_iterations = 200000\n",
        punch::block(n, E, NU, sy, element),
        punch::pressed(depth)
    )
}

/// Mean punch pressure after each step (the punch nodes' reaction over the punch area) and
/// the CG iterations.
pub fn punch_curve(
    n: usize,
    depth: f64,
    steps: usize,
    volumetric: &str,
) -> (Vec<(f64, f64)>, CgCount) {
    curve_of(&scene(n, depth, steps, volumetric), n, depth)
}

/// Mean punch pressure after each step of the prescribed-punch scene `text` at mesh `n`
/// pressed `depth`, and the CG iterations.
fn curve_of(text: &str, n: usize, depth: f64) -> (Vec<(f64, f64)>, CgCount) {
    let p = common::problem(text);
    let comm = SerialComm;
    let d = Decomposition::partition(p.mesh.num_nodes(), &p.mesh.elements, 1).unwrap();
    let local = LocalMesh::new(&p.mesh, &d, 0);
    let mut st = Stepper::new(&comm, &p, &local, &p.mesh).expect("the stepper is built");
    let punch = &p.node_set("punch").unwrap().nodes;
    let thickness = L / n as f64;
    let mut out = Vec::new();
    let mut cg = CgCount::default();
    for (k, &t) in p.step_times.iter().enumerate() {
        let its = st
            .advance(k + 1, t)
            .unwrap_or_else(|f| panic!("n = {n}: {f}"))
            .cg_iterations;
        cg.total += its;
        cg.largest = cg.largest.max(its);
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
    let (c, cg) = punch_curve(n, depth * A, 10, "mean_dilatation");
    for (d, p) in c {
        println!("n = {n}: depth {d:.4}: mean pressure {p:.2}");
    }
    println!("{cg} CG iterations");
}

/// The issue-47 punch (sigma_y = 100, pressed 0.03 a in 50 steps) at mesh `n` with the
/// block's element line `element`: the pressure at 20, 40, 60, 80 and 100% of the depth.
fn levels(n: usize, element: &str) -> [f64; 5] {
    const SY47: f64 = 100.0;
    let (depth, steps) = (0.03 * A, 50);
    let t0 = std::time::Instant::now();
    let mut text = scene_with(n, depth, steps, element, SY47);
    if let Ok(pc) = std::env::var("PUNCH_PRECONDITIONER") {
        text = text.replace(
            "[solver]\n",
            &format!("[solver]\npreconditioner = \"{pc}\"\n"),
        );
    }
    let (c, cg) = curve_of(&text, n, depth);
    let out: [f64; 5] = std::array::from_fn(|k| c[10 * k + 9].1);
    println!(
        "n = {n}: [{element}] pressure at 20/40/60/80/100% of the depth: {out:.2?}; Prandtl {:.2}; {cg} CG iterations, {:.1} s",
        (2.0 + std::f64::consts::PI) * SY47 / 3f64.sqrt(),
        t0.elapsed().as_secs_f64()
    );
    out
}

/// The punch with `mean` elements against `full` + `mean_dilatation` on the same mesh
/// (issue 47): the `mean` pressure levels off (it rises by less than 1% over the last 40%
/// of the depth; with the elastic hourglass stiffness it rose 3.7% at n = 20 and kept
/// rising), and at every one of the five depths from 40% on it is within 2% of the other.
fn mean_levels_off_beside_mean_dilatation(n: usize) {
    // PUNCH_HOURGLASS = "\"assumed_strain\"" (or a coefficient) measures another control
    // than a plastic body's default.
    let mean = match std::env::var("PUNCH_HOURGLASS") {
        Ok(h) => levels(n, &format!("integration = \"mean\"\nhourglass = {h}")),
        Err(_) => levels(n, "integration = \"mean\""),
    };
    let bar = levels(n, "volumetric = \"mean_dilatation\"");
    let rise = mean[4] / mean[2] - 1.0;
    println!(
        "n = {n}: mean rises {:.3}% over the last 40%; mean / mean_dilatation at 40-100%: {:.4?}",
        100.0 * rise,
        std::array::from_fn::<f64, 4, _>(|k| mean[k + 1] / bar[k + 1])
    );
    assert!(
        rise.abs() < 0.01,
        "n = {n}: the mean punch still rises {rise}"
    );
    for k in 1..5 {
        let d = mean[k] / bar[k] - 1.0;
        assert!(
            d.abs() < 0.02,
            "n = {n}, at {}%: {} vs {}",
            20 * (k + 1),
            mean[k],
            bar[k]
        );
    }
}

#[test]
fn mean_punch_levels_off_at_n20() {
    mean_levels_off_beside_mean_dilatation(20);
}

#[test]
#[ignore = "slow: PUNCH_N=40 cargo test --release --test plastic_punch mean_punch_levels_off_at -- --ignored --nocapture; n = 80: PUNCH_N=80 PUNCH_PRECONDITIONER=tangent (the full tangent preconditioner; the default one did not finish in 45 minutes)"]
fn mean_punch_levels_off_at() {
    let n: usize = std::env::var("PUNCH_N").map_or(40, |v| v.parse().unwrap());
    mean_levels_off_beside_mean_dilatation(n);
}

#[test]
fn flat_punch_approaches_prandtl() {
    let prandtl = (2.0 + std::f64::consts::PI) * SY / 3f64.sqrt();
    let mut last = 0.0;
    for n in [12, 24, 48] {
        let (curve, cg) = punch_curve(n, 0.06 * A, 12, "mean_dilatation");
        let pm = curve.last().unwrap().1;
        println!(
            "n = {n}: rigid smooth punch (prescribed): mean pressure at depth {:.3} a: {pm:.2} = {:.4} of Prandtl's {prandtl:.2}; {cg} CG iterations",
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
#[ignore = "measurement: PUNCH_N=24 PUNCH_MU=0 [PUNCH_DISCRETIZATION=mortar] cargo test --release --test plastic_punch contact_curve_at -- --ignored --nocapture"]
fn contact_curve_at() {
    let n: usize = std::env::var("PUNCH_N").map_or(24, |v| v.parse().unwrap());
    let mu: f64 = std::env::var("PUNCH_MU").map_or(0.0, |v| v.parse().unwrap());
    let prandtl = (2.0 + std::f64::consts::PI) * SY / 3f64.sqrt();
    let disc = std::env::var("PUNCH_DISCRETIZATION").unwrap_or("node_face".into());
    let (c, cg) = contact_curve_mu(n, 0.06 * A, 12, mu, &disc);
    for (d, pm) in &c {
        println!(
            "depth {d:.4}: mean pressure {pm:.3} = {:.4} of Prandtl",
            pm / prandtl
        );
    }
    println!(
        "n = {n}, mu = {mu}, {disc}: rigid punch in contact: {:.2} = {:.4} of Prandtl; {cg} CG iterations",
        c.last().unwrap().1,
        c.last().unwrap().1 / prandtl
    );
}

#[test]
fn contact_punch_converges_to_prandtl_at_first_order() {
    // Through node-to-face contact the block's top nodes slide outward under the smooth
    // punch, and the one at the punch's edge slides past it and is released: the strip
    // between the last node in contact and the edge carries nothing, an error of order h
    // below the limit (the prescribed punch, whose nodes stay under it, errs above). So the
    // contact punch approaches Prandtl's pressure from below with its error halving at each
    // refinement: measured 0.8263, 0.9144, 0.9577 of it at n = 24, 48, 96 (errors 17.4%,
    // 8.6%, 4.2%; n = 96 takes 96 s, `contact_punch_at_n96_is_within_5_percent`).
    // Here n = 24 and 48: both below the limit, the ratio of their errors that of first
    // order (2; 1.6 to 2.5 leaves room for the higher-order terms at these coarse meshes),
    // and the error that ratio predicts at n = 96 within the issue's 5%.
    let prandtl = (2.0 + std::f64::consts::PI) * SY / 3f64.sqrt();
    // Each increment within CG_PER_INCREMENT iterations: the first, where the punch's
    // edge first yields the block, is the hardest (26 at n = 48).
    let error = |n: usize| {
        let (c, cg) = contact_curve(n, 0.06 * A, 12, "node_face");
        let p = c.last().unwrap().1;
        println!(
            "n = {n}: contact punch {:.4} of Prandtl; CG {cg}",
            p / prandtl
        );
        assert!(cg.largest <= CG_PER_INCREMENT, "n = {n}: CG {cg}");
        1.0 - p / prandtl
    };
    let (e24, e48) = (error(24), error(48));
    assert!(e24 > 0.0 && e48 > 0.0, "{e24} {e48}");
    let ratio = e24 / e48;
    assert!((1.6..=2.5).contains(&ratio), "error ratio {ratio}");
    let predicted = e48 / ratio;
    println!("error ratio {ratio:.3}; predicted error at n = 96: {predicted:.4}");
    assert!(predicted < 0.05, "{predicted}");
}

#[test]
#[ignore = "slow (96 s on one rank): cargo test --release --test plastic_punch contact_punch_at_n96 -- --ignored --nocapture"]
fn contact_punch_at_n96_is_within_5_percent() {
    // The finest of the three meshes of `contact_punch_converges_to_prandtl_at_first_order`
    // (measured 0.9577 of Prandtl, 571 CG iterations, at most 107 in an increment).
    let prandtl = (2.0 + std::f64::consts::PI) * SY / 3f64.sqrt();
    let (c, cg) = contact_curve(96, 0.06 * A, 12, "node_face");
    let p = c.last().unwrap().1;
    println!(
        "n = 96: contact punch {:.4} of Prandtl; {cg} CG iterations",
        p / prandtl
    );
    assert!((p - prandtl).abs() < 0.05 * prandtl, "{p} vs {prandtl}");
    assert!(cg.largest <= CG_PER_INCREMENT, "CG {cg}");
}

#[test]
#[ignore = "measurement"]
fn plane_strain_compression_limit() {
    // One element, u_z = 0, compressed in y with x free: sigma_yy -> 2 sigma_y / sqrt(3).
    let text = scene(1, 0.01, 4, "mean_dilatation")
        .replace(&format!("max = [{A}, {L}, "), &format!("max = [{L}, {L}, "));
    let p = common::problem(&text);
    let comm = SerialComm;
    let d = Decomposition::partition(p.mesh.num_nodes(), &p.mesh.elements, 1).unwrap();
    let local = LocalMesh::new(&p.mesh, &d, 0);
    let mut st = Stepper::new(&comm, &p, &local, &p.mesh).expect("the stepper is built");
    for (k, &t) in p.step_times.iter().enumerate() {
        st.advance(k + 1, t).unwrap();
        let s = st.assembly().owned_stresses(&st.u).unwrap()[0];
        println!("t {t}: stress {s:?}, 2k = {}", 2.0 * SY / 3f64.sqrt());
    }
}

/// The punch scene (full integration, C3D8's) as a CalculiX deck: the same nodes and
/// elements (ids = ours, the same corner order), *ELASTIC and *PLASTIC (perfect), the
/// prescribed displacements ramped over one static step in fixed increments, and the
/// punch set's total reaction printed at every increment.
fn calculix_deck(n: usize, depth: f64, steps: usize) -> String {
    use std::fmt::Write;
    let p = common::problem(&scene(n, depth, steps, "standard"));
    let mut w = String::from(
        "*HEADING\nflat punch, elastic-perfectly plastic, plane strain\n*NODE, NSET=NALL\n",
    );
    for (i, x) in p.mesh.coords.iter().enumerate() {
        let _ = writeln!(w, "{}, {:.12e}, {:.12e}, {:.12e}", i + 1, x[0], x[1], x[2]);
    }
    let _ = writeln!(w, "*ELEMENT, TYPE=C3D8, ELSET=EALL");
    for (e, el) in p.mesh.elements.iter().enumerate() {
        let ids: Vec<String> = el.iter().map(|&k| (k + 1).to_string()).collect();
        let _ = writeln!(w, "{}, {}", e + 1, ids.join(", "));
    }
    for set in ["x0", "bottom", "right", "punch"] {
        let _ = writeln!(w, "*NSET, NSET=N{}", set.to_uppercase());
        for chunk in p.node_set(set).unwrap().nodes.chunks(8) {
            let ids: Vec<String> = chunk.iter().map(|&k| (k + 1).to_string()).collect();
            let _ = writeln!(w, "{},", ids.join(", "));
        }
    }
    let _ = writeln!(
        w,
        "*MATERIAL, NAME=STEEL\n*ELASTIC\n{E:.6e}, {NU}\n*PLASTIC\n{SY:.6e}, 0.0"
    );
    let _ = writeln!(w, "*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL");
    let _ = writeln!(
        w,
        "*STEP, INC=10000\n*STATIC, DIRECT\n{:.12e}, 1.0",
        1.0 / steps as f64
    );
    let _ = writeln!(
        w,
        "*BOUNDARY\nNALL, 3, 3, 0.0\nNX0, 1, 1, 0.0\nNBOTTOM, 1, 2, 0.0\nNRIGHT, 1, 1, 0.0"
    );
    let _ = writeln!(w, "NPUNCH, 2, 2, {:.12e}", -depth);
    let _ = writeln!(w, "*NODE PRINT, NSET=NPUNCH, TOTALS=ONLY\nRF\n*END STEP");
    w
}

/// Every "total force (fx,fy,fz) for set NPUNCH and time t" of a .dat file: (t, fy).
fn ccx_totals(dat: &str) -> Vec<(f64, f64)> {
    let lines: Vec<&str> = dat.lines().collect();
    let mut out = Vec::new();
    for (i, l) in lines.iter().enumerate() {
        if let Some(rest) = l.split("for set NPUNCH and time").nth(1) {
            let t: f64 = rest.trim().parse().unwrap();
            let v: Vec<f64> = lines[i + 1..]
                .iter()
                .find(|l| !l.trim().is_empty())
                .unwrap()
                .split_whitespace()
                .filter_map(|x| x.parse().ok())
                .collect();
            out.push((t, v[1]));
        }
    }
    out
}

#[test]
fn flat_punch_beside_calculix() {
    let (n, depth, steps) = (12, 0.06 * A, 12);
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("plastic-punch-ccx");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("punch.inp"), calculix_deck(n, depth, steps)).unwrap();
    let out = std::process::Command::new("ccx")
        .arg("punch")
        .current_dir(&dir)
        .output()
        .expect("ccx (calculix-ccx; run/setup --calculix) runs");
    let log = String::from_utf8_lossy(&out.stdout);
    assert!(!log.contains("*ERROR"), "{log}");
    let dat = std::fs::read_to_string(dir.join("punch.dat")).unwrap();
    let ccx = ccx_totals(&dat);
    assert_eq!(ccx.len(), steps, "{dat}");
    let (ours, _) = punch_curve(n, depth, steps, "standard");
    let thickness = L / n as f64;
    let mut worst = 0.0f64;
    for ((d, p), (t, fy)) in ours.iter().zip(&ccx) {
        let pc = -fy / (A * thickness);
        let rel = (p - pc).abs() / pc.abs();
        worst = worst.max(rel);
        println!(
            "depth {d:.4} (ccx time {t:.4}): mean punch pressure ours {p:.3}, CalculiX {pc:.3}, difference {:.3}%",
            100.0 * rel
        );
    }
    // The issue's acceptance: force-displacement curves within 2 %.
    assert!(worst < 0.02, "worst difference {worst}");
}

/// The punch as a body: a rigid plate (every node prescribed) whose bottom faces are the
/// master surface of a frictionless contact with the block's top, pressed down by `depth`.
fn contact_scene(n: usize, depth: f64, steps: usize, mu: f64, disc: &str) -> String {
    let mut friction = if mu > 0.0 {
        format!("friction = \"coulomb\"\nmu = {mu}")
    } else {
        String::new()
    };
    friction = format!("discretization = \"{disc}\"\n{friction}");
    let t = L / n as f64;
    let m = (A / t).round() as usize;
    format!(
        r#"
kinematics = "small"
[[body]]
name = "block"
box = {{ min = [0.0, 0.0, 0.0], max = [{L}, {L}, {t}] }}
divisions = [{n}, {n}, 1]
material = {{ model = "j2_plastic", E = {E}, nu = {NU}, yield_stress = {SY} }}
volumetric = "mean_dilatation"
[[body]]
name = "punch"
box = {{ min = [0.0, {L}, 0.0], max = [{A}, {top}, {t}] }}
divisions = [{m}, 1, 1]
material = {{ model = "linear_elastic", E = {E}, nu = {NU} }}
[[node_set]]
name = "block_all"
body = "block"
box = {{ min = [0.0, 0.0, 0.0], max = [{L}, {L}, {t}] }}
[[node_set]]
name = "punch"
body = "punch"
box = {{ min = [0.0, {L}, 0.0], max = [{A}, {top}, {t}] }}
[[node_set]]
name = "x0"
body = "block"
plane = {{ point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}
[[node_set]]
name = "bottom"
plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}
[[node_set]]
name = "right"
plane = {{ point = [{L}, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}
[[side_set]]
name = "punch_bottom"
body = "punch"
plane = {{ point = [0.0, {L}, 0.0], normal = [0.0, 1.0, 0.0] }}
[[side_set]]
name = "block_top"
body = "block"
plane = {{ point = [0.0, {L}, 0.0], normal = [0.0, 1.0, 0.0] }}
[[contact]]
master = "punch_bottom"
slave = "block_top"
{friction}
[[displacement]]
node_set = "block_all"
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
components = ["x", "z"]
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
        top = L + t,
        d = -depth
    )
}

/// CG iterations of a run: in all, and the most in one increment.
#[derive(Default, Clone, Copy)]
pub struct CgCount {
    pub total: u64,
    pub largest: u64,
}

impl std::fmt::Display for CgCount {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} (at most {} in an increment)",
            self.total, self.largest
        )
    }
}

/// The CG iterations an increment may take at most (issue 46's bound for plastic bodies).
const CG_PER_INCREMENT: u64 = 200;

/// Mean pressure on the punch from the block's contact forces after each step, and the CG
/// iterations.
fn contact_curve(n: usize, depth: f64, steps: usize, disc: &str) -> (Vec<(f64, f64)>, CgCount) {
    contact_curve_mu(n, depth, steps, 0.0, disc)
}

fn contact_curve_mu(
    n: usize,
    depth: f64,
    steps: usize,
    mu: f64,
    disc: &str,
) -> (Vec<(f64, f64)>, CgCount) {
    let p = common::problem(&contact_scene(n, depth, steps, mu, disc));
    let comm = SerialComm;
    let d = Decomposition::partition(p.mesh.num_nodes(), &p.mesh.elements, 1).unwrap();
    let local = LocalMesh::new(&p.mesh, &d, 0);
    let mut st = Stepper::new(&comm, &p, &local, &p.mesh).expect("the stepper is built");
    // The block's top nodes under the punch: the internal force they carry is the contact
    // force (the punch moves rigidly, so its own internal force is zero).
    let block = &p.mesh.bodies[0];
    let punch: Vec<u32> = (block.first_node..block.first_node + block.num_nodes)
        .filter(|&g| {
            let x = p.mesh.coords[g];
            // Every top node: those not in contact carry no internal force at equilibrium
            // (to the residual), and a mortar tie may hold a node just beyond the edge.
            (x[1] - L).abs() < 1e-9
        })
        .map(|g| g as u32)
        .collect();
    let thickness = L / n as f64;
    let mut out = Vec::new();
    let mut cg = CgCount::default();
    for (k, &t) in p.step_times.iter().enumerate() {
        let its = st
            .advance(k + 1, t)
            .unwrap_or_else(|f| panic!("n = {n}: {f}"))
            .cg_iterations;
        cg.total += its;
        cg.largest = cg.largest.max(its);
        let (fi, _) = st.forces();
        let force: f64 = punch
            .iter()
            .map(|&g| fi[local.local_node(g).unwrap()][1])
            .sum();
        out.push((depth * t, -force / (A * thickness)));
    }
    (out, cg)
}

/// The punch through contact against the prescribed punch at `n`: (worst relative
/// difference of the curves, contact punch / Prandtl at depth 0.06 a).
fn contact_against_prescribed(n: usize, disc: &str) -> (f64, f64) {
    let prandtl = (2.0 + std::f64::consts::PI) * SY / 3f64.sqrt();
    let (c, cg_c) = contact_curve(n, 0.06 * A, 12, disc);
    let (p, cg_p) = punch_curve(n, 0.06 * A, 12, "mean_dilatation");
    let mut worst = 0.0f64;
    for ((d, pc), (_, pp)) in c.iter().zip(&p) {
        worst = worst.max((pc - pp).abs() / pp);
        println!("depth {d:.4}: contact punch ({disc}) {pc:.3}, prescribed punch {pp:.3}");
    }
    let ratio = c.last().unwrap().1 / prandtl;
    println!(
        "n = {n}, {disc}: contact punch {ratio:.4} of Prandtl at depth 0.06 a; curves differ by {worst:.2e} at most; CG {cg_c} (contact) vs {cg_p}",
    );
    (worst, ratio)
}

#[test]
fn contact_punch_matches_the_prescribed_punch() {
    // A rigid frictionless punch through contact: on matching meshes the slave nodes under
    // it move with it, which is the prescribed (smooth) punch; the curves agree to the
    // solver tolerance. Both stop at a residual of 1e-8 of the reference force (measured
    // difference 2e-9); 1e-6 leaves margin for the different paths (contact updates) the
    // two take to the same discrete answer.
    let (worst, _) = contact_against_prescribed(12, "node_face");
    assert!(worst < 1e-6, "{worst}");
}

#[test]
fn mortar_contact_punch_matches_the_prescribed_punch_at_n24() {
    // At n = 24 node-to-face contact loses the block's top nodes at the punch's edge (they
    // slide past it and are released, and the strip between the last node in contact and
    // the edge carries nothing: 0.826 of Prandtl against the prescribed punch's 1.077).
    // Mortar ties integrate over the slave faces the punch covers, so the node at the
    // edge keeps its share: the contact punch is the prescribed punch, to the same 1e-6.
    let (worst, _) = contact_against_prescribed(24, "mortar");
    assert!(worst < 1e-6, "{worst}");
}

/// The comment lines at the top of the contact punch scenes in `run/scenes/plasticity/`.
fn contact_scene_header(n: usize) -> String {
    format!(
        "# The contact punch of tests/plastic_punch.rs (`contact_scene`) at n = {n}: a linear elastic\n\
         # punch body (every node prescribed) pressed 0.06 into an elastic-perfectly plastic block\n\
         # (sigma_y = 250, full + mean_dilatation) through frictionless node-to-face contact, 12\n\
         # steps. Run by `run/bench --plasticity`. Below this header: the text the test generates\n\
         # (`contact_scene_files_are_the_generated_ones` checks it; PUNCH_WRITE_SCENES=1 rewrites).\n"
    )
}

#[test]
fn contact_scene_files_are_the_generated_ones() {
    for n in [48, 96] {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join(format!("run/scenes/plasticity/contact_punch_{n}.toml"));
        let text = format!(
            "{}{}",
            contact_scene_header(n),
            contact_scene(n, 0.06 * A, 12, 0.0, "node_face")
        );
        if std::env::var_os("PUNCH_WRITE_SCENES").is_some() {
            std::fs::write(&path, &text).unwrap();
        }
        let file = std::fs::read_to_string(&path).unwrap();
        assert!(
            file == text,
            "{} differs from contact_scene({n})",
            path.display()
        );
    }
}
