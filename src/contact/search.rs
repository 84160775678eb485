//! The contact search: a bounding-volume hierarchy of master faces (parry3d), inflated by
//! the search tolerances and rebuilt from current coordinates at each contact update, and
//! the closest-point projection of each slave node. Ties between faces go to the lowest
//! face index, so the result does not depend on traversal order.

use super::facet::{self, closest_point, normal};
use super::project::interpolate;
use super::ContactPair;
use crate::math::{add, dot, norm, scale, sub, Vec3};
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::Point;
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy};
use std::collections::HashMap;

/// A node beyond a face's edge by less than this fraction of the face size sits on the
/// edge (round-off of the projection): its interaction has no offset.
const BEYOND_NOISE: f64 = 1e-10;
/// General contact's normal smoothing blends two faces' normals across their edge only
/// where they meet at less than 45 degrees: facets of a curved surface, whose normal should
/// turn continuously (the paper's "V", 12 degrees). Its master surface is every exterior
/// face, so a steeper edge is a corner of the body (a block's), whose faces keep their own
/// normals: blended there, the normal of a block's top tilted by 45 degrees toward its
/// sides, and the nodes lying along those edges were no longer found facing it. A
/// `[[contact]]` pair blends across every edge of the faces it names: a die's bottom and
/// front named with smoothing round its edge (the ironing die of run/scenes/sliding at 300
/// drag steps completes with it and stops at t = 1.52 without).
const SMOOTH_EDGE_COSINE: f64 = std::f64::consts::FRAC_1_SQRT_2;
/// How far below zero the cosine between a slave facet's normal and a master face's must
/// be for the two to oppose (`MasterSurface::overlaps`): beyond the round-off of unit
/// normals, so that faces at right angles (a block's side beside another's top) do not.
const OPPOSED: f64 = 1e-8;

/// A slave node's interaction with a master face (the paper's section 3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interaction {
    /// Index of the master face in the pair.
    pub face: u32,
    /// Local coordinates of the contact point on the face (clamped to the face).
    pub s: [f64; 2],
    /// Unit normal used for the constraint (smoothed near edges when smoothing is on),
    /// pointing out of the master body.
    pub normal: Vec3,
    /// Signed normal distance of the slave node from the contact point: negative is
    /// penetration. The push-back vector is -sign(gap) * normal.
    pub gap: f64,
    /// Where the node sits beyond the face's edge, across the normal: the part of its
    /// offset from the contact point that the clamped projection leaves (zero for a node
    /// that projects onto the face, or beyond it by round-off only).
    pub offset: Vec3,
}

/// Where a node sits on the edge shared by two master faces (`MasterSurface::fold`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FoldPoint {
    /// Local coordinates of the edge point on the first face, and on the second.
    pub s: [f64; 2],
    pub second_s: [f64; 2],
    /// Each face's unit outward normal there (unsmoothed).
    pub normal: Vec3,
    pub second: Vec3,
    /// The unit direction of the edge.
    pub edge: Vec3,
}

/// The master surface of one pair at the current configuration: all of its faces, or on
/// one rank of many, the faces near the rank's slave nodes.
pub struct MasterSurface<'a> {
    pair: &'a ContactPair,
    /// Indices (in the pair) of the faces held, ascending.
    faces: Vec<u32>,
    /// Position in `faces` of a face index of the pair.
    index: HashMap<u32, u32>,
    corners: Vec<[Vec3; 4]>,
    /// Corner positions at the start of the step.
    start: Vec<[Vec3; 4]>,
    /// Reference corner positions, when normals are taken from the undeformed faces
    /// (small kinematics: the constraint directions of linear theory).
    reference: Option<Vec<[Vec3; 4]>>,
    bvh: Bvh,
    /// A self contact's node normals (`symmetrise`); None for every other pair.
    node_normals: Option<HashMap<u32, Vec3>>,
}

impl<'a> MasterSurface<'a> {
    /// Every face of the pair; `position(global node)` gives the current position of any
    /// node of the pair.
    pub fn new(pair: &'a ContactPair, position: impl Fn(u32) -> Vec3) -> Self {
        let corners: Vec<[Vec3; 4]> = pair
            .face_nodes
            .iter()
            .map(|f| std::array::from_fn(|a| position(f[a])))
            .collect();
        let faces = (0..corners.len() as u32).collect();
        Self::from_faces(pair, faces, corners.clone(), corners)
    }

