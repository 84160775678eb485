//! The bracket example (run/examples/bracket.toml): an L-shaped steel bracket made with
//! Gmsh's OpenCASCADE kernel (run/gmsh/bracket.geo), tetrahedra read as 10-node ones,
//! J2 plastic, held at its bolt's bearing ring and resting on an elastic plate of
//! hexahedra (mortar contact), its arm's top pushed sideways. Run as written, checked
//! against the statics and the physics it is meant to show:
//! - equilibrium: the reactions at the arm's top, the bolt and the plate's bottom sum to
//!   zero in every direction, and the contact forces on the foot balance the plate's
//!   bottom reaction;
//! - the bracket yields at the bend, where the moment of the push is largest, and not in
//!   the upper half of the arm, where it is at most half of it (below);
//! - the heel of the foot (under the arm) lifts off the plate while the toe, beyond the
//!   bolt, is pressed into it (prying);
//! - no slave node ends a step inside the plate by more than the capture tolerance.

use crate::common;
use common::{fresh_dir, repo, run_serial};
use solver::output::{contact_status, ResultFile};
use solver::problem::Problem;
use solver::scene::load_scene;

/// The geometry of run/gmsh/bracket.geo: the thickness t of the foot and the arm, the arm's
/// height H, the bolt's axis at x = XB.
const T: f64 = 5.0;
const H: f64 = 40.0;
const XB: f64 = 25.0;

fn nodes_of(p: &Problem, name: &str) -> Vec<u32> {
    p.node_sets
        .iter()
        .find(|s| s.name == name)
        .unwrap_or_else(|| panic!("node set {name}"))
        .nodes
        .clone()
}

fn sum(r: &[[f64; 3]], nodes: &[u32]) -> [f64; 3] {
    nodes.iter().fold([0.0; 3], |a, &n| {
        let f = r[n as usize];
        [a[0] + f[0], a[1] + f[1], a[2] + f[2]]
    })
}

/// The centroid of element e (the mean of its nodes).
fn centroid(p: &Problem, e: usize) -> [f64; 3] {
    let nodes = p.mesh.elements.element(e);
    let mut c = [0.0; 3];
    for &n in nodes {
        for (ci, xi) in c.iter_mut().zip(p.mesh.coords[n as usize]) {
            *ci += xi / nodes.len() as f64;
        }
    }
    c
}

