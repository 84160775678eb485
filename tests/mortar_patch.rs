//! Contact patch tests on non-matching meshes, node-to-face against mortar contact.
//!
//! Frictionless contact, small kinematics, linear elastic bodies under a uniform pressure p
//! on their tops. Each case has an exact uniform solution in the finite element space
//! (displacements linear in x, y, z), which a contact discretization that passes the patch
//! test reproduces to solver round-off however the interface meshes meet:
//! - `stack` and `arrangement` (z vertical): uniaxial stress sigma_zz = -p, every other
//!   component 0, u = (nu p x / E, nu p y / E, -p z / E);
//! - the paper's `multi_constraint_nonmatching` (y vertical, laterally confined): the
//!   exact answer and its error measures are those of `solver post verify`
//!   (src/post/verify.rs).
//!
//! Each case runs with `discretization = "node_face"` and `"mortar"`. Node-to-face contact
//! transfers the slave forces to the master nodes at single points, which is not the
//! consistent load of a uniform pressure on a non-matching master mesh: it does not pass
//! (errors of a few percent, printed, not asserted). Mortar contact weights each slave
//! node's gap and force over the slave surface against the overlapping master faces and
//! must pass: stress and displacement errors <= 1e-8.
//!
//! Tolerance. Every scene solves to a residual of 1e-12 of the reference force (as in
//! tests/contact.rs); the stress and displacement errors are then round-off amplified by
//! the stiffness' condition number (1e2 to 1e3 on these meshes of a few dozen elements):
//! < 1e-9, asserted at 1e-8. A resultant (sum of nodal contact forces over one interface)
//! differs from the load by at most sqrt(number of nodes) times the residual, asserted at
//! 1e-10 for both discretizations (node-to-face contact too balances the load exactly).
//!
//! Each case runs both discretizations and prints them side by side
//! (`cargo test --release --test mortar_patch -- --nocapture`); the patch test is asserted
//! for mortar only (node-to-face is known not to pass it on non-matching meshes).

use crate::common;
use std::fmt::Write;

use common::{problem, solve};
use solver::comm::SerialComm;
use solver::post::verify::verify_file;
use solver::problem::{Discretization, Problem};
use solver::run::{run, GlobalState, RunOptions};
use solver::scene::parse_scene;

const E: f64 = 1.0e6;
const NU: f64 = 0.3;
/// The pressure on the tops.
const P: f64 = 1.0e3;
/// Residual tolerance of every scene below (see the top of the file).
const TOL: f64 = 1e-12;
/// The patch test's bar for the stress and displacement errors (see the top of the file).
const PATCH: f64 = 1e-8;

const NODE_FACE: &str = "node_face";
const MORTAR: &str = "mortar";

/// Errors of a run against the exact answer.
#[derive(Clone, Copy, Debug)]
struct Errors {
    /// max |sigma - exact| / p over the elements and components.
    stress: f64,
    /// max |u - exact| over the nodes and components, over the largest exact component.
    displacement: f64,
    /// Largest |sum of slave contact forces - p A| / (p A) over the interfaces (NaN where
    /// not measured).
    resultant: f64,
}

/// The numbers of both discretizations, side by side.
fn print_side_by_side(case: &str, node_face: &Errors, mortar: &Errors) {
    println!("{case}: {:>28}  {:>12}  {:>12}", "", NODE_FACE, MORTAR);
    let rows = [
        ("max |sigma - exact| / p", node_face.stress, mortar.stress),
        (
            "max |u - exact| / max |u|",
            node_face.displacement,
            mortar.displacement,
        ),
        (
            "max interface resultant error",
            node_face.resultant,
            mortar.resultant,
        ),
    ];
    for (name, a, b) in rows {
        println!("{case}: {name:>28}  {:>12}  {:>12}", shown(a), shown(b));
    }
}

