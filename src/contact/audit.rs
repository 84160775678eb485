//! The penetration audit of the equilibrium query: at the end of a load step every slave
//! node is tested against the elements of its pair's master bodies in the current
//! configuration. The test does not depend on the search tolerances, so a node the search
//! lost (driven deeper than the normal tolerance in one increment, or released while the
//! master still presses on it) is found inside a master body, with its depth: the distance
//! to the nearest master face, where gap removal would put it back. Collective; every rank
//! returns the same findings, in the order (slave node, pair).

use super::ghost::{self, position};
use super::search::{Interaction, MasterSurface};
use crate::comm::{message, Comm};
use crate::fem::hex8;
use crate::math::{add, inverse, matvec, norm, sub, Vec3};
use crate::mesh::local::LocalMesh;
use crate::problem::Problem;
use parry3d_f64::bounding_volume::{Aabb, BoundingVolume};
use parry3d_f64::math::Point;
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy};
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::Triangle;
use std::collections::BTreeMap;

/// A slave node found inside a master body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Finding {
    pub pair: usize,
    /// Global node id of the slave node.
    pub slave: u32,
    /// Distance from the node to the nearest master face.
    pub depth: f64,
    /// The node's interaction with that face (gap removal puts it there).
    pub interaction: Interaction,
    /// The nearest boundary face of the master bodies that is not in the pair's master
    /// surface, when it is nearer than `depth`: where the node most likely entered the
    /// body, unresisted (the contact definition leaves that face out).
    pub entry: Option<Entry>,
}

/// A boundary face of a master body outside the master surface, near a finding.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Entry {
    /// Global element index (0-based) and local face (0..5), as a side set's `faces` lists
    /// them (there 1-based elements).
    pub element: u32,
    pub face: u8,
    /// Distance from the node to the face.
    pub distance: f64,
}

/// Whether `p` lies inside the hexahedron with corners `x` (trilinear map, inverted by
/// Newton's method), its surface included: a node on the surface counts, and its depth
/// (round-off) then says it does not matter. A degenerate element or a point far outside
/// gives false.
pub fn contains(x: &[Vec3; 8], p: &Vec3) -> bool {
    let mut xi = [0.0f64; 3];
    for _ in 0..25 {
        let n = hex8::shape(&xi);
        let mut r = *p;
        for (a, &na) in n.iter().enumerate() {
            for i in 0..3 {
                r[i] -= na * x[a][i];
            }
        }
        let (jinv, det) = inverse(&hex8::jacobian(x, &hex8::shape_derivatives(&xi)));
        if !(det.abs() > 0.0) || !det.is_finite() {
            return false;
        }
        let d = matvec(&jinv, &r);
        for i in 0..3 {
            xi[i] += d[i];
        }
        if xi.iter().any(|v| !(v.abs() <= 3.0)) {
            return false;
        }
        if d.iter().map(|v| v.abs()).sum::<f64>() < 1e-13 {
            break;
        }
    }
    xi.iter().all(|v| v.abs() <= 1.0)
}

/// Whether `p` lies inside the element with nodes `x`: a hexahedron (8 nodes) by
/// [`contains`], a tet10 (10 nodes, its corners first) by the tetrahedron of its corners
/// (its region when its edges are straight, as Gmsh's and the reader's are; a curved
/// tet10 is audited by its straight-sided approximation).
fn contains_any(x: &[Vec3], p: &Vec3) -> bool {
    match x.len() {
        8 => contains(x.try_into().expect("eight nodes"), p),
        _ => contains_tetrahedron(&[x[0], x[1], x[2], x[3]], p),
    }
}

/// Whether `p` lies inside the tetrahedron with corners `x`, its surface included (to
/// 1e-12 of a barycentric coordinate: round-off of a point on a face).
pub fn contains_tetrahedron(x: &[Vec3; 4], p: &Vec3) -> bool {
    let j = [0, 1, 2].map(|i| [0, 1, 2].map(|k| x[k + 1][i] - x[0][i]));
    let (jinv, det) = inverse(&j);
    if !(det.abs() > 0.0) || !det.is_finite() {
        return false;
    }
    let l = matvec(&jinv, &[p[0] - x[0][0], p[1] - x[0][1], p[2] - x[0][2]]);
    l.iter().all(|&v| v >= -1e-12) && l.iter().sum::<f64>() <= 1.0 + 1e-12
}

