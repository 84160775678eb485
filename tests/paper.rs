//! The paper's five verification tests (section 4), run and checked against the exact
//! answers of shared/paper/scenes.md by `solver post verify` (one implementation for the
//! command, these tests and the run/paper report), plus the refinement studies the issue asks
//! to report. Run with `cargo test --release --test paper -- --nocapture` to see the numbers.

use solver::comm::SerialComm;
use solver::post::verify::{verify_file, Verification};
use solver::run::{run, GlobalState, RunOptions};
use solver::scene::parse_scene;
use solver::scene::refine::refine_scene_text;
use std::path::PathBuf;

use crate::common;
fn out_dir() -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("paper");
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn scene_text(name: &str) -> String {
    std::fs::read_to_string(format!("run/scenes/paper/{name}.toml")).unwrap()
}

/// Runs a scene (text) to a result file; returns the verification, the final state and
/// whether the run completed.
fn run_text(text: &str, file: &str) -> (Verification, GlobalState, Option<String>) {
    let problem = parse_scene(text, file, "scene").unwrap_or_else(|e| panic!("{e}"));
    let path = out_dir().join(format!("{}.h5", problem.name));
    let (summary, state) = run(
        &SerialComm,
        &problem,
        &RunOptions {
            output: Some(path.clone()),
            verbosity: 0,
            export_operator: None,
            final_state: true,
            partition: Default::default(),
        },
    )
    .expect("run starts");
    let written = summary.output.expect("a result file");
    let v = verify_file(&written).unwrap_or_else(|e| panic!("{e}"));
    println!("{}", v.render());
    (v, state, summary.failure)
}

fn run_scene(name: &str) -> (Verification, GlobalState, Option<String>) {
    run_text(&scene_text(name), &format!("run/scenes/paper/{name}.toml"))
}

fn assert_passes(v: &Verification) {
    assert!(!v.checks.is_empty(), "{}: nothing was checked", v.scene);
    for c in &v.checks {
        assert!(
            c.pass,
            "{}: {} = {:e} exceeds {:e}",
            v.scene, c.name, c.value, c.limit
        );
    }
}

fn reported(v: &Verification, name: &str) -> f64 {
    v.reported
        .iter()
        .find(|(n, _)| n.starts_with(name))
        .map(|(_, x)| *x)
        .unwrap_or(f64::NAN)
}

// Tolerances are those of the issue and scenes.md; each check's limit and why lives in
// src/post/verify.rs beside the formula it checks.

#[test]
fn bc_interaction_stick_is_exact() {
    let (v, ..) = run_scene("bc_interaction");
    assert_passes(&v);
}

#[test]
fn bc_interaction_mu_sweep_onset_of_slip() {
    let (v, ..) = run_scene("bc_interaction_mu037");
    assert_passes(&v);
    let (v, ..) = run_scene("bc_interaction_mu036");
    assert_passes(&v);
}

#[test]
fn bc_interaction_frictionless_converges_under_refinement() {
    let base = scene_text("bc_interaction_frictionless");
    let (v1, s1, f1) = run_scene("bc_interaction_frictionless");
    assert!(f1.is_none(), "{f1:?}");
    assert_passes(&v1);
    let mut profiles = vec![];
    for factor in [1u32, 2, 4] {
        let (v, s) = if factor == 1 {
            (v1.clone(), s1.clone())
        } else {
            let text = refine_scene_text(&base, factor, "bc_interaction_frictionless").unwrap();
            let (v, s, f) = run_text(&text, "refined");
            assert!(f.is_none(), "{f:?}");
            assert_passes(&v);
            (v, s)
        };
        let _ = v;
        profiles.push(interface_profile(&text_for(&base, factor), &s));
    }
    // U_x(s) at the coarse mesh's interface stations, on meshes h, h/2, h/4.
    let d = |a: &Vec<(f64, f64)>, b: &Vec<(f64, f64)>| -> f64 {
        a.iter()
            .map(|&(s, u)| (u - lookup(b, s)).abs())
            .fold(0.0, f64::max)
    };
    let scale = profiles[2].iter().map(|p| p.1.abs()).fold(0.0, f64::max);
    let d12 = d(&profiles[0], &profiles[1]) / scale;
    let d24 = d(&profiles[1], &profiles[2]) / scale;
    println!("frictionless U_x(s): max difference h vs h/2 = {d12:.4e}, h/2 vs h/4 = {d24:.4e} (relative to max |U_x| = {scale:.4e})");
    for (s, u) in &profiles[0] {
        println!(
            "  s = {s:.4}  U_x(h) = {u:.6e}  U_x(h/2) = {:.6e}  U_x(h/4) = {:.6e}",
            lookup(&profiles[1], *s),
            lookup(&profiles[2], *s)
        );
    }
    // Convergence: the differences shrink as the mesh is refined.
    assert!(
        d24 < d12,
        "the U_x(s) profile does not converge: {d12:e} then {d24:e}"
    );
}

