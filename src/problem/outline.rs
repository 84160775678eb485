//! A run's problem once it is set up holds the whole mesh as an outline (its bodies and
//! counts, `GlobalMesh::outline`): every rank held the whole mesh's positions,
//! connectivity and element bodies before (60 MB per rank at 10^6 elements). What a run
//! reads of them after its setup is kept here, taken from the whole mesh before it goes:
//! the reference positions of the nodes of every contact pair and of every prescribed
//! node set, each body's centre and size (the support check's lever arms), and the
//! boundary faces of the contact master bodies (the penetration audit names the face a
//! node entered by). Each is read through a `Problem` method (`Problem::outline`) that
//! reads the whole mesh where the problem still has it, so the same values either way.

use super::ContactPair;
use crate::math::Vec3;
use crate::mesh::GlobalMesh;

/// What a set-up run keeps of the whole mesh (see the module's note).
#[derive(serde::Serialize, serde::Deserialize, Clone, Debug, Default)]
pub struct Retained {
    /// Global ids, ascending, and their reference positions.
    ids: Vec<u32>,
    positions: Vec<Vec3>,
    /// Per body, the centre and size of its nodes (`body_frame`).
    frames: Vec<(Vec3, f64)>,
    /// The boundary faces of the contact pairs' master bodies (`BoundaryFace`).
    master_boundary: Vec<BoundaryFace>,
}

/// A boundary face (a face of one element only) of a body: its element, its face, its
/// body and its corners as a contact facet has them (a quadrilateral's four; a 6-node
/// triangle's three corners, the third repeated).
pub type BoundaryFace = (u32, u8, u32, [u32; 4]);

/// The centre (the mean of the nodes' positions, in node order) and size (the largest
/// distance of a node from it, at least the smallest positive number) of a body's nodes.
pub fn frame_of(nodes: &[Vec3]) -> (Vec3, f64) {
    let n = nodes.len() as f64;
    let mut centre = [0.0; 3];
    for x in nodes {
        for i in 0..3 {
            centre[i] += x[i] / n;
        }
    }
    let size = nodes
        .iter()
        .map(|x| {
            (0..3)
                .map(|i| (x[i] - centre[i]).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    (centre, size)
}

/// The boundary faces of the bodies `bodies` (ascending) of a whole mesh, in (element,
/// face) order.
pub fn boundary_of(mesh: &GlobalMesh, bodies: &[u32]) -> Vec<BoundaryFace> {
    mesh.boundary_faces()
        .into_iter()
        .filter_map(|(e, k)| {
            let b = mesh.element_body[e as usize];
            bodies.binary_search(&b).ok()?;
            let nodes: Vec<u32> = mesh.face_nodes(e, k).collect();
            let corner = |a: usize| {
                if nodes.len() == 4 {
                    nodes[a]
                } else {
                    nodes[a.min(2)]
                }
            };
            Some((e, k, b, [0, 1, 2, 3].map(corner)))
        })
        .collect()
}

impl Retained {
    /// What a run of these contact pairs and prescribed node sets reads of its whole mesh
    /// `mesh` after setup.
    pub fn of<'a>(
        contacts: &[ContactPair],
        prescribed: impl Iterator<Item = &'a [u32]>,
        mesh: &GlobalMesh,
    ) -> Self {
        let mut ids: Vec<u32> = Vec::new();
        for pair in contacts {
            ids.extend_from_slice(&pair.slave_nodes);
            ids.extend(pair.face_nodes.iter().flatten());
            ids.extend(pair.slave_face_nodes.iter().flatten());
        }
        for nodes in prescribed {
            ids.extend_from_slice(nodes);
        }
        ids.sort_unstable();
        ids.dedup();
        // Held through the run on every rank: no spare capacity (the lists above name
        // most nodes several times; a collected list may hold up to twice its entries).
        ids.shrink_to_fit();
        let mut master_boundary = boundary_of(mesh, &master_bodies_of(contacts, mesh));
        master_boundary.shrink_to_fit();
        let positions = ids.iter().map(|&n| mesh.coords[n as usize]).collect();
        let frames = mesh
            .bodies
            .iter()
            .map(|b| frame_of(&mesh.coords[b.first_node..b.first_node + b.num_nodes]))
            .collect();
        Retained {
            ids,
            positions,
            frames,
            master_boundary,
        }
    }

    /// The reference position of node `n`.
    pub fn position(&self, n: u32) -> Vec3 {
        match self.ids.binary_search(&n) {
            Ok(i) => self.positions[i],
            Err(_) => panic!("node {} is not among the positions a run keeps", n + 1),
        }
    }

    /// Body `b`'s centre and size (`frame_of`).
    pub fn frame(&self, b: usize) -> (Vec3, f64) {
        self.frames[b]
    }

    /// The boundary faces of the contact pairs' master bodies.
    pub fn master_boundary(&self) -> &[BoundaryFace] {
        &self.master_boundary
    }
}

/// The bodies of every pair's master faces, ascending.
pub fn master_bodies_of(contacts: &[ContactPair], mesh: &GlobalMesh) -> Vec<u32> {
    let mut bodies: Vec<u32> = contacts
        .iter()
        .flat_map(|p| {
            p.master_faces
                .iter()
                .map(|&(e, _)| mesh.body_of_element(e as usize) as u32)
        })
        .collect();
    bodies.sort_unstable();
    bodies.dedup();
    bodies
}
