//! Gmsh mesh import: the checked-in example (ASCII and binary), the scene keys that use a
//! Gmsh mesh, every refusal (exit code 2, a message naming the scene file, the mesh file and
//! the group or element), and a run of the example scene.

use crate::common;
use common::{bad_scene, repo, run_serial};

use solver::fem::hex8::min_jacobian_ratio;
use solver::math::Vec3;
use solver::mesh::gmsh::GmshMesh;
use solver::output::ResultFile;
use solver::problem::Problem;
use solver::scene::load_scene;
use std::path::{Path, PathBuf};
use std::process::Command;

fn fixture(name: &str) -> String {
    repo("tests/fixtures/gmsh").join(name).display().to_string()
}

const EXAMPLE_SCENE: &str = "run/examples/cylinder_on_block.toml";
const EXAMPLE_MSH: &str = "run/gmsh/cylinder_on_block.msh";
const EXAMPLE_MSH_BINARY: &str = "run/gmsh/cylinder_on_block_binary.msh";

/// The tests' files, under cargo's directory for integration tests' temporary files (each
/// test writes its own names there; a later run overwrites them).
fn temp_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("gmsh-tests");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The example scene with its mesh file replaced by `mesh` (an absolute path), written to
/// a temporary scene file and loaded.
fn example_with_mesh(mesh: &Path, name: &str) -> Problem {
    let text = std::fs::read_to_string(repo(EXAMPLE_SCENE)).unwrap();
    let text = text.replace("../gmsh/cylinder_on_block.msh", &mesh.display().to_string());
    let path = temp_dir().join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    load_scene(&path).unwrap_or_else(|e| panic!("{e}"))
}

fn face_coords(p: &Problem, set: &str) -> Vec<Vec3> {
    p.side_set(set)
        .unwrap()
        .faces
        .iter()
        .flat_map(|&(e, f)| p.mesh.face_nodes(e, f))
        .map(|n| p.mesh.coords[n as usize])
        .collect()
}

#[test]
fn example_mesh_is_read_with_its_counts() {
    let m = GmshMesh::read(&repo(EXAMPLE_MSH)).unwrap();
    // Gmsh saves the nodes of the saved elements only: those of the two volumes.
    assert_eq!(m.nodes.len(), 794 + 836);
    let names: Vec<(i32, &str)> = m.groups.iter().map(|g| (g.dim, g.name.as_str())).collect();
    assert_eq!(
        names,
        vec![
            (2, "cylinder_top"),
            (2, "cylinder_arc"),
            (2, "block_top"),
            (2, "block_bottom"),
            (3, "cylinder"),
            (3, "block")
        ]
    );
    let cylinder = m.volume("cylinder").unwrap();
    let block = m.volume("block").unwrap();
    // Cylinder: 24 x 6 (inner rectangle) + 24 x 6 (bottom) + 2 x 6 x 6 (sides) hexahedra,
    // one layer; block: (21 + 2 x 8) x 10.
    assert_eq!((cylinder.elements.len(), cylinder.coords.len()), (360, 794));
    assert_eq!((block.elements.len(), block.coords.len()), (370, 836));
    assert_eq!(m.surface_faces("cylinder_top").unwrap().len(), 36);
    assert_eq!(m.surface_faces("cylinder_arc").unwrap().len(), 36);
    assert_eq!(m.surface_faces("block_top").unwrap().len(), 37);
    assert_eq!(m.group_nodes("block_bottom").unwrap().len(), 76);

    let p = load_scene(&repo(EXAMPLE_SCENE)).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(p.mesh.bodies.len(), 2);
    assert_eq!(p.mesh.num_elements(), 730);
    assert_eq!(p.mesh.num_nodes(), 1630);
    let b = &p.mesh.bodies;
    assert_eq!(
        (b[0].name.as_str(), b[0].num_elements, b[0].num_nodes),
        ("cylinder", 360, 794)
    );
    assert_eq!(
        (b[1].name.as_str(), b[1].num_elements, b[1].num_nodes),
        ("block", 370, 836)
    );
    let sizes: Vec<(&str, usize)> = p
        .side_sets
        .iter()
        .map(|s| (s.name.as_str(), s.faces.len()))
        .collect();
    assert_eq!(
        sizes,
        vec![
            ("cylinder_top", 36),
            ("cylinder_arc", 36),
            ("block_top", 37)
        ]
    );
    let sizes: Vec<(&str, usize)> = p
        .node_sets
        .iter()
        .map(|s| (s.name.as_str(), s.nodes.len()))
        .collect();
    assert_eq!(
        sizes,
        vec![
            ("block_bottom", 76),
            ("cylinder_axis", 26),
            ("front", 815),
            ("back", 815)
        ]
    );
    // The groups are where the .geo puts them (R = 10, the block's top at y = 0).
    let eps = 1e-12;
    assert!(face_coords(&p, "cylinder_top")
        .iter()
        .all(|x| (x[1] - 10.0).abs() < eps));
    assert!(face_coords(&p, "cylinder_arc")
        .iter()
        .all(|x| (x[0].hypot(x[1] - 10.0) - 10.0).abs() < eps && x[1] <= 10.0 + eps));
    assert!(face_coords(&p, "block_top")
        .iter()
        .all(|x| x[1].abs() < eps));
    for &n in &p.node_set("block_bottom").unwrap().nodes {
        assert!((p.mesh.coords[n as usize][1] + 20.0).abs() < eps);
        assert!(n as usize >= b[1].first_node, "a block node");
    }
    // Every element is a positively oriented hexahedron in the solver's node order.
    for e in 0..p.mesh.num_elements() {
        assert!(
            min_jacobian_ratio(&p.mesh.element_coords(e)) > 0.1,
            "element {e}"
        );
    }
}

