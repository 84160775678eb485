//! `ContactState` as the stepper's `Enforcement`: each step of the interface runs the
//! contact set's shared part (release of tensile nodes, Coulomb's law, the rows, the forces
//! read back: state.rs, coulomb.rs, slip.rs) and each discretisation's part, through its
//! `PairKind` (discretisation.rs; node_face/, mortar/). The state is made whole on every
//! rank after each change.

use super::active::{ContactCounts, ContactState, Mode, FOLD_COMPONENT};
use super::audit::{self, Finding};
use super::discretisation::Geometry;
use super::enforcement::{Enforcement, SetEntry, TieSupport};
use super::ghost;
use super::mortar::surfaces::Positions;
use super::project::tangents;
use super::self_contact;
use crate::comm::{self, message, Comm};
use crate::constraints::{Constraints, RowKind, RowSpec};
use crate::math::{add, scale, sub, Mat3, Vec3};
use crate::mesh::local::LocalMesh;
use crate::problem::Problem;
use crate::springs::Spring;

impl Enforcement for ContactState {
    /// Starts a load step: records where each constrained node sits on its master surface,
    /// the point a node that turns out not to slip in this step sticks to.
    fn begin_step(&mut self) {
        self.released.clear();
        self.let_go.clear();
        self.newton_turns.clear();
        self.newton_off.clear();
        self.steady = false;
        self.spring_turns.clear();
        for a in &mut self.active {
            a.secant = None;
            a.start = Some((a.face, a.s, a.offset));
            a.reversals = 0;
            a.left = None;
        }
    }

    fn counts(&self) -> ContactCounts {
        let mut c = ContactCounts {
            active: self.active.len() as u64,
            released: self.released.len() as u64,
            ..Default::default()
        };
        for a in &self.active {
            match a.mode {
                Mode::Stick => c.stick += 1,
                Mode::Slip { .. } | Mode::Free => c.slip += 1,
            }
        }
        c
    }

    /// Constraint rows of the active constraints whose slave node this rank owns, in the
    /// order of `active`: every normal first, then the tangents of the sticking nodes. On a
    /// node with several ties, another pair's normal (like a Dirichlet row, which comes
    /// before all of them) thus takes precedence over a stick: a tangential row in its span
    /// is dropped, and the node's motion along the master is then driven, which the update
    /// judges as slip (see `driven_slip`).
    fn rows(&self, problem: &Problem, mesh: &LocalMesh) -> Vec<RowSpec> {
        let mut out = Vec::new();
        for tangents_pass in [false, true] {
            self.rows_into(problem, mesh, tangents_pass, &mut out);
        }
        out
    }

    /// Friction forces of slipping nodes on slave and master nodes, added to `extra` (on
    /// every local node, each summed in the order of `active`).
    fn friction_forces(&self, problem: &Problem, mesh: &LocalMesh, extra: &mut [Vec3]) {
        for a in &self.active {
            let Mode::Slip { dir, magnitude } = a.mode else {
                continue;
            };
            let f = scale(&dir, magnitude);
            if let Some(s) = mesh.local_node(a.slave) {
                extra[s] = add(&extra[s], &f);
            }
            for (m, w) in self.masters(problem, a) {
                if let Some(l) = mesh.local_node(m) {
                    extra[l] = sub(&extra[l], &scale(&f, w));
                }
            }
        }
    }

    /// Reads each active constraint's forces from the row multipliers of the last model
    /// problem (force on the slave = sum of multiplier times row direction) on the slave's
    /// rank, and shares them with every rank. Collective.
    fn read_forces<C: Comm + ?Sized>(
        &mut self,
        comm: &C,
        mesh: &LocalMesh,
        cons: &Constraints,
        multipliers: &[f64],
    ) {
        for a in self.active.iter_mut() {
            a.normal_force = 0.0;
            a.tangential_force = [0.0; 3];
            if let Some(f) = a.fold.as_mut() {
                f.forces = [0.0; 2];
            }
        }
        let mut seen = vec![false; self.active.len()];
        let mut mine = Vec::new();
        for a in 0..self.active.len() {
            let Some(s) = mesh.owned_node(self.active[a].slave) else {
                continue;
            };
            if seen[a] {
                continue;
            }
            for (i, row) in cons.rows(s) {
                if let RowKind::Contact {
                    constraint,
                    component,
                } = row.kind
                {
                    if !seen[constraint] {
                        seen[constraint] = true;
                        mine.push(constraint);
                    }
                    let m = multipliers[i];
                    let act = &mut self.active[constraint];
                    if component == 0 {
                        act.normal_force = m;
                    } else if component == FOLD_COMPONENT {
                        if let Some(f) = act.fold.as_mut() {
                            f.forces[1] = m;
                        }
                    } else {
                        act.tangential_force = add(&act.tangential_force, &scale(&row.dir, m));
                    }
                }
            }
        }
        // A node at a fold: its normal force is the sum of its two faces'.
        for &k in &mine {
            let a = &mut self.active[k];
            if let Some(f) = a.fold.as_mut() {
                f.forces = f.face_forces(&a.normal, [a.normal_force, f.forces[1]]);
                a.normal_force = f.forces[0] + f.forces[1];
            }
        }
        if comm.size() == 1 {
            return;
        }
        let forces: Vec<(usize, f64, Vec3, [f64; 2])> = mine
            .iter()
            .map(|&k| {
                let a = &self.active[k];
                (
                    k,
                    a.normal_force,
                    a.tangential_force,
                    a.fold.map_or([0.0; 2], |f| f.forces),
                )
            })
            .collect();
        for (k, normal, tangential, folded) in message::all_gather(comm, &forces) {
            let a = &mut self.active[k];
            a.normal_force = normal;
            a.tangential_force = tangential;
            if let Some(f) = a.fold.as_mut() {
                f.forces = folded;
            }
        }
    }