fn text_for(base: &str, factor: u32) -> String {
    if factor == 1 {
        base.to_string()
    } else {
        refine_scene_text(base, factor, "s").unwrap()
    }
}

/// (s, U_x) along the slave interface, sorted by s; s = x / cos(20 deg).
fn interface_profile(text: &str, state: &GlobalState) -> Vec<(f64, f64)> {
    let p = parse_scene(text, "t", "t").unwrap();
    let set = p.node_set("interface").expect("interface node set");
    let mut out: Vec<(f64, f64)> = set
        .nodes
        .iter()
        .filter(|&&n| p.mesh.coords[n as usize][2] == 0.0)
        .map(|&n| {
            (
                p.mesh.coords[n as usize][0] / 20f64.to_radians().cos(),
                state.displacement[n as usize][0],
            )
        })
        .collect();
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out
}

fn lookup(profile: &[(f64, f64)], s: f64) -> f64 {
    profile
        .iter()
        .find(|p| (p.0 - s).abs() < 1e-9)
        .map(|p| p.1)
        .expect("station present on the finer mesh")
}

/// Paper 4.2. With smoothing the node at the V's bottom has the facets' mean normal there;
/// without it the paper's node flips between the facets, and here, back on the facet it
/// left, it is held at their shared edge by both (a fold). Both pass the symmetry checks
/// (1e-10, src/post/verify.rs), and they are the same answer: at the V's bottom the mean
/// normal and the fold's two rows hold the node at the same point, the other slave nodes
/// lie on flat faces. The 1e-10 of the largest displacement between them is a hundred
/// times the solver's tolerance (1e-12, the scenes' own); measured 1.9e-15 at the last step.
#[test]
fn normal_smoothing_keeps_the_v_bottom_symmetric() {
    let (on, on_state, f) = run_scene("normal_smoothing");
    assert!(f.is_none(), "{f:?}");
    assert_passes(&on);
    let (off, off_state, f_off) = run_scene("normal_smoothing_off");
    assert!(f_off.is_none(), "{f_off:?}");
    assert_passes(&off);
    let (diff, scale) = common::max_displacement_difference(&off_state, &on_state);
    println!(
        "contact updates: smoothing on {}, off {}; max difference {:.1e} of max |u| {scale}",
        reported(&on, "contact updates"),
        reported(&off, "contact updates"),
        diff / scale
    );
    assert!(diff <= 1e-10 * scale, "{diff:e} of {scale:e}");
}

#[test]
fn capture_and_release() {
    let (v, _, f) = run_scene("capture_release");
    assert!(f.is_none(), "{f:?}");
    assert_passes(&v);
}

/// The bar at mesh `factor` (1 = the paper's 40 x 2). `loading_only` stops at t = 2 (where
/// the difference from the 1-D formula is measured) and uses a residual tolerance of 1e-8
/// instead of 1e-10, which leaves that difference unchanged to 5 digits at h/2 (3.6714e-2
/// both ways, checked when this was written) and makes the h/4 run affordable.
fn stick_slip_difference(factor: u32, loading_only: bool) -> f64 {
    let mut text = text_for(&scene_text("stick_slip"), factor);
    if loading_only {
        let mut doc: toml::Table = text.parse().unwrap();
        let time = doc.get_mut("time").unwrap().as_table_mut().unwrap();
        time.get_mut("segments")
            .unwrap()
            .as_array_mut()
            .unwrap()
            .truncate(2);
        doc.get_mut("solver")
            .unwrap()
            .as_table_mut()
            .unwrap()
            .insert("tolerance".into(), toml::Value::Float(1e-8));
        text = toml::to_string(&doc).unwrap();
    }
    let (v, _, f) = run_text(&text, "run/scenes/paper/stick_slip.toml");
    assert!(f.is_none(), "{f:?}");
    assert_passes(&v);
    reported(&v, "difference from the 1-D formula at t = 2")
}

