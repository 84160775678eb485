//! Tetrahedral Gmsh meshes: a cube of 4-node tetrahedra read as 10-node ones (node counts
//! against Euler's formula, midside nodes at their edges' midpoints), the same cube at
//! order 2 (the same mesh), triangles as side sets, a mesh of a hexahedral and a
//! tetrahedral volume, `solver check`, the refusals; and a result file of tet10 and mixed
//! meshes written through the output layer, read by `solver post` and by ParaView.
//! The fixtures are made by tests/fixtures/gmsh/make_tet.

use crate::common;
use common::{bad_scene, repo, solver};
use solver::fem::ElementKind;
use solver::math::Vec3;
use solver::mesh::gmsh::GmshMesh;
use solver::problem::Problem;
use solver::scene::parse_scene;
use std::collections::{BTreeSet, HashMap};
use std::path::Path;

#[path = "gmsh_tet/result.rs"]
mod result;

fn fixture(name: &str) -> String {
    repo("tests/fixtures/gmsh").join(name).display().to_string()
}

/// A one-body scene on the cube mesh `mesh`, with the side sets of its top and bottom
/// triangles and the node set of its bottom (fixed), plus `extra`.
fn cube_scene(mesh: &str, extra: &str) -> String {
    format!(
        r#"
name = "tet_cube"
[gmsh]
file = "{mesh}"

[[body]]
name = "cube"
gmsh_volume = "cube"
material = {{ model = "linear_elastic", E = 1000.0, nu = 0.3 }}

[[side_set]]
name = "top"
gmsh_surface = "top"

[[side_set]]
name = "bottom"
gmsh_surface = "bottom"

[[node_set]]
name = "bottom"
gmsh_group = "bottom"

[[displacement]]
node_set = "bottom"
components = ["x", "y", "z"]
value = 0.0

[[pressure]]
side_set = "top"
value = 1.0
{extra}
[time]
segments = [{{ end = 1.0, steps = 1 }}]
"#
    )
}

fn load(text: &str) -> Problem {
    parse_scene(text, "tet.toml", "tet").unwrap_or_else(|e| panic!("{e}"))
}

/// The corner tags of every 4-node tetrahedron of the volume.
fn file_tets(m: &GmshMesh, volume: &str) -> Vec<Vec<u64>> {
    let g = m.groups.iter().position(|g| g.dim == 3 && g.name == volume);
    m.group_elements[g.unwrap()]
        .iter()
        .map(|e| e.nodes[..4].to_vec())
        .collect()
}

#[test]
fn a_cube_of_4_node_tetrahedra_reads_as_tet10_with_a_node_on_every_edge() {
    let m = GmshMesh::read(Path::new(&fixture("tet_cube.msh"))).unwrap();
    let v = m.volume("cube").unwrap();
    assert_eq!(v.kind, ElementKind::Tet10);
    let tets = file_tets(&m, "cube");
    // Euler's formula for a tetrahedralised ball: V - E + F - T = 1, with F counted from
    // the tetrahedra's faces: an independent count of the edges.
    let mut faces = BTreeSet::new();
    for t in &tets {
        for skip in 0..4 {
            let mut f: Vec<u64> = (0..4).filter(|&a| a != skip).map(|a| t[a]).collect();
            f.sort_unstable();
            faces.insert(f);
        }
    }
    let (corners, tn) = (v.node_tags.len() as i64, tets.len() as i64);
    let edges = corners + faces.len() as i64 - tn - 1;
    println!(
        "{tn} tetrahedra, {corners} corners, {edges} edges, {} faces",
        faces.len()
    );
    assert_eq!(v.midsides.len() as i64, edges);
    assert_eq!(v.coords.len() as i64, corners + edges);
    assert_eq!(v.elements.len() as i64, tn);
    let mut worst = f64::INFINITY;
    for el in v.elements.iter() {
        let x: Vec<Vec3> = el.iter().map(|&n| v.coords[n as usize]).collect();
        for (m, &(i, j)) in solver::fem::tet10::MIDSIDE.iter().enumerate() {
            let mid: Vec3 = std::array::from_fn(|k| 0.5 * (x[i][k] + x[j][k]));
            assert_eq!(
                x[4 + m],
                mid,
                "the midside node sits at its edge's midpoint"
            );
        }
        worst = worst.min(ElementKind::Tet10.min_jacobian_ratio(&x));
    }
    println!("smallest Jacobian ratio {worst:.4}");
    assert!(worst > 0.0);
}