/// A number as printed, "-" where it was not measured (NaN).
fn shown(x: f64) -> String {
    if x.is_nan() {
        "-".to_string()
    } else {
        format!("{x:.3e}")
    }
}

fn print_one(case: &str, disc: &str, e: &Errors) {
    println!(
        "{case} ({disc}): max |sigma - exact| / p {:.3e}, max |u - exact| / max |u| {:.3e}, max interface resultant error {}",
        e.stress,
        e.displacement,
        shown(e.resultant)
    );
}

/// The errors of a passed patch test.
fn assert_patch_passed(case: &str, e: &Errors) {
    assert!(
        e.stress <= PATCH,
        "{case}: stress error {:e} > {PATCH:e}",
        e.stress
    );
    assert!(
        e.displacement <= PATCH,
        "{case}: displacement error {:e} > {PATCH:e}",
        e.displacement
    );
}

/// Every interface carries the load: a resultant that is off is a wrong contact force,
/// whatever the discretization.
fn assert_resultants(case: &str, disc: &str, e: &Errors) {
    assert!(
        e.resultant <= 1e-10,
        "{case} ({disc}): an interface's contact forces do not balance the load (error {:e})",
        e.resultant
    );
}

// ---------------------------------------------------------------------------------------
// Scenes built from blocks.

/// The text of a scene of generated blocks: bodies, sets, conditions and contact pairs
/// added in order, the pairs with the discretization `disc`.
struct Scene {
    text: String,
    disc: &'static str,
}

impl Scene {
    fn new(name: &str, disc: &'static str) -> Self {
        Scene {
            text: format!("name = \"{name}\"\nkinematics = \"small\"\n"),
            disc,
        }
    }

    fn block(&mut self, name: &str, min: [f64; 3], max: [f64; 3], div: [usize; 3]) {
        let _ = write!(
            self.text,
            "\n[[body]]\nname = \"{name}\"\nbox = {{ min = {min:?}, max = {max:?} }}\ndivisions = {div:?}\nmaterial = {{ model = \"linear_elastic\", E = {E:?}, nu = {NU:?} }}\n"
        );
    }

    /// A node set (kind "node_set") or side set ("side_set") on the plane through `point`
    /// with normal `normal`, of one body or (None) of all.
    fn plane_set(
        &mut self,
        kind: &str,
        name: &str,
        body: Option<&str>,
        point: [f64; 3],
        normal: [f64; 3],
    ) {
        let _ = write!(self.text, "\n[[{kind}]]\nname = \"{name}\"\n");
        if let Some(b) = body {
            let _ = writeln!(self.text, "body = \"{b}\"");
        }
        let _ = writeln!(
            self.text,
            "plane = {{ point = {point:?}, normal = {normal:?} }}"
        );
    }

    fn displacement(&mut self, node_set: &str, component: &str, value: f64) {
        let _ = write!(
            self.text,
            "\n[[displacement]]\nnode_set = \"{node_set}\"\ncomponents = [\"{component}\"]\nvalue = {value:?}\n"
        );
    }

    fn pressure(&mut self, side_set: &str) {
        let _ = write!(
            self.text,
            "\n[[pressure]]\nside_set = \"{side_set}\"\nvalue = {P:?}\n"
        );
    }

    fn contact(&mut self, master: &str, slave: &str) {
        let _ = write!(
            self.text,
            "\n[[contact]]\nmaster = \"{master}\"\nslave = \"{slave}\"\nfriction = \"frictionless\"\ndiscretization = \"{}\"\n",
            self.disc
        );
    }

    /// One load step to t = 1 at the residual tolerance TOL.
    fn finish(mut self) -> String {
        let _ = write!(
            self.text,
            "\n[time]\nsegments = [{{ end = 1.0, steps = 1 }}]\n\n[solver]\ntolerance = {TOL:?}\n"
        );
        self.text
    }
}

const X: [f64; 3] = [1.0, 0.0, 0.0];
const Y: [f64; 3] = [0.0, 1.0, 0.0];
const Z: [f64; 3] = [0.0, 0.0, 1.0];

