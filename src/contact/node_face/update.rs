//! Node-to-face pairs in the contact set: each slave node tied to one point of a bilinear
//! master face, found by the search (search.rs over the ghosted master surfaces, ghost.rs):
//! capture before a model problem, the search of a contact update (a node in contact keeps,
//! moves or loses its contact point; one not in contact is captured), and the predicted
//! slide of the slipping nodes at the start of an increment.

use crate::contact::active::{new_active, ContactState, Fold, Mode, PENETRATION_NOISE};
use crate::contact::ghost;
use crate::contact::search::{Interaction, MasterSurface};
use crate::contact::self_contact::Sides;
use crate::math::{norm, sub, Vec3};
use crate::mesh::local::LocalMesh;
use crate::problem::{Discretization, Problem};
use std::collections::{HashMap, HashSet};

/// How far (in face coordinates, which span 2) a node in contact may pass a face's edge
/// and keep the face: enough to absorb the solver's round-off of a node sliding along an
/// edge, small enough that the tie point stays within 1e-4 face sizes of the face.
const EDGE_HYSTERESIS: f64 = 1e-4;

/// Two faces whose normals at their edge differ by less than this (coplanar, to
/// round-off) make no fold: a node moves between them as on one face.
const FOLD_NOISE: f64 = 1e-8;

impl ContactState {
    /// Captures the owned slave nodes of the node-to-face pairs not in contact that
    /// penetrate, or touch within the capture tolerance, at `u` (`Enforcement::capture`).
    /// Returns whether any node was added.
    pub(in crate::contact) fn capture_node_face(
        &mut self,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
        surfaces: &[MasterSurface],
    ) -> bool {
        let released = self.released_set();
        let existing: HashSet<(u32, usize)> =
            self.active.iter().map(|a| (a.slave, a.pair)).collect();
        let sides = Sides::of(self, problem);
        let mut changed = false;
        for (p, pair) in problem.contacts.iter().enumerate() {
            // A surface without faces here finds nothing for any node.
            if pair.discretization != Discretization::NodeFace || surfaces[p].is_empty() {
                continue;
            }
            for (i, &s) in pair.slave_nodes.iter().enumerate() {
                let Some(l) = mesh.owned_node(s) else {
                    continue;
                };
                if existing.contains(&(s, p)) {
                    continue;
                }
                let x = ghost::position(mesh, u, l);
                let found = surfaces[p].search_near(&x, pair.facing(i), pair.skipped(i));
                if let Some(it) = found.map(|it| surfaces[p].symmetrise(it, &x, s)) {
                    if pair.captures(it.gap, PENETRATION_NOISE, released.contains(&(s, p)))
                        && sides.admits(problem, p, s, it.face)
                        && pair
                            .tributary(i)
                            .is_none_or(|t| surfaces[p].overlaps(&x, t))
                    {
                        self.active.push(new_active(p, s, &it, pair.mu));
                        changed = true;
                    }
                }
            }
        }
        changed
    }

