//! The contact set's core, shared by every discretisation: an active constraint (`Active`,
//! its tangential `Mode`), the set (`ContactState`: the active constraints, the released
//! nodes, the frozen mortar ties and the friction bookkeeping of a step) and the counts
//! reported per step. It names nothing of the contact module above the search and the
//! mortar ties: the update (state.rs, coulomb.rs, slip.rs), the discretisations
//! (node_face/, mortar/) and the stepper's interface (enforcement.rs) build on it.

use super::mortar::Tie;
use super::search::Interaction;
use crate::math::Vec3;
use std::collections::{HashMap, HashSet};

/// A gap more negative than this fraction of the face size is a penetration; closer to
/// zero it is round-off of a node that sits on the surface.
pub(super) const PENETRATION_NOISE: f64 = 1e-10;

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
    }
}