/// Case a: three unit cubes stacked along z, meshed 3x3x2 (bottom), 2x2x2 (middle) and
/// 3x3x3 (top): two non-matching interfaces, the upper body of each the slave. Rollers
/// u_x = 0 on x = 0 and u_y = 0 on y = 0 (every body: the symmetry planes of the exact
/// field, which remove the lateral rigid motions that frictionless contact leaves free),
/// u_z = 0 on the bottom; the pressure on the top. The middle and top bodies are held
/// along z by contact alone.
/// `meshes` are the bodies' divisions, bottom to top.
fn stack(disc: &'static str, meshes: [[usize; 3]; 3]) -> String {
    let mut s = Scene::new("mortar_patch_stack", disc);
    let names = ["bottom", "middle", "top"];
    for (i, (name, div)) in names.into_iter().zip(meshes).enumerate() {
        let z = i as f64;
        s.block(name, [0.0, 0.0, z], [1.0, 1.0, z + 1.0], div);
        s.plane_set(
            "side_set",
            &format!("{name}_zm"),
            Some(name),
            [0.0, 0.0, z],
            Z,
        );
        s.plane_set(
            "side_set",
            &format!("{name}_zp"),
            Some(name),
            [0.0, 0.0, z + 1.0],
            Z,
        );
    }
    s.plane_set("node_set", "x0", None, [0.0; 3], X);
    s.plane_set("node_set", "y0", None, [0.0; 3], Y);
    s.plane_set("node_set", "z0", Some("bottom"), [0.0; 3], Z);
    s.displacement("x0", "x", 0.0);
    s.displacement("y0", "y", 0.0);
    s.displacement("z0", "z", 0.0);
    s.pressure("top_zp");
    s.contact("bottom_zp", "middle_zm");
    s.contact("middle_zp", "top_zm");
    s.finish()
}

/// The meshes of case a, bottom to top.
const STACK: [[usize; 3]; 3] = [[3, 3, 2], [2, 2, 2], [3, 3, 3]];

/// The upper blocks of case b: (name, lower corner in x and y).
const ARRANGEMENT: [(&str, [f64; 2]); 4] = [
    ("b00", [0.0, 0.0]),
    ("b10", [1.0, 0.0]),
    ("b01", [0.0, 1.0]),
    ("b11", [1.0, 1.0]),
];

/// The meshes of case b: the base, then the upper blocks in the order of ARRANGEMENT.
const ARRANGEMENT_MESHES: [[usize; 3]; 5] = [[3, 3, 2], [2, 2, 2], [3, 3, 3], [3, 3, 3], [2, 2, 2]];

