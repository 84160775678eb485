//! Nodal contact pressure: each active constraint's normal force over its slave node's
//! area in the pair, the integral of the node's bilinear shape function over the pair's
//! slave faces around it (see [`crate::fem::face::nodal_areas`]).
//!
//! Computed on rank 0 from the gathered displacements of the slave faces, summing face by face in the
//! order of the pair's slave faces and constraint by constraint in the order of the active
//! set: the same numbers on any number of ranks.

use super::active::Active;
use crate::math::{add, Vec3};
use crate::problem::{ContactPair, Kinematics, Problem};

/// The area of each slave node of `pair` (in the order of `pair.slave_nodes`): the sum over
/// the pair's slave faces of the integral of the node's shape function, with the corner
/// positions `position(node)`. Face corners that are not slave nodes of the pair are
/// skipped (none are, for a pair from a scene).
pub fn slave_areas(pair: &ContactPair, position: impl Fn(u32) -> Vec3) -> Vec<f64> {
    let mut area = vec![0.0; pair.slave_nodes.len()];
    for nodes in pair.slave_face_nodes.iter() {
        let x: [Vec3; 4] = std::array::from_fn(|a| position(nodes[a]));
        let a = super::facet::nodal_areas(&x);
        for (k, &n) in nodes.iter().enumerate() {
            if let Ok(i) = pair.slave_nodes.binary_search(&n) {
                area[i] += a[k];
            }
        }
    }
    area
}

/// The contact pressure of every node (global order; compressive > 0): the sum over the
/// node's active constraints of the normal force over the node's slave area in the
/// constraint's pair, measured in the current configuration under large kinematics and in
/// the reference one under small (as pressure loads are applied). Zero at nodes without an
/// active constraint, and for a constraint whose node has no area (a collapsed face).
/// `displacement` gives a node's displacement by global id; it is asked only under large
/// kinematics and only for the nodes of the slave faces of pairs with an active constraint
/// (`pressure_nodes`).
pub fn contact_pressure(
    problem: &Problem,
    active: &[Active],
    displacement: impl Fn(u32) -> Vec3,
) -> Vec<f64> {
    let mut pressure = vec![0.0; problem.mesh.num_nodes()];
    for (n, p) in node_pressures(problem, active, displacement) {
        pressure[n as usize] = p;
    }
    pressure
}

/// `contact_pressure` at the nodes where it may differ from zero, as (global id, pressure)
/// by id: those with an active constraint whose node has an area (the same sums, in the
/// same order). A writer holds these rather than a value for every node of the mesh.
pub fn node_pressures(
    problem: &Problem,
    active: &[Active],
    displacement: impl Fn(u32) -> Vec3,
) -> Vec<(u32, f64)> {
    let mut pressure = std::collections::BTreeMap::new();
    if active.is_empty() {
        return Vec::new();
    }
    let current = problem.kinematics == Kinematics::Large;
    let position = |n: u32| {
        let x = problem.reference_position(n);
        if current {
            add(&x, &displacement(n))
        } else {
            x
        }
    };
    let mut areas: Vec<Option<Vec<f64>>> = vec![None; problem.contacts.len()];
    for a in active {
        let pair = &problem.contacts[a.pair];
        let area = areas[a.pair].get_or_insert_with(|| slave_areas(pair, position));
        let Ok(i) = pair.slave_nodes.binary_search(&a.slave) else {
            continue;
        };
        if area[i] > 0.0 {
            *pressure.entry(a.slave).or_insert(0.0) += a.normal_force / area[i];
        }
    }
    pressure.into_iter().collect()
}

/// The nodes whose displacement `contact_pressure` reads, sorted: those of the slave faces
/// of the pairs with an active constraint, under large kinematics (none under small).
pub fn pressure_nodes(problem: &Problem, active: &[Active]) -> Vec<u32> {
    if problem.kinematics != Kinematics::Large {
        return Vec::new();
    }
    let mut on = vec![false; problem.contacts.len()];
    for a in active {
        on[a.pair] = true;
    }
    let mut nodes: Vec<u32> = problem
        .contacts
        .iter()
        .zip(&on)
        .filter(|(_, &on)| on)
        .flat_map(|(pair, _)| pair.slave_face_nodes.iter().flatten().copied())
        .collect();
    nodes.sort_unstable();
    nodes.dedup();
    nodes
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::GlobalMesh;

    /// A 2 x 1 grid of unit faces in the plane z = 0 as a pair's slave surface, nodes
    /// 0 1 2 / 3 4 5 (x = 0, 1, 2; y = 0, 1).
    fn strip() -> (ContactPair, Vec<Vec3>) {
        let coords: Vec<Vec3> = (0..6)
            .map(|n| [(n % 3) as f64, (n / 3) as f64, 0.0])
            .collect();
        let mut pair = ContactPair::new(
            "p".into(),
            &GlobalMesh::default(),
            Vec::new(),
            (0..6).collect(),
            0.0,
            0.1,
            0.1,
            0.0,
            None,
            1.0,
        );
        pair.slave_faces = std::sync::Arc::new(vec![(0, 5), (1, 5)]);
        pair.slave_face_nodes = std::sync::Arc::new(vec![[0, 1, 4, 3], [1, 2, 5, 4]]);
        (pair, coords)
    }

    /// Equal to a few units in the last place (the Gauss points are not exact binary numbers).
    fn assert_close(a: &[f64], b: &[f64]) {
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= 1e-15 * y.abs(), "{a:?} vs {b:?}");
        }
    }

    #[test]
    fn a_node_shared_by_two_faces_has_both_shares() {
        let (pair, coords) = strip();
        let area = slave_areas(&pair, |n| coords[n as usize]);
        assert_close(&area, &[0.25, 0.5, 0.25, 0.25, 0.5, 0.25]);
        // Stretched to twice the length along x: every share doubles.
        let area = slave_areas(&pair, |n| {
            let x = coords[n as usize];
            [2.0 * x[0], x[1], x[2]]
        });
        assert_close(&area, &[0.5, 1.0, 0.5, 0.5, 1.0, 0.5]);
    }
}