    /// The search from the current configuration, for the owned slave nodes: a node in
    /// contact keeps or moves its contact point (or is released when it slid out of the
    /// search tolerances); a node not in contact that penetrates, or touches within the
    /// capture tolerance, is captured. Returns whether the set changed.
    pub(in crate::contact) fn search(
        &mut self,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
        surfaces: &[MasterSurface],
    ) -> bool {
        let mut changed = false;
        // Search from the current configuration, for the owned slave nodes.
        let mut index: HashMap<(u32, usize), usize> = HashMap::new();
        for (k, a) in self.active.iter().enumerate() {
            if mesh.owned_node(a.slave).is_some() {
                index.insert((a.slave, a.pair), k);
            }
        }
        let released = self.released_set();
        let sides = Sides::of(self, problem);
        let mut gone = vec![false; self.active.len()];
        let mut added = Vec::new();
        let mut tied = vec![false; problem.contacts.len()];
        for &(_, p) in index.keys() {
            tied[p] = true;
        }
        for (p, pair) in problem.contacts.iter().enumerate() {
            // A surface without faces here finds nothing: only a pair with a node in
            // contact has something to do (release it).
            if pair.discretization != Discretization::NodeFace
                || (surfaces[p].is_empty() && !tied[p])
            {
                continue;
            }
            for (i, &s) in pair.slave_nodes.iter().enumerate() {
                let Some(l) = mesh.owned_node(s) else {
                    continue;
                };
                let x = ghost::position(mesh, u, l);
                if let Some(&k) = index.get(&(s, p)) {
                    match self.follow_fold(k, &surfaces[p], &x) {
                        Some(true) => continue,
                        Some(false) => changed = true,
                        None => {}
                    }
                }
                let current = index.get(&(s, p)).map(|&k| self.active[k].face);
                let found = current
                    .and_then(|f| surfaces[p].stay_on(f, &x, EDGE_HYSTERESIS))
                    .or_else(|| surfaces[p].search_near(&x, pair.facing(i), pair.skipped(i)))
                    .map(|it| surfaces[p].symmetrise(it, &x, s));
                // A self contact keeps one side of a zone (self_contact.rs): a node is not
                // captured, nor moved, onto a face that breaks it.
                let admitted = found.is_none_or(|it| sides.admits(problem, p, s, it.face));
                if let (Some(&k), Some(it), true) = (index.get(&(s, p)), &found, admitted) {
                    if self.folds(k, it, &surfaces[p], &x) {
                        changed = true;
                        continue;
                    }
                }
                match (index.get(&(s, p)), found) {
                    (Some(_), _) if !admitted => {}
                    (Some(&k), found) => {
                        if self.follow(k, found, (s, p), &released, pair.face_size) {
                            gone[k] = true;
                            changed = true;
                        }
                    }
                    (None, Some(it)) => {
                        // A node released in this step is only pushed back if it clearly
                        // penetrates; at zero gap it is just leaving.
                        if admitted
                            && pair.captures(it.gap, PENETRATION_NOISE, released.contains(&(s, p)))
                            && pair
                                .tributary(i)
                                .is_none_or(|t| surfaces[p].overlaps(&x, t))
                        {
                            added.push(new_active(p, s, &it, pair.mu));
                            changed = true;
                        }
                    }
                    (None, None) => {}
                }
            }
        }
        let mut k = 0;
        self.active.retain(|_| {
            k += 1;
            !gone[k - 1]
        });
        self.active.extend(added);
        changed
    }

    /// A node held at a fold (`Active::fold`) follows the shared edge: Some(true) while
    /// it stays along the edge (its point and normals move with it, or it sticks), Some(false)
    /// when it has slid past the edge's end and the fold is let go (a change of the set;
    /// the search then places it as any node), None for a node not at a fold.
    fn follow_fold(&mut self, k: usize, surface: &MasterSurface, x: &Vec3) -> Option<bool> {
        let a = &mut self.active[k];
        let fold = a.fold?;
        if a.mode == Mode::Stick {
            return Some(true);
        }
        match surface.fold(a.face, fold.face, x, 0.5 * EDGE_HYSTERESIS) {
            Some(fp) => {
                a.s = fp.s;
                a.normal = fp.normal;
                a.fold = Some(Fold {
                    s: fp.second_s,
                    normal: fp.second,
                    edge: fp.edge,
                    ..fold
                });
                Some(true)
            }
            None => {
                a.fold = None;
                a.normal_force = fold.forces[0];
                Some(false)
            }
        }
    }

