//! Which contact pairs' bodies are near enough for their search to find anything: the broad
//! phase of the contact search. General contact makes a pass per ordered body pair, so a
//! scene of B bodies has B (B - 1) passes, of which only those of touching or neighbouring
//! bodies can tie a node; the others are left out of the ghost exchange and the search
//! before any per-node work. The test is conservative and exact: a pass is left out only
//! when no face of its master bodies can reach the box of its slave nodes within the margin
//! the ghost exchange sends faces by (`margin`), so it changes no result.

use crate::comm::Comm;
use crate::math::{add, norm, sub, Vec3};
use crate::mesh::local::LocalMesh;
use crate::mesh::GlobalMesh;
use crate::problem::{ContactPair, Problem};

/// Per body, over every rank: the box of its nodes at the current configuration and the
/// largest diagonal of its elements' boxes (at least the diagonal of any of its faces, as
/// `ghost` measures a face: both ends of a face diagonal are in the element's box, and
/// rounding is monotone).
struct BodyBoxes {
    /// -lo[3], hi[3], largest element diagonal: seven numbers per body.
    values: Vec<f64>,
}

impl BodyBoxes {
    /// Collective: each rank's owned elements, then the maximum over the ranks (exact).
    fn new<C: Comm + ?Sized>(comm: &C, problem: &Problem, mesh: &LocalMesh, u: &[Vec3]) -> Self {
        let mut values = vec![f64::NEG_INFINITY; 7 * problem.mesh.bodies.len()];
        for e in 0..mesh.elements.len() {
            if !mesh.element_owned[e] {
                continue;
            }
            let mut lo = [f64::INFINITY; 3];
            let mut hi = [f64::NEG_INFINITY; 3];
            for &n in mesh.elements.element(e) {
                let x = add(&mesh.coords[n as usize], &u[n as usize]);
                for i in 0..3 {
                    lo[i] = lo[i].min(x[i]);
                    hi[i] = hi[i].max(x[i]);
                }
            }
            let b = &mut values[7 * mesh.element_body[e] as usize..][..7];
            for i in 0..3 {
                b[i] = b[i].max(-lo[i]);
                b[3 + i] = b[3 + i].max(hi[i]);
            }
            b[6] = b[6].max(norm(&sub(&hi, &lo)));
        }
        comm.max_f64(&mut values);
        BodyBoxes { values }
    }

    fn lo(&self, b: usize, i: usize) -> f64 {
        -self.values[7 * b + i]
    }

    fn hi(&self, b: usize, i: usize) -> f64 {
        self.values[7 * b + 3 + i]
    }

    fn diagonal(&self, b: usize) -> f64 {
        self.values[7 * b + 6]
    }
}

/// The bodies whose node ranges meet [first, last] of the pair's slave nodes (ascending
/// ids; a body's nodes are consecutive): every body holding one of them, and perhaps more.
fn slave_bodies(mesh: &GlobalMesh, pair: &ContactPair) -> std::ops::Range<usize> {
    let (Some(&first), Some(&last)) = (pair.slave_nodes.first(), pair.slave_nodes.last()) else {
        return 0..0;
    };
    let of = |n: u32| {
        mesh.bodies
            .partition_point(|b| b.first_node + b.num_nodes <= n as usize)
    };
    of(first)..of(last) + 1
}

/// The bodies whose element ranges meet those of the pair's master faces (ascending by
/// element; a body's elements are consecutive).
fn master_bodies(mesh: &GlobalMesh, pair: &ContactPair) -> std::ops::Range<usize> {
    let (Some(&(first, _)), Some(&(last, _))) =
        (pair.master_faces.first(), pair.master_faces.last())
    else {
        return 0..0;
    };
    mesh.body_of_element(first as usize)..mesh.body_of_element(last as usize) + 1
}

/// Whether each pair's slave nodes may come within reach of its master faces: some slave
/// body's box and some master body's box within the pair's margin of each other on every
/// axis. A face's corners are in its master body's box and a slave node in its body's, and
/// the margin is computed as `margin` computes it from a diameter at least the
/// pair's, so a pass found far here is one `ghost` would send no face for. Collective.
pub fn near_pairs<C: Comm + ?Sized>(
    comm: &C,
    problem: &Problem,
    mesh: &LocalMesh,
    u: &[Vec3],
) -> Vec<bool> {
    let boxes = BodyBoxes::new(comm, problem, mesh, u);
    let global = &problem.mesh;
    problem
        .contacts
        .iter()
        .map(|pair| {
            let diameter = master_bodies(global, pair)
                .map(|m| boxes.diagonal(m))
                .fold(0.0, f64::max);
            let pad = margin(pair, diameter);
            master_bodies(global, pair).any(|m| {
                slave_bodies(global, pair).any(|s| {
                    (0..3).all(|i| {
                        boxes.lo(m, i) <= boxes.hi(s, i) + pad
                            && boxes.hi(m, i) >= boxes.lo(s, i) - pad
                    })
                })
            })
        })
        .collect()
}

/// How far beyond a rank's slave box a master face is still sent: the search tolerance,
/// plus a face size and a half so the neighbours of every face in reach come too.
pub(super) fn margin(pair: &ContactPair, diameter: f64) -> f64 {
    pair.normal_tolerance.max(pair.tangential_tolerance) + 1.5 * diameter
}