/// Every slave node inside a master body, with its depth, except the nodes in `tied`
/// (slave node, pair; ascending): the caller's, the mortar pairs' tied nodes. A mortar tie
/// constrains a weighted gap, not
/// the node's point, so a tied node may sit inside a curved master by the
/// discretization's error; a mortar node without a tie is held by nothing, and one inside
/// the master body was lost (released, or beyond the normal search tolerance of every
/// master face). Collective.
pub fn audit<C: Comm + ?Sized>(
    comm: &C,
    problem: &Problem,
    mesh: &LocalMesh,
    u: &[Vec3],
    tied: &[(u32, usize)],
) -> Vec<Finding> {
    let slaves = gather_slaves(comm, problem, mesh, u);
    let mut found: Vec<(usize, u32, Vec3)> = Vec::new();
    for (p, slaves_p) in slaves.iter().enumerate() {
        found.extend(
            inside(problem, mesh, u, tied, p, slaves_p)
                .into_iter()
                .map(|s| (p, s, slaves_p[&s])),
        );
    }
    drop(slaves);
    // A node found by two ranks (inside elements of both) comes with the same position
    // from each: the one its owner sent.
    let mut found: Vec<(usize, u32, Vec3)> = message::all_gather(comm, &found);
    found.sort_unstable_by_key(|&(p, s, _)| (s, p));
    found.dedup();
    if found.is_empty() {
        return Vec::new();
    }
    let pairs: Vec<(usize, u32)> = found.iter().map(|&(p, s, _)| (p, s)).collect();
    let surfaces = gather_masters(comm, problem, mesh, u, &pairs);
    let checked: Vec<(Finding, Vec3, bool)> = found
        .into_iter()
        .filter_map(|(p, s, x)| {
            let surface = surfaces[p].as_ref()?;
            let f = measured(problem, surface, p, s, &x)?;
            let edge = edge_only(problem, surface, &f, &x);
            Some((f, x, edge))
        })
        .collect();
    // A node that looks like an edge touch but whose own surface around it is inside the
    // master body too went in, through a face its surface does not lie over (a die's
    // front face, at right angles to the slab top it ploughs): kept.
    let beside: Vec<(usize, u32, Vec3)> = (checked.iter())
        .filter(|m| m.2)
        .map(|(f, x, _)| (f.pair, f.slave, *x))
        .collect();
    let surrounded = surface_inside(comm, problem, mesh, u, &beside);
    let mut findings: Vec<(Finding, Vec3)> = checked
        .into_iter()
        .filter(|(f, _, edge)| !edge || surrounded.binary_search(&(f.pair, f.slave)).is_ok())
        .map(|(f, x, _)| (f, x))
        .collect();
    // The face a node entered by is named only in what the step does with a node too deep
    // (`too_deep`), so only those are measured against the master bodies' other faces
    // (every rank holds the same findings, so every rank takes part alike or none does).
    // A node sitting on the master surface, found inside by round-off, costs no more.
    let deep: Vec<(usize, u32)> = findings
        .iter()
        .filter(|(f, _)| is_deep(problem, f))
        .map(|(f, _)| (f.pair, f.slave))
        .collect();
    if !deep.is_empty() {
        let others = gather_other_faces(comm, problem, mesh, u, &deep);
        for (f, x) in findings.iter_mut().filter(|(f, _)| is_deep(problem, f)) {
            f.entry = nearest_entry(&others[f.pair], x).filter(|e| e.distance < f.depth);
        }
    }
    findings.into_iter().map(|(f, _)| f).collect()
}