/// Each element's ten node positions, keyed by its sorted corner positions (bit patterns).
fn elements_by_corners(p: &Problem) -> HashMap<Vec<[u64; 3]>, Vec<Vec3>> {
    (0..p.mesh.num_elements())
        .map(|e| {
            let x: Vec<Vec3> = p
                .mesh
                .elements
                .element(e)
                .iter()
                .map(|&n| p.mesh.coords[n as usize])
                .collect();
            let mut key: Vec<[u64; 3]> = x[..4].iter().map(|c| c.map(f64::to_bits)).collect();
            key.sort_unstable();
            (key, x)
        })
        .collect()
}

#[test]
fn the_same_cube_at_order_2_is_the_same_mesh() {
    let linear = load(&cube_scene(&fixture("tet_cube.msh"), ""));
    let quadratic = load(&cube_scene(&fixture("tet_cube_order2.msh"), ""));
    let binary = load(&cube_scene(&fixture("tet_cube_binary.msh"), ""));
    assert_eq!(linear.mesh.num_nodes(), quadratic.mesh.num_nodes());
    assert_eq!(linear.mesh.num_elements(), quadratic.mesh.num_elements());
    let (a, b) = (
        elements_by_corners(&linear),
        elements_by_corners(&quadratic),
    );
    assert_eq!(a.len(), linear.mesh.num_elements(), "distinct corner sets");
    let mut worst: f64 = 0.0;
    for (key, x) in &a {
        let y = &b[key];
        // The corners are the same points in the same order (each element's first four
        // are its corners in the file's order, the same in both files).
        assert_eq!(x[..4], y[..4]);
        for k in 4..10 {
            for i in 0..3 {
                worst = worst.max((x[k][i] - y[k][i]).abs());
            }
        }
    }
    println!("largest midside node difference, computed against Gmsh's: {worst:e}");
    // Gmsh prints 16 significant digits, so its midpoints of the unit cube's points may
    // differ from ours in the last bits: 1e-15 is a few units in the last place.
    assert!(worst <= 1e-15, "{worst:e}");
    // ASCII and binary files of the same mesh: the same numbering; the coordinates as in
    // tests/gmsh.rs (16 printed digits against the binary's exact ones).
    assert_eq!(linear.mesh.elements, binary.mesh.elements);
    for (x, y) in linear.mesh.coords.iter().zip(&binary.mesh.coords) {
        assert!((0..3).all(|i| (x[i] - y[i]).abs() <= 1e-15), "{x:?} {y:?}");
    }
    for (s, t) in linear.side_sets.iter().zip(&quadratic.side_sets) {
        assert_eq!(s.faces.len(), t.faces.len(), "side set {}", s.name);
    }
    for (s, t) in linear.node_sets.iter().zip(&quadratic.node_sets) {
        assert_eq!(s.nodes.len(), t.nodes.len(), "node set {}", s.name);
    }
}

/// Total area of a side set's faces (each a flat triangle of its corners).
fn area(p: &Problem, set: &str) -> f64 {
    p.side_set(set)
        .unwrap()
        .faces
        .iter()
        .map(|&(e, f)| {
            let c: Vec<Vec3> = p
                .mesh
                .face_nodes(e, f)
                .take(3)
                .map(|n| p.mesh.coords[n as usize])
                .collect();
            let n = solver::math::cross(
                &solver::math::sub(&c[1], &c[0]),
                &solver::math::sub(&c[2], &c[0]),
            );
            0.5 * solver::math::norm(&n)
        })
        .sum()
}