/// Case b: four unit cubes in a 2x2 plan arrangement, alternately meshed 2x2x2 and 3x3x3,
/// standing on one 2 x 2 x 1 base meshed 3x3x2 (its element edges at x, y = 2/3 and 4/3
/// cross the blocks' bottoms and none lies on their shared edges at x, y = 1). Four pairs,
/// the base top the master of each, a block bottom the slave. The blocks touch each other
/// with no contact pair between them: in the exact field their touching faces move
/// together and carry no stress, so none is needed.
///
/// Rigid motions. Frictionless contact holds the blocks along z only; their x and y
/// translations and rotation about z are removed by prescribing the exact normal
/// displacement on outer lateral faces: u_x = 0 on x = 0 and u_y = 0 on y = 0 (the
/// symmetry planes, every body touching them), and on the far faces of the blocks that do
/// not touch them, u_x = nu p 2 / E on x = 2 (b10, b11) and u_y = nu p 2 / E on y = 2
/// (b01, b11). Each block is so held on one face normal to x and one normal to y, at the
/// exact values, which in the exact field carry no force (sigma_xx = sigma_yy = 0); the
/// base is held by the symmetry planes and u_z = 0 on its bottom.
/// `meshes`: the base's divisions, then the blocks' in the order of ARRANGEMENT.
fn arrangement(disc: &'static str, meshes: [[usize; 3]; 5]) -> String {
    let far = NU * P * 2.0 / E;
    let mut s = Scene::new("mortar_patch_arrangement", disc);
    s.block("base", [0.0; 3], [2.0, 2.0, 1.0], meshes[0]);
    s.plane_set("side_set", "base_zp", Some("base"), [0.0, 0.0, 1.0], Z);
    for ((name, [x, y]), div) in ARRANGEMENT.into_iter().zip(&meshes[1..]) {
        let div = *div;
        s.block(name, [x, y, 1.0], [x + 1.0, y + 1.0, 2.0], div);
        s.plane_set(
            "side_set",
            &format!("{name}_zm"),
            Some(name),
            [0.0, 0.0, 1.0],
            Z,
        );
        s.plane_set(
            "side_set",
            &format!("{name}_zp"),
            Some(name),
            [0.0, 0.0, 2.0],
            Z,
        );
        if x > 0.0 {
            let set = format!("{name}_x2");
            s.plane_set("node_set", &set, Some(name), [2.0, 0.0, 0.0], X);
            s.displacement(&set, "x", far);
        }
        if y > 0.0 {
            let set = format!("{name}_y2");
            s.plane_set("node_set", &set, Some(name), [0.0, 2.0, 0.0], Y);
            s.displacement(&set, "y", far);
        }
    }
    s.plane_set("node_set", "x0", None, [0.0; 3], X);
    s.plane_set("node_set", "y0", None, [0.0; 3], Y);
    s.plane_set("node_set", "z0", Some("base"), [0.0; 3], Z);
    s.displacement("x0", "x", 0.0);
    s.displacement("y0", "y", 0.0);
    s.displacement("z0", "z", 0.0);
    for (name, ..) in ARRANGEMENT {
        s.pressure(&format!("{name}_zp"));
        s.contact("base_zp", &format!("{name}_zm"));
    }
    s.finish()
}

/// Errors of a z-vertical uniaxial case against sigma = diag(0, 0, -p) and
/// u = (nu p x / E, nu p y / E, -p z / E); the resultant over each slave body's nodes on
/// its bottom z = `z` (the (body, z, area) of `interfaces`) against p times its area.
fn uniaxial_errors(p: &Problem, state: &GlobalState, interfaces: &[(&str, f64, f64)]) -> Errors {
    let exact_u = |x: &[f64; 3]| [NU * P * x[0] / E, NU * P * x[1] / E, -P * x[2] / E];
    let scale = p
        .mesh
        .coords
        .iter()
        .flat_map(exact_u)
        .fold(0.0, |m: f64, v| m.max(v.abs()));
    let displacement = p
        .mesh
        .coords
        .iter()
        .zip(&state.displacement)
        .flat_map(|(x, u)| {
            let e = exact_u(x);
            (0..3).map(move |i| (u[i] - e[i]).abs())
        })
        .fold(0.0, f64::max)
        / scale;
    let exact_s = [0.0, 0.0, -P, 0.0, 0.0, 0.0];
    let stress = state
        .stress
        .iter()
        .flat_map(|s| s.iter().zip(&exact_s).map(|(a, e)| (a - e).abs() / P))
        .fold(0.0, f64::max);
    let resultant = interfaces
        .iter()
        .map(|&(name, z, area)| {
            let b = p.mesh.bodies.iter().find(|b| b.name == name).unwrap();
            let total: f64 = (b.first_node..b.first_node + b.num_nodes)
                .filter(|&n| (p.mesh.coords[n][2] - z).abs() < 1e-12)
                .map(|n| state.contact_force[n][2])
                .sum();
            (total - P * area).abs() / (P * area)
        })
        .fold(0.0, f64::max);
    Errors {
        stress,
        displacement,
        resultant,
    }
}

