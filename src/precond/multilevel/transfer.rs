//! The fine level's transfer: Q, whose columns are the six rigid-body modes of every
//! fine-level aggregate of nodes (projected on the free directions of constrained nodes).
//! Restriction Q^T r sums each aggregate on one rank, over its nodes in global node order
//! (values of nodes owned elsewhere fetched first), and every rank gathers all aggregates:
//! the coarse vector is the same on every rank and on any number of ranks.

use super::aggregation::{aggregate, StrongMesh};
use super::prolongator::MODES;
use crate::comm::{message, Comm};
use crate::math::Vec3;
use crate::mesh::local::LocalMesh;
use crate::mesh::whole::Whole;
use crate::mesh::GlobalMesh;
use crate::precond::aggregates::Aggregates;

/// Mesh neighbours farther apart than this times the shortest distance from either to a
/// neighbour are weakly coupled and not aggregated together (`StrongMesh`). Measured on
/// the Hertz example x2 (one element thick, graded): 3233 CG iterations with every
/// neighbour aggregated, 756 with this ratio; cubes (diagonals 1.41 and 1.73) keep all.
pub const STRONG_RATIO: f64 = 2.0;

/// Meshes of at most this many nodes get one aggregate per node: the first coarse level
/// is then the fine operator itself, factored directly (its rotation modes have no
/// stiffness and are left out), and CG converges in a few iterations per model problem.
pub const SINGLETON_NODES: usize = 300;

pub struct Transfer {
    pub num_aggregates: usize,
    /// The aggregates (the aggregate of each local node, offsets scaled by each aggregate's
    /// size, their centres and sizes): restriction, prolongation, probes and colouring.
    pub aggregates: Aggregates,
    /// The body of every aggregate (aggregates follow mesh edges, so never span two).
    pub body: Vec<u32>,
}

/// The fine-level aggregates of the whole mesh `g`: the aggregate of every node, and
/// every aggregate's centre (the mean of its nodes' positions, in node order), scale (the
/// largest distance of its nodes from the centre, at least 1e-12 of the mesh's diagonal)
/// and body.
fn whole_aggregates(g: &GlobalMesh) -> (Vec<u32>, Vec<Vec3>, Vec<f64>, Vec<u32>) {
    let n = g.num_nodes();
    let (agg_of, na) = fine_aggregates(g);
    let mut centre = vec![[0.0; 3]; na];
    let mut count = vec![0usize; na];
    for a in 0..n {
        let k = agg_of[a] as usize;
        for i in 0..3 {
            centre[k][i] += g.coords[a][i];
        }
        count[k] += 1;
    }
    for k in 0..na {
        for i in 0..3 {
            centre[k][i] /= count[k] as f64;
        }
    }
    let mut scale = vec![0.0f64; na];
    for a in 0..n {
        let k = agg_of[a] as usize;
        let d = crate::math::sub(&g.coords[a], &centre[k]);
        scale[k] = scale[k].max(crate::math::dot(&d, &d).sqrt());
    }
    let floor = g.bounding_diagonal() * 1e-12;
    scale
        .iter_mut()
        .for_each(|s| *s = s.max(floor).max(f64::MIN_POSITIVE));
    let mut body = vec![0u32; na];
    for (b, info) in g.bodies.iter().enumerate() {
        for a in info.first_node..info.first_node + info.num_nodes {
            body[agg_of[a] as usize] = b as u32;
        }
    }
    (agg_of, centre, scale, body)
}

/// The fine-level aggregates of the whole mesh: the aggregate of every node and their
/// number (one per node on a mesh of at most SINGLETON_NODES nodes).
pub fn fine_aggregates(g: &GlobalMesh) -> (Vec<u32>, usize) {
    let n = g.num_nodes();
    if n <= SINGLETON_NODES {
        ((0..n as u32).collect(), n)
    } else {
        aggregate(&mut StrongMesh::new(g, STRONG_RATIO), &vec![true; n])
    }
}

impl Transfer {
    /// Aggregates the global node graph on rank 0, which holds the whole mesh (`whole`),
    /// and plans the sums from each rank's part of them (collective).
    pub fn new<C: Comm + ?Sized>(comm: &C, whole: Option<&Whole>, mesh: &LocalMesh) -> Self {
        let made = whole.map(|w| whole_aggregates(&w.mesh));
        let (centre, scale, body): (Vec<Vec3>, Vec<f64>, Vec<u32>) = message::broadcast(
            comm,
            made.as_ref()
                .map(|(_, centre, scale, body)| (centre.clone(), scale.clone(), body.clone()))
                .as_ref(),
        );
        let num_aggregates = centre.len();
        let agg_of = made.map(|(agg_of, ..)| agg_of);
        let aggregates =
            Aggregates::scattered(comm, mesh, whole.zip(agg_of.as_deref()), (centre, scale));
        Transfer {
            body,
            num_aggregates,
            aggregates,
        }
    }

    pub fn dim(&self) -> usize {
        MODES * self.num_aggregates
    }

    /// The coarse near-nullspace: the coefficients of the six global rigid-body modes
    /// (rotations about `origin`, divided by `length`) in every aggregate's modes.
    pub fn nullspace(&self, origin: &Vec3, length: f64) -> RigidModes {
        RigidModes {
            at: (0..self.num_aggregates)
                .map(|k| {
                    let (centre, scale) = self.aggregates.centre_and_scale(k);
                    (crate::math::sub(&centre, origin), scale)
                })
                .collect(),
            length,
        }
    }
}

/// The first coarse level's near-nullspace, each row formed when asked for from its
/// aggregate's centre (less the origin) and scale: every rank needs rows of any aggregate
/// in the build, and the rows held whole took six times the memory (1.58 MB per rank at
/// n = 40, 32928 unknowns, against 0.18 MB).
pub struct RigidModes {
    at: Vec<(Vec3, f64)>,
    length: f64,
}

impl RigidModes {
    /// Row `i` (unknown `i % MODES` of aggregate `i / MODES`): a translation's row has its
    /// 1 and e_a x c / length in the rotation about each axis a, a rotation's row its
    /// scale / length.
    pub fn row(&self, i: usize) -> [f64; MODES] {
        let (c, scale) = &self.at[i / MODES];
        let r = i % MODES;
        let mut row = [0.0; MODES];
        if r < 3 {
            row[r] = 1.0;
            for a in 0..3 {
                let mut e = [0.0; 3];
                e[a] = 1.0;
                row[3 + a] = crate::math::cross(&e, c)[r] / self.length;
            }
        } else {
            row[r] = scale / self.length;
        }
        row
    }

    /// Every row.
    pub fn rows(&self) -> Vec<[f64; MODES]> {
        (0..MODES * self.at.len()).map(|i| self.row(i)).collect()
    }
}
