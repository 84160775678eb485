//! A run's problem is the loaded problem's outline (`Problem::outline`): what the steps
//! read of the whole mesh through it is the whole mesh's, bit for bit.
use solver::problem::Problem;
use std::path::Path;

/// A scene of the repository, loaded.
fn scene(path: &str) -> Problem {
    solver::scene::load_scene(&Path::new(env!("CARGO_MANIFEST_DIR")).join(path))
        .expect("the scene loads")
}

#[test]
fn the_outline_reads_what_the_whole_mesh_gives() {
    // Two bodies with a contact pair and prescribed node sets (node-to-face), a general
    // contact scene of three bodies (passes both ways, self contact off): every value
    // a run reads through the outline is the whole mesh's, bit for bit.
    for path in [
        "run/scenes/sliding/ironing_block.toml",
        "run/scenes/general/paper/capture_release.toml",
    ] {
        let p = scene(path);
        let o = p.outline();
        assert!(o.mesh.is_outline() && o.mesh.coords.is_empty() && o.mesh.elements.is_empty());
        assert_eq!(
            (o.mesh.num_nodes(), o.mesh.num_elements()),
            (p.mesh.num_nodes(), p.mesh.num_elements())
        );
        let mut nodes: Vec<u32> = Vec::new();
        for pair in &p.contacts {
            nodes.extend_from_slice(&pair.slave_nodes);
            nodes.extend(pair.face_nodes.iter().flatten());
            nodes.extend(pair.slave_face_nodes.iter().flatten());
        }
        for bc in &p.dirichlet {
            nodes.extend_from_slice(&p.node_sets[bc.node_set].nodes);
        }
        assert!(!nodes.is_empty(), "{path}");
        for &n in &nodes {
            let (a, b) = (o.reference_position(n), p.reference_position(n));
            assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits), "{path}: node {n}");
        }
        for b in 0..p.mesh.bodies.len() {
            let ((ca, sa), (cb, sb)) = (o.body_frame(b), p.body_frame(b));
            assert_eq!(ca.map(f64::to_bits), cb.map(f64::to_bits));
            assert_eq!(sa.to_bits(), sb.to_bits());
        }
        assert!(!p.master_boundary().is_empty());
        assert_eq!(o.master_boundary(), p.master_boundary());
        for e in 0..p.mesh.num_elements() {
            assert_eq!(o.mesh.body_of_element(e), p.mesh.element_body[e] as usize);
        }
        for n in 0..p.mesh.num_nodes() {
            let body = p
                .mesh
                .bodies
                .iter()
                .position(|b| (b.first_node..b.first_node + b.num_nodes).contains(&n));
            assert_eq!(o.mesh.body_of_node(n), body);
        }
        let (q, whole) = p.clone().into_outline();
        assert_eq!(
            (whole.coords.len(), whole.elements.len()),
            (p.mesh.coords.len(), p.mesh.elements.len())
        );
        assert_eq!(q.master_boundary(), o.master_boundary());
    }
}

#[test]
#[should_panic(expected = "is not among the positions a run keeps")]
fn a_node_the_outline_does_not_keep_is_a_defect_not_a_value() {
    let p = scene("run/scenes/sliding/ironing_block.toml");
    let o = p.outline();
    // A node on no contact surface and in no prescribed set (the slab's interior).
    let mut kept: Vec<u32> = p
        .contacts
        .iter()
        .flat_map(|c| c.slave_nodes.iter().chain(c.face_nodes.iter().flatten()))
        .chain(
            p.contacts
                .iter()
                .flat_map(|c| c.slave_face_nodes.iter().flatten()),
        )
        .chain(
            p.dirichlet
                .iter()
                .flat_map(|bc| &p.node_sets[bc.node_set].nodes),
        )
        .copied()
        .collect();
    kept.sort_unstable();
    let other = (0..o.mesh.num_nodes() as u32)
        .find(|n| kept.binary_search(n).is_err())
        .expect("some node is not kept");
    o.reference_position(other);
}