fn stack_errors(disc: &'static str, meshes: [[usize; 3]; 3]) -> Errors {
    let p = problem(&stack(disc, meshes));
    let (_, state) = solve(&p);
    uniaxial_errors(&p, &state, &[("middle", 1.0, 1.0), ("top", 2.0, 1.0)])
}

fn arrangement_errors(disc: &'static str, meshes: [[usize; 3]; 5]) -> Errors {
    let p = problem(&arrangement(disc, meshes));
    let (_, state) = solve(&p);
    let slaves: Vec<(&str, f64, f64)> = ARRANGEMENT.iter().map(|b| (b.0, 1.0, 1.0)).collect();
    uniaxial_errors(&p, &state, &slaves)
}

// ---------------------------------------------------------------------------------------
// Large kinematics: the stack compressed by 15%.

/// The pressure of the large-deformation stack: 0.15 E, about 15% compression.
const P_LARGE: f64 = 0.15 * E;

/// The stack with neo-Hookean bodies under `kinematics = "large"`, the pressure P_LARGE in
/// 4 steps. The exact answer is a homogeneous deformation (the interfaces stay flat and
/// the bodies, of one material under one uniaxial Cauchy stress, deform alike): the
/// Cauchy stress is -P_LARGE along z and zero otherwise (the pressure follows the current
/// face), and the displacement is one affine function of the reference position.
fn stack_large(disc: &'static str) -> String {
    let text = stack(disc, STACK)
        .replace("kinematics = \"small\"", "kinematics = \"large\"")
        .replace("model = \"linear_elastic\"", "model = \"neo_hookean\"")
        .replace(&format!("value = {P:?}"), &format!("value = {P_LARGE:?}"))
        .replace("steps = 1 }", "steps = 4 }");
    assert!(text.contains("neo_hookean") && text.contains(&format!("{P_LARGE:?}")));
    text
}

/// (max |sigma - exact| / P_LARGE, max distance of a node's displacement from the best
/// affine fit over all nodes / max |u|), or why the run stopped.
fn large_errors(disc: &'static str) -> Result<(f64, f64), String> {
    let p = problem(&stack_large(disc));
    let (summary, state) = common::run_serial(&p, None);
    if let Some(f) = summary.failure {
        return Err(f.to_string());
    }
    let exact_s = [0.0, 0.0, -P_LARGE, 0.0, 0.0, 0.0];
    let stress = state
        .stress
        .iter()
        .flat_map(|s| s.iter().zip(&exact_s).map(|(a, e)| (a - e).abs() / P_LARGE))
        .fold(0.0, f64::max);
    // Least squares u_i = a_i . X + b_i (normal equations of the 4 unknowns per component).
    let x = &p.mesh.coords;
    let mut m = nalgebra::Matrix4::<f64>::zeros();
    let mut r = nalgebra::Matrix4x3::<f64>::zeros();
    for (xn, un) in x.iter().zip(&state.displacement) {
        let v = nalgebra::Vector4::new(xn[0], xn[1], xn[2], 1.0);
        m += v * v.transpose();
        for i in 0..3 {
            for k in 0..4 {
                r[(k, i)] += v[k] * un[i];
            }
        }
    }
    let c = m.try_inverse().unwrap() * r;
    let mut worst = 0.0f64;
    let mut scale = 0.0f64;
    for (xn, un) in x.iter().zip(&state.displacement) {
        let v = nalgebra::Vector4::new(xn[0], xn[1], xn[2], 1.0);
        for i in 0..3 {
            let fit: f64 = (0..4).map(|k| c[(k, i)] * v[k]).sum();
            worst = worst.max((un[i] - fit).abs());
            scale = scale.max(un[i].abs());
        }
    }
    Ok((stress, worst / scale))
}