#[test]
fn stick_slip_bar_against_the_one_dimensional_theory() {
    let diffs = [
        stick_slip_difference(1, false),
        stick_slip_difference(2, false),
    ];
    println!(
        "stick/slip: cross-section average vs the 1-D formula at t = 2, / u_max: h {:.4}, h/2 {:.4}",
        diffs[0], diffs[1]
    );
    // The difference approaches where a converged 3-D solution sits (3-4% of u_max, up to
    // 4.7% at mid-height; scenes.md) and stays under the 5% bar.
    assert!(diffs.iter().all(|&d| d < 0.05), "{diffs:?}");
}

/// The h, h/2, h/4 study: about 5 minutes on this 2-core machine (the h/4 bar needs some
/// 50,000 CG iterations with the nodal block-Jacobi preconditioner), too long for every CI
/// run. Run it with `cargo test --release --test paper -- --ignored --nocapture`.
#[test]
#[ignore = "slow (about 5 minutes): run with -- --ignored"]
fn stick_slip_difference_settles_under_refinement() {
    let diffs = [
        stick_slip_difference(1, false),
        stick_slip_difference(2, false),
        stick_slip_difference(4, true),
    ];
    println!(
        "stick/slip: cross-section average vs the 1-D formula at t = 2, / u_max: h {:.4}, h/2 {:.4}, h/4 {:.4}",
        diffs[0], diffs[1], diffs[2]
    );
    // Settles, does not grow: successive changes shrink, and the limit stays under 5%.
    assert!(
        (diffs[2] - diffs[1]).abs() < (diffs[1] - diffs[0]).abs(),
        "{diffs:?}"
    );
    assert!(diffs.iter().all(|&d| d < 0.05), "{diffs:?}");
}

#[test]
fn multi_constraint_patch_test() {
    let (v, state, f) = run_scene("multi_constraint");
    assert!(f.is_none(), "{f:?}");
    assert_passes(&v);
    // Node (1,1,1) of the shaded block (body b010, the last body; node 198) carries three
    // active constraints on three different master bodies.
    let p = parse_scene(&scene_text("multi_constraint"), "t", "t").unwrap();
    let shaded = p.mesh.bodies.iter().position(|b| b.name == "b010").unwrap();
    let b = &p.mesh.bodies[shaded];
    let corner = (b.first_node..b.first_node + b.num_nodes)
        .find(|&n| p.mesh.coords[n].iter().all(|&x| (x - 1.0).abs() < 1e-12))
        .unwrap() as u32;
    let at: Vec<_> = state
        .constraints
        .iter()
        .filter(|c| c.slave == corner)
        .collect();
    let mut masters: Vec<usize> = at.iter().map(|c| c.master_body).collect();
    masters.sort_unstable();
    masters.dedup();
    println!(
        "node {} (1,1,1): {} constraints, master bodies {:?}, normal forces {:?}",
        corner + 1,
        at.len(),
        masters
            .iter()
            .map(|&m| p.mesh.bodies[m].name.clone())
            .collect::<Vec<_>>(),
        at.iter().map(|c| c.normal_force).collect::<Vec<_>>()
    );
    assert_eq!(at.len(), 3);
    assert_eq!(masters.len(), 3);
    assert!(at.iter().all(|c| c.normal_force > 0.0));
    let (nm, _, f) = run_scene("multi_constraint_nonmatching");
    assert!(f.is_none(), "{f:?}");
    println!(
        "non-matching variant: displacement error {:.4e}, stress error {:.4e} (one-pass node-to-face contact does not pass the patch test)",
        reported(&nm, "max |u - exact|"),
        reported(&nm, "max |sigma - exact|")
    );
}