#[test]
fn ascii_and_binary_files_give_identical_meshes() {
    let ascii = GmshMesh::read(&repo(EXAMPLE_MSH)).unwrap();
    let binary = GmshMesh::read(&repo(EXAMPLE_MSH_BINARY)).unwrap();
    assert_eq!(ascii.groups, binary.groups);
    assert_eq!(ascii.group_elements, binary.group_elements);
    // Gmsh prints ASCII coordinates with 16 significant digits, one short of a round
    // trip, so they may differ from the binary file's in the last bits: 1e-15 of the
    // mesh size (40) allows a few units in the last place.
    let tol = 40.0 * 1e-15;
    assert_eq!(
        ascii.nodes.keys().collect::<Vec<_>>(),
        binary.nodes.keys().collect::<Vec<_>>()
    );
    let worst = max_difference(ascii.nodes.values(), binary.nodes.values());
    println!("largest coordinate difference, ASCII against binary: {worst:e}");
    assert!(worst <= tol, "{worst:e}");

    let a = example_with_mesh(&repo(EXAMPLE_MSH), "ascii");
    let b = example_with_mesh(&repo(EXAMPLE_MSH_BINARY), "binary");
    assert!(max_difference(a.mesh.coords.iter(), b.mesh.coords.iter()) <= tol);
    assert_eq!(a.mesh.elements, b.mesh.elements);
    assert_eq!(a.mesh.element_body, b.mesh.element_body);
    for (x, y) in a.side_sets.iter().zip(&b.side_sets) {
        assert_eq!(x.faces, y.faces, "side set {}", x.name);
    }
    for (x, y) in a.node_sets.iter().zip(&b.node_sets) {
        assert_eq!(x.nodes, y.nodes, "node set {}", x.name);
    }
}

fn max_difference<'a>(a: impl Iterator<Item = &'a Vec3>, b: impl Iterator<Item = &'a Vec3>) -> f64 {
    a.zip(b)
        .flat_map(|(x, y)| (0..3).map(move |i| (x[i] - y[i]).abs()))
        .fold(0.0, f64::max)
}

/// A one-body scene on `mesh` with extra TOML after the body.
fn scene(mesh: &str, volume: &str, extra: &str) -> String {
    format!(
        r#"
[gmsh]
file = "{mesh}"

[[body]]
name = "b"
gmsh_volume = "{volume}"
material = {{ model = "linear_elastic", E = 1000.0, nu = 0.3 }}
{extra}
[[node_set]]
name = "all"
box = {{ min = [-100.0, -100.0, -100.0], max = [100.0, 100.0, 100.0] }}

[[displacement]]
node_set = "all"
components = ["x", "y", "z"]
value = 0.0

[time]
segments = [{{ end = 1.0, steps = 1 }}]
"#
    )
}

