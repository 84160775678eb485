//! Mortar pairs in the contact set: the ties of the active slave nodes (frozen while a
//! model problem is solved, refreshed at each contact update from the deformed
//! surfaces), capture by the weighted gap, and release of nodes whose support has left
//! the master surface. Everything else (release of tensile nodes, the forces read back,
//! the loop) is the contact set's, shared with node-to-face pairs.

use super::surfaces::Positions;
use super::ties::{relative, Tie};
use crate::comm::Comm;
use crate::contact::active::{new_active, ContactState, Mode, PENETRATION_NOISE};
use crate::contact::audit::Finding;
use crate::contact::search::Interaction;
use crate::math::{norm, sub, Vec3};
use crate::mesh::local::LocalMesh;
use crate::problem::{Discretization, Problem};
use std::collections::{HashMap, HashSet};

impl ContactState {
    /// The frozen tie of (slave node, pair).
    pub fn tie(&self, slave: u32, pair: usize) -> Option<&Tie> {
        self.ties
            .binary_search_by_key(&(slave, pair), |(p, t)| (t.slave, *p))
            .ok()
            .map(|i| &self.ties[i].1)
    }

    /// Mortar pair `p` at the gathered positions, for the slave nodes this rank owns: an
    /// active node takes its tie at these positions (`follow`; a node whose support left
    /// the master surface is released), a node not in contact whose weighted gap
    /// penetrates, or closes within the capture tolerance, is captured. Returns whether
    /// the set changed.
    pub(in crate::contact) fn mortar_pass(
        &mut self,
        problem: &Problem,
        mesh: &LocalMesh,
        p: usize,
        positions: &Positions,
        follow: bool,
    ) -> bool {
        let pair = &problem.contacts[p];
        let released: HashSet<(u32, usize)> = self.released.iter().copied().collect();
        let ties = positions.ties(problem, p, mesh);
        let mut changed = false;
        let mut found = HashSet::new();
        // The pair's active nodes by slave node (nodes captured below are pushed at the end
        // and never looked up again: a slave node has one tie per pair).
        let index: HashMap<u32, usize> = self
            .active
            .iter()
            .enumerate()
            .filter(|(_, a)| a.pair == p)
            .map(|(i, a)| (a.slave, i))
            .collect();
        for t in ties {
            found.insert(t.slave);
            let k = index.get(&t.slave).copied();
            match k {
                Some(k) => {
                    // A sliding node takes its tie at the new positions (not a change of
                    // the set: the equilibrium query judges it). Round-off-sized changes
                    // are ignored so the loop can settle.
                    let moved = self.tie(t.slave, p).is_none_or(|old| moved(old, &t));
                    if follow && self.active[k].mode != Mode::Stick && moved {
                        self.active[k].normal = t.normal;
                        self.active[k].face = t.face;
                        self.set_tie(p, t);
                    }
                }
                None => {
                    // A node the present update released (its force pulled at the frozen
                    // tie) is not judged again by its tie at the same positions: integrated
                    // afresh after it slid, a tie over faces at an angle gives another
                    // weighted gap (by 3e-6 face sizes on the block die), and the node would
                    // go out and in at every update. The next model problem shows where it
                    // goes free.
                    let penetrates = t.gap < -PENETRATION_NOISE * pair.face_size;
                    let closes = penetrates
                        || (t.gap <= pair.capture_tolerance && !released.contains(&(t.slave, p)));
                    if closes && self.let_go.binary_search(&(t.slave, p)).is_err() {
                        let it = Interaction {
                            face: t.face,
                            s: [0.0, 0.0],
                            gap: t.gap,
                            normal: t.normal,
                            offset: [0.0; 3],
                        };
                        self.active.push(new_active(p, t.slave, &it, pair.mu));
                        self.set_tie(p, t);
                        changed = true;
                    }
                }
            }
        }
        if follow {
            // Owned active nodes of the pair without a tie slid off the master surface.
            let gone: Vec<u32> = self
                .active
                .iter()
                .filter(|a| a.pair == p && mesh.owned_node(a.slave).is_some())
                .filter(|a| !found.contains(&a.slave))
                .map(|a| a.slave)
                .collect();
            let off: HashSet<u32> = gone.iter().copied().collect();
            self.active
                .retain(|a| !(a.pair == p && off.contains(&a.slave)));
            self.ties
                .retain(|(q, t)| !(*q == p && off.contains(&t.slave)));
            for s in gone {
                if !self.released.contains(&(s, p)) {
                    self.released.push((s, p));
                }
                changed = true;
            }
        }
        changed
    }

    /// Gap removal for mortar nodes the penetration audit found inside a master body
    /// without a tie: each slave node this rank owns is tied again, with master faces
    /// overlapped up to its depth beyond the normal search tolerance (it was lost because
    /// it lay deeper than that), so the next model problem puts its weighted gap at zero.
    /// A node whose support no master face covers enough stays untied; the audit then
    /// finds it again and the step fails. Call `share` after.
    pub(in crate::contact) fn mortar_recapture(
        &mut self,
        problem: &Problem,
        mesh: &LocalMesh,
        positions: &Positions,
        findings: &[Finding],
    ) {
        for f in findings {
            if mesh.owned_node(f.slave).is_none() {
                continue;
            }
            let pair = &problem.contacts[f.pair];
            let reach = pair.normal_tolerance + 2.0 * f.depth;
            let Some(t) = positions
                .ties_of(problem, f.pair, &[f.slave], reach)
                .into_iter()
                .next()
            else {
                continue;
            };
            let it = Interaction {
                face: t.face,
                s: [0.0, 0.0],
                gap: t.gap,
                normal: t.normal,
                offset: [0.0; 3],
            };
            self.active.push(new_active(f.pair, f.slave, &it, pair.mu));
            self.set_tie(f.pair, t);
        }
    }