/// The slave nodes of pair `p` on this rank's view (`slaves_p`: global id to position)
/// that lie inside an owned element of a master body not holding them, the tied ones left
/// out.
fn inside(
    problem: &Problem,
    mesh: &LocalMesh,
    u: &[Vec3],
    tied: &[(u32, usize)],
    p: usize,
    slaves_p: &BTreeMap<u32, Vec3>,
) -> Vec<u32> {
    if slaves_p.is_empty() {
        return Vec::new();
    }
    let Some(masters) = MasterElements::near(problem, mesh, u, p, slaves_p.values()) else {
        return Vec::new();
    };
    (slaves_p.iter())
        .filter(|&(&s, x)| tied.binary_search(&(s, p)).is_err() && masters.hold(mesh, s, x))
        .map(|(&s, _)| s)
        .collect()
}

/// The owned elements of a pair's master bodies whose boxes meet the box of some points,
/// in a tree. Only those can hold one of the points (a point of a hexahedron is a convex
/// combination of its corners): the others are left out of the tree (a whole master
/// body's corners were a step's largest transient at 10^6 elements).
struct MasterElements {
    elements: Vec<usize>,
    corners: Vec<Vec<Vec3>>,
    bvh: Bvh,
}

impl MasterElements {
    fn near<'a>(
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
        p: usize,
        points: impl Iterator<Item = &'a Vec3>,
    ) -> Option<MasterElements> {
        let bodies = master_bodies(problem, p);
        let near = bounding_box_of(points);
        let mut elements: Vec<usize> = Vec::new();
        let mut corners: Vec<Vec<Vec3>> = Vec::new();
        let mut aabbs: Vec<Aabb> = Vec::new();
        for e in 0..mesh.elements.len() {
            if !(mesh.element_owned[e] && bodies.contains(&mesh.element_body[e])) {
                continue;
            }
            let x: Vec<Vec3> = mesh
                .elements
                .element(e)
                .iter()
                .map(|&n| position(mesh, u, n as usize))
                .collect();
            let b = bounding_box(&x);
            if b.intersects(&near) {
                elements.push(e);
                corners.push(x);
                aabbs.push(b);
            }
        }
        if elements.is_empty() {
            return None;
        }
        let bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &aabbs);
        Some(MasterElements {
            elements,
            corners,
            bvh,
        })
    }

    /// Whether `x` lies inside one of the elements that does not hold node `s`.
    fn hold(&self, mesh: &LocalMesh, s: u32, x: &Vec3) -> bool {
        let probe = Aabb::new(Point::new(x[0], x[1], x[2]), Point::new(x[0], x[1], x[2]));
        let held = self.bvh.intersect_aabb(&probe).any(|k| {
            let e = self.elements[k as usize];
            let own = mesh
                .elements
                .element(e)
                .iter()
                .any(|&l| mesh.node_global[l as usize] == s);
            !own && contains_any(&self.corners[k as usize], x)
        });
        held
    }
}

/// Of the general contact nodes `beside` (pair, slave node, position), found inside a
/// master body but within the normal tolerance and with no slave area over a master face
/// (`edge_only`), those with a point of their own surface inside an element of the master
/// body too: one of the points halfway from the node to the centres of its slave facets
/// (the reference offsets added to its position, as `MasterSurface::overlaps` takes them).
/// A node where two bodies meet along an edge has its surface beside the other body, not
/// in it. Ascending (pair, node); every rank returns the same. Collective when `beside`
/// is not empty (alike on every rank).
fn surface_inside<C: Comm + ?Sized>(
    comm: &C,
    problem: &Problem,
    mesh: &LocalMesh,
    u: &[Vec3],
    beside: &[(usize, u32, Vec3)],
) -> Vec<(usize, u32)> {
    if beside.is_empty() {
        return Vec::new();
    }
    let mut mine: Vec<(usize, u32)> = Vec::new();
    for p in 0..problem.contacts.len() {
        let pair = &problem.contacts[p];
        let around: Vec<(u32, Vec<Vec3>)> = (beside.iter())
            .filter(|b| b.0 == p)
            .filter_map(|&(_, s, x)| {
                let i = pair.slave_nodes.binary_search(&s).ok()?;
                let points = pair.tributary(i)?.iter().map(|[d, _]| add(&x, d));
                Some((s, points.collect()))
            })
            .collect();
        if around.is_empty() {
            continue;
        }
        let points = around.iter().flat_map(|(_, q)| q.iter());
        let Some(masters) = MasterElements::near(problem, mesh, u, p, points) else {
            continue;
        };
        mine.extend(
            (around.iter())
                .filter(|(s, q)| q.iter().any(|x| masters.hold(mesh, *s, x)))
                .map(|(s, _)| (p, *s)),
        );
    }
    let mut all: Vec<(usize, u32)> = message::all_gather(comm, &mine);
    all.sort_unstable();
    all.dedup();
    all
}