    /// The given faces (ascending indices in the pair) with their current corner positions
    /// and those at the start of the step.
    pub fn from_faces(
        pair: &'a ContactPair,
        faces: Vec<u32>,
        corners: Vec<[Vec3; 4]>,
        start: Vec<[Vec3; 4]>,
    ) -> Self {
        let index = faces
            .iter()
            .enumerate()
            .map(|(k, &f)| (f, k as u32))
            .collect();
        let pad = pair.normal_tolerance.max(pair.tangential_tolerance);
        let aabbs: Vec<Aabb> = corners
            .iter()
            .map(|x| {
                let mut lo = [f64::INFINITY; 3];
                let mut hi = [f64::NEG_INFINITY; 3];
                for p in x {
                    for i in 0..3 {
                        lo[i] = lo[i].min(p[i]);
                        hi[i] = hi[i].max(p[i]);
                    }
                }
                Aabb::new(
                    Point::new(lo[0] - pad, lo[1] - pad, lo[2] - pad),
                    Point::new(hi[0] + pad, hi[1] + pad, hi[2] + pad),
                )
            })
            .collect();
        let bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &aabbs);
        let mut surface = MasterSurface {
            pair,
            faces,
            index,
            corners,
            start,
            reference: None,
            bvh,
            node_normals: None,
        };
        surface.node_normals = surface.self_normals();
        surface
    }

    /// Whether the surface is a self contact's.
    pub fn is_self(&self) -> bool {
        self.pair.is_self()
    }

    /// Whether the surface holds no face (on this rank): then no slave node finds one.
    pub fn is_empty(&self) -> bool {
        self.faces.is_empty()
    }

    /// A self contact's node normals: per node of the faces held, the mean of the unit
    /// normals of its faces held (the normal corners' diagonals' cross product), summed in
    /// the order of the faces' indices (so alike on every rank for a node whose faces are
    /// all held, as those near a rank's slave nodes are). None outside a self contact.
    fn self_normals(&self) -> Option<HashMap<u32, Vec3>> {
        if !self.pair.is_self() {
            return None;
        }
        let mut sum: HashMap<u32, Vec3> = HashMap::new();
        for (k, &f) in self.faces.iter().enumerate() {
            let x = self.normal_corners(k);
            let n = crate::math::cross(&sub(&x[2], &x[0]), &sub(&x[3], &x[1]));
            let n = scale(&n, 1.0 / norm(&n));
            let nodes = self.pair.face_nodes[f as usize];
            let corners = if nodes[3] == nodes[2] { 3 } else { 4 };
            for &a in &nodes[..corners] {
                let v = sum.entry(a).or_insert([0.0; 3]);
                *v = add(v, &n);
            }
        }
        for v in sum.values_mut() {
            *v = scale(v, 1.0 / norm(v).max(f64::MIN_POSITIVE));
        }
        Some(sum)
    }

    /// A self contact's interaction of slave node `slave` at `x` (`it` as found): its
    /// direction the mean of the master surface's normal at the contact point (the face
    /// nodes' normals interpolated) and the opposite of the slave node's own normal, the
    /// gap measured along it. Neither side of a zone is then preferred: two nodes that are
    /// mirror images of each other are tied along the mirror's normal, as a node of the
    /// half model is against a wall on the mirror plane, where the face's own normal would
    /// tilt the tie at a zone's edge (measured on the U squeezed shut, tests/self_contact.rs:
    /// 6e-4 of the largest displacement off its half model). `it` unchanged outside a self
    /// contact.
    pub fn symmetrise(&self, it: Interaction, x: &Vec3, slave: u32) -> Interaction {
        let Some(normals) = &self.node_normals else {
            return it;
        };
        let nodes = self.pair.face_nodes[it.face as usize];
        let w = facet::shape_of(&nodes, &it.s);
        let mut master = [0.0; 3];
        for (a, n) in nodes.iter().enumerate() {
            let Some(v) = normals.get(n) else {
                return it;
            };
            master = add(&master, &scale(v, w[a]));
        }
        let (Some(own), Some(xc)) = (normals.get(&slave), self.point(it.face, &it.s)) else {
            return it;
        };
        let v = sub(&master, own);
        let l = norm(&v);
        if !(l > 1e-12) {
            return it;
        }
        let n = scale(&v, 1.0 / l);
        let d = sub(x, &xc);
        let gap = dot(&d, &n);
        let beyond = it.offset != [0.0; 3];
        Interaction {
            normal: n,
            gap,
            offset: if beyond {
                sub(&d, &scale(&n, gap))
            } else {
                [0.0; 3]
            },
            ..it
        }
    }

    /// Takes normals from the faces' reference corners (in the order of the faces held):
    /// under small kinematics the contact directions are those of the undeformed surface,
    /// as linear theory has them, while points and gaps follow the displacement.
    pub fn with_reference_normals(mut self, reference: Vec<[Vec3; 4]>) -> Self {
        self.reference = Some(reference);
        self.node_normals = self.self_normals();
        self
    }

    /// The corners normals are computed from.
    fn normal_corners(&self, k: usize) -> &[Vec3; 4] {
        match &self.reference {
            Some(r) => &r[k],
            None => &self.corners[k],
        }
    }

    /// Number of faces held.
    pub fn num_faces(&self) -> usize {
        self.faces.len()
    }

    /// Current and step-start corner positions of a face (index in the pair), if held.
    pub fn face_corners(&self, face: u32) -> Option<(&[Vec3; 4], &[Vec3; 4])> {
        self.index
            .get(&face)
            .map(|&k| (&self.corners[k as usize], &self.start[k as usize]))
    }

    /// The interaction of a slave node at `x`, if it is within the search tolerances.
    pub fn search(&self, x: &Vec3) -> Option<Interaction> {
        self.search_facing(x, None)
    }

    /// `search` among the faces whose normal at the found point opposes `facing` (a
    /// general contact slave node's outward normal; every face when None): a node on the
    /// edge of a contact zone is as near to the master body's side faces as to the face it
    /// lies on, and only the one it faces may take it.
    pub fn search_facing(&self, x: &Vec3, facing: Option<&Vec3>) -> Option<Interaction> {
        self.search_near(x, facing, &[])
    }

    /// `search_facing` leaving out the faces `skip` (ascending indices in the pair): a self
    /// contact node's own neighbourhood (`ContactPair::skipped`).
    pub fn search_near(
        &self,
        x: &Vec3,
        facing: Option<&Vec3>,
        skip: &[u32],
    ) -> Option<Interaction> {
        let probe = Aabb::new(Point::new(x[0], x[1], x[2]), Point::new(x[0], x[1], x[2]));
        let candidates: Vec<(f64, Interaction)> = self
            .bvh
            .intersect_aabb(&probe)
            .filter_map(|k| self.project_on(k, x))
            .filter(|c| facing.is_none_or(|n| crate::math::dot(&c.1.normal, n) < 0.0))
            .filter(|c| skip.binary_search(&c.1.face).is_err())
            .collect();
        // The nearest face; faces within round-off of it go to the lowest index, so the
        // choice depends neither on traversal order nor on which other faces are held.
        let nearest = candidates.iter().map(|c| c.0).fold(f64::INFINITY, f64::min);
        candidates
            .into_iter()
            .filter(|c| c.0 <= nearest + 1e-12 * self.pair.face_size)
            .min_by_key(|c| c.1.face)
            .map(|(_, it)| it)
    }

    /// Whether the slave surface around a node at `x` overlaps a held face: some point
    /// of it (`tributary`: offsets from the node halfway to the centres of the slave
    /// facets around it, each with that facet's outward normal) lies over a face whose
    /// normal opposes the facet's (beyond round-off), within the normal tolerance and the
    /// offset's length (the point is off the master plane where the slave facet is
    /// tilted). Faces that meet another body's only along an edge or at a corner (blocks
    /// side by side) do not overlap: their nodes on the shared edge are not tied across it.
    pub fn overlaps(&self, x: &Vec3, tributary: &[[Vec3; 2]]) -> bool {
        tributary.iter().any(|[d, n_slave]| {
            let p = add(x, d);
            let reach = self.pair.normal_tolerance + norm(d);
            let probe = Aabb::new(
                Point::new(p[0] - reach, p[1] - reach, p[2] - reach),
                Point::new(p[0] + reach, p[1] + reach, p[2] + reach),
            );
            let found = self.bvh.intersect_aabb(&probe).any(|k| {
                let c = &self.corners[k as usize];
                let (s, ok) = closest_point(c, &p);
                let triangle = facet::is_triangle(c);
                if !ok || facet::beyond(triangle, &s, 0.0) {
                    return false;
                }
                let n = normal(self.normal_corners(k as usize), &s);
                let xc = interpolate(c, &facet::shape(triangle, &s));
                dot(&n, n_slave) < -OPPOSED && dot(&sub(&p, &xc), &n).abs() <= reach
            });
            found
        })
    }

    /// The interaction of a slave node at `x` with the face it touches now (index in the
    /// pair), if the node's projection lies on that face or beyond an edge by at most
    /// `margin` (in local coordinates, which span 2 across the face) and within the normal
    /// tolerance. A node in contact keeps its face while it sits on the edge to a neighbour,
    /// instead of flipping between the two with the solver's round-off.
    pub fn stay_on(&self, face: u32, x: &Vec3, margin: f64) -> Option<Interaction> {
        let &k = self.index.get(&face)?;
        let c = &self.corners[k as usize];
        let (s, ok) = closest_point(c, x);
        if !ok || facet::beyond(facet::is_triangle(c), &s, margin) {
            return None;
        }
        self.project_on(k, x).map(|(_, it)| it)
    }

    /// Where a node at `x` sits on the edge that faces `a` and `b` (indices in the pair,
    /// both held) share: the edge's point nearest to `x`, with each face's normal there
    /// and the edge's direction. None when they share no edge, or the point of the edge's
    /// line nearest to `x` lies beyond the edge's ends by more than `margin` of its length.
    pub fn fold(&self, a: u32, b: u32, x: &Vec3, margin: f64) -> Option<FoldPoint> {
        let edge = self.pair.neighbours[a as usize]
            .iter()
            .position(|n| n.is_some_and(|(g, _)| g == b))?;
        let (&ka, &kb) = (self.index.get(&a)?, self.index.get(&b)?);
        let c = &self.corners[ka as usize];
        let triangle = facet::is_triangle(c);
        let next = (edge + 1) % facet::edges(triangle);
        let e = sub(&c[next], &c[edge]);
        let length2 = dot(&e, &e);
        if !(length2 > 0.0) {
            return None;
        }
        let lambda = dot(&sub(x, &c[edge]), &e) / length2;
        if !(lambda >= -margin && lambda <= 1.0 + margin) {
            return None;
        }
        let lambda = lambda.clamp(0.0, 1.0);
        let (p, q) = (facet::corner(triangle, edge), facet::corner(triangle, next));
        let s = [p[0] + lambda * (q[0] - p[0]), p[1] + lambda * (q[1] - p[1])];
        let xe = interpolate(c, &facet::shape(triangle, &s));
        let cb = &self.corners[kb as usize];
        let triangle_b = facet::is_triangle(cb);
        let second_s = facet::clamp(triangle_b, &closest_point(cb, &xe).0);
        Some(FoldPoint {
            s,
            second_s,
            normal: normal(self.normal_corners(ka as usize), &s),
            second: normal(self.normal_corners(kb as usize), &second_s),
            edge: scale(&e, 1.0 / length2.sqrt()),
        })
    }

    /// The interaction of a slave node at `x` with the nearest face held, however far
    /// away: the search of the penetration audit, which must not depend on the search
    /// tolerances. Ties go to the lowest face index, as in `search`.
    ///
    /// The faces whose boxes (inflated by the search tolerances, `pad`) hold `x` are
    /// measured first: a face at distance d <= pad holds the projected point within its
    /// box, so when the nearest of them is within half of `pad` (ties included) it is the
    /// nearest of all, the same answer as measuring every face. Otherwise every face is
    /// measured. (The audit of a mesh of 10^6 elements measured its 6400 master faces for
    /// each of 6561 nodes sitting on them: 22 s a step.)
    pub fn nearest(&self, x: &Vec3) -> Option<Interaction> {
        self.nearest_among(x, None, &[])
    }

    /// `nearest` among the faces whose normal opposes `facing` (every face when None),
    /// leaving out the faces `skip` (ascending indices in the pair): for a self contact
    /// node, the nearest face that is not around it.
    pub fn nearest_among(
        &self,
        x: &Vec3,
        facing: Option<&Vec3>,
        skip: &[u32],
    ) -> Option<Interaction> {
        self.nearest_where(x, facing.map(|n| (n, 0.0)), skip)
    }

    /// `nearest` among the faces whose normal does not point along `along` (cosine below
    /// 1/2): a general contact node found inside a master body goes back out of a face it
    /// could have come in by, not one its own surface lies alongside (`audit::measured`).
    pub fn nearest_not_along(&self, x: &Vec3, along: &Vec3) -> Option<Interaction> {
        self.nearest_where(x, Some((along, 0.5)), &[])
    }

    /// `nearest` among the faces whose normal has a cosine below `limit` with `direction`
    /// (every face when None), leaving out the faces `skip`.
    fn nearest_where(
        &self,
        x: &Vec3,
        direction: Option<(&Vec3, f64)>,
        skip: &[u32],
    ) -> Option<Interaction> {
        let measure = |k: u32| {
            self.project_within(k, x, f64::INFINITY, f64::INFINITY)
                .filter(|c| direction.is_none_or(|(n, limit)| dot(&c.1.normal, n) < limit))
                .filter(|c| skip.binary_search(&c.1.face).is_err())
        };
        let probe = Aabb::new(Point::new(x[0], x[1], x[2]), Point::new(x[0], x[1], x[2]));
        let near: Vec<(f64, Interaction)> = self
            .bvh
            .intersect_aabb(&probe)
            .filter_map(measure)
            .collect();
        let pad = self
            .pair
            .normal_tolerance
            .max(self.pair.tangential_tolerance);
        let tie = 1e-12 * self.pair.face_size;
        let closest = near.iter().map(|c| c.0).fold(f64::INFINITY, f64::min);
        let candidates = if closest + tie <= 0.5 * pad {
            near
        } else {
            (0..self.faces.len() as u32).filter_map(measure).collect()
        };
        let nearest = candidates.iter().map(|c| c.0).fold(f64::INFINITY, f64::min);
        candidates
            .into_iter()
            .filter(|c| c.0 <= nearest + tie)
            .min_by_key(|c| c.1.face)
            .map(|(_, it)| it)
    }

    /// Projection onto one face: (distance to the face, interaction), or None outside the
    /// tolerances.
    fn project_on(&self, k: u32, x: &Vec3) -> Option<(f64, Interaction)> {
        self.project_within(
            k,
            x,
            self.pair.normal_tolerance,
            self.pair.tangential_tolerance,
        )
    }

    /// Projection onto one face within the given normal and tangential distances.
    fn project_within(
        &self,
        k: u32,
        x: &Vec3,
        normal_tolerance: f64,
        tangential_tolerance: f64,
    ) -> Option<(f64, Interaction)> {
        let f = self.faces[k as usize];
        let c = &self.corners[k as usize];
        let (s, ok) = closest_point(c, x);
        if !ok {
            return None;
        }
        let triangle = facet::is_triangle(c);
        let clamped = facet::clamp(triangle, &s);
        let xc = interpolate(c, &facet::shape(triangle, &clamped));
        let n_face = normal(self.normal_corners(k as usize), &clamped);
        let d = sub(x, &xc);
        let gap = dot(&d, &n_face);
        let tangential = norm(&sub(&d, &scale(&n_face, gap)));
        if gap.abs() > normal_tolerance || tangential > tangential_tolerance {
            return None;
        }
        let n = match self.pair.smoothing_width {
            Some(w) => self.smoothed_normal(k, &clamped, &n_face, w),
            None => n_face,
        };
        let gap = dot(&d, &n);
        let across = sub(&d, &scale(&n, gap));
        let beyond = clamped != s && norm(&across) > BEYOND_NOISE * self.pair.face_size;
        Some((
            norm(&d),
            Interaction {
                face: f,
                s: clamped,
                normal: n,
                gap,
                offset: if beyond { across } else { [0.0; 3] },
            },
        ))
    }

    /// Within `w` (fraction of the face size) of an edge shared with another master face,
    /// the normal blends continuously from this face's to the average of the two at the
    /// edge; near a corner the two edges are blended in turn. On a triangle the distance to
    /// an edge is the barycentric coordinate of the opposite corner (the fraction of the
    /// height), and its three edges are blended in turn; the sub-triangles of one flat
    /// 6-node face share its normal, so the blend changes nothing inside a face.
    fn smoothed_normal(&self, k: u32, s: &[f64; 2], n_face: &Vec3, w: f64) -> Vec3 {
        let f = self.faces[k as usize];
        let c = &self.corners[k as usize];
        let triangle = facet::is_triangle(c);
        let mut n = *n_face;
        for (edge, dist) in edge_distances(triangle, s) {
            if dist >= w {
                continue;
            }
            let Some((g, _)) = self.pair.neighbours[f as usize][edge] else {
                continue;
            };
            // A rank holds the faces around its slave nodes' region with a margin of a
            // face size, so the neighbour of a face in reach is held.
            let Some(&kg) = self.index.get(&g) else {
                debug_assert!(false, "neighbour face {g} of face {f} not held");
                continue;
            };
            let cg = &self.corners[kg as usize];
            let xe = interpolate(c, &facet::shape(triangle, s));
            let (sg, _) = closest_point(cg, &xe);
            let sg = facet::clamp(facet::is_triangle(cg), &sg);
            let ng = normal(self.normal_corners(kg as usize), &sg);
            if self.pair.slave_normals.is_some() && dot(n_face, &ng) < SMOOTH_EDGE_COSINE {
                continue;
            }
            let avg = add(n_face, &ng);
            let la = norm(&avg);
            if !(la > 1e-12) {
                continue;
            }
            let avg = scale(&avg, 1.0 / la);
            let beta = 1.0 - dist / w;
            let blended = add(&scale(&n, 1.0 - beta), &scale(&avg, beta));
            n = scale(&blended, 1.0 / norm(&blended));
        }
        n
    }

    /// Weights (face shape functions) of the contact point and the face's nodes.
    pub fn weights(&self, it: &Interaction) -> ([u32; 4], [f64; 4]) {
        let nodes = self.pair.face_nodes[it.face as usize];
        (nodes, facet::shape_of(&nodes, &it.s))
    }

    /// The shape functions of a face of the pair (index in the pair) at `s`.
    pub fn shape(&self, face: u32, s: &[f64; 2]) -> [f64; 4] {
        facet::shape_of(&self.pair.face_nodes[face as usize], s)
    }

    /// Current position of a contact point.
    pub fn point(&self, face: u32, s: &[f64; 2]) -> Option<Vec3> {
        self.face_corners(face)
            .map(|(c, _)| interpolate(c, &facet::shape_of(c, s)))
    }
}

