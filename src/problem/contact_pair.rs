//! The description of a contact pair: master faces, slave nodes and the pair's settings.

use crate::mesh::GlobalMesh;

/// How a pair's contact constraints are formed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Discretization {
    /// Each slave node tied to one point of a master face (the paper's).
    #[default]
    NodeFace,
    /// Each slave node's gap weighted over the slave surface against the master faces it
    /// overlaps (dual Lagrange multiplier basis): exact on non-matching meshes.
    Mortar,
}

impl Discretization {
    /// Every discretisation with its scene key (`contacts.NAME.discretization`), the
    /// default first.
    pub const KEYS: [(&'static str, Discretization); 2] = [
        ("node_face", Discretization::NodeFace),
        ("mortar", Discretization::Mortar),
    ];

    /// The discretisation a scene key names.
    pub fn from_key(key: &str) -> Option<Discretization> {
        Self::KEYS.iter().find(|(k, _)| *k == key).map(|(_, d)| *d)
    }
}

/// A validated contact pair.
#[derive(Clone, Debug)]
pub struct ContactPair {
    pub name: String,
    /// (element, local face) of each master facet, ascending: a "face" of the pair is a
    /// contact facet (`contact::facet`), a hexahedron's face or one of the four
    /// sub-triangles of a tet10's face (which then appears four times here).
    pub master_faces: Vec<(u32, u8)>,
    /// Global node ids of each master facet, ordered with an outward normal (a triangle's
    /// fourth repeats its third).
    pub face_nodes: Vec<[u32; 4]>,
    /// For each master face and edge k (between corners k and k+1), the master face across
    /// it and that face's edge index, if any.
    pub neighbours: Vec<[Option<(u32, u8)>; 4]>,
    /// Slave nodes, ascending global ids.
    pub slave_nodes: Vec<u32>,
    /// (element, local face) of each slave face, ascending (as given: not per facet).
    pub slave_faces: Vec<(u32, u8)>,
    /// Global node ids of each slave facet, ordered with an outward normal.
    pub slave_face_nodes: Vec<[u32; 4]>,
    pub discretization: Discretization,
    /// Coulomb coefficient; 0 is frictionless.
    pub mu: f64,
    pub normal_tolerance: f64,
    pub tangential_tolerance: f64,
    pub capture_tolerance: f64,
    pub smoothing_width: Option<f64>,
    /// Mean sqrt(area) of the master faces: the length the defaults scale with.
    pub face_size: f64,
}

impl ContactPair {
    /// The pair with its slave faces and discretization set.
    pub fn with_slave_faces(
        mut self,
        mesh: &GlobalMesh,
        slave_faces: Vec<(u32, u8)>,
        discretization: Discretization,
    ) -> Self {
        self.slave_face_nodes = slave_faces
            .iter()
            .flat_map(|&(e, f)| mesh.contact_facets(e, f))
            .collect();
        self.slave_faces = slave_faces;
        self.discretization = discretization;
        self
    }

    #[allow(clippy::too_many_arguments)]
    pub fn new(
        name: String,
        mesh: &GlobalMesh,
        master_faces: Vec<(u32, u8)>,
        slave_nodes: Vec<u32>,
        mu: f64,
        normal_tolerance: f64,
        tangential_tolerance: f64,
        capture_tolerance: f64,
        smoothing_width: Option<f64>,
        face_size: f64,
    ) -> Self {
        let (master_faces, face_nodes): (Vec<(u32, u8)>, Vec<[u32; 4]>) = master_faces
            .iter()
            .flat_map(|&(e, f)| {
                mesh.contact_facets(e, f)
                    .into_iter()
                    .map(move |n| ((e, f), n))
            })
            .unzip();
        let mut edges: std::collections::HashMap<(u32, u32), Vec<(u32, u8)>> =
            std::collections::HashMap::new();
        // Edges per facet: a triangle's fourth node repeats its third (`contact::facet`).
        let sides = |nodes: &[u32; 4]| if nodes[3] == nodes[2] { 3 } else { 4 };
        for (fi, nodes) in face_nodes.iter().enumerate() {
            let m = sides(nodes);
            for k in 0..m {
                let (a, b) = (nodes[k], nodes[(k + 1) % m]);
                edges
                    .entry((a.min(b), a.max(b)))
                    .or_default()
                    .push((fi as u32, k as u8));
            }
        }
        let neighbours = face_nodes
            .iter()
            .enumerate()
            .map(|(fi, nodes)| {
                let m = sides(nodes);
                std::array::from_fn(|k| {
                    if k >= m {
                        return None;
                    }
                    let (a, b) = (nodes[k], nodes[(k + 1) % m]);
                    edges[&(a.min(b), a.max(b))]
                        .iter()
                        .copied()
                        .find(|&(g, _)| g != fi as u32)
                })
            })
            .collect();
        ContactPair {
            name,
            master_faces,
            face_nodes,
            neighbours,
            slave_nodes,
            slave_faces: Vec::new(),
            slave_face_nodes: Vec::new(),
            discretization: Discretization::NodeFace,
            mu,
            normal_tolerance,
            tangential_tolerance,
            capture_tolerance,
            smoothing_width,
            face_size,
        }
    }
}