/// Slave node `s` of pair `p` at `x`, found inside: its depth below the nearest point of
/// the pair's master `surface`. For a general contact node, the nearest face whose normal
/// is not within 60 degrees of the node's own: a block's corner pushed through a base's
/// top lies beside the base's side face where the two bodies' sides are flush, and gap
/// removal must put it back on the top, not on that face, which it could not have come
/// in by. The bound is loose because the node's normal is the reference configuration's:
/// the slab a die's front edge ploughs into the die has turned, and its nodes go back out
/// of the die's front face (at right angles to their reference normal), the nearest. For
/// a self contact node, the nearest face facing it and not around it.
fn measured(
    problem: &Problem,
    surface: &MasterSurface,
    p: usize,
    s: u32,
    x: &Vec3,
) -> Option<Finding> {
    let pair = &problem.contacts[p];
    let it = match pair.slave_nodes.binary_search(&s) {
        Ok(i) if pair.is_self() => surface
            .nearest_among(x, pair.facing(i), pair.skipped(i))
            .map(|it| surface.symmetrise(it, x, s)),
        Ok(i) => match pair.facing(i) {
            Some(n) => surface.nearest_not_along(x, n),
            None => surface.nearest(x),
        },
        _ => surface.nearest(x),
    }?;
    let xc = surface.point(it.face, &it.s)?;
    let depth = norm(&sub(x, &xc));
    Some(Finding {
        pair: p,
        slave: s,
        depth,
        interaction: it,
        entry: None,
    })
}

/// Whether a finding of a general contact pass is a node that meets the master body only
/// along an edge: within the normal search tolerance of it, with no slave area around it
/// over a master face (`MasterSurface::overlaps`), as the search would not capture it. On
/// non-matching meshes of blocks side by side, a node tied to one neighbour's face sits
/// inside the block diagonally across the edge by the discretisation's error (3.8e-5 on
/// `multi_constraint_nonmatching`); tying it there too makes each block's slave the
/// other's master. A node deeper than the normal tolerance is found as any other.
fn edge_only(problem: &Problem, surface: &MasterSurface, f: &Finding, x: &Vec3) -> bool {
    let pair = &problem.contacts[f.pair];
    let Ok(i) = pair.slave_nodes.binary_search(&f.slave) else {
        return false;
    };
    pair.tributary(i)
        .is_some_and(|t| f.depth <= pair.normal_tolerance && !surface.overlaps(x, t))
}

/// The face of `faces` (element, local face, corners) nearest to `x`; ties go to the first
/// in the list, which every rank holds in the same order.
fn nearest_entry(faces: &[(u32, u8, [Vec3; 4])], x: &Vec3) -> Option<Entry> {
    let p = Point::new(x[0], x[1], x[2]);
    let mut best: Option<Entry> = None;
    for (e, k, c) in faces {
        let v = c.map(|q| Point::new(q[0], q[1], q[2]));
        let halves: &[[usize; 3]] = if c[3] == c[2] {
            &[[0, 1, 2]]
        } else {
            &[[0, 1, 2], [0, 2, 3]]
        };
        let d = halves
            .iter()
            .map(|t| Triangle::new(v[t[0]], v[t[1]], v[t[2]]).distance_to_local_point(&p, true))
            .fold(f64::INFINITY, f64::min);
        if best.is_none_or(|b| d < b.distance) {
            best = Some(Entry {
                element: *e,
                face: *k,
                distance: d,
            });
        }
    }
    best
}

