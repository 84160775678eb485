//! Tetrahedral bodies through the whole solver: a unit cube meshed with tetrahedra by Gmsh
//! (run/tet/cube.geo; 4-node tetrahedra completed to 10 nodes by the reader, and 10-node
//! ones written by Gmsh), stretched along z by a prescribed displacement of its top while
//! three symmetry planes hold it. The exact solution is a homogeneous deformation for every
//! material (the lateral contraction is whatever the material gives under uniaxial stress,
//! plastic flow included): every node's displacement is u = G x with one diagonal G. The
//! composite tetrahedron reproduces a linear field exactly on any mesh (its patch test), so
//! the computed field must be linear in x to the solver's tolerance.

use crate::common;
use common::{fresh_dir, gmsh, repo, solve};
use solver::scene::load_scene;
use solver::solver::choice::tangent_decision;
use std::path::{Path, PathBuf};

/// Meshes run/tet/cube.geo into `dir/cube_o{order}.msh` with element size `h`.
pub(crate) fn cube_mesh(dir: &Path, h: f64, order: u32) -> PathBuf {
    let (h, order) = (h.to_string(), order.to_string());
    gmsh(
        &repo("run/tet/cube.geo"),
        &["-setnumber", "h", &h, "-setnumber", "order", &order],
        dir.join(format!("cube_o{order}.msh")),
    )
}

/// The stretched cube's scene: `material` on the tet10 body, the top moved by `stretch`.
pub(crate) fn scene(
    mesh: &Path,
    kinematics: &str,
    material: &str,
    stretch: f64,
    steps: usize,
) -> String {
    format!(
        r#"
name = "tet_cube"
kinematics = "{kinematics}"
[gmsh]
file = "{mesh}"
[[body]]
name = "cube"
gmsh_volume = "cube"
material = {material}
[[node_set]]
name = "x0"
plane = {{ point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}
[[node_set]]
name = "y0"
plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}
[[node_set]]
name = "z0"
plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }}
[[node_set]]
name = "z1"
plane = {{ point = [0.0, 0.0, 1.0], normal = [0.0, 0.0, 1.0] }}
[[displacement]]
node_set = "x0"
components = ["x"]
value = 0.0
[[displacement]]
node_set = "y0"
components = ["y"]
value = 0.0
[[displacement]]
node_set = "z0"
components = ["z"]
value = 0.0
[[displacement]]
node_set = "z1"
components = ["z"]
function = [[0.0, 0.0], [1.0, {stretch}]]
[time]
segments = [{{ end = 1.0, steps = {steps} }}]
[solver]
tolerance = 1e-13
"#,
        mesh = mesh.display()
    )
}

/// The largest deviation of the computed displacements from u_i = g_i x_i, relative to the
/// largest displacement, with g read at the node farthest from the origin.
fn deviation_from_homogeneous(coords: &[[f64; 3]], u: &[[f64; 3]]) -> f64 {
    let far = (0..coords.len())
        .max_by(|&a, &b| {
            let n = |k: usize| coords[k].iter().map(|c| c * c).sum::<f64>();
            n(a).total_cmp(&n(b))
        })
        .unwrap();
    let g: [f64; 3] = std::array::from_fn(|i| u[far][i] / coords[far][i]);
    let scale = u.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    let dev = coords
        .iter()
        .zip(u)
        .flat_map(|(x, v)| (0..3).map(move |i| (v[i] - g[i] * x[i]).abs()))
        .fold(0.0f64, f64::max);
    dev / scale
}

fn stretched(
    case: usize,
    order: u32,
    kin: &str,
    material: &str,
    stretch: f64,
    steps: usize,
) -> f64 {
    let dir = fresh_dir(&format!("tet_gmsh_solve_{case}"));
    let mesh = cube_mesh(&dir, 0.34, order);
    let path = dir.join("cube.toml");
    std::fs::write(&path, scene(&mesh, kin, material, stretch, steps)).unwrap();
    let p = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        p.mesh
            .bodies
            .iter()
            .all(|b| b.kind == solver::fem::ElementKind::Tet10),
        "the cube is read as tet10"
    );
    let (_, state) = solve(&p);
    deviation_from_homogeneous(&p.mesh.coords, &state.displacement)
}