    fn set_tie(&mut self, p: usize, t: Tie) {
        match self
            .ties
            .binary_search_by_key(&(t.slave, p), |(q, u)| (u.slave, *q))
        {
            Ok(i) => self.ties[i].1 = t,
            Err(i) => self.ties.insert(i, (p, t)),
        }
    }

    /// Drops the ties of nodes no longer in the set.
    pub(in crate::contact) fn prune_ties(&mut self) {
        let live: HashSet<(u32, usize)> = self.active.iter().map(|a| (a.slave, a.pair)).collect();
        self.ties.retain(|(p, t)| live.contains(&(t.slave, *p)));
    }

    /// The gathered surfaces of the mortar pairs at (current, step-start) displacements;
    /// None when the problem has no mortar pair. Collective.
    pub(in crate::contact) fn mortar_positions<C: Comm + ?Sized>(
        &self,
        comm: &C,
        problem: &Problem,
        mesh: &LocalMesh,
        (u, start): (&[Vec3], &[Vec3]),
    ) -> Option<Positions> {
        problem
            .contacts
            .iter()
            .any(|p| p.discretization == Discretization::Mortar)
            .then(|| Positions::gather(comm, problem, mesh, u, start))
    }

    /// Capture (`follow` false) or the search (true) of every mortar pair at the
    /// gathered `positions`.
    pub(in crate::contact) fn mortar_pairs(
        &mut self,
        problem: &Problem,
        mesh: &LocalMesh,
        positions: Option<&Positions>,
        follow: bool,
    ) -> bool {
        let Some(positions) = positions else {
            return false;
        };
        let mut changed = false;
        for (p, pair) in problem.contacts.iter().enumerate() {
            if pair.discretization == Discretization::Mortar {
                changed |= self.mortar_pass(problem, mesh, p, positions, follow);
            }
        }
        changed
    }
}

impl ContactState {
    /// A mortar node that sticks again after slipping is held where the step began
    /// relative to its master point (as a node-to-face node sticks at its step-start
    /// point): its tie's offset becomes the one at the step-start positions.
    pub(in crate::contact) fn restick_mortar(
        &mut self,
        k: usize,
        mesh: &LocalMesh,
        positions: &Positions,
    ) {
        let (slave, pair) = (self.active[k].slave, self.active[k].pair);
        if mesh.owned_node(slave).is_none() {
            return;
        }
        if let Ok(i) = self
            .ties
            .binary_search_by_key(&(slave, pair), |(q, t)| (t.slave, *q))
        {
            let t = &mut self.ties[i].1;
            t.offset = relative(t, &positions.start(slave), &|g| positions.start(g));
        }
    }
}

/// The audit's findings less the mortar nodes whose weighted gap is open: a node released
/// (its multiplier pulled) or never captured whose tie at `u` has a weighted gap of at
/// least -`PENETRATION_NOISE` face sizes satisfies the pair's non-penetration condition,
/// as a tied node does, though its point may sit inside a master whose faces meet at an
/// angle by the discretisation's error (as a tied node's may: the audit leaves those out).
/// A node without a tie within the normal search tolerance, or whose weighted gap
/// penetrates, stays a finding. Collective when a finding is of a mortar pair (the
/// findings are alike on every rank).
pub(in crate::contact) fn open_weighted_gaps<C: Comm + ?Sized>(
    comm: &C,
    problem: &Problem,
    mesh: &LocalMesh,
    u: &[Vec3],
    findings: Vec<Finding>,
) -> Vec<Finding> {
    let mortar = |f: &Finding| problem.contacts[f.pair].discretization == Discretization::Mortar;
    if !findings.iter().any(mortar) {
        return findings;
    }
    let positions = Positions::gather(comm, problem, mesh, u, u);
    findings
        .into_iter()
        .filter(|f| {
            let pair = &problem.contacts[f.pair];
            let open = || {
                let ties = positions.ties_of(problem, f.pair, &[f.slave], pair.normal_tolerance);
                ties.first()
                    .is_some_and(|t| t.gap >= -PENETRATION_NOISE * pair.face_size)
            };
            !(mortar(f) && open())
        })
        .collect()
}

/// Whether a tie at new positions differs from the frozen one by more than round-off:
/// another set of master nodes, a weight by more than 1e-12, or the normal turned by
/// more than 1e-12.
fn moved(old: &Tie, new: &Tie) -> bool {
    old.masters.len() != new.masters.len()
        || old
            .masters
            .iter()
            .zip(&new.masters)
            .any(|(a, b)| a.0 != b.0 || (a.1 - b.1).abs() > 1e-12)
        || norm(&sub(&old.normal, &new.normal)) > 1e-12
}