/// The boundary faces of each wanted pair's master bodies that are not master faces of
/// the pair, at the current configuration, on every rank in (element, face) order (empty
/// for the other pairs). Collective; called only when the audit found a node too deep.
fn gather_other_faces<C: Comm + ?Sized>(
    comm: &C,
    problem: &Problem,
    mesh: &LocalMesh,
    u: &[Vec3],
    found: &[(usize, u32)],
) -> Vec<Vec<(u32, u8, [Vec3; 4])>> {
    let boundary = problem.master_boundary();
    let mut mine: Vec<(usize, u32, u32, [f64; 12])> = Vec::new();
    for (p, pair) in problem.contacts.iter().enumerate() {
        if !found.iter().any(|f| f.0 == p) {
            continue;
        }
        let bodies = master_bodies(problem, p);
        let mut masters = pair.master_faces.to_vec();
        masters.sort_unstable();
        // A tet10's face by its corner triangle (the fourth corner repeating the third, as
        // a contact facet's: `BoundaryFace`).
        for &(e, k, b, corners) in boundary.iter() {
            if !bodies.contains(&b)
                || masters.binary_search(&(e, k)).is_ok()
                || mesh.owned_element(e).is_none()
            {
                continue;
            }
            let c: [Vec3; 4] = corners.map(|n| {
                let l = mesh
                    .local_node(n)
                    .expect("a face node of an owned element is local");
                position(mesh, u, l)
            });
            mine.push((p, e, k as u32, ghost::flat(&c)));
        }
    }
    let mut out = vec![Vec::new(); problem.contacts.len()];
    let mut all = message::all_gather(comm, &mine);
    all.sort_unstable_by_key(|a| (a.0, a.1, a.2));
    for (p, e, k, c) in all {
        out[p].push((e, k as u8, ghost::corners_of(&c)));
    }
    out
}

/// The findings deeper than their pair's capture tolerance (at least round-off of the face
/// size, for a tolerance of zero): the nodes the step must not end with.
pub fn too_deep(problem: &Problem, findings: &[Finding]) -> Vec<Finding> {
    findings
        .iter()
        .filter(|f| is_deep(problem, f))
        .copied()
        .collect()
}

/// Whether a finding is deeper than its pair's capture tolerance (`too_deep`).
fn is_deep(problem: &Problem, f: &Finding) -> bool {
    let pair = &problem.contacts[f.pair];
    f.depth > pair.capture_tolerance.max(1e-10 * pair.face_size)
}

/// The bodies that own a pair's master faces.
fn master_bodies(problem: &Problem, p: usize) -> Vec<u32> {
    let mut bodies: Vec<u32> = problem.contacts[p]
        .master_faces
        .iter()
        .map(|&(e, _)| problem.mesh.body_of_element(e as usize) as u32)
        .collect();
    bodies.sort_unstable();
    bodies.dedup();
    bodies
}

fn bounding_box(x: &[Vec3]) -> Aabb {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in x {
        for i in 0..3 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    Aabb::new(
        Point::new(lo[0], lo[1], lo[2]),
        Point::new(hi[0], hi[1], hi[2]),
    )
}

/// The box of some points.
fn bounding_box_of<'a>(points: impl Iterator<Item = &'a Vec3>) -> Aabb {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        for i in 0..3 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    Aabb::new(
        Point::new(lo[0], lo[1], lo[2]),
        Point::new(hi[0], hi[1], hi[2]),
    )
}