// The bound: the run stops at a residual of 1e-13 of the reference force; with the stiffness
// matrix's condition number on this mesh (a few hundred nodes: about 1e3) the displacement
// error is below 1e-9 of the displacement. A formulation that does not pass the patch test
// is off by 1e-3 or more on this distorted unstructured mesh.
const LINEAR_FIELD: f64 = 1e-9;

#[test]
fn a_stretched_cube_of_tetrahedra_deforms_homogeneously_for_every_material() {
    let elastic = r#"{ model = "linear_elastic", E = 1000.0, nu = 0.3 }"#;
    let plastic = r#"{ model = "j2_plastic", E = 1000.0, nu = 0.3, yield_stress = 1.0, isotropic_hardening = 10.0 }"#;
    let neo = r#"{ model = "neo_hookean", E = 1000.0, nu = 0.3 }"#;
    let cases = [
        (1, "small", elastic, 0.01, 1),
        (2, "small", elastic, 0.01, 1),
        (1, "small", plastic, 0.01, 4),
        (1, "large", neo, 0.3, 4),
        (1, "large", plastic, 0.2, 4),
    ];
    for (case, (order, kin, mat, stretch, steps)) in cases.into_iter().enumerate() {
        let dev = stretched(case, order, kin, mat, stretch, steps);
        println!("order {order}, {kin}, {mat}: deviation from homogeneous {dev:.2e}");
        assert!(dev < LINEAR_FIELD, "{kin} {mat}: {dev:e}");
    }
}

/// Under `auto` a plastic body takes the full tangent only where its factorization is cheap
/// (solver/choice.rs, FACTOR_WORK_LIMIT): the plane-strain punch at 40 x 40 (work 1.4e7)
/// and a 3-D cube of tetrahedra at h = 0.125 (4679 nodes, work 1.1e8: a factor of 4.0
/// million entries in 0.58 s, measured) take it; the same cube at h = 0.08 (16194 nodes,
/// work above 5e8: 26.3 million entries, 8.4 s a factorization, measured) does not, though
/// it is plastic and below 20000 nodes: a 3-D mesh's fill grows as its nodes squared.
#[test]
fn auto_factors_the_tangent_of_a_slab_but_not_of_a_3d_tetrahedral_block() {
    let plastic = r#"{ model = "j2_plastic", E = 1000.0, nu = 0.3, yield_stress = 1.0, isotropic_hardening = 10.0 }"#;
    let dir = fresh_dir("tet_gmsh_solve_choice");
    let mut nodes = Vec::new();
    for (h, takes) in [(0.125, true), (0.08, false)] {
        let sub = dir.join(format!("h{h}"));
        std::fs::create_dir_all(&sub).unwrap();
        let mesh = cube_mesh(&sub, h, 1);
        let path = sub.join("cube.toml");
        std::fs::write(&path, scene(&mesh, "small", plastic, 0.01, 1)).unwrap();
        let cube = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
        nodes.push(cube.mesh.num_nodes());
        assert_eq!(
            solver::solver::choice::full_tangent(&tangent_decision(&cube, &cube.mesh)),
            takes,
            "h = {h}, {} nodes",
            cube.mesh.num_nodes()
        );
        // The memory estimate counts what runs: the tangent's factor, or in its place the
        // multilevel hierarchy with its first coarse level slow (the cube's aggregates span
        // 3.6 vertices each; its V-cycle's rate, measured, is 0.93; its factor, the work of
        // 45 V-cycles, is declined: `factor_choice`).
        let c = solver::preflight::loaded_size(&cube).counts;
        assert_eq!((c.tangent, c.multilevel), (takes, !takes), "h = {h}");
        assert_eq!(c.coarse_slow, !takes, "h = {h}");
    }
    assert!(nodes[0] > 4000 && nodes[1] < 20000, "{nodes:?}");
    let punch = load_scene(&repo("run/scenes/plasticity/punch_40.toml")).unwrap();
    assert!(solver::solver::choice::full_tangent(&tangent_decision(
        &punch,
        &punch.mesh
    )));
}