#[test]
fn triangles_become_the_tetrahedron_faces_under_them() {
    for file in ["tet_cube.msh", "tet_cube_order2.msh"] {
        let p = load(&cube_scene(&fixture(file), ""));
        let m = GmshMesh::read(Path::new(&fixture(file))).unwrap();
        for (set, z) in [("top", 1.0), ("bottom", 0.0)] {
            let faces = &p.side_set(set).unwrap().faces;
            assert_eq!(faces.len(), m.surface_faces(set).unwrap().len());
            for &(e, f) in faces {
                assert_eq!(p.mesh.kind(e as usize), ElementKind::Tet10);
                // All six nodes on the plane, and the face is on the boundary.
                assert!(p
                    .mesh
                    .face_nodes(e, f)
                    .all(|n| p.mesh.coords[n as usize][2] == z));
            }
            let a = area(&p, set);
            println!("{file}: side set {set}, {} faces, area {a}", faces.len());
            // The unit square, summed over ~26 triangles: rounding of order 1e-16 each.
            assert!((a - 1.0).abs() <= 1e-12, "{a}");
        }
        // The bottom node set: every node of its triangles, midside nodes included.
        let bottom = &p.node_set("bottom").unwrap().nodes;
        let on_plane = (0..p.mesh.num_nodes())
            .filter(|&n| p.mesh.coords[n][2] == 0.0)
            .count();
        assert_eq!(bottom.len(), on_plane, "{file}");
    }
}

/// The hexahedral cube as body "h", the tetrahedral one as "t" (its top fixed).
fn mixed_scene() -> String {
    format!(
        r#"
[gmsh]
file = "{}"
[[body]]
name = "h"
gmsh_volume = "hex"
material = {{ model = "linear_elastic", E = 1000.0, nu = 0.3 }}
[[body]]
name = "t"
gmsh_volume = "tet"
material = {{ model = "linear_elastic", E = 1000.0, nu = 0.3 }}
[[side_set]]
name = "hex_top"
gmsh_surface = "hex_top"
[[side_set]]
name = "tet_top"
gmsh_surface = "tet_top"
[[node_set]]
name = "tet_top"
gmsh_group = "tet_top"
[[displacement]]
node_set = "tet_top"
components = ["x", "y", "z"]
value = 0.0
[time]
segments = [{{ end = 1.0, steps = 1 }}]
"#,
        fixture("hex_and_tet.msh")
    )
}

#[test]
fn a_hexahedral_and_a_tetrahedral_volume_make_two_bodies() {
    let p = load(&mixed_scene());
    let b = &p.mesh.bodies;
    assert_eq!(
        (b[0].kind, b[0].num_elements, b[0].num_nodes),
        (ElementKind::Hex8, 8, 27)
    );
    assert_eq!((b[1].kind, b[1].num_elements), (ElementKind::Tet10, 100));
    assert_eq!(b[1].first_node, 27);
    for e in 0..p.mesh.num_elements() {
        assert_eq!(p.mesh.elements.element(e).len(), p.mesh.kind(e).nodes());
    }
    assert_eq!(p.side_set("hex_top").unwrap().faces.len(), 4);
    for set in ["hex_top", "tet_top"] {
        let a = area(&p, set);
        // A quadrangle's area from two of its corners' triangle is half of it.
        let want = if set == "hex_top" { 0.5 } else { 1.0 };
        assert!((a - want).abs() <= 1e-12, "{set}: {a}");
    }
    let top = &p.node_set("tet_top").unwrap().nodes;
    let on_plane = (27..p.mesh.num_nodes())
        .filter(|&n| p.mesh.coords[n][2] == 1.0)
        .count();
    assert_eq!(top.len(), on_plane);
    result::mixed_result_file_reads_everywhere(&p);
}

#[test]
fn solver_check_prints_a_tet_scenes_summary() {
    let dir = common::fresh_dir("gmsh-tet/check");
    let scene = dir.join("cube.toml");
    std::fs::write(&scene, cube_scene(&fixture("tet_cube.msh"), "")).unwrap();
    let out = solver().arg("check").arg(&scene).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    println!("{text}");
    assert!(out.status.success(), "{}", common::stderr_text(&out));
    let p = load(&cube_scene(&fixture("tet_cube.msh"), ""));
    let n = p.mesh.num_nodes();
    assert!(
        text.contains(&format!("1 bodies, 184 elements, {n} nodes")),
        "{text}"
    );
    assert!(
        text.contains("body 'cube': tet10 elements 1..184"),
        "{text}"
    );
    assert!(text.contains("side set 'top': 26 faces"), "{text}");
    result::tet_result_file_reads_everywhere(&p);
}

/// Writes the scene, runs `solver check` and `solver run` on it; both must exit with 2 and
/// the same message, which names the scene file and contains every needle.
fn expect_error(name: &str, text: &str, needles: &[&str]) {
    bad_scene::expect_error("gmsh-tet", name, text, needles);
}

