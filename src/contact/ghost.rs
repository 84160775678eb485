//! Ghosted master faces: each rank searches only for the slave nodes it owns, against the
//! master faces near them. The ranks exchange the bounding boxes of their slave nodes;
//! the owner of each master face (the owner of its element) sends the face, with its
//! corners' current and step-start positions, to every rank whose box it reaches within
//! the search tolerance plus a face size (so that the neighbours of a face in reach, which
//! normal smoothing reads, come too). Nothing is gathered onto every rank.

use super::proximity::{self, margin};
use super::search::MasterSurface;
use crate::comm::{message, Comm};
use crate::math::{add, norm, sub, Vec3};
use crate::mesh::local::LocalMesh;
use crate::problem::Problem;

/// A received face: index in the pair, current and step-start corners.
type GhostFace = (u32, [Vec3; 4], [Vec3; 4]);

/// A face as sent: pair, face, current and step-start corners (4 x 3 coordinates each).
type FaceMessage = (usize, u32, [f64; 12], [f64; 12]);

/// The current position of a rank's local node from the displacement.
pub fn position(mesh: &LocalMesh, u: &[Vec3], local: usize) -> Vec3 {
    add(&mesh.coords[local], &u[local])
}

/// The master surface of every pair as this rank needs it for its owned slave nodes, at
/// displacement `u` (and `start` at the start of the step). Collective.
pub fn surfaces<'p, C: Comm + ?Sized>(
    comm: &C,
    problem: &'p Problem,
    mesh: &LocalMesh,
    u: &[Vec3],
    start: &[Vec3],
) -> Vec<MasterSurface<'p>> {
    let npairs = problem.contacts.len();
    let near = proximity::near_pairs(comm, problem, mesh, u);
    let (boxes, mut diameter) = slave_boxes(problem, mesh, u, &near);
    comm.max_f64(&mut diameter);
    let all_boxes = comm.all_gather_f64(&boxes);
    let send = faces_to_send(comm.size(), problem, mesh, u, start, &all_boxes, &diameter);
    let received = message::all_to_all(comm, &send);
    let mut faces: Vec<Vec<GhostFace>> = vec![Vec::new(); npairs];
    for (p, f, current, start) in received.into_iter().flatten() {
        faces[p].push((f, corners_of(&current), corners_of(&start)));
    }
    master_surfaces(problem, faces)
}

/// Bounding box of this rank's owned slave nodes per pair (lo[3], hi[3]), and the largest
/// diameter of the master faces it owns per pair; for a pair whose bodies are not `near`
/// (`proximity`), an empty box, so that no face is sent for it.
fn slave_boxes(
    problem: &Problem,
    mesh: &LocalMesh,
    u: &[Vec3],
    near: &[bool],
) -> (Vec<f64>, Vec<f64>) {
    let npairs = problem.contacts.len();
    let mut boxes = [[f64::INFINITY; 3], [f64::NEG_INFINITY; 3]]
        .concat()
        .repeat(npairs);
    let mut diameter = vec![0.0; npairs];
    for (p, pair) in problem.contacts.iter().enumerate() {
        if !near[p] {
            continue;
        }
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for &s in pair.slave_nodes.iter() {
            if let Some(l) = mesh.owned_node(s) {
                let x = position(mesh, u, l);
                for i in 0..3 {
                    lo[i] = lo[i].min(x[i]);
                    hi[i] = hi[i].max(x[i]);
                }
            }
        }
        boxes[6 * p..6 * p + 3].copy_from_slice(&lo);
        boxes[6 * p + 3..6 * p + 6].copy_from_slice(&hi);
        for (f, &(e, _)) in pair.master_faces.iter().enumerate() {
            if mesh.owned_element(e).is_some() {
                let c = corners(mesh, u, &pair.face_nodes[f]);
                let d = norm(&sub(&c[0], &c[2])).max(norm(&sub(&c[1], &c[3])));
                diameter[p] = f64::max(diameter[p], d);
            }
        }
    }
    (boxes, diameter)
}

/// For every rank, the owned master faces that reach its slave box (`all_boxes`, 6 numbers
/// per pair per rank) within the margin.
fn faces_to_send(
    size: usize,
    problem: &Problem,
    mesh: &LocalMesh,
    u: &[Vec3],
    start: &[Vec3],
    all_boxes: &[Vec<f64>],
    diameter: &[f64],
) -> Vec<Vec<FaceMessage>> {
    let mut send: Vec<Vec<FaceMessage>> = vec![Vec::new(); size];
    for (p, pair) in problem.contacts.iter().enumerate() {
        // No rank's box holds a slave node (the pair's bodies are apart, `proximity`):
        // no face reaches one.
        if all_boxes.iter().all(|b| !(b[6 * p] <= b[6 * p + 3])) {
            continue;
        }
        let pad = margin(pair, diameter[p]);
        for (f, &(e, _)) in pair.master_faces.iter().enumerate() {
            if mesh.owned_element(e).is_none() {
                continue;
            }
            let c = corners(mesh, u, &pair.face_nodes[f]);
            let mut face: Option<FaceMessage> = None;
            for (r, b) in all_boxes.iter().enumerate() {
                if reaches(&c, &b[6 * p..6 * p + 6], pad) {
                    let m = *face.get_or_insert_with(|| {
                        let s = corners(mesh, start, &pair.face_nodes[f]);
                        (p, f as u32, flat(&c), flat(&s))
                    });
                    send[r].push(m);
                }
            }
        }
    }
    send
}

