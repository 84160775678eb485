//! Coulomb friction at nodes on symmetry planes: the quarter model of a sphere pressed on a
//! block (run/tet/sphere_on_block.geo at its defaults: Gmsh's 10-node tetrahedra, 3310
//! nodes; the planes x = 0 and z = 0 held in x and in z at both bodies' nodes), mortar
//! contact of the sphere on the block's top with mu = 0.3, both bodies of one steel
//! (E = 210000, nu = 0.3), 50 MPa on the sphere's flat top in 4 steps.
//!
//! With equal elastic constants the two surfaces move alike along the interface (Dundurs'
//! beta = 0): the exact answer carries no friction force and is Hertz's point contact,
//! a = (3 P R / (4 E*))^(1/3), p0 = 3 P / (2 pi a^2), P the whole sphere's load (four
//! times the quarter's contact force), E* = E / (2 (1 - nu^2)).
//!
//! A slave node on a symmetry plane is held along the plane's normal, and so are the master
//! nodes on the plane; its master point, weighted over master nodes off the plane too,
//! moves a little along it all the same. Taken as slip, that motion set friction forces
//! along the normal, which the node's Dirichlet reaction took: the node moved along its own
//! friction force, stuck, slipped again, and this scene failed its first step at t = 0.0039
//! after 6 cut-backs of 200 contact updates each ("the contact forces were still
//! changing"). Coulomb's law now acts across a direction both surfaces hold at zero
//! (`contact::held`): measured, the run completes in 12 s (4 steps, no cut-back).

use crate::common;
use common::{fresh_dir, gmsh, repo, solve};
use solver::scene::load_scene;
use std::path::Path;

const E: f64 = 210000.0;
const NU: f64 = 0.3;
const R: f64 = 10.0;

/// The scene: both bodies of steel, mortar with Coulomb friction, 4 steps.
fn scene(mesh: &Path) -> String {
    format!(
        r#"
name = "sphere_on_block_friction"
kinematics = "small"
[gmsh]
file = "{mesh}"
[[body]]
name = "sphere"
gmsh_volume = "sphere"
material = {{ model = "linear_elastic", E = {E}, nu = {NU} }}
[[body]]
name = "block"
gmsh_volume = "block"
material = {{ model = "linear_elastic", E = {E}, nu = {NU} }}
[[side_set]]
name = "sphere_top"
gmsh_surface = "sphere_top"
[[side_set]]
name = "sphere_surface"
gmsh_surface = "sphere_surface"
[[side_set]]
name = "block_top"
gmsh_surface = "block_top"
[[node_set]]
name = "block_bottom"
gmsh_group = "block_bottom"
[[node_set]]
name = "x0"
plane = {{ point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}
[[node_set]]
name = "z0"
plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }}
[[displacement]]
node_set = "block_bottom"
components = ["y"]
value = 0.0
[[displacement]]
node_set = "x0"
components = ["x"]
value = 0.0
[[displacement]]
node_set = "z0"
components = ["z"]
value = 0.0
[[pressure]]
side_set = "sphere_top"
function = [[0.0, 0.0], [1.0, 50.0]]
[[contact]]
name = "sphere/block"
master = "block_top"
slave = "sphere_surface"
discretization = "mortar"
friction = "coulomb"
mu = 0.3
[time]
segments = [{{ end = 1.0, steps = 4 }}]
"#,
        mesh = mesh.display()
    )
}

#[test]
fn friction_on_symmetry_planes_settles_and_the_sphere_meets_hertz() {
    let dir = fresh_dir("friction_symmetry");
    let mesh = gmsh(
        &repo("run/tet/sphere_on_block.geo"),
        &["-order", "2"],
        dir.join("sphere_on_block.msh"),
    );
    let scene = scene(&mesh);
    let path = dir.join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    let p = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
    let (summary, state) = solve(&p);
    let cutbacks: u64 = summary.steps.iter().map(|s| s.cutbacks).sum();
    let x = &p.mesh.coords;
    // Nodes on a symmetry plane carry no contact force along its normal: a sticking node's
    // row there is dropped (the Dirichlet row holds it), a slipping node's friction force
    // lies across it. Exactly zero, as either way nothing is added along it.
    let mut on_planes = 0;
    for c in &state.constraints {
        let s = c.slave as usize;
        let f = state.contact_force[s];
        for (axis, name) in [(0, "x"), (2, "z")] {
            if x[s][axis] == 0.0 {
                on_planes += 1;
                assert_eq!(
                    f[axis],
                    0.0,
                    "slave node {} on the plane {name} = 0: contact force {f:?}",
                    s + 1
                );
            }
        }
    }
    // Hertz from the load the contact carried (the whole sphere's: four quarters).
    let load = 4.0
        * state
            .constraints
            .iter()
            .map(|c| c.normal_force)
            .sum::<f64>();
    let e_star = E / (2.0 * (1.0 - NU * NU));
    let a = (3.0 * load * R / (4.0 * e_star)).cbrt();
    let p0 = 3.0 * load / (2.0 * std::f64::consts::PI * a * a);
    let peak = state
        .constraints
        .iter()
        .map(|c| state.contact_pressure[c.slave as usize])
        .fold(0.0f64, f64::max);
    let radius = state
        .constraints
        .iter()
        .map(|c| x[c.slave as usize][0].hypot(x[c.slave as usize][2]))
        .fold(0.0f64, f64::max);
    let sticking = state.constraints.iter().filter(|c| c.stick).count();
    println!(
        "cut-backs {cutbacks}, {} nodes in contact ({sticking} sticking, {on_planes} on the planes), \
         load {load:.1}, a {a:.4}, outermost node in contact {radius:.4}, p0 {p0:.1}, \
         peak {peak:.1} ({:+.2}%)",
        state.constraints.len(),
        100.0 * (peak / p0 - 1.0)
    );
    assert!(on_planes > 0, "no node in contact on a symmetry plane");
    // The load is 50 MPa on the quarter disk of radius 10 (the mesh's chords make its area
    // about 0.4% less): within 1% of 4 x 3927.
    assert!((load / (50.0 * std::f64::consts::PI * R * R) - 1.0).abs() < 0.01);
    // Measured: peak -3.3% of p0 (the same mesh frictionless: +4.1%; the 6-node faces'
    // node-by-node scatter is a few % of p0, tests/hertz_tet.rs); bound 5% of p0.
    assert!(
        (peak / p0 - 1.0).abs() < 0.05,
        "peak {peak} against p0 {p0}"
    );
    // The outermost node in contact lies within one element of the Hertz radius (the
    // elements there are hmin + g a = 0.5 mm; measured 1.023 against 1.005).
    assert!(
        (radius - a).abs() < 0.5,
        "contact radius {radius} against {a}"
    );
    // Equal materials: the exact answer sticks everywhere. The outermost ring, whose
    // normal force goes to zero, may slip (measured: 34 of 35 stick).
    assert!(
        sticking * 10 >= 9 * state.constraints.len(),
        "{sticking} of {} stick",
        state.constraints.len()
    );
}
