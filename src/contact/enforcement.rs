//! The one interface through which the stepper's control-contact loop enforces contact.
//! The loop knows the phases (gap removal, the frozen set as rows and loads, the model
//! problem's forces read back, the update, the penetration audit) and nothing of how a
//! constraint is made: `ContactState` implements it (dispatch.rs) for every pair, the
//! node-to-face (node_face/) and the mortar (mortar/) ones, and another discretization is
//! an edit of the dispatch, not of the loop.

use super::active::ContactCounts;
use super::audit::Finding;
use crate::comm::Comm;
use crate::constraints::{Constraints, RowSpec};
use crate::math::{Mat3, Vec3};
use crate::mesh::local::LocalMesh;
use crate::problem::Problem;
use crate::springs::Spring;

/// A contact constraint as the loop compares sets to tell a cycle: (slave node, pair,
/// master face, 1 when sticking).
pub type SetEntry = (u32, usize, u32, u8);

/// The directions a contact tie blocks: (slave node, a node of the master side,
/// directions), global ids. The diagnosis of unheld bodies counts them as supports of both
/// bodies.
pub type TieSupport = (u32, u32, Vec<Vec3>);

/// A slipping constraint as `slip_links` gives it.
pub struct SlipLink {
    pub constraint: usize,
    pub slave: u32,
    pub masters: Vec<(u32, f64)>,
    pub mu: f64,
    pub dir: Vec3,
    pub held: f64,
}

/// Contact enforcement as the stepper calls it. Every collective method is called by every
/// rank together, and every implementation keeps its state the same on every rank.
pub trait Enforcement: Clone + Default {
    /// An increment begins from the last converged state (which this is a copy of).
    fn begin_step(&mut self);

    /// Gap removal at the predicted configuration `u`: constrains the nodes that penetrate
    /// or touch within the capture tolerance; with `slide`, slipping nodes first move their
    /// contact points to where the search finds them at `u` (node-to-face pairs). Returns
    /// whether any node was added. Collective.
    fn capture<C: Comm + ?Sized>(
        &mut self,
        comm: &C,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
        slide: bool,
    ) -> bool;

    /// The kinematic constraint rows of the frozen set, for this rank's owned nodes.
    fn rows(&self, problem: &Problem, mesh: &LocalMesh) -> Vec<RowSpec>;

    /// Whether any constraint carries a friction force as a load (a slipping node).
    fn slipping(&self) -> bool;

    /// The active slave node that has slid farthest relative to its master point since the
    /// reference configuration: (global node id + 1, face sizes). Collective.
    fn largest_slide<C: Comm + ?Sized>(
        &self,
        comm: &C,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
    ) -> Option<(u64, f64)>;

    /// Whether every slipping node's friction force is mu times the normal force last read,
    /// to `force_tol`.
    fn friction_settled(&self, problem: &Problem, force_tol: f64) -> bool;

    /// Adds the friction forces of slipping nodes (loads of the model problem) to `out`.
    fn friction_forces(&self, problem: &Problem, mesh: &LocalMesh, out: &mut [Vec3]);

    /// The slipping constraints whose friction follows their normal force within a model
    /// problem: (index in the set, slave node, master nodes and weights (global ids), mu,
    /// friction direction, the magnitude the fixed loads hold).
    fn slip_links(&self, problem: &Problem) -> Vec<SlipLink>;

    /// Tangential springs that hold slipping nodes while a model problem is solved, from
    /// the nodal stiffness blocks `diag`.
    fn slip_springs(&self, mesh: &LocalMesh, u: &[Vec3], diag: &[Mat3]) -> Vec<Spring>;

    /// Springs at the slipping nodes: with `newton`, Coulomb's tangent where a node is
    /// beyond its stick range (see `contact::slip::coulomb_tangent`), unstretched at `u`;
    /// the onset spring at the others (`contact::slip::onset_spring`; `diag` holds the
    /// structure's nodal diagonal stiffness blocks).
    fn tangent_springs(
        &mut self,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
        newton: bool,
        diag: &[crate::math::Mat3],
    ) -> Vec<Spring>;

    /// What the model problem just solved carried (the same on every rank): Coulomb's
    /// tangent (`newton`; the next update then sets those nodes' friction against their
    /// slip) and the onset springs (`onset`; the update's return mapping then takes the
    /// spring's stiffness).
    fn set_tangent(&mut self, newton: bool, onset: bool);

    /// Reads the contact forces from the multipliers of the model problem's rows.
    /// Collective.
    fn read_forces<C: Comm + ?Sized>(
        &mut self,
        comm: &C,
        mesh: &LocalMesh,
        cons: &Constraints,
        multipliers: &[f64],
    );

    /// The contact update after a model problem at `u` (`start`: the step's start): release,
    /// friction, search. Forces below `force_tol` are noise. Returns whether the set or its
    /// forces changed. Collective.
    #[allow(clippy::too_many_arguments)]
    fn update<C: Comm + ?Sized>(
        &mut self,
        comm: &C,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
        start: &[Vec3],
        force_tol: f64,
    ) -> bool;

    /// The set as the loop compares it between updates.
    fn set(&self) -> Vec<SetEntry>;

    /// The slave nodes found inside a master body at `u` (the same on every rank).
    /// Collective.
    fn audit<C: Comm + ?Sized>(
        &self,
        comm: &C,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
    ) -> Vec<Finding>;

    /// Gap removal for audit findings: each node tied to the nearest master face (a
    /// mortar node: tied again by its weighted gap). Collective.
    fn recapture<C: Comm + ?Sized>(
        &mut self,
        comm: &C,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
        findings: &[Finding],
    );

    /// The signed gap of every constrained slave node this rank owns. Collective.
    fn gaps<C: Comm + ?Sized>(
        &self,
        comm: &C,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
    ) -> Vec<(u32, f64)>;

    /// The directions the ties block, for the diagnosis of bodies nothing holds.
    fn supports(&self, problem: &Problem) -> Vec<TieSupport>;

    fn counts(&self) -> ContactCounts;

    /// The set, one line per constraint, for debugging output.
    fn describe(&self) -> String;
}