#[test]
fn bad_tetrahedral_meshes_are_refused_by_name() {
    let dir = common::fresh_dir("gmsh-tet/bad");
    let text = std::fs::read_to_string(fixture("tet_cube.msh")).unwrap();
    // The first tetrahedron with two corners swapped: negative volume.
    let block = text.find("3 1 4 184\n").unwrap() + "3 1 4 184\n".len();
    let line_end = block + text[block..].find('\n').unwrap();
    let words: Vec<&str> = text[block..line_end].split(' ').collect();
    let tag = words[0];
    let swapped = format!(
        "{} {} {} {} {}",
        words[0], words[2], words[1], words[3], words[4]
    );
    let inverted = dir.join("inverted.msh");
    std::fs::write(
        &inverted,
        format!("{}{swapped}{}", &text[..block], &text[line_end..]),
    )
    .unwrap();
    expect_error(
        "inverted",
        &cube_scene(&inverted.display().to_string(), ""),
        &[
            "body[0].gmsh_volume",
            &format!("element {tag} (4-node tetrahedron) of physical volume 'cube'"),
            "inverted.msh",
            "inverted or degenerate",
        ],
    );
    // The first top triangle with a corner moved to a bottom node: no tetrahedron's face.
    let block = text.find("2 6 2 26\n").unwrap() + "2 6 2 26\n".len();
    let line_end = block + text[block..].find('\n').unwrap();
    let words: Vec<&str> = text[block..line_end].split_whitespace().collect();
    let moved = format!("{} {} {} 1", words[0], words[1], words[2]);
    let stray = dir.join("stray.msh");
    std::fs::write(
        &stray,
        format!("{}{moved}{}", &text[..block], &text[line_end..]),
    )
    .unwrap();
    expect_error(
        "stray_triangle",
        &cube_scene(&stray.display().to_string(), ""),
        &[
            "side_set[0].gmsh_surface",
            &format!("triangle {} of physical surface 'top'", words[0]),
            "stray.msh",
            "not a face of any body's element",
        ],
    );
    let both = format!(
        "[gmsh]\nfile = \"{}\"\n[[body]]\nname = \"b\"\ngmsh_volume = \"both\"\nmaterial = {{ model = \"linear_elastic\", E = 1.0, nu = 0.3 }}\n[time]\nsegments = [{{ end = 1.0, steps = 1 }}]\n",
        fixture("hex_and_tet.msh")
    );
    expect_error(
        "mixed_volume",
        &both,
        &[
            "body[0].gmsh_volume",
            "physical volume 'both'",
            "100 elements of Gmsh type 4",
            "8 elements of Gmsh type 5",
            "a body is of one element kind",
        ],
    );
}

/// The tet10 and mixed meshes over 1, 2 and 3 ranks: every element owned once, every node
/// owned once, each rank's elements in their global kind and node order, their nodes local.
#[test]
fn tet_and_mixed_meshes_partition_with_ghosts() {
    let cube = load(&cube_scene(&fixture("tet_cube.msh"), ""));
    let mixed = load(&mixed_scene());
    for p in [&cube, &mixed] {
        let g = &p.mesh;
        for ranks in 1..=3 {
            let d = partition::Decomposition::partition(g.num_nodes(), &g.elements, ranks).unwrap();
            let mut owned_elements = vec![0; g.num_elements()];
            let mut owned_nodes = vec![0; g.num_nodes()];
            for r in 0..ranks {
                let l = solver::mesh::local::LocalMesh::new(g, &d, r);
                for (k, &e) in l.element_global.iter().enumerate() {
                    let global: Vec<u32> = l
                        .elements
                        .element(k)
                        .iter()
                        .map(|&n| l.node_global[n as usize])
                        .collect();
                    assert_eq!(global, g.elements.element(e as usize));
                    assert_eq!(l.kind(k), g.kind(e as usize));
                    owned_elements[e as usize] += usize::from(l.element_owned[k]);
                }
                for &n in &l.node_global[..l.num_owned_nodes] {
                    owned_nodes[n as usize] += 1;
                }
            }
            assert!(owned_elements.iter().all(|&c| c == 1), "{ranks} ranks");
            assert!(owned_nodes.iter().all(|&c| c == 1), "{ranks} ranks");
        }
    }
}
