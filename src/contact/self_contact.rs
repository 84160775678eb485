//! Self contact (a body's exterior nodes against its own exterior faces,
//! `ContactPair::neighbourhood`): one side of each contact zone is the slave. A node tied
//! to a face makes that face's nodes its masters; were one of them tied in turn to a face
//! holding the first node, each would be the other's master (the constraint rows'
//! circular dependency), and on matching meshes the two ties would say the same thing
//! twice. So in a self contact a node that is a master of a tie is not tied itself, and a
//! face with a tied node is not a master face. When two new ties would break that rule,
//! the ties kept are those the contact set already held, then the new ones in the order of
//! `SIDE` (of two nodes that would tie to each other's faces, the one whose outward normal
//! points further along it), then by node: every rank holds the same set after it is
//! shared, so every rank keeps the same ties.

use super::active::{Active, ContactState};
use crate::math::{dot, Vec3};
use crate::problem::Problem;
use std::collections::{HashMap, HashSet};

/// The direction that orders the two sides of a zone (a unit vector along no axis, so
/// that the opposite faces of a zone normal to an axis are not tied).
const SIDE: Vec3 = [0.8, 0.48, 0.36];

/// The slave nodes and the master nodes (every node of a face tied to) of each self
/// contact pair's ties.
#[derive(Default)]
pub(super) struct Sides {
    slaves: HashMap<usize, HashSet<u32>>,
    masters: HashMap<usize, HashSet<u32>>,
}

impl Sides {
    /// The sides of the self contact ties in `state` (empty without a self contact).
    pub(super) fn of(state: &ContactState, problem: &Problem) -> Sides {
        let mut sides = Sides::default();
        for a in &state.active {
            if problem.contacts[a.pair].is_self() {
                sides.add(problem, a);
            }
        }
        sides
    }

    fn add(&mut self, problem: &Problem, a: &Active) {
        self.slaves.entry(a.pair).or_default().insert(a.slave);
        let nodes = &problem.contacts[a.pair].face_nodes[a.face as usize];
        self.masters.entry(a.pair).or_default().extend(nodes);
    }

    /// Whether slave node `slave` of pair `pair` may be tied to the pair's face `face`:
    /// always outside a self contact; in one, when the node is no master of a tie and no
    /// node of the face is tied.
    pub(super) fn admits(&self, problem: &Problem, pair: usize, slave: u32, face: u32) -> bool {
        let c = &problem.contacts[pair];
        if !c.is_self() {
            return true;
        }
        let master = self.masters.get(&pair).is_some_and(|m| m.contains(&slave));
        let tied = self
            .slaves
            .get(&pair)
            .is_some_and(|s| c.face_nodes[face as usize].iter().any(|n| s.contains(n)));
        !master && !tied
    }
}

/// Keeps one side of each self contact zone in the shared set (`before`: the (slave node,
/// pair) the set held before the pass that added ties): a tie the set held that now
/// breaks the rule is released, a new one is not added. Returns whether a tie the set
/// held was released (a change of the set). Every rank holds the same set and does alike.
pub(super) fn one_side(
    state: &mut ContactState,
    problem: &Problem,
    before: &HashSet<(u32, usize)>,
) -> bool {
    if !problem.contacts.iter().any(|c| c.is_self()) {
        return false;
    }
    let key = |a: &Active| {
        let pair = &problem.contacts[a.pair];
        let i = pair.slave_nodes.binary_search(&a.slave).ok();
        i.and_then(|i| pair.facing(i))
            .map_or(0.0, |n| dot(n, &SIDE))
    };
    let mut order: Vec<usize> = (0..state.active.len())
        .filter(|&k| problem.contacts[state.active[k].pair].is_self())
        .collect();
    order.sort_by(|&i, &j| {
        let (a, b) = (&state.active[i], &state.active[j]);
        let new = |a: &Active| !before.contains(&(a.slave, a.pair));
        new(a)
            .cmp(&new(b))
            .then(key(b).total_cmp(&key(a)))
            .then((a.slave, a.pair).cmp(&(b.slave, b.pair)))
    });
    let mut sides = Sides::default();
    let mut keep = vec![true; state.active.len()];
    let mut changed = false;
    for k in order {
        let a = state.active[k];
        if sides.admits(problem, a.pair, a.slave, a.face) {
            sides.add(problem, &a);
        } else {
            keep[k] = false;
            if before.contains(&(a.slave, a.pair)) {
                state.released.push((a.slave, a.pair));
                changed = true;
            }
        }
    }
    let mut k = 0;
    state.active.retain(|_| {
        k += 1;
        keep[k - 1]
    });
    state.released.sort_unstable();
    state.released.dedup();
    changed
}

/// The (node, pair) of the self contact pairs' master nodes (every node of a face a tie
/// of the pair is on): the penetration audit leaves them out, as the general contact's
/// second pass leaves out the nodes its primary pass holds (dispatch.rs).
pub(super) fn held_masters(state: &ContactState, problem: &Problem) -> Vec<(u32, usize)> {
    let mut out: Vec<(u32, usize)> = state
        .active
        .iter()
        .filter(|a| problem.contacts[a.pair].is_self())
        .flat_map(|a| {
            problem.contacts[a.pair].face_nodes[a.face as usize]
                .into_iter()
                .map(move |n| (n, a.pair))
        })
        .collect();
    out.sort_unstable();
    out.dedup();
    out
}

/// The (slave node, pair) keys of a set.
pub(super) fn keys(state: &ContactState) -> HashSet<(u32, usize)> {
    state.active.iter().map(|a| (a.slave, a.pair)).collect()
}