/// Writes the scene, runs `solver check` and `solver run` on it; both must exit with 2 and
/// the same message, which names the scene file and contains every needle.
fn expect_error(name: &str, text: &str, needles: &[&str]) {
    bad_scene::expect_error("gmsh", name, text, needles);
}

#[test]
fn unsupported_element_types_are_named_and_counted() {
    // The cube's five tetrahedra replaced by a 6-node prism: a type no body takes.
    let text = std::fs::read_to_string(fixture("tetrahedra.msh")).unwrap();
    let tets = &text[text.find("3 1 4 5\n").unwrap()..text.find("$EndElements").unwrap()];
    let text = text
        .replace(tets, "3 1 6 1\n3 1 2 3 5 6 7\n")
        .replace("2 7 1 7\n", "2 3 1 3\n");
    let prisms = temp_dir().join("prism.msh");
    std::fs::write(&prisms, text).unwrap();
    expect_error(
        "prism",
        &scene(&prisms.display().to_string(), "solid", ""),
        &[
            "body[0].gmsh_volume",
            "prism.msh",
            "physical volume 'solid'",
            "1 element of Gmsh type 6 (6-node prism; the first is element 3)",
            "only 8-node hexahedra (Gmsh type 5) and 4- or 10-node tetrahedra (types 4, 11)",
        ],
    );
    let side = "[[side_set]]\nname = \"bottom\"\ngmsh_surface = \"bottom\"\n";
    expect_error(
        "triangles",
        &scene(&fixture("triangles.msh"), "cube", side),
        &[
            "side_set[0].gmsh_surface",
            "triangles.msh",
            "triangle 1 of physical surface 'bottom'",
            "not a face of any body's element",
        ],
    );
}

#[test]
fn a_missing_physical_group_lists_the_available_ones() {
    let mesh = repo(EXAMPLE_MSH).display().to_string();
    expect_error(
        "missing_volume",
        &scene(&mesh, "cylindre", ""),
        &[
            "body[0].gmsh_volume",
            "cylinder_on_block.msh has no physical volume named 'cylindre'",
            "'cylinder', 'block'",
        ],
    );
    let side = "[[side_set]]\nname = \"top\"\ngmsh_surface = \"top\"\n";
    expect_error(
        "missing_surface",
        &scene(&mesh, "cylinder", side),
        &[
            "side_set[0].gmsh_surface",
            "no physical surface named 'top'",
            "'cylinder_top', 'cylinder_arc', 'block_top', 'block_bottom'",
        ],
    );
    let nodes = "[[node_set]]\nname = \"base\"\ngmsh_group = \"base\"\n";
    expect_error(
        "missing_group",
        &scene(&mesh, "cylinder", nodes),
        &[
            "node_set[0].gmsh_group",
            "no physical group named 'base'",
            "'block_bottom' (surface)",
            "'block' (volume)",
        ],
    );
}

#[test]
fn an_inverted_hexahedron_is_named_by_its_element_tag() {
    expect_error(
        "inverted",
        &scene(&fixture("inverted.msh"), "bar", ""),
        &[
            "body[0].gmsh_volume",
            "element 7 (8-node hexahedron) of physical volume 'bar' in",
            "inverted.msh",
            "inverted or degenerate",
        ],
    );
}

#[test]
fn unreadable_and_missing_files_are_refused() {
    expect_error(
        "truncated",
        &scene(&fixture("truncated.msh"), "cube", ""),
        &[
            "gmsh.file",
            "truncated.msh is not a readable MSH 4.1 file",
            "line",
        ],
    );
    expect_error(
        "old_format",
        &scene(&fixture("old_format.msh"), "cube", ""),
        &["gmsh.file", "old_format.msh is in MSH format 2.2", "4.1"],
    );
    expect_error(
        "not_a_mesh",
        &scene(&fixture("README.md"), "cube", ""),
        &["gmsh.file", "README.md is not a Gmsh mesh file"],
    );
    // Relative to the scene file, which is in the temporary directory.
    expect_error(
        "missing_file",
        &scene("meshes/no_such.msh", "cube", ""),
        &[
            "gmsh.file",
            "no mesh file",
            "meshes/no_such.msh",
            "relative to the scene file",
        ],
    );
}