/// Current positions of the slave nodes of every pair that this rank's owned elements of
/// one of the pair's master bodies may hold: each rank sends its owned slave nodes to the
/// ranks whose box of those elements (per body, exchanged first) holds the node. A node is
/// tested only against the elements whose box holds it (`inside`), and a rank's box of a
/// body holds every box of its elements of that body, so each rank receives every node it
/// can find, and what each rank holds is bounded by the nodes near its region, not the
/// whole contact surface. Collective.
fn gather_slaves<C: Comm + ?Sized>(
    comm: &C,
    problem: &Problem,
    mesh: &LocalMesh,
    u: &[Vec3],
) -> Vec<BTreeMap<u32, Vec3>> {
    let all_boxes = comm.all_gather_f64(&body_boxes(problem, mesh, u));
    let mut send: Vec<Vec<(usize, u32, Vec3)>> = vec![Vec::new(); comm.size()];
    for (p, pair) in problem.contacts.iter().enumerate() {
        let bodies = master_bodies(problem, p);
        let ranks: Vec<usize> = (0..comm.size())
            .filter(|&r| {
                bodies
                    .iter()
                    .any(|&b| all_boxes[r][6 * b as usize] <= all_boxes[r][6 * b as usize + 3])
            })
            .collect();
        if ranks.is_empty() {
            continue;
        }
        for &s in pair.slave_nodes.iter() {
            if let Some(l) = mesh.owned_node(s) {
                let x = position(mesh, u, l);
                for &r in &ranks {
                    if bodies
                        .iter()
                        .any(|&b| holds(&all_boxes[r][6 * b as usize..][..6], &x))
                    {
                        send[r].push((p, s, x));
                    }
                }
            }
        }
    }
    let mut out = vec![BTreeMap::new(); problem.contacts.len()];
    for (p, s, x) in message::all_to_all(comm, &send).into_iter().flatten() {
        out[p].insert(s, x);
    }
    out
}

/// Per body, the box (lo[3], hi[3]) of the current corners of this rank's owned elements
/// of it (lo above hi for a body with none).
fn body_boxes(problem: &Problem, mesh: &LocalMesh, u: &[Vec3]) -> Vec<f64> {
    let mut boxes = [[f64::INFINITY; 3], [f64::NEG_INFINITY; 3]]
        .concat()
        .repeat(problem.mesh.bodies.len());
    for e in 0..mesh.elements.len() {
        if !mesh.element_owned[e] {
            continue;
        }
        let b = &mut boxes[6 * mesh.element_body[e] as usize..][..6];
        for &n in mesh.elements.element(e) {
            let x = position(mesh, u, n as usize);
            for i in 0..3 {
                b[i] = b[i].min(x[i]);
                b[3 + i] = b[3 + i].max(x[i]);
            }
        }
    }
    boxes
}

/// Whether the box (lo[3], hi[3]) holds the point (its faces included, as parry's boxes'
/// intersection test has them).
fn holds(b: &[f64], x: &Vec3) -> bool {
    (0..3).all(|i| b[i] <= x[i] && x[i] <= b[3 + i])
}