/// Whether contact directions are those of the undeformed master surface: with small
/// strains in every body, as linear theory has them.
pub fn reference_normals(problem: &Problem) -> bool {
    problem.body_models.iter().all(|m| !m.material.is_large())
}

/// Each pair's master surface from its received faces, in face order; with small strains
/// the normals are those of the reference configuration.
fn master_surfaces<'p>(problem: &'p Problem, faces: Vec<Vec<GhostFace>>) -> Vec<MasterSurface<'p>> {
    let small = reference_normals(problem);
    problem
        .contacts
        .iter()
        .zip(faces)
        .map(|(pair, mut list)| {
            list.sort_unstable_by_key(|f| f.0);
            let ids: Vec<u32> = list.iter().map(|f| f.0).collect();
            let current = list.iter().map(|f| f.1).collect();
            let start = list.iter().map(|f| f.2).collect();
            let reference: Vec<[Vec3; 4]> = ids
                .iter()
                .map(|&f| {
                    let n = &pair.face_nodes[f as usize];
                    std::array::from_fn(|a| problem.reference_position(n[a]))
                })
                .collect();
            let surface = MasterSurface::from_faces(pair, ids, current, start);
            if small {
                surface.with_reference_normals(reference)
            } else {
                surface
            }
        })
        .collect()
}

/// Whether a face with these corners reaches the box (lo[3], hi[3]) grown by `pad`.
fn reaches(c: &[Vec3; 4], b: &[f64], pad: f64) -> bool {
    (0..3).all(|i| {
        let lo = c.iter().map(|x| x[i]).fold(f64::INFINITY, f64::min);
        let hi = c.iter().map(|x| x[i]).fold(f64::NEG_INFINITY, f64::max);
        lo <= b[3 + i] + pad && hi >= b[i] - pad
    })
}

/// Master faces each rank would hold at the reference configuration, per pair
/// (`[rank][pair]`), for a decomposition: what `surfaces` ghosts, computed on one process
/// (for `solver check --ranks` and the benchmark).
pub fn face_counts(problem: &Problem, decomposition: &partition::Decomposition) -> Vec<Vec<usize>> {
    let x = &problem.mesh.coords;
    let owner = decomposition.node_owner();
    let nparts = decomposition.nparts();
    let mut out = vec![vec![0usize; problem.contacts.len()]; nparts];
    for (p, pair) in problem.contacts.iter().enumerate() {
        let faces: Vec<[Vec3; 4]> = pair
            .face_nodes
            .iter()
            .map(|f| std::array::from_fn(|a| x[f[a] as usize]))
            .collect();
        let diameter = faces
            .iter()
            .map(|c| norm(&sub(&c[0], &c[2])).max(norm(&sub(&c[1], &c[3]))))
            .fold(0.0, f64::max);
        let pad = margin(pair, diameter);
        for (r, counts) in out.iter_mut().enumerate() {
            let mut b = [
                f64::INFINITY,
                f64::INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::NEG_INFINITY,
                f64::NEG_INFINITY,
            ];
            for &s in pair
                .slave_nodes
                .iter()
                .filter(|&&s| owner[s as usize] as usize == r)
            {
                for i in 0..3 {
                    b[i] = b[i].min(x[s as usize][i]);
                    b[3 + i] = b[3 + i].max(x[s as usize][i]);
                }
            }
            counts[p] = faces.iter().filter(|c| reaches(c, &b, pad)).count();
        }
    }
    out
}

fn corners(mesh: &LocalMesh, u: &[Vec3], nodes: &[u32; 4]) -> [Vec3; 4] {
    std::array::from_fn(|a| {
        let l = mesh
            .local_node(nodes[a])
            .expect("the nodes of an owned element are local");
        position(mesh, u, l)
    })
}

/// Four corners as twelve coordinates, and back.
pub(super) fn flat(c: &[Vec3; 4]) -> [f64; 12] {
    std::array::from_fn(|k| c[k / 3][k % 3])
}

pub(super) fn corners_of(x: &[f64; 12]) -> [Vec3; 4] {
    std::array::from_fn(|a| std::array::from_fn(|i| x[3 * a + i]))
}