#[test]
fn other_gmsh_scene_errors() {
    let two = fixture("two_cubes.msh");
    let right = "[[body]]\nname = \"r\"\ngmsh_volume = \"right\"\nmaterial = { model = \"linear_elastic\", E = 1000.0, nu = 0.3 }\n";
    expect_error(
        "shared_nodes",
        &scene(&two, "left", right),
        &[
            "body[1].gmsh_volume",
            "physical volumes 'left' and 'right'",
            "share node 2",
        ],
    );
    let side = "[[side_set]]\nname = \"middle\"\ngmsh_surface = \"middle\"\n";
    expect_error(
        "inner_face",
        &scene(&two, "both", side),
        &[
            "side_set[0].gmsh_surface",
            "quadrangle 1 of physical surface 'middle'",
            "a face between two elements, not on a body's boundary",
        ],
    );
    let text = scene(&fixture("cube.msh"), "cube", "").replace("[gmsh]\nfile", "# file");
    expect_error(
        "no_gmsh_table",
        &text,
        &["body[0].gmsh_volume", "needs the mesh file", "[gmsh]"],
    );
    let text = scene(&fixture("cube.msh"), "cube", "")
        .replace("gmsh_volume", "divisions = [1, 1, 1]\ngmsh_volume");
    expect_error(
        "volume_and_divisions",
        &text,
        &["body[0]", "either `gmsh_volume` or `box`/`corners`"],
    );
    let nodes = "[[node_set]]\nname = \"n\"\ngmsh_surface = \"bottom\"\n";
    expect_error(
        "surface_as_node_set",
        &scene(&fixture("cube.msh"), "cube", nodes),
        &["node_set[0].gmsh_surface", "selects side sets"],
    );
}

/// A Gmsh cube resting on a generated block, pressed by a pressure: the two kinds of body
/// in one scene, numbered in scene order, with sets of both kinds.
#[test]
fn gmsh_and_generated_bodies_mix() {
    let text = format!(
        r#"
[gmsh]
file = "{cube}"

[[body]]
name = "base"
box = {{ min = [-0.5, -0.5, -1.0], max = [1.5, 1.5, 0.0] }}
divisions = [1, 1, 1]
material = {{ model = "linear_elastic", E = 1000.0, nu = 0.3 }}

[[body]]
name = "cube"
gmsh_volume = "cube"
material = {{ model = "linear_elastic", E = 500.0, nu = 0.25 }}

[[side_set]]
name = "cube_bottom"
gmsh_surface = "bottom"

[[side_set]]
name = "base_top"
body = "base"
plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }}

[[side_set]]
name = "cube_top"
plane = {{ point = [0.0, 0.0, 1.0], normal = [0.0, 0.0, 1.0] }}

[[node_set]]
name = "base_bottom"
plane = {{ point = [0.0, 0.0, -1.0], normal = [0.0, 0.0, 1.0] }}

[[node_set]]
name = "corner"
gmsh_group = "corner"

[[node_set]]
name = "cube_all"
body = "cube"
box = {{ min = [0.0, 0.0, 0.0], max = [1.0, 1.0, 1.0] }}

[[displacement]]
node_set = "base_bottom"
components = ["x", "y", "z"]
value = 0.0

[[displacement]]
node_set = "cube_all"
components = ["x", "y"]
value = 0.0

[[pressure]]
side_set = "cube_top"
value = 2.0

[[contact]]
master = "base_top"
slave = "cube_bottom"