/// Every master face of the pairs with findings, at the current configuration, on every
/// rank (None for the other pairs). Collective.
fn gather_masters<'p, C: Comm + ?Sized>(
    comm: &C,
    problem: &'p Problem,
    mesh: &LocalMesh,
    u: &[Vec3],
    found: &[(usize, u32)],
) -> Vec<Option<MasterSurface<'p>>> {
    let wanted: Vec<bool> = (0..problem.contacts.len())
        .map(|p| found.iter().any(|f| f.0 == p))
        .collect();
    let mut mine: Vec<(usize, u32, [f64; 12])> = Vec::new();
    for (p, pair) in problem.contacts.iter().enumerate() {
        if !wanted[p] {
            continue;
        }
        for (f, &(e, _)) in pair.master_faces.iter().enumerate() {
            if mesh.owned_element(e).is_none() {
                continue;
            }
            let c: [Vec3; 4] = pair.face_nodes[f].map(|n| {
                let l = mesh
                    .local_node(n)
                    .expect("a face node of an owned element is local");
                position(mesh, u, l)
            });
            mine.push((p, f as u32, ghost::flat(&c)));
        }
    }
    let mut faces: Vec<BTreeMap<u32, [Vec3; 4]>> = vec![BTreeMap::new(); problem.contacts.len()];
    for (p, f, c) in message::all_gather(comm, &mine) {
        faces[p].insert(f, ghost::corners_of(&c));
    }
    let small = problem.body_models.iter().all(|m| !m.material.is_large());
    problem
        .contacts
        .iter()
        .zip(faces)
        .enumerate()
        .map(|(p, (pair, faces))| {
            if !wanted[p] {
                return None;
            }
            let ids: Vec<u32> = faces.keys().copied().collect();
            let corners: Vec<[Vec3; 4]> = faces.values().copied().collect();
            let surface = MasterSurface::from_faces(pair, ids.clone(), corners.clone(), corners);
            Some(if small {
                let reference = ids
                    .iter()
                    .map(|&f| {
                        let n = &pair.face_nodes[f as usize];
                        std::array::from_fn(|a| problem.reference_position(n[a]))
                    })
                    .collect();
                surface.with_reference_normals(reference)
            } else {
                surface
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_cube() -> [Vec3; 8] {
        [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
            [0.0, 1.0, 1.0],
        ]
    }

    #[test]
    fn inside_and_outside_a_cube() {
        let x = unit_cube();
        assert!(contains(&x, &[0.5, 0.5, 0.5]));
        assert!(contains(&x, &[0.01, 0.99, 0.5]));
        assert!(!contains(&x, &[1.01, 0.5, 0.5]));
        assert!(!contains(&x, &[0.5, -0.01, 0.5]));
        assert!(!contains(&x, &[5.0, 5.0, 5.0]));
    }

    #[test]
    fn the_nearest_face_outside_the_master_surface() {
        // Two faces of the unit cube: z = 1 (element 7, face 5) and x = 1 (element 7, face
        // 1). Distances are exact in binary for these points (the closest points are the
        // projections onto the planes, or an edge point).
        let top = [
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
            [0.0, 1.0, 1.0],
        ];
        let side = [
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [1.0, 1.0, 1.0],
            [1.0, 0.0, 1.0],
        ];
        let faces = [(7, 5, top), (7, 1, side)];
        let e = nearest_entry(&faces, &[0.75, 0.5, 0.875]).expect("a face");
        assert_eq!((e.element, e.face, e.distance), (7, 5, 0.125));
        let e = nearest_entry(&faces, &[0.875, 0.5, 0.5]).expect("a face");
        assert_eq!((e.element, e.face, e.distance), (7, 1, 0.125));
        // Beyond the edge both faces share: the edge point (1, 0.5, 1) is nearest to each,
        // at sqrt(0.5^2 + 1) (the tie goes to the first face listed).
        let e = nearest_entry(&faces, &[1.5, 0.5, 2.0]).expect("a face");
        assert_eq!((e.element, e.face), (7, 5));
        assert!((e.distance - 1.25f64.sqrt()).abs() <= 1e-15);
        assert!(nearest_entry(&[], &[0.0; 3]).is_none());
    }

    #[test]
    fn inside_a_sheared_twisted_hexahedron() {
        // A distorted element: the top face shifted and one corner pulled out. The mapped
        // centre of the reference cube is inside; a point mapped from xi = 1.05 is not.
        let mut x = unit_cube();
        for c in x.iter_mut().skip(4) {
            c[0] += 0.4;
        }
        x[6] = [1.7, 1.3, 1.2];
        let map = |xi: [f64; 3]| {
            let n = hex8::shape(&xi);
            let mut p = [0.0; 3];
            for a in 0..8 {
                for i in 0..3 {
                    p[i] += n[a] * x[a][i];
                }
            }
            p
        };
        assert!(contains(&x, &map([0.0, 0.0, 0.0])));
        assert!(contains(&x, &map([0.9, 0.9, 0.9])));
        assert!(contains(&x, &map([-0.99, 0.5, 0.99])));
        assert!(!contains(&x, &map([1.05, 0.0, 0.0])));
        assert!(!contains(&x, &map([0.0, -1.05, 0.5])));
    }
}