/// The edges a smoothed normal blends toward, in turn, with the distance of `s` from each
/// (a fraction of the face across it). A quadrilateral's nearer edge along each local
/// coordinate (t = -1: 0, s = +1: 1, t = +1: 2, s = -1: 3); a triangle's three edges.
fn edge_distances(triangle: bool, s: &[f64; 2]) -> Vec<(usize, f64)> {
    if triangle {
        return vec![(0, s[1]), (1, 1.0 - s[0] - s[1]), (2, s[0])];
    }
    [(0usize, 1usize, 3usize), (1, 2, 0)]
        .iter()
        .map(|&(i, edge_pos, edge_neg)| {
            let v = s[i];
            let edge = if v >= 0.0 { edge_pos } else { edge_neg };
            (edge, (1.0 - v.abs()) / 2.0)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::problem::Discretization;
    use std::sync::Arc;

    /// A master surface of m x m faces on the dome y = 0.3 (x^2 + z^2) over [0, 1]^2, the
    /// faces' normals up (+y), search tolerances 0.05 (normal) and 0.02 (tangential).
    fn dome(m: usize) -> (ContactPair, Vec<Vec3>) {
        let h = 1.0 / m as f64;
        let id = |i: usize, k: usize| (i * (m + 1) + k) as u32;
        let mut coords = Vec::new();
        for i in 0..=m {
            for k in 0..=m {
                let (x, z) = (i as f64 * h, k as f64 * h);
                coords.push([x, 0.3 * (x * x + z * z), z]);
            }
        }
        let mut face_nodes = Vec::new();
        for i in 0..m {
            for k in 0..m {
                face_nodes.push([id(i, k), id(i, k + 1), id(i + 1, k + 1), id(i + 1, k)]);
            }
        }
        let n = face_nodes.len();
        let pair = ContactPair {
            name: "dome".into(),
            master_faces: Arc::new((0..n as u32).map(|f| (f, 2)).collect()),
            face_nodes: Arc::new(face_nodes),
            neighbours: Arc::new(vec![[None; 4]; n]),
            slave_nodes: Arc::default(),
            slave_faces: Arc::default(),
            slave_face_nodes: Arc::default(),
            discretization: Discretization::NodeFace,
            mu: 0.0,
            normal_tolerance: 0.05,
            tangential_tolerance: 0.02,
            capture_tolerance: 1e-7,
            adjust: 0.0,
            smoothing_width: None,
            face_size: h,
            secondary: false,
            partner: None,
            slave_normals: None,
            slave_tributaries: None,
            neighbourhood: None,
        };
        (pair, coords)
    }

    /// The nearest face found through the search boxes is the one measuring every face
    /// finds (the audit's answer before the boxes were used), bit for bit: for points on the
    /// surface, just inside and outside it (the boxes' answer), and far from it (every face
    /// measured), over a pseudo-random cloud.
    #[test]
    fn the_nearest_face_through_the_boxes_is_the_nearest_of_all() {
        let (pair, coords) = dome(8);
        let surface = MasterSurface::new(&pair, |n| coords[n as usize]);
        let every = |x: &Vec3| {
            let all: Vec<(f64, Interaction)> = (0..surface.num_faces() as u32)
                .filter_map(|k| surface.project_within(k, x, f64::INFINITY, f64::INFINITY))
                .collect();
            let nearest = all.iter().map(|c| c.0).fold(f64::INFINITY, f64::min);
            all.into_iter()
                .filter(|c| c.0 <= nearest + 1e-12 * pair.face_size)
                .min_by_key(|c| c.1.face)
                .map(|(_, it)| it)
        };
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for trial in 0..3000 {
            let (mut x, z) = (1.2 * next() - 0.1, 1.2 * next() - 0.1);
            if trial % 5 == 0 {
                // On a line of edges: faces tie, the lower index wins.
                x = (x * 8.0).round() / 8.0;
            }
            // On the surface or within 0.02 of it (answered through the boxes, pad 0.05),
            // or up to 0.6 away (mostly every face measured).
            let off = match trial % 3 {
                0 => 0.0,
                1 => 0.04 * next() - 0.02,
                _ => 1.2 * next() - 0.6,
            };
            let p = [x, 0.3 * (x * x + z * z) + off, z];
            let near = surface.nearest(&p);
            assert_eq!(near, every(&p), "at {p:?}");
        }
    }

    /// A node on the master surface's edge is captured only where the slave surface around
    /// it lies over the master (a block's bottom on the dome), not where it lies beyond the
    /// edge (a block beside the dome, meeting it along the edge only), nor where the slave
    /// facet over the master does not oppose its normal (a side face turned away from the
    /// dome's slope, or one facing the same way).
    #[test]
    fn only_slave_area_over_the_master_overlaps_it() {
        let (pair, coords) = dome(2);
        let surface = MasterSurface::new(&pair, |n| coords[n as usize]);
        let x = [1.0, 0.3 * (1.0 + 0.25), 0.5];
        let down = [0.0, -1.0, 0.0];
        let beyond = [[0.125, 0.0, 0.125], down];
        let over = [[-0.125, 0.0, 0.125], down];
        assert!(!surface.overlaps(&x, &[beyond]));
        assert!(surface.overlaps(&x, &[beyond, over]));
        assert!(!surface.overlaps(&x, &[[[-0.125, 0.0, 0.125], [-1.0, 0.0, 0.0]]]));
        assert!(!surface.overlaps(&x, &[[[-0.125, 0.0, 0.125], [0.0, 1.0, 0.0]]]));
    }

    /// The fold of a V-groove (two faces sloping down at 26.6 degrees to the line x = 0,
    /// y = 0 along z): a point near the line sits on the edge point at its z, with each
    /// face's outward normal and the edge's direction; beyond the edge's ends by more than
    /// the margin, or for faces that share no edge, there is none.
    #[test]
    fn a_v_grooves_fold_is_its_bottom_line() {
        let coords: Vec<Vec3> = vec![
            [-1.0, 0.5, 0.0],
            [0.0, 0.0, 0.0],
            [0.0, 0.0, 1.0],
            [-1.0, 0.5, 1.0],
            [1.0, 0.5, 0.0],
            [1.0, 0.5, 1.0],
        ];
        // Face 0's edge 2 (corners 2 -> 3: nodes 2 -> 1) is face 1's edge 0 (nodes 1 -> 2).
        let pair = ContactPair {
            name: "groove".into(),
            master_faces: Arc::new(vec![(0, 2), (1, 2)]),
            face_nodes: Arc::new(vec![[0, 3, 2, 1], [1, 2, 5, 4]]),
            neighbours: Arc::new(vec![
                [None, None, Some((1, 0)), None],
                [Some((0, 2)), None, None, None],
            ]),
            ..dome(1).0
        };
        let surface = MasterSurface::new(&pair, |n| coords[n as usize]);
        let fp = surface
            .fold(0, 1, &[0.01, -0.02, 0.3], 0.0)
            .expect("near the bottom line");
        let c = [coords[0], coords[3], coords[2], coords[1]];
        let at = interpolate(&c, &facet::shape(false, &fp.s));
        assert!(norm(&sub(&at, &[0.0, 0.0, 0.3])) < 1e-15, "{at:?}");
        let r = 1.0 / 1.25f64.sqrt();
        assert!(norm(&sub(&fp.normal, &[0.5 * r, r, 0.0])) < 1e-15);
        assert!(norm(&sub(&fp.second, &[-0.5 * r, r, 0.0])) < 1e-15);
        assert!((dot(&fp.edge, &[0.0, 0.0, 1.0]).abs() - 1.0).abs() < 1e-15);
        let b = [coords[1], coords[2], coords[5], coords[4]];
        let on_b = interpolate(&b, &facet::shape(false, &fp.second_s));
        assert!(norm(&sub(&on_b, &at)) < 1e-15);
        assert!(surface.fold(0, 1, &[0.0, 0.0, 1.01], 0.005).is_none());
        assert!(surface.fold(0, 1, &[0.0, 0.0, 1.004], 0.005).is_some());
        assert!(surface.fold(0, 0, &[0.0, 0.0, 0.5], 0.005).is_none());
    }

    /// Normal smoothing on triangles (two sub-triangles meeting at a crease, as across the
    /// edge of two tet10 faces): on the shared edge the normal is the average of the two
    /// facets' normals; at a facet's centroid, farther from every edge than the width
    /// (barycentric 1/3 > 0.3), it is the facet's own.
    #[test]
    fn smoothing_on_triangles_blends_across_the_shared_edge() {
        let coords: Vec<Vec3> = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.2],
        ];
        // Facet 0's edge 1 (corner 1 to 2) is facet 1's edge 2 (corner 2 to 0).
        let pair = ContactPair {
            name: "crease".into(),
            master_faces: Arc::new(vec![(0, 0), (1, 0)]),
            face_nodes: Arc::new(vec![[0, 1, 2, 2], [1, 3, 2, 2]]),
            neighbours: Arc::new(vec![
                [None, Some((1, 2)), None, None],
                [None, None, Some((0, 1)), None],
            ]),
            slave_nodes: Arc::default(),
            slave_faces: Arc::default(),
            slave_face_nodes: Arc::default(),
            discretization: Discretization::NodeFace,
            mu: 0.0,
            normal_tolerance: 0.05,
            tangential_tolerance: 0.02,
            capture_tolerance: 1e-7,
            adjust: 0.0,
            smoothing_width: Some(0.3),
            face_size: 0.7,
            secondary: false,
            partner: None,
            slave_normals: None,
            slave_tributaries: None,
            neighbourhood: None,
        };
        let surface = MasterSurface::new(&pair, |n| coords[n as usize]);
        let nb = scale(&[-0.2, -0.2, 1.0], 1.0 / 1.08f64.sqrt());
        let avg = add(&[0.0, 0.0, 1.0], &nb);
        let avg = scale(&avg, 1.0 / norm(&avg));
        let (_, on_edge) = surface
            .project_within(0, &[0.5, 0.5, 0.01], 1.0, 1.0)
            .unwrap();
        // Round-off of a few products of order 1.
        assert!(
            norm(&sub(&on_edge.normal, &avg)) < 1e-15,
            "{:?}",
            on_edge.normal
        );
        let c = [1.0 / 3.0, 1.0 / 3.0, 0.01];
        let (_, inside) = surface.project_within(0, &c, 1.0, 1.0).unwrap();
        assert_eq!(inside.normal, [0.0, 0.0, 1.0]);
    }
}