[time]
segments = [{{ end = 1.0, steps = 1 }}]
"#,
        cube = fixture("cube.msh")
    );
    let path = temp_dir().join("mixed.toml");
    std::fs::write(&path, text).unwrap();
    let p = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
    let b = &p.mesh.bodies;
    assert_eq!((b[0].first_node, b[0].num_nodes), (0, 8));
    assert_eq!((b[1].first_node, b[1].num_nodes), (8, 8));
    // The cube's Gmsh node tag t became node 8 + t - 1 (tags in order), so the quadrangle
    // (1, 4, 3, 2) is the cube's -z face, local face 4.
    assert_eq!(p.side_set("cube_bottom").unwrap().faces, vec![(1, 4)]);
    assert_eq!(p.mesh.elements.element(1), &[8, 9, 10, 11, 12, 13, 14, 15]);
    // A physical point: the node of tag 1.
    assert_eq!(p.node_set("corner").unwrap().nodes, vec![8]);
    let (_, state) = common::solve(&p);
    let total: f64 = (8..12).map(|n| state.contact_force[n][2]).sum();
    // The cube is held in z by contact alone: the contact force balances the pressure
    // (2 on the unit face) to the solver's tolerance.
    assert!((total - 2.0).abs() < 1e-8, "total contact force {total}");
}

/// The example scene: the contact force under the cylinder carries the applied load; the
/// Hertz comparison reads R, P and E* back from the result file.
#[test]
fn example_scene_carries_the_applied_load() {
    let p = load_scene(&repo(EXAMPLE_SCENE)).unwrap_or_else(|e| panic!("{e}"));
    let out = temp_dir().join("cylinder_on_block.h5");
    let (summary, state) = run_serial(&p, Some(out.clone()));
    assert!(summary.failure.is_none(), "{:?}", summary.failure);
    // Applied: 500 on the flat top, 20 x 1.
    let load = 500.0 * 20.0 * 1.0;
    let slaves = &p.contacts[0].slave_nodes;
    let total: Vec<f64> = (0..3)
        .map(|d| {
            slaves
                .iter()
                .map(|&s| state.contact_force[s as usize][d])
                .sum()
        })
        .collect();
    println!("total contact force {total:?}, applied {load}");
    // The cylinder is held in y by contact alone, so y-equilibrium of the cylinder makes
    // the contact force equal the load up to the residual: |r| <= 1e-10 x the reference
    // force (about the load), summed over at most 794 nodes at most sqrt(794) |r| ~ 3e-9
    // of the load. 1e-7 leaves room.
    assert!(
        ((total[1] - load) / load).abs() < 1e-7,
        "contact force {} against load {load}",
        total[1]
    );

    let f = ResultFile::open(&out).unwrap();
    let c = solver::post::hertz::compare(&f).unwrap();
    print!("{}", c.render());
    assert!((c.radius - 10.0).abs() < 1e-9, "fitted radius {}", c.radius);
    assert!(((c.load_per_length - load) / load).abs() < 1e-7);
    let e_star = solver::post::hertz::contact_modulus(210000.0, 0.3, 70000.0, 0.33);
    assert!((c.e_star - e_star).abs() < 1e-9 * e_star);
    // The Hertz error itself is reported, not asserted: the mesh is coarse on purpose.
    assert!(c.rms_error.is_finite());

    let png = temp_dir().join("hertz.png");
    let cli = Command::new(env!("CARGO_BIN_EXE_solver"))
        .args([
            "post",
            "hertz",
            out.to_str().unwrap(),
            "-o",
            png.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&cli.stdout);
    assert_eq!(
        cli.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&cli.stderr)
    );
    assert!(
        text.contains("RMS error") && text.contains("peak pressure"),
        "{text}"
    );
    assert!(std::fs::metadata(&png).unwrap().len() > 0);

    // --overlay: every file reported, each with its summary line, one plot.
    let both = temp_dir().join("hertz_overlay.png");
    let cli = Command::new(env!("CARGO_BIN_EXE_solver"))
        .args(["post", "hertz", out.to_str().unwrap(), "--overlay"])
        .arg(&out)
        .arg("-o")
        .arg(&both)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&cli.stdout);
    assert_eq!(cli.status.code(), Some(0), "{}", common::stderr_text(&cli));
    assert_eq!(text.matches("summary: peak/p0-1").count(), 2, "{text}");
    assert!(text.contains("(node_face)"), "{text}");
    assert!(std::fs::metadata(&both).unwrap().len() > 0);
}