#[test]
fn bracket_bolted_to_a_plate_yields_at_the_bend_and_its_heel_lifts() {
    let p = load_scene(&repo("run/examples/bracket.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(p.mesh.bodies[0].kind, solver::fem::ElementKind::Tet10);
    let out = fresh_dir("bracket").join("bracket.h5");
    let t0 = std::time::Instant::now();
    let (summary, state) = run_serial(&p, Some(out.clone()));
    let wall = t0.elapsed().as_secs_f64();
    assert!(summary.failure.is_none(), "{:?}", summary.failure);
    let f = ResultFile::open(&out).expect("result file");
    let stats = f.stats().unwrap();
    let capture = p.contacts[0].capture_tolerance;
    for (k, s) in stats.iter().enumerate() {
        assert!(
            s.max_penetration <= capture,
            "step {}: a slave node {:.3e} inside the plate",
            k + 1,
            s.max_penetration
        );
    }
    let last = f.num_steps() - 1;
    let r = f.reaction(last).unwrap();
    let (top, bolt, bottom) = (
        sum(&r, &nodes_of(&p, "arm_top")),
        sum(&r, &nodes_of(&p, "washer")),
        sum(&r, &nodes_of(&p, "plate_bottom")),
    );
    let push = top[0];
    println!(
        "wall {wall:.1} s, CG {}, contact updates {}; push {push:.3} N; bolt ({:.3}, {:.3}, {:.3}); plate bottom ({:.3}, {:.3}, {:.3})",
        stats.iter().map(|s| s.cg_iterations).sum::<u64>(),
        stats.iter().map(|s| s.contact_updates).sum::<u64>(),
        bolt[0], bolt[1], bolt[2], bottom[0], bottom[1], bottom[2]
    );
    // Equilibrium: the run stops at a residual of 1e-10 of the reference force (the
    // reactions' norm); summed over a few thousand nodes the unbalance stays below
    // sqrt(3 N) x 1e-10 < 1e-8 of the push.
    for i in 0..3 {
        let unbalance = top[i] + bolt[i] + bottom[i];
        assert!(
            unbalance.abs() <= 1e-8 * push.abs(),
            "component {i}: reactions sum to {unbalance:e} against a push of {push}"
        );
    }
    let contact = state
        .contact_force
        .iter()
        .take(p.mesh.bodies[0].num_nodes)
        .fold([0.0; 3], |a, f| [a[0] + f[0], a[1] + f[1], a[2] + f[2]]);
    for i in 0..3 {
        assert!(
            (contact[i] - bottom[i]).abs() <= 1e-8 * push.abs(),
            "component {i}: contact on the foot {} against the plate's bottom reaction {}",
            contact[i],
            bottom[i]
        );
    }
    check_plastic_zone(&p, &state.plastic_strain, push);
    check_prying(&p, &f, last);
}

/// Yield at the bend, none in the upper half of the arm. The push F at y = H bends the arm
/// with the moment F (H - y) at height y, largest at its root; the foot between the arm and
/// the bolt carries F (H - t / 2) along its length (with the axial force F), so it yields
/// with the arm's root: the plastic zone is the bend and the foot up to the bolt. The bend
/// cannot carry more than its fully plastic moment M_p = sigma_y b t^2 / 4 (plus the
/// hardening's few percent), so above y = H / 2 the moment stays below M_p / 2 = 0.75 M_y,
/// M_y = sigma_y b t^2 / 6 the first-yield moment: elastic there.
fn check_plastic_zone(p: &Problem, eps: &[f64], push: f64) {
    let bracket = &p.mesh.bodies[0];
    let yielded: Vec<(usize, [f64; 3])> = (0..bracket.num_elements)
        .map(|e| bracket.first_element + e)
        .filter(|&e| eps[e] > 0.0)
        .map(|e| (e, centroid(p, e)))
        .collect();
    let peak = (0..bracket.num_elements)
        .map(|e| bracket.first_element + e)
        .max_by(|&a, &b| eps[a].total_cmp(&eps[b]))
        .unwrap();
    let c = centroid(p, peak);
    let (b, sy) = (20.0, 250.0);
    println!(
        "yielded {} of {} elements; largest plastic strain {:.3e} at ({:.2}, {:.2}, {:.2}); \
         highest yielded centroid y = {:.2}; push x lever {:.0} N mm against M_y {:.0}, M_p {:.0}",
        yielded.len(),
        bracket.num_elements,
        eps[peak],
        c[0],
        c[1],
        c[2],
        yielded.iter().map(|(_, c)| c[1]).fold(0.0, f64::max),
        push.abs() * (H - T / 2.0),
        sy * b * T * T / 6.0,
        sy * b * T * T / 4.0
    );
    assert!(!yielded.is_empty(), "the bracket did not yield");
    // Yielded at the bend: elements within a thickness of the inner corner (x = y = t).
    assert!(
        yielded
            .iter()
            .any(|(_, c)| (c[0] - T).abs() < T && (c[1] - T).abs() < T),
        "no element at the bend yielded"
    );
    // The peak between the arm and the bolt's bearing ring (radius 6): where the moment is.
    assert!(c[0] < XB - 6.0 && c[1] < 2.0 * T, "peak at {c:?}");
    for (e, c) in &yielded {
        assert!(c[1] < H / 2.0, "element {} at {c:?} yielded", e + 1);
    }
}

/// The heel (the foot's bottom under the arm, x < t) lifts: every one of its nodes rises
/// and none is in contact; the toe beyond the bolt (x > XB) carries the contact.
fn check_prying(p: &Problem, f: &ResultFile, last: usize) {
    let u = f.displacement(last).unwrap();
    let status = f.contact_status(last).unwrap();
    let cf = f.contact_force(last).unwrap();
    let bracket = &p.mesh.bodies[0];
    let bottom: Vec<usize> = (bracket.first_node..bracket.first_node + bracket.num_nodes)
        .filter(|&n| p.mesh.coords[n][1].abs() < 1e-9)
        .collect();
    let heel: Vec<usize> = bottom
        .iter()
        .copied()
        .filter(|&n| p.mesh.coords[n][0] < T)
        .collect();
    let lift = heel.iter().map(|&n| u[n][1]).fold(f64::INFINITY, f64::min);
    let (toe, inner) = bottom.iter().fold((0.0, 0.0), |(toe, inner), &n| {
        if p.mesh.coords[n][0] > XB {
            (toe + cf[n][1], inner)
        } else {
            (toe, inner + cf[n][1])
        }
    });
    println!(
        "heel: {} nodes, lowest lift {lift:.4e}; contact force on the foot beyond the bolt {toe:.3}, \
         before it {inner:.3}",
        heel.len()
    );
    assert!(!heel.is_empty());
    assert!(lift > 0.0, "a heel node did not rise: {lift}");
    for &n in &heel {
        assert!(
            status[n] == contact_status::FREE || status[n] == contact_status::RELEASED,
            "heel node {} in contact",
            n + 1
        );
    }
    // The plate pushes the toe up (contact forces on the foot along +y) and carries the
    // bolt's pull there: more than half of the contact force is beyond the bolt.
    assert!(
        toe > 0.5 * (toe + inner),
        "toe {toe}, before the bolt {inner}"
    );
}

/// run/gmsh/make_examples writes the mesh twice, ASCII and binary: both read as the same
/// mesh (the same elements and sets, coordinates to the ASCII file's last digit).
#[test]
fn the_bracket_binary_mesh_reads_as_the_ascii_one() {
    let path = repo("run/examples/bracket.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let binary = text.replace("../gmsh/bracket.msh", "../gmsh/bracket_binary.msh");
    assert_ne!(text, binary);
    let dir = fresh_dir("bracket_binary");
    let scene = dir.join("bracket.toml");
    let mesh_dir = repo("run/gmsh").display().to_string();
    std::fs::write(&scene, binary.replace("../gmsh", &mesh_dir)).unwrap();
    let (a, b) = (
        load_scene(&path).unwrap_or_else(|e| panic!("{e}")),
        load_scene(&scene).unwrap_or_else(|e| panic!("{e}")),
    );
    // Gmsh prints ASCII coordinates with 16 significant digits, one short of a round trip:
    // they may differ from the binary file's in the last bits, 1e-15 of the mesh's size
    // (60, the plate) allows a few units in the last place.
    let worst = a
        .mesh
        .coords
        .iter()
        .zip(&b.mesh.coords)
        .flat_map(|(x, y)| (0..3).map(move |i| (x[i] - y[i]).abs()))
        .fold(0.0f64, f64::max);
    assert!(worst <= 60.0 * 1e-15, "{worst:e}");
    assert_eq!(a.mesh.elements, b.mesh.elements);
    assert_eq!(a.mesh.element_body, b.mesh.element_body);
    let sets = |p: &Problem| -> Vec<(String, Vec<u32>)> {
        p.node_sets
            .iter()
            .map(|s| (s.name.clone(), s.nodes.clone()))
            .collect()
    };
    assert_eq!(sets(&a), sets(&b));
}
