//! What differs between contact discretisations, behind one trait: `PairKind`, implemented
//! once by node-to-face (node_face/) and once by mortar (mortar/kind.rs), registered in
//! `contact/mod.rs` (`KINDS`). A pair's kind is the registered one of its
//! `ContactPair::discretization`, chosen when the scene is validated; the contact set's
//! shared steps (dispatch.rs, state.rs) call it where a step differs, over one set sorted
//! by (slave node, pair), so every sum keeps its order.

use super::active::{Active, ContactState};
use super::audit::Finding;
use super::mortar::surfaces::Positions;
use super::search::MasterSurface;
use crate::math::Vec3;
use crate::mesh::local::LocalMesh;
use crate::problem::{Discretization, Problem};

/// The master surfaces of one contact step, gathered once and read by every kind: the
/// ghosted master faces of every pair (node-to-face) and the surfaces of the mortar pairs
/// gathered on every rank (None without a mortar pair).
pub struct Geometry<'p> {
    pub surfaces: Vec<MasterSurface<'p>>,
    pub positions: Option<Positions>,
}

/// One contact discretisation's part of the contact set. The passes (`capture`, `search`,
/// `recapture`) run over the kind's own pairs, kind after kind in the order of `KINDS`;
/// the per-constraint queries (`masters`, `slips`, `restick`) are asked of the kind of the
/// constraint's pair.
pub trait PairKind: Sync {
    /// The variant of `Discretization` this kind implements.
    fn discretization(&self) -> Discretization;

    /// The master nodes and weights of an active constraint's master point.
    fn masters(&self, state: &ContactState, problem: &Problem, a: &Active) -> Vec<(u32, f64)>;

    /// The step's slip and the slip prescribed motion drives of a constraint in contact
    /// (on the rank that owns its slave node), measured at its master point.
    fn slips(
        &self,
        state: &ContactState,
        problem: &Problem,
        mesh: &LocalMesh,
        u: (&[Vec3], &[Vec3]),
        geometry: &Geometry<'_>,
        a: &Active,
    ) -> (Option<Vec3>, Option<Vec3>);

    /// Constraint `k`, slipping, sticks again: where it is held.
    fn restick(&self, _state: &mut ContactState, _k: usize, _mesh: &LocalMesh, _g: &Geometry<'_>) {}

    /// Capture before a model problem (`slide`: first the predicted slide of the slipping
    /// nodes) of the kind's pairs. Returns whether a node was added.
    fn capture(
        &self,
        state: &mut ContactState,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
        geometry: &Geometry<'_>,
        slide: bool,
    ) -> bool;

    /// The search of a contact update for the kind's pairs. Returns whether the set
    /// changed.
    fn search(
        &self,
        state: &mut ContactState,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
        geometry: &Geometry<'_>,
    ) -> bool;

    /// The signed gaps of pair `p`'s slave nodes this rank owns, appended to `out`.
    fn gaps(
        &self,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
        p: usize,
        geometry: &Geometry<'_>,
        out: &mut Vec<(u32, f64)>,
    );

    /// Whether the penetration audit leaves the kind's active nodes out (`audit::audit`'s
    /// `tied`: held by a tie that is not the node's point).
    fn audit_tied(&self) -> bool {
        false
    }

    /// Gap removal for the kind's nodes the penetration audit found inside a master body
    /// (`findings`, alike on every rank); `positions` gathers the mortar surfaces
    /// (collective: called alike on every rank or on none). Returns whether the state must
    /// be shared across ranks after.
    fn recapture(
        &self,
        state: &mut ContactState,
        problem: &Problem,
        mesh: &LocalMesh,
        positions: &dyn Fn() -> Positions,
        findings: &[Finding],
    ) -> bool;
}