    /// Captures, before a model problem, nodes that penetrate or touch (within the capture
    /// tolerance) at the predicted configuration, so a body held only by contact is not
    /// left unconstrained. Returns whether any node was added. Collective.
    fn capture<C: Comm + ?Sized>(
        &mut self,
        comm: &C,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
        slide: bool,
    ) -> bool {
        let geometry = self.geometry(comm, problem, mesh, (u, u));
        let before = self_contact::keys(self);
        let mut changed = false;
        for kind in super::kinds() {
            changed |= kind.capture(self, problem, mesh, u, &geometry, slide);
        }
        self.share(comm, mesh);
        // Alike on every rank (the shared set): no collective needed for its answer.
        let released = self_contact::one_side(self, problem, &before);
        comm::any(comm, changed) || released
    }

    /// One contact update at the current displacement `u` (`start`: at the start of the
    /// step). Returns whether the constraint set changed (a node added, released, switched
    /// between stick and slip, or moved to another face). `force_tol` is the force below
    /// which a tensile or tangential force is noise. Release and the switch to slip follow
    /// from the shared forces on every rank; the reversal of slip and the search are done
    /// for the slave nodes a rank owns, and the results are shared. Collective.
    #[allow(clippy::too_many_arguments)]
    fn update<C: Comm + ?Sized>(
        &mut self,
        comm: &C,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
        start: &[Vec3],
        force_tol: f64,
    ) -> bool {
        let mut changed = self.release_tensile(problem, force_tol);
        let geometry = self.geometry(comm, problem, mesh, (u, start));
        changed |= self.coulomb(problem, mesh, (u, start), &geometry, force_tol);
        let before = self_contact::keys(self);
        for kind in super::kinds() {
            changed |= kind.search(self, problem, mesh, u, &geometry);
        }
        self.share(comm, mesh);
        let released = self_contact::one_side(self, problem, &before);
        let changed = comm::any(comm, changed) || released;
        self.steady = !changed;
        if changed {
            // Newton's turns are compared between updates of one constraint set only.
            self.newton_turns.clear();
            self.spring_turns.clear();
        }
        changed
    }

    /// Signed gap of every slave node this rank owns (None where the search finds no master
    /// face). Collective.
    fn gaps<C: Comm + ?Sized>(
        &self,
        comm: &C,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
    ) -> Vec<(u32, f64)> {
        let geometry = self.geometry(comm, problem, mesh, (u, u));
        let mut out = Vec::new();
        for (p, pair) in problem.contacts.iter().enumerate() {
            super::kind(pair.discretization).gaps(problem, mesh, u, p, &geometry, &mut out);
        }
        out
    }

    fn slip_links(&self, problem: &Problem) -> Vec<super::enforcement::SlipLink> {
        self.active
            .iter()
            .enumerate()
            // A node at a fold keeps its friction as held: its normal force is two rows'.
            .filter(|(_, a)| a.fold.is_none())
            .filter_map(|(k, a)| match a.mode {
                Mode::Slip { dir, magnitude } => Some(super::enforcement::SlipLink {
                    constraint: k,
                    slave: a.slave,
                    masters: self.masters(problem, a),
                    mu: problem.contacts[a.pair].mu,
                    dir,
                    held: magnitude,
                }),
                _ => None,
            })
            .collect()
    }

    fn largest_slide<C: Comm + ?Sized>(
        &self,
        comm: &C,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
    ) -> Option<(u64, f64)> {
        ContactState::largest_slide(self, comm, problem, mesh, u)
    }

    fn friction_settled(&self, problem: &Problem, force_tol: f64) -> bool {
        ContactState::friction_settled(self, problem, force_tol)
    }

    fn slipping(&self) -> bool {
        self.active
            .iter()
            .any(|a| matches!(a.mode, Mode::Slip { .. }))
    }

    fn slip_springs(&self, mesh: &LocalMesh, u: &[Vec3], diag: &[Mat3]) -> Vec<Spring> {
        ContactState::slip_springs(self, mesh, u, diag)
    }

    fn tangent_springs(
        &mut self,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
        newton: bool,
        diag: &[crate::math::Mat3],
    ) -> Vec<Spring> {
        ContactState::tangent_springs(self, problem, mesh, u, newton, diag)
    }

    fn set_tangent(&mut self, newton: bool, onset: bool) {
        self.tangent = newton;
        self.onset = onset;
    }

