//! The mortar pairs' surfaces on every rank: the current (and step-start) positions of
//! every node of a mortar pair's slave and master faces, gathered from their owners. A
//! slave node's tie integrates over all slave faces around it and all master faces they
//! overlap, wherever those elements live; with the whole surfaces in hand, each rank
//! computes the ties of the slave nodes it owns, summing in the pair's face order, so a
//! tie is bitwise the same on any number of ranks. (Surfaces are a small fraction of a
//! mesh; gathering them once per contact update costs less than one CG iteration's halo
//! exchange on the meshes this code runs.)

use super::ties::{ties, Face, Tie};
use crate::comm::{message, Comm};
use crate::contact::ghost::position;
use crate::math::{add, Vec3};
use crate::mesh::local::LocalMesh;
use crate::problem::{Discretization, Problem};

/// Node positions of the mortar surfaces, by global id.
pub struct Positions {
    ids: Vec<u32>,
    now: Vec<Vec3>,
    start: Vec<Vec3>,
}

impl Positions {
    /// Gathers the positions at `u` and `start` of every node of every mortar pair's
    /// faces. Collective.
    pub fn gather<C: Comm + ?Sized>(
        comm: &C,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
        start: &[Vec3],
    ) -> Positions {
        let mut nodes: Vec<u32> = Vec::new();
        for pair in problem.contacts.iter() {
            if pair.discretization == Discretization::Mortar {
                nodes.extend(pair.slave_face_nodes.iter().flatten());
                nodes.extend(pair.face_nodes.iter().flatten());
            }
        }
        nodes.sort_unstable();
        nodes.dedup();
        let mine: Vec<(u32, Vec3, Vec3)> = nodes
            .iter()
            .filter_map(|&g| {
                let l = mesh.owned_node(g)?;
                Some((g, position(mesh, u, l), add(&mesh.coords[l], &start[l])))
            })
            .collect();
        let mut all = if comm.size() == 1 {
            mine
        } else {
            message::all_gather(comm, &mine)
        };
        all.sort_by_key(|e| e.0);
        Positions {
            ids: all.iter().map(|e| e.0).collect(),
            now: all.iter().map(|e| e.1).collect(),
            start: all.iter().map(|e| e.2).collect(),
        }
    }

    fn index(&self, g: u32) -> usize {
        self.ids
            .binary_search(&g)
            .expect("every node of a mortar surface is gathered")
    }

    /// The current position of a surface node.
    pub fn now(&self, g: u32) -> Vec3 {
        self.now[self.index(g)]
    }

    /// The position of a surface node at the start of the step.
    pub fn start(&self, g: u32) -> Vec3 {
        self.start[self.index(g)]
    }

    /// The ties, at the current positions, of pair `p`'s slave nodes this rank owns.
    pub fn ties(&self, problem: &Problem, p: usize, mesh: &LocalMesh) -> Vec<Tie> {
        let pair = &problem.contacts[p];
        let wanted: Vec<u32> = pair
            .slave_nodes
            .iter()
            .copied()
            .filter(|&s| mesh.owned_node(s).is_some())
            .collect();
        self.ties_of(problem, p, &wanted, pair.normal_tolerance)
    }

    /// The ties, at the current positions, of pair `p`'s slave nodes in `wanted`
    /// (ascending), with master faces overlapped up to `reach` along the normal.
    pub fn ties_of(&self, problem: &Problem, p: usize, wanted: &[u32], reach: f64) -> Vec<Tie> {
        let pair = &problem.contacts[p];
        let small = crate::contact::ghost::reference_normals(problem);
        let faces = |nodes: &[[u32; 4]]| -> Vec<Face> {
            nodes
                .iter()
                .map(|&n| {
                    let reference = small.then(|| n.map(|g| problem.reference_position(g)));
                    Face::new(n, n.map(|g| self.now(g)), reference)
                })
                .collect()
        };
        let slave: Vec<Face> = faces(&pair.slave_face_nodes)
            .into_iter()
            .filter(|f| f.nodes.iter().any(|n| wanted.binary_search(n).is_ok()))
            .collect();
        ties(&slave, &faces(&pair.face_nodes), wanted, reach, |g| {
            self.now(g)
        })
    }
}
