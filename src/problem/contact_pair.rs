//! The description of a contact pair: master faces, slave nodes and the pair's settings.

use crate::mesh::GlobalMesh;
use std::sync::Arc;

/// How a pair's contact constraints are formed.
#[derive(serde::Serialize, serde::Deserialize, Clone, Copy, Debug, Default, PartialEq, Eq)]
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

/// Per edge of a master facet, the facet across it and that facet's edge index, if any.
pub type EdgeNeighbours = [Option<(u32, u8)>; 4];

/// Per slave node, the points of the slave surface around it (`ContactPair::slave_tributaries`).
pub type Tributaries = Arc<Vec<Vec<[crate::math::Vec3; 2]>>>;

/// A validated contact pair. The lists are shared: the passes of general contact that have
/// a body in the same role hold one copy of its lists (`scene::validate::general`).
#[derive(serde::Serialize, serde::Deserialize, Clone, Debug)]
pub struct ContactPair {
    pub name: String,
    /// (element, local face) of each master facet, ascending: a "face" of the pair is a
    /// contact facet (`contact::facet`), a hexahedron's face or one of the four
    /// sub-triangles of a tet10's face (which then appears four times here).
    pub master_faces: Arc<Vec<(u32, u8)>>,
    /// Global node ids of each master facet, ordered with an outward normal (a triangle's
    /// fourth repeats its third).
    pub face_nodes: Arc<Vec<[u32; 4]>>,
    /// For each master face and edge k (between corners k and k+1), the master face across
    /// it and that face's edge index, if any.
    pub neighbours: Arc<Vec<EdgeNeighbours>>,
    /// Slave nodes, ascending global ids.
    pub slave_nodes: Arc<Vec<u32>>,
    /// (element, local face) of each slave face, ascending (as given: not per facet).
    pub slave_faces: Arc<Vec<(u32, u8)>>,
    /// Global node ids of each slave facet, ordered with an outward normal.
    pub slave_face_nodes: Arc<Vec<[u32; 4]>>,
    pub discretization: Discretization,
    /// Coulomb coefficient; 0 is frictionless.
    pub mu: f64,
    pub normal_tolerance: f64,
    pub tangential_tolerance: f64,
    pub capture_tolerance: f64,
    /// Slave nodes within this distance of the master surface in the reference
    /// configuration are moved onto it before the run (`contact::adjust`); 0: none.
    pub adjust: f64,
    pub smoothing_width: Option<f64>,
    /// Mean sqrt(area) of the master faces: the length the defaults scale with.
    pub face_size: f64,
    /// The second pass of a general contact body pair (`scene::validate::general`): its
    /// slave nodes are never captured by the search (whose gap, measured along a face's
    /// normal within the tangential tolerance, is negative for a node beside an edge, not
    /// inside the body), only by the penetration audit, when a node is inside an element
    /// of the master body by more than the capture tolerance. Where the first pass holds
    /// the contact zone, the two passes then never tie the same points to each other.
    pub secondary: bool,
    /// A second pass's primary pass (index in the problem's pairs): the audit leaves out
    /// the second pass's nodes on a master face the primary pass ties a node to, where the
    /// primary pass already holds the zone (tying them too would make each pass's slave the
    /// other's master: a circular dependency on non-matching meshes).
    pub partner: Option<usize>,
    /// General contact: each slave node's outward normal (the mean of its slave faces'
    /// unit normals in the reference configuration), by position in `slave_nodes`; a
    /// master face is found for a node only if its normal opposes this. None for
    /// `[[contact]]` pairs, whose side sets already say which faces meet.
    pub slave_normals: Option<Arc<Vec<crate::math::Vec3>>>,
    /// General contact between two bodies: per slave node (by position in
    /// `slave_nodes`), the slave surface around it, as points it is captured by
    /// (`MasterSurface::overlaps`): for each slave facet around the node, the offset from
    /// the node halfway to the facet's centre and the facet's outward normal, in the
    /// reference configuration. A node is captured only where this area overlaps a master
    /// face, not where the two bodies meet along an edge only. None for every other pair.
    pub slave_tributaries: Option<Tributaries>,
    /// Self contact (`scene::validate::general`, a body's exterior nodes against its own
    /// exterior faces): per slave node (by position in `slave_nodes`), the master facets
    /// (ascending indices in the pair) it is never tied to, the faces around it: those
    /// that share a node with a face that holds the node. None for every other pair.
    pub neighbourhood: Option<Vec<Vec<u32>>>,
}

impl ContactPair {
    /// The pair with its slave faces and discretization set.
    pub fn with_slave_faces(
        mut self,
        mesh: &GlobalMesh,
        slave_faces: Vec<(u32, u8)>,
        discretization: Discretization,
    ) -> Self {
        self.slave_face_nodes = Arc::new(
            slave_faces
                .iter()
                .flat_map(|&(e, f)| mesh.contact_facets(e, f))
                .collect(),
        );
        self.slave_faces = Arc::new(slave_faces);
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
            master_faces: Arc::new(master_faces),
            face_nodes: Arc::new(face_nodes),
            neighbours: Arc::new(neighbours),
            slave_nodes: Arc::new(slave_nodes),
            slave_faces: Arc::default(),
            slave_face_nodes: Arc::default(),
            discretization: Discretization::NodeFace,
            mu,
            normal_tolerance,
            tangential_tolerance,
            capture_tolerance,
            adjust: 0.0,
            smoothing_width,
            face_size,
            secondary: false,
            partner: None,
            slave_normals: None,
            slave_tributaries: None,
            neighbourhood: None,
        }
    }

    /// Whether the pair is a self contact (its slave nodes are on its own master faces).
    pub fn is_self(&self) -> bool {
        self.neighbourhood.is_some()
    }

    /// The master facets slave node `i` (its position in `slave_nodes`) is never tied to,
    /// ascending: the faces around it in a self contact, none otherwise.
    pub fn skipped(&self, i: usize) -> &[u32] {
        self.neighbourhood.as_ref().map_or(&[], |n| &n[i])
    }

    /// The outward normal slave node `i` (its position in `slave_nodes`) must oppose.
    pub fn facing(&self, i: usize) -> Option<&crate::math::Vec3> {
        self.slave_normals.as_ref().map(|n| &n[i])
    }

    /// The slave surface around slave node `i` (its position in `slave_nodes`) that a
    /// master face must overlap to capture it; None: no such condition.
    pub fn tributary(&self, i: usize) -> Option<&[[crate::math::Vec3; 2]]> {
        self.slave_tributaries.as_ref().map(|t| &t[i][..])
    }

    /// Whether a slave node not in contact at `gap` from the master surface is captured
    /// (`released`: it was released in this step, when only a clear penetration is).
    pub fn captures(&self, gap: f64, noise: f64, released: bool) -> bool {
        if self.secondary {
            return false;
        }
        gap < -noise * self.face_size || (gap <= self.capture_tolerance && !released)
    }
}