#[test]
fn large_kinematics_stack_mortar_passes_the_patch_test() {
    // The ties are made on the deformed surfaces (the pressure is 15% of E). The fit is
    // exact for the exact field; round-off of the solve (residual 1e-12 of the reference
    // force, amplified by the condition number as in the small-strain cases) stays far
    // below the 1e-8 asserted.
    let m = large_errors(MORTAR).unwrap_or_else(|e| panic!("mortar: {e}"));
    println!("stack, large kinematics (pressure 0.15 E), mortar:");
    println!("  max |sigma - exact| / p                {:.3e}", m.0);
    println!("  max |u - affine fit| / max |u|         {:.3e}", m.1);
    match large_errors(NODE_FACE) {
        Ok(nf) => println!("  node_face: {:.3e}, {:.3e}", nf.0, nf.1),
        Err(e) => println!("  node_face: {e}"),
    }
    assert!(
        m.0 <= 1e-8 && m.1 <= 1e-8,
        "mortar, large kinematics: {m:?}"
    );
}

// ---------------------------------------------------------------------------------------
// The paper's non-matching multi-constraint scene.

/// `text` with `discretization = disc` in every `[[contact]]` pair.
fn with_discretization(text: &str, disc: &str) -> String {
    let mut doc: toml::Table = text.parse().unwrap();
    let pairs = doc
        .get_mut("contact")
        .and_then(|c| c.as_array_mut())
        .expect("the scene has [[contact]] pairs");
    for pair in pairs {
        pair.as_table_mut()
            .unwrap()
            .insert("discretization".into(), toml::Value::String(disc.into()));
    }
    toml::to_string(&doc).unwrap()
}

/// Case c: run/scenes/paper/multi_constraint_nonmatching.toml (its solver tolerance is
/// already 1e-12) with its pairs switched to `disc`, written to a result file and measured
/// by `solver post verify`'s exact answer (sigma_yy = -p, sigma_xx = sigma_zz =
/// -p nu / (1 - nu), u_x = u_z = 0, u_y linear in y). The scene's name is kept, so that
/// verify recognises it.
fn multi_constraint_errors(disc: &str) -> Errors {
    let path = common::paper_scene("multi_constraint_nonmatching");
    let text = with_discretization(&std::fs::read_to_string(&path).unwrap(), disc);
    let p = parse_scene(&text, &path, "scene").unwrap_or_else(|e| panic!("{e}"));
    let dir = common::fresh_dir(&format!("mortar_patch_multi_{disc}"));
    let (summary, _) = run(
        &SerialComm,
        &p,
        &RunOptions {
            output: Some(dir.join("multi_constraint_nonmatching.h5")),
            verbosity: 0,
            export_operator: None,
            final_state: true,
            partition: Default::default(),
        },
    )
    .expect("run starts");
    assert!(summary.failure.is_none(), "{disc}: {:?}", summary.failure);
    let v = verify_file(&summary.output.expect("a result file")).unwrap();
    let reported = |name: &str| {
        v.reported
            .iter()
            .find(|(n, _)| n.starts_with(name))
            .map(|(_, x)| *x)
            .unwrap_or_else(|| panic!("verify reports no '{name}': {}", v.render()))
    };
    Errors {
        stress: reported("max |sigma - exact|"),
        displacement: reported("max |u - exact|"),
        resultant: f64::NAN,
    }
}

// ---------------------------------------------------------------------------------------
// The tests: the harness itself on matching meshes, node-to-face runs (printed; the load balance asserted) and mortar runs
// (compared with node-to-face side by side; the patch test asserted).

