//! The contact set's core, shared by every discretisation: an active constraint (`Active`,
//! its tangential `Mode`), the set (`ContactState`: the active constraints, the released
//! nodes, the frozen mortar ties and the friction bookkeeping of a step) and the counts
//! reported per step. It names nothing of the contact module above the search and the
//! mortar ties: the update (state.rs, coulomb.rs, slip.rs), the discretisations
//! (node_face/, mortar/) and the stepper's interface (enforcement.rs) build on it.

use super::mortar::Tie;
use super::search::Interaction;
use crate::math::{add, dot, norm, scale, sub, Vec3};
use std::collections::{HashMap, HashSet};

/// A gap more negative than this fraction of the face size is a penetration; closer to
/// zero it is round-off of a node that sits on the surface.
pub(super) const PENETRATION_NOISE: f64 = 1e-10;

/// The component of a contact row (`RowKind::Contact`) that ties a node at a fold to its
/// second face (0 is the normal, 1 and 2 the stick rows).
pub(super) const FOLD_COMPONENT: u8 = 3;

/// Tangential behaviour of an active constraint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mode {
    /// Frictionless: only the normal is tied.
    Free,
    /// Tied to its master point in every direction.
    Stick,
    /// Slipping: normal tied, a friction force of the last computed magnitude along `dir`
    /// (unit, acting on the slave) opposes the slip.
    Slip { dir: Vec3, magnitude: f64 },
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Active {
    pub pair: usize,
    /// Global node id of the slave node.
    pub slave: u32,
    pub face: u32,
    pub s: [f64; 2],
    pub normal: Vec3,
    /// The slave's offset from its master point across the normal, which a stick holds:
    /// nonzero for a node beyond its face's edge (within the search's tangential
    /// tolerance), which the clamped projection ties to a point of the edge (node-to-face;
    /// zero for mortar, whose ties hold their own offsets).
    pub offset: Vec3,
    pub mode: Mode,
    /// Normal contact force on the slave from the last model problem (compressive > 0).
    pub normal_force: f64,
    /// Tangential contact force on the slave from the last model problem.
    pub tangential_force: Vec3,
    /// Secant estimate of the node's tangential stiffness (force per slip), measured from
    /// two model problems of one step; 0 until measured. Kept across steps.
    pub slip_stiffness: f64,
    /// The tangential force held on the slave in the last model problem of this step (the
    /// stick force, or the friction force) with the slip measured after it: one end of the
    /// next secant. Cleared when a step begins.
    pub secant: Option<(Vec3, Vec3)>,
    /// The master point (face, coordinates, offset) the node sat on when the step began;
    /// None for a node captured during the step.
    pub start: Option<(u32, [f64; 2], Vec3)>,
    /// How often the node's slip reversed (slip -> stick) in this step.
    pub reversals: u32,
    /// A second master face the node is held against (node-to-face): at the edge between
    /// two faces that each push the node onto the other, it sits on their shared edge with
    /// both faces' normals tied. None elsewhere.
    pub fold: Option<Fold>,
    /// The face a node-to-face node left in this step's contact updates: moved back onto it
    /// across their shared edge, the node is held by both (`fold`).
    pub left: Option<u32>,
}

/// The second face of a node held at an edge between two master faces (`Active::fold`):
/// the node's master point is on the shared edge, its rows are both faces' normals there
/// (and, sticking, the edge's direction), and it can slide only along the edge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fold {
    /// Index in the pair of the second face, an edge neighbour of `Active::face`.
    pub face: u32,
    /// The edge point's local coordinates on the second face.
    pub s: [f64; 2],
    /// Its unit outward normal at the edge point.
    pub normal: Vec3,
    /// The unit direction of the shared edge.
    pub edge: Vec3,
    /// The normal forces of the first face and of the second from the last model problem
    /// (compressive > 0; `face_forces`); `Active::normal_force` is their sum.
    pub forces: [f64; 2],
}

impl Fold {
    /// The directions of the rows that hold a node at the fold, given the first face's
    /// normal `first`: their bisector and the direction across the edge in the plane of
    /// the two normals (orthonormal, so that the node's rows stay well conditioned however
    /// small the fold's angle).
    pub fn row_directions(&self, first: &Vec3) -> [Vec3; 2] {
        let unit = |v: Vec3| scale(&v, 1.0 / norm(&v));
        [
            unit(add(first, &self.normal)),
            unit(sub(first, &self.normal)),
        ]
    }

    /// Each face's normal force, from the multipliers of the rows along `row_directions`:
    /// the force m0 d0 + m1 d1 written as f_a n_a + f_b n_b.
    pub fn face_forces(&self, first: &Vec3, multipliers: [f64; 2]) -> [f64; 2] {
        let [d0, d1] = self.row_directions(first);
        let f = add(&scale(&d0, multipliers[0]), &scale(&d1, multipliers[1]));
        let c = dot(first, &self.normal);
        let (fa, fb) = (dot(&f, first), dot(&f, &self.normal));
        let det = 1.0 - c * c;
        [(fa - c * fb) / det, (fb - c * fa) / det]
    }
}

impl Active {
    /// The part of a relative motion `d` along the master surface: across the normal, or
    /// along the edge for a node held at a fold.
    pub fn along_surface(&self, d: &Vec3) -> Vec3 {
        match &self.fold {
            Some(f) => scale(&f.edge, dot(d, &f.edge)),
            None => sub(d, &scale(&self.normal, dot(d, &self.normal))),
        }
    }
}