    /// Whether contact `k`, found by the search on face `it.face`, is held at a fold from
    /// now on: a sliding node that moves back onto the face it left in this step, across
    /// the edge the two share, is pushed by each face onto the other (on one, the rows
    /// leave it where it penetrates the other; the updates would move it to and fro), so
    /// it is held on their shared edge by both (`Active::fold`); each face's row is let go
    /// when its force pulls (`release_tensile`). A node moving to another face notes the
    /// face it left. Not for a self contact, whose sides are judged by their faces.
    fn folds(&mut self, k: usize, it: &Interaction, surface: &MasterSurface, x: &Vec3) -> bool {
        let self_contact = surface.is_self();
        let a = &mut self.active[k];
        if it.face == a.face || a.mode == Mode::Stick {
            return false;
        }
        let fold = (a.left == Some(it.face) && !self_contact)
            .then(|| surface.fold(a.face, it.face, x, 0.5 * EDGE_HYSTERESIS))
            .flatten()
            .filter(|fp| norm(&sub(&fp.normal, &fp.second)) > FOLD_NOISE);
        let Some(fp) = fold else {
            a.left = Some(a.face);
            return false;
        };
        a.s = fp.s;
        a.normal = fp.normal;
        a.offset = [0.0; 3];
        a.fold = Some(Fold {
            face: it.face,
            s: fp.second_s,
            normal: fp.second,
            edge: fp.edge,
            forces: [a.normal_force, 0.0],
        });
        true
    }

    /// The slipping nodes this rank owns (node-to-face pairs) move their contact points to
    /// where the search finds them at `u`, the predicted configuration of an increment: the
    /// ties of its first model problem are then those of the predicted slide, not of the
    /// last increment's end. A node the search does not find keeps its point (the update
    /// judges it). Not a change of the set.
    pub(in crate::contact) fn slide_to(
        &mut self,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
        surfaces: &[MasterSurface],
    ) {
        let sides = Sides::of(self, problem);
        for a in &mut self.active {
            if !matches!(a.mode, Mode::Slip { .. })
                || a.fold.is_some()
                || problem.contacts[a.pair].discretization != Discretization::NodeFace
            {
                continue;
            }
            let Some(l) = mesh.owned_node(a.slave) else {
                continue;
            };
            let x = ghost::position(mesh, u, l);
            let surface = &surfaces[a.pair];
            let pair = &problem.contacts[a.pair];
            let i = pair.slave_nodes.binary_search(&a.slave).ok();
            let facing = i.and_then(|i| pair.facing(i));
            let skip = i.map_or(&[][..], |i| pair.skipped(i));
            if let Some(it) = surface
                .stay_on(a.face, &x, EDGE_HYSTERESIS)
                .or_else(|| surface.search_near(&x, facing, skip))
                .map(|it| surface.symmetrise(it, &x, a.slave))
                .filter(|it| sides.admits(problem, a.pair, a.slave, it.face))
            {
                a.face = it.face;
                a.s = it.s;
                a.normal = it.normal;
                a.offset = it.offset;
            }
        }
    }

    /// Follows contact `k` of (slave node, pair) `sp` to what the search found: a sticking
    /// contact stays, a sliding one moves its contact point, or is released when nothing was
    /// found. Returns whether it was released.
    fn follow(
        &mut self,
        k: usize,
        found: Option<Interaction>,
        sp: (u32, usize),
        released: &HashSet<(u32, usize)>,
        pair_size: f64,
    ) -> bool {
        let a = &mut self.active[k];
        if a.mode == Mode::Stick {
            return false;
        }
        match found {
            Some(it) => {
                // Moving the contact point (also onto a neighbouring face, or along
                // an edge the node has passed) is not a change of the set: the equilibrium query after the
                // next model problem judges it. Round-off-sized moves are
                // ignored so the loop can settle.
                let moved = it.face != a.face
                    || (it.s[0] - a.s[0]).abs() + (it.s[1] - a.s[1]).abs() > 1e-12
                    || norm(&sub(&it.normal, &a.normal)) > 1e-12
                    || norm(&sub(&it.offset, &a.offset)) > 1e-12 * pair_size;
                if moved {
                    a.face = it.face;
                    a.s = it.s;
                    a.normal = it.normal;
                    a.offset = it.offset;
                }
                false
            }
            None => {
                // Slid out of the search tolerances: no longer in contact.
                if !released.contains(&sp) {
                    self.released.push(sp);
                }
                true
            }
        }
    }
}