/// The exact answers and the removal of the rigid motions are right: with matching meshes
/// node-to-face contact passes the patch test, so cases a and b meshed to match (every
/// interface's slave nodes on master nodes) reproduce the exact field to round-off.
#[test]
fn matching_meshes_reproduce_the_exact_field_with_node_face() {
    let stack = stack_errors(NODE_FACE, [[2, 2, 2], [2, 2, 1], [2, 2, 3]]);
    print_one("stack, matching meshes", NODE_FACE, &stack);
    let arr = arrangement_errors(
        NODE_FACE,
        [[4, 4, 2], [2, 2, 2], [2, 2, 3], [2, 2, 1], [2, 2, 2]],
    );
    print_one("2x2 arrangement, matching meshes", NODE_FACE, &arr);
    for (case, e) in [("stack", stack), ("2x2 arrangement", arr)] {
        assert_resultants(case, NODE_FACE, &e);
        assert_patch_passed(case, &e);
    }
}

#[test]
fn stack_mortar_passes_the_patch_test() {
    let (nf, m) = (stack_errors(NODE_FACE, STACK), stack_errors(MORTAR, STACK));
    print_side_by_side("stack", &nf, &m);
    assert_resultants("stack", MORTAR, &m);
    assert_patch_passed("stack (mortar)", &m);
}

#[test]
fn arrangement_mortar_passes_the_patch_test() {
    let (nf, m) = (
        arrangement_errors(NODE_FACE, ARRANGEMENT_MESHES),
        arrangement_errors(MORTAR, ARRANGEMENT_MESHES),
    );
    print_side_by_side("2x2 arrangement", &nf, &m);
    assert_resultants("2x2 arrangement", MORTAR, &m);
    assert_patch_passed("2x2 arrangement (mortar)", &m);
}

#[test]
fn multi_constraint_nonmatching_mortar_passes_the_patch_test() {
    let (nf, m) = (
        multi_constraint_errors(NODE_FACE),
        multi_constraint_errors(MORTAR),
    );
    print_side_by_side("multi_constraint_nonmatching", &nf, &m);
    assert_patch_passed("multi_constraint_nonmatching (mortar)", &m);
}

/// The switch to mortar reaches every pair of the paper scene and nothing else changes.
#[test]
fn switching_the_paper_scene_to_mortar_changes_only_the_pairs() {
    let text =
        std::fs::read_to_string(common::paper_scene("multi_constraint_nonmatching")).unwrap();
    let original: toml::Table = text.parse().unwrap();
    let mut switched: toml::Table = with_discretization(&text, MORTAR).parse().unwrap();
    let pairs = switched["contact"].as_array().unwrap();
    assert_eq!(pairs.len(), 12);
    assert!(pairs
        .iter()
        .all(|c| c.get("discretization").and_then(|d| d.as_str()) == Some(MORTAR)));
    for c in switched["contact"].as_array_mut().unwrap() {
        c.as_table_mut().unwrap().remove("discretization");
    }
    assert_eq!(switched, original);
    let p = parse_scene(&with_discretization(&text, MORTAR), "t.toml", "t").unwrap();
    assert_eq!(p.contacts.len(), 12);
    assert!(p
        .contacts
        .iter()
        .all(|c| c.discretization == Discretization::Mortar));
}

/// The paper's mortar variants (run by run/paper and mpi-tests on 1, 2 and 3 ranks) are
/// their base scenes with every pair switched to mortar, renamed `<base>_mortar`, and
/// nothing else.
#[test]
fn paper_mortar_scenes_are_their_base_scenes_with_mortar_contact() {
    let dir = common::repo("run/scenes/paper");
    let mut found = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_stem().unwrap().to_str().unwrap().to_string();
        let Some(base) = name.strip_suffix("_mortar") else {
            continue;
        };
        found += 1;
        let base_text = std::fs::read_to_string(dir.join(format!("{base}.toml"))).unwrap();
        let mut want: toml::Table = with_discretization(&base_text, MORTAR).parse().unwrap();
        want.insert("name".into(), toml::Value::String(name.clone()));
        let got: toml::Table = std::fs::read_to_string(&path).unwrap().parse().unwrap();
        assert_eq!(
            got, want,
            "{name}.toml is not {base}.toml with mortar contact"
        );
    }
    assert_eq!(found, 6, "the six mortar variants of the paper scenes");
}
