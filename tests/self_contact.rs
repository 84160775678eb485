//! Self contact (`[general_contact] self`): a body's exterior nodes against its own
//! exterior faces. The reference is symmetry: a U symmetric about x = 0 squeezed until its
//! arms press on each other on that plane (run/scenes/self/u_full.toml, self contact on
//! the whole U) against its half model with a frictionless rigid wall on the plane
//! (u_half.toml, an explicit pair against a prescribed block), which involves no self
//! contact at all.

use crate::common;
use common::bad_scene::expect_error;
use common::{fresh_dir, repo, run_serial};
use solver::contact::audit::contains;
use solver::math::Vec3;
use solver::output::ResultFile;
use solver::problem::Problem;
use solver::run::RunSummary;
use solver::scene::load_scene;

/// Loads and runs a scene to a result file; the run must complete.
fn run_file(rel: &str, dir: &std::path::Path) -> (Problem, RunSummary, ResultFile) {
    let p = load_scene(&repo(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"));
    let out = dir.join(format!("{}.h5", p.name));
    let (summary, _) = run_serial(&p, Some(out.clone()));
    if let Some(f) = &summary.failure {
        panic!("{rel}: run failed: {f}");
    }
    let f = ResultFile::open(&out).unwrap();
    (p, summary, f)
}

/// The node of `coords` at `x` (to 1e-9: the two meshes are made by the same Gmsh
/// construction, and a mirrored coordinate differs from its image by round-off).
fn node_at(coords: &[Vec3], x: &Vec3) -> usize {
    coords
        .iter()
        .position(|c| (0..3).all(|i| (c[i] - x[i]).abs() <= 1e-9))
        .unwrap_or_else(|| panic!("no node at {x:?}"))
}

/// The U's half against its whole: at every step the whole U's node and its mirror image
/// move as the half model's node (the mirror's displacement mirrored), to 1e-6 of the
/// largest displacement; both count the same nodes in contact, carry the same contact
/// force, and no node of the whole U ends inside one of its elements.
#[test]
fn a_u_squeezed_shut_matches_its_half_model_on_a_rigid_wall() {
    full_against_half("run/scenes/self/u_full.toml", "run/scenes/self/u_half.toml");
}

/// The same under small kinematics, pushed 0.5 (the half model's wall takes 20 nodes).
#[test]
fn a_u_squeezed_shut_under_small_kinematics_matches_its_half_model() {
    full_against_half(
        "run/scenes/self/u_full_small.toml",
        "run/scenes/self/u_half_small.toml",
    );
}

/// The test of the whole U (a scene file) against its half: see
/// `a_u_squeezed_shut_matches_its_half_model_on_a_rigid_wall`.
fn full_against_half(full: &str, half: &str) {
    let dir = fresh_dir(&format!("self-contact/{}", full.replace('/', "_")));
    let (full, full_summary, ff) = run_file(full, &dir);
    let (half, half_summary, hf) = run_file(half, &dir);
    // One self contact pass: the U is the only body.
    assert_eq!(full.contacts.len(), 1);
    assert!(full.contacts[0].is_self());
    let u = &half.mesh.bodies[0];
    let matches: Vec<(usize, usize, usize)> = (u.first_node..u.first_node + u.num_nodes)
        .map(|n| {
            let x = half.mesh.coords[n];
            let m = [-x[0], x[1], x[2]];
            (
                n,
                node_at(&full.mesh.coords, &x),
                node_at(&full.mesh.coords, &m),
            )
        })
        .collect();
    assert_eq!(ff.num_steps(), hf.num_steps());
    let mut worst = 0.0f64;
    for step in 0..ff.num_steps() {
        let (uf, uh) = (
            ff.displacement(step).unwrap(),
            hf.displacement(step).unwrap(),
        );
        let scale = uf.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        let mut diff = 0.0f64;
        for &(h, f, m) in &matches {
            let mirrored = [-uf[m][0], uf[m][1], uf[m][2]];
            for i in 0..3 {
                diff = diff.max((uf[f][i] - uh[h][i]).abs());
                diff = diff.max((mirrored[i] - uh[h][i]).abs());
            }
        }
        let (cf, ch) = (
            &full_summary.steps[step].contact,
            &half_summary.steps[step].contact,
        );
        println!(
            "step {step}: max |u| {scale:.6e}, full against half {:.3e} of it; in contact: \
             full {}, half {}; max penetration: full {:.3e}, half {:.3e}",
            diff / scale,
            cf.active,
            ch.active,
            cf.max_penetration,
            ch.max_penetration
        );
        // 1e-6 of the largest displacement: the acceptance tolerance of issue 42 (both
        // runs converge to 1e-10 of their reference force).
        assert!(diff <= 1e-6 * scale, "step {step}: {diff:e} of {scale:e}");
        // One side of the zone is tied, as many nodes as the half model ties to the wall.
        assert_eq!(cf.active, ch.active, "step {step}");
        worst = worst.max(cf.max_penetration);
        assert_no_node_inside(&full, &uf, step);
    }
    // The gap closes and contact carries load: the last step ties nodes and the contact
    // force across the plane is the wall's, to 1e-6 of itself.
    let last = ff.num_steps() - 1;
    assert!(full_summary.steps[last].contact.active > 0);
    let force_x = |f: &ResultFile, p: &Problem, left: bool| {
        let c = f.contact_force(last).unwrap();
        (0..c.len())
            // The U is body 0 of either scene.
            .filter(|&n| n < p.mesh.bodies[0].num_nodes && (!left || p.mesh.coords[n][0] < 0.0))
            .map(|n| c[n][0])
            .sum::<f64>()
    };
    let (full_force, half_force) = (force_x(&ff, &full, true), force_x(&hf, &half, false));
    println!("contact force on the left half: full {full_force:.9e}, half {half_force:.9e}; deepest penetration {worst:.3e}");
    assert!(half_force.abs() > 0.0);
    // 1e-6: the displacements' tolerance, for the forces they carry.
    assert!((full_force - half_force).abs() <= 1e-6 * half_force.abs());
}

/// No node of the U lies inside one of its elements that does not hold it, deeper than
/// 1e-9 of the element: each element is shrunk about its centroid by that much, so a node
/// on its surface (the two arms' nodes meet on the plane) is outside it.
fn assert_no_node_inside(p: &Problem, u: &[[f64; 3]], step: usize) {
    let x: Vec<Vec3> = (0..p.mesh.coords.len())
        .map(|n| std::array::from_fn(|i| p.mesh.coords[n][i] + u[n][i]))
        .collect();
    for e in 0..p.mesh.elements.len() {
        let nodes = p.mesh.elements.element(e);
        let c: Vec<Vec3> = nodes.iter().map(|&n| x[n as usize]).collect();
        let mid: Vec3 = std::array::from_fn(|i| c.iter().map(|v| v[i]).sum::<f64>() / 8.0);
        let shrunk: [Vec3; 8] = std::array::from_fn(|a| {
            std::array::from_fn(|i| mid[i] + (1.0 - 1e-9) * (c[a][i] - mid[i]))
        });
        let lo: Vec3 =
            std::array::from_fn(|i| shrunk.iter().map(|v| v[i]).fold(f64::MAX, f64::min));
        let hi: Vec3 =
            std::array::from_fn(|i| shrunk.iter().map(|v| v[i]).fold(f64::MIN, f64::max));
        for (n, xn) in x.iter().enumerate() {
            if nodes.contains(&(n as u32)) || (0..3).any(|i| xn[i] < lo[i] || xn[i] > hi[i]) {
                continue;
            }
            assert!(
                !contains(&shrunk, xn),
                "step {step}: node {n} inside element {e}"
            );
        }
    }
}

const BLOCK: &str = r#"
[[body]]
name = "a"
box = { min = [0.0, 0.0, 0.0], max = [1.0, 1.0, 1.0] }
divisions = [2, 2, 2]
material = { model = "linear_elastic", E = 1.0e6, nu = 0.3 }

[[body]]
name = "wall"
box = { min = [0.0, 0.0, 1.0], max = [1.0, 1.0, 2.0] }
divisions = [1, 1, 1]
material = { model = "linear_elastic", E = 1.0e6, nu = 0.3 }

[[node_set]]
name = "wall_all"
body = "wall"
box = { min = [-1.0, -1.0, -1.0], max = [3.0, 3.0, 3.0] }

[[displacement]]
node_set = "wall_all"
components = ["x", "y", "z"]
value = 0.0

[time]
segments = [{ end = 1.0, steps = 1 }]
"#;

/// `self` takes true, false or a list of bodies that can touch themselves; mortar self
/// contact is refused.
#[test]
fn bad_self_contact_keys_are_refused_by_name() {
    let with = |g: &str| format!("{BLOCK}\n[general_contact]\n{g}\n");
    let cases: [(&str, &str, &[&str]); 6] = [
        (
            "self_number",
            "self = 3",
            &[
                "general_contact.self",
                "expected true, false or a list of body names",
            ],
        ),
        (
            "self_not_a_name",
            "self = [1]",
            &["general_contact.self[0]", "expected a body name"],
        ),
        (
            "self_unknown",
            "self = [\"nobody\"]",
            &["general_contact.self[0]", "no body named 'nobody'"],
        ),
        (
            "self_rigid",
            "self = [\"wall\"]",
            &["general_contact.self[0]", "every node prescribed"],
        ),
        (
            "self_left_out",
            "self = [\"a\"]\nexclude = [[\"a\"]]",
            &["general_contact.self[0]", "left out"],
        ),
        (
            "self_mortar",
            "self = true\ndiscretization = \"mortar\"",
            &["general_contact.self", "node-to-face only"],
        ),
    ];
    for (name, g, needles) in cases {
        expect_error("self-contact", name, &with(g), needles);
    }
    // A body pair of one body is not a self contact's key.
    expect_error(
        "self-contact",
        "pair_of_one",
        &with("[[general_contact.pair]]\nbodies = [\"a\", \"a\"]"),
        &["general_contact.pair[0].bodies", "two different bodies"],
    );
}

/// The self contact pass of `self = true` leaves the prescribed body out, and a node's
/// neighbourhood is the faces that touch its own faces. On the 2 x 2 x 2 block (24 faces,
/// four on each side): the corner (0, 0, 0) is on one face of each of its three sides,
/// each holding that side's centre node, which is on all four faces of the side: 12
/// faces. The centre (0.5, 0.5, 0) of the side z = 0 is on its four faces, which hold the
/// side's edge nodes, on two faces each of the four sides around it: 4 + 8 = 12.
#[test]
fn self_contact_pass_skips_rigid_bodies_and_the_faces_around_a_node() {
    let p = common::problem(&format!("{BLOCK}\n[general_contact]\nself = true\n"));
    let selfs: Vec<_> = p.contacts.iter().filter(|c| c.is_self()).collect();
    assert_eq!(selfs.len(), 1);
    let c = selfs[0];
    assert_eq!(c.name, "general:a/self");
    assert_eq!(c.master_faces.len(), 24);
    let skipped_at = |x: [f64; 3]| {
        let n = (0..p.mesh.coords.len())
            .find(|&n| p.mesh.coords[n] == x)
            .unwrap() as u32;
        c.skipped(c.slave_nodes.binary_search(&n).unwrap()).len()
    };
    assert_eq!(skipped_at([0.0, 0.0, 0.0]), 12);
    assert_eq!(skipped_at([0.5, 0.5, 0.0]), 12);
    // The centre of the side x = 1 is not near the side x = 0: its faces are not skipped.
    let far = c.skipped(
        c.slave_nodes
            .binary_search(
                &((0..p.mesh.coords.len())
                    .find(|&n| p.mesh.coords[n] == [1.0, 0.5, 0.5])
                    .unwrap() as u32),
            )
            .unwrap(),
    );
    assert!(far.iter().all(|&f| {
        c.face_nodes[f as usize]
            .iter()
            .any(|&n| p.mesh.coords[n as usize][0] > 0.0)
    }));
}

/// The self contact's set (one side of the zone, its ties' normals) carries across a
/// restart: the U killed after step 7 (8 nodes in contact) and continued ends bitwise
/// identical to the uninterrupted run.
#[test]
fn u_squeezed_shut_killed_after_step_7_restarts_bitwise() {
    let scene = repo("run/scenes/self/u_full.toml").display().to_string();
    common::restart::killed_and_restarted_is_identical(
        &scene,
        &fresh_dir("self-contact/restart"),
        7,
    );
}

/// Self contact on bodies that do not fold ties nothing: the 8-block stack of
/// tests/general_contact.rs with `self = true` (8 more passes, each block's nodes against
/// its own faces) gives bitwise the answer without, step by step the same nodes in
/// contact. A node is never tied to the faces around it, nor to its block's faces on the
/// same side (not facing it), and the opposite sides are a block's height away.
#[test]
fn self_contact_on_blocks_that_do_not_fold_ties_nothing() {
    let text = std::fs::read_to_string(repo("run/scenes/general/stack8.toml")).unwrap();
    let with = text.replace("[general_contact]\n", "[general_contact]\nself = true\n");
    let (p, q) = (common::problem(&text), common::problem(&with));
    assert_eq!(q.contacts.len(), p.contacts.len() + 8);
    let (a_summary, a) = common::solve(&p);
    let (b_summary, b) = common::solve(&q);
    assert_eq!(a.displacement, b.displacement);
    for (x, y) in a_summary.steps.iter().zip(&b_summary.steps) {
        assert_eq!(x.contact.active, y.contact.active);
    }
}