    fn set(&self) -> Vec<SetEntry> {
        self.active
            .iter()
            .map(|a| {
                let mode = matches!(a.mode, Mode::Stick) as u8 + 2 * a.fold.is_some() as u8;
                (a.slave, a.pair, a.face, mode)
            })
            .collect()
    }

    fn audit<C: Comm + ?Sized>(
        &self,
        comm: &C,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
    ) -> Vec<Finding> {
        let mut tied: Vec<(u32, usize)> = self
            .active
            .iter()
            .filter(|a| super::kind(problem.contacts[a.pair].discretization).audit_tied())
            .map(|a| (a.slave, a.pair))
            .collect();
        tied.extend(held_by_partner(self, problem));
        tied.extend(self_contact::held_masters(self, problem));
        tied.sort_unstable();
        let findings = audit::audit(comm, problem, mesh, u, &tied);
        super::mortar::enforce::open_weighted_gaps(comm, problem, mesh, u, findings)
    }

    fn recapture<C: Comm + ?Sized>(
        &mut self,
        comm: &C,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
        findings: &[Finding],
    ) {
        let positions = || Positions::gather(comm, problem, mesh, u, u);
        let before = self_contact::keys(self);
        for kind in super::kinds() {
            let mine: Vec<Finding> = findings
                .iter()
                .filter(|f| problem.contacts[f.pair].discretization == kind.discretization())
                .copied()
                .collect();
            if kind.recapture(self, problem, mesh, &positions, &mine) {
                self.share(comm, mesh);
            }
        }
        // The findings and the set are alike on every rank.
        self_contact::one_side(self, problem, &before);
    }

    fn supports(&self, problem: &Problem) -> Vec<TieSupport> {
        let tie = |a: &super::active::Active| {
            let master = self.masters(problem, a).first().map_or(
                problem.contacts[a.pair].face_nodes[a.face as usize][0],
                |m| m.0,
            );
            let mut dirs = vec![a.normal];
            match (a.fold, a.mode) {
                (Some(f), Mode::Stick) => dirs.extend([f.normal, f.edge]),
                (Some(f), _) => dirs.push(f.normal),
                (None, Mode::Stick) => {
                    let (t1, t2) = tangents(&a.normal);
                    dirs.extend([t1, t2]);
                }
                (None, _) => {}
            }
            (a.slave, master, dirs)
        };
        self.active.iter().map(tie).collect()
    }

    fn describe(&self) -> String {
        let mut out = String::new();
        for a in &self.active {
            out += &format!(
                "  slave {} pair {} face {} s {:?} n {:?} {:?} f_n {:.6e} f_t {:?}{}{}\n",
                a.slave + 1,
                a.pair,
                a.face,
                a.s,
                a.normal,
                a.mode,
                a.normal_force,
                a.tangential_force,
                a.fold.map_or(String::new(), |f| format!(
                    " fold: face {} n {:?} forces {:?}",
                    f.face, f.normal, f.forces
                )),
                a.secant.map_or(String::new(), |(_, slip)| format!(
                    " slip {:?} k {:.6e} reversals {}",
                    slip, a.slip_stiffness, a.reversals
                ))
            );
        }
        out + &format!("  released {:?}", self.released())
    }
}

impl ContactState {
    /// The master surfaces of every kind at (current, step-start) displacements: the
    /// ghosted faces of every pair and the mortar pairs' gathered surfaces. Collective.
    fn geometry<'p, C: Comm + ?Sized>(
        &self,
        comm: &C,
        problem: &'p Problem,
        mesh: &LocalMesh,
        (u, start): (&[Vec3], &[Vec3]),
    ) -> Geometry<'p> {
        Geometry {
            surfaces: ghost::surfaces(comm, problem, mesh, u, start),
            positions: self.mortar_positions(comm, problem, mesh, (u, start)),
        }
    }
}

/// The (slave node, pair) of the general contact second passes whose node is on a master
/// face its primary pass ties a node to (`ContactPair::partner`): left out of the audit.
/// Empty without second passes.
fn held_by_partner(state: &ContactState, problem: &Problem) -> Vec<(u32, usize)> {
    let seconds: Vec<(usize, usize)> = (problem.contacts.iter().enumerate())
        .filter_map(|(p, c)| c.partner.map(|q| (p, q)))
        .collect();
    if seconds.is_empty() {
        return Vec::new();
    }
    let mut held: Vec<(usize, u32)> = state
        .active
        .iter()
        .filter(|a| seconds.iter().any(|&(_, q)| q == a.pair))
        .flat_map(|a| {
            super::kind(problem.contacts[a.pair].discretization)
                .masters(state, problem, a)
                .into_iter()
                .map(move |(n, _)| (a.pair, n))
        })
        .collect();
    held.sort_unstable();
    held.dedup();
    let mut out = Vec::new();
    for (p, q) in seconds {
        for &s in problem.contacts[p].slave_nodes.iter() {
            if held.binary_search(&(q, s)).is_ok() {
                out.push((s, p));
            }
        }
    }
    out
}