/// Counts reported per step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactCounts {
    pub active: u64,
    pub stick: u64,
    pub slip: u64,
    pub released: u64,
    /// Largest penetration (minus the most negative gap) of any slave node after
    /// enforcement; 0 when none penetrates.
    pub max_penetration: f64,
}

#[derive(Clone, Debug, Default)]
pub struct ContactState {
    /// Active constraints, ordered by (slave node, pair).
    pub active: Vec<Active>,
    /// (slave node, pair) released during the current step: not pulled back in by the
    /// capture tolerance until the next step (a penetrating node is still pushed out).
    pub(super) released: Vec<(u32, usize)>,
    /// (slave node, pair) released by the present contact update (ascending): a mortar
    /// pair does not capture them again in that update.
    pub(super) let_go: Vec<(u32, usize)>,
    /// The ties of the active constraints of mortar pairs, ordered by (slave node, pair),
    /// frozen between contact updates.
    pub(super) ties: Vec<(usize, Tie)>,
    /// Whether the last model problem carried Coulomb's tangent at the slipping nodes that
    /// have one (set by the solver, alike on every rank).
    pub(super) tangent: bool,
    /// Whether the last model problem carried the onset springs (`slip::onset_spring`) at
    /// the slipping nodes without Coulomb's tangent (set by the solver, alike on every rank).
    pub(super) onset: bool,
    /// The onset springs' stiffnesses of the last model problem, by (slave node, pair), at
    /// the nodes this rank owns.
    pub(super) onset_springs: HashMap<(u32, usize), f64>,
    /// Whether the last update left the constraint set unchanged (alike on every rank);
    /// false when a step begins.
    pub(super) steady: bool,
    /// Per pair, whether its master nodes are all prescribed (`slip::held_masters`),
    /// found at the first use.
    pub(super) held_masters: Option<Vec<bool>>,
    /// The directions held at zero at the friction pairs' surface nodes
    /// (`held::HeldDirections`), found at the first use.
    pub(super) held_directions: Option<super::held::HeldDirections>,
    /// The turn of each slipping node's friction direction (owned nodes) in the last
    /// update that followed a model problem with its onset spring.
    pub(super) spring_turns: HashMap<(u32, usize), f64>,
    /// Newton's turn of each slipping node's friction direction in the last update of this
    /// step (owned nodes, by (slave node, pair)), and the nodes for which Newton is off for
    /// the rest of the step: a turn that did not shrink below `slip::NEWTON_CONTRACTION` of the last
    /// (a direction that cycles, typically a node moving between master faces) goes back to
    /// the return mapping, which contracts.
    pub(super) newton_turns: HashMap<(u32, usize), f64>,
    pub(super) newton_off: HashSet<(u32, usize)>,
}

pub(super) fn new_active(pair: usize, slave: u32, it: &Interaction, mu: f64) -> Active {
    Active {
        pair,
        slave,
        face: it.face,
        s: it.s,
        normal: it.normal,
        offset: it.offset,
        mode: if mu > 0.0 { Mode::Stick } else { Mode::Free },
        normal_force: 0.0,
        tangential_force: [0.0; 3],
        slip_stiffness: 0.0,
        secant: None,
        start: None,
        reversals: 0,
        fold: None,
        left: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rows of a fold are orthonormal, and the multipliers along them give back each
    /// face's normal force, for a wide fold and for one of a hundredth of a degree (where
    /// the two normals' own rows would be nearly parallel).
    #[test]
    fn a_folds_rows_are_orthonormal_and_give_each_faces_force() {
        for angle in [60f64, 0.01] {
            let h = 0.5 * angle.to_radians();
            let first = [h.sin(), h.cos(), 0.0];
            let fold = Fold {
                face: 1,
                s: [0.0; 2],
                normal: [-h.sin(), h.cos(), 0.0],
                edge: [0.0, 0.0, 1.0],
                forces: [0.0; 2],
            };
            let [d0, d1] = fold.row_directions(&first);
            assert!((dot(&d0, &d0) - 1.0).abs() < 1e-15 && (dot(&d1, &d1) - 1.0).abs() < 1e-15);
            assert!(dot(&d0, &d1).abs() < 1e-15);
            // The force on the node: 2 along the first face's normal, -0.5 along the second's.
            let force = add(&scale(&first, 2.0), &scale(&fold.normal, -0.5));
            let [fa, fb] = fold.face_forces(&first, [dot(&force, &d0), dot(&force, &d1)]);
            // Recovering them divides by 1 - cos^2 of the angle (3e-8 at 0.01 degrees): a
            // hundred times the multipliers' round-off (1e-16) divided by it.
            let tol = 1e-14 / (1.0 - dot(&first, &fold.normal).powi(2));
            assert!(
                (fa - 2.0).abs() < tol && (fb + 0.5).abs() < tol,
                "{angle}: {fa} {fb}"
            );
        }
    }

    /// A node at a fold slides along the edge only; elsewhere across the normal.
    #[test]
    fn along_the_surface_is_along_the_edge_at_a_fold() {
        let mut a = new_active(
            0,
            3,
            &Interaction {
                face: 0,
                s: [0.0; 2],
                normal: [0.0, 1.0, 0.0],
                gap: 0.0,
                offset: [0.0; 3],
            },
            0.0,
        );
        let d = [0.3, -0.2, 0.7];
        assert_eq!(a.along_surface(&d), [0.3, 0.0, 0.7]);
        a.fold = Some(Fold {
            face: 1,
            s: [0.0; 2],
            normal: [0.6, 0.8, 0.0],
            edge: [0.0, 0.0, 1.0],
            forces: [0.0; 2],
        });
        assert_eq!(a.along_surface(&d), [0.0, 0.0, 0.7]);
    }
}
