//! The contact set's update that every discretisation shares: the outer level of the
//! paper's control contact. With the set frozen, CG solves a model problem; then the update
//! releases nodes whose contact force turned tensile and decides stick or slip for Coulomb
//! friction (here), and each discretisation searches and captures (node_face/, mortar/).
//! Gap removal happens when the new constraint rows are imposed. The rows of the active
//! constraints and their master points are here too.

use super::active::{Active, ContactState, Mode, FOLD_COMPONENT};
use super::coulomb::{exceeds, judge_slip, judge_stick, newton_applies, tensile};
use super::discretisation::Geometry;
use super::held::{across, HeldDirections};
use super::mortar::Tie;
use super::project::tangents;
use super::slip::SLIP_NOISE;
use crate::comm::{message, Comm};
use crate::constraints::{Row, RowKind, RowSpec};
use crate::math::{dot, norm, scale, sub, Vec3};
use crate::mesh::local::LocalMesh;
use crate::problem::Problem;
use std::collections::HashSet;

/// A node's measured slip and the slip prescribed motion drives (`slip::driven_slip`).
type Slips = (Option<Vec3>, Option<Vec3>);

/// Slipping nodes' friction forces count as settled once each is within this fraction of
/// its capacity (the capacity's own change between model problems): the reversal of a
/// slip is judged from then on.
const SETTLED: f64 = 1e-8;

/// A slipping node's friction force across the directions `held` (that it and its master
/// point both hold at zero): its direction without its parts along them, kept as it
/// is when it has none across them.
fn friction_across(a: &mut Active, held: &[Vec3]) {
    if held.is_empty() {
        return;
    }
    if let Mode::Slip { dir, magnitude } = a.mode {
        let d = across(held, &dir);
        let l = norm(&d);
        if l > 1e-9 {
            a.mode = Mode::Slip {
                dir: scale(&d, 1.0 / l),
                magnitude,
            };
        }
    }
}

/// A node at a fold whose row on one face pulls (beyond `force_tol`) while the other's
/// pushes leaves the pulling face: it stays tied to the other alone, from the edge point,
/// and slides off the edge onto that face if the model problem takes it there. Returns
/// whether the fold was let go (a change of the set). Both rows pulling is the node's
/// release (`tensile`, on the sum).
fn let_go_of_fold(a: &mut Active, force_tol: f64) -> bool {
    let Some(f) = a.fold else {
        return false;
    };
    let [first, second] = f.forces;
    if first.min(second) >= -force_tol || first.max(second) < -force_tol {
        return false;
    }
    a.fold = None;
    if second < -force_tol {
        a.normal_force = first;
    } else {
        a.left = Some(a.face);
        a.face = f.face;
        a.s = f.s;
        a.normal = f.normal;
        a.normal_force = second;
    }
    true
}

impl ContactState {
    pub fn released(&self) -> &[(u32, usize)] {
        &self.released
    }

    /// The master nodes and weights of an active constraint's master point: the face's
    /// shape functions at the contact point (node-to-face) or the tie's weights (mortar):
    /// its pair's kind's.
    pub fn masters(&self, problem: &Problem, a: &Active) -> Vec<(u32, f64)> {
        super::kind(problem.contacts[a.pair].discretization).masters(self, problem, a)
    }

    /// The normal rows (`tangents_pass` false) or the stick rows (true) of `rows`.
    pub(super) fn rows_into(
        &self,
        problem: &Problem,
        mesh: &LocalMesh,
        tangents_pass: bool,
        out: &mut Vec<RowSpec>,
    ) {
        for (k, a) in self.active.iter().enumerate() {
            if tangents_pass && a.mode != Mode::Stick {
                continue;
            }
            let Some(slave) = mesh.owned_node(a.slave) else {
                continue;
            };
            let masters = self.masters(problem, a);
            // Reference offset of the slave from its master point; the rows make the
            // current offset zero along each direction.
            let mut xm = [0.0; 3];
            for &(m, w) in &masters {
                for i in 0..3 {
                    xm[i] += w * problem.reference_position(m)[i];
                }
            }
            let offset = sub(&problem.reference_position(a.slave), &xm);
            // A node at a fold is tied along both faces' normals, and, sticking, along
            // their edge.
            let dirs = match (tangents_pass, a.fold) {
                (true, Some(f)) => vec![(1, f.edge)],
                (true, None) => {
                    let (t1, t2) = tangents(&a.normal);
                    vec![(1, t1), (2, t2)]
                }
                (false, Some(f)) => {
                    let [d0, d1] = f.row_directions(&a.normal);
                    vec![(0, d0), (FOLD_COMPONENT, d1)]
                }
                (false, None) => vec![(0, a.normal)],
            };
            // A sticking node is held where its tie put it relative to its master point:
            // a mortar tie's offset; a node-to-face tie point is the node's projection,
            // offset only beyond the face's edge.
            let held = match self.tie(a.slave, a.pair) {
                Some(t) if tangents_pass => t.offset,
                _ if tangents_pass => a.offset,
                _ => [0.0; 3],
            };
            for (c, dir) in dirs {
                out.push(RowSpec {
                    node: slave,
                    row: Row {
                        dir,
                        value: dot(&dir, &held) - dot(&dir, &offset),
                        masters: masters.clone(),
                        kind: RowKind::Contact {
                            constraint: k,
                            component: c,
                        },
                    },
                });
            }
        }
    }

    /// Whether every slipping node's friction force is its capacity mu |f_n| (from the last
    /// forces read) to `force_tol`, or to SETTLED of the capacity.
    pub(super) fn friction_settled(&self, problem: &Problem, force_tol: f64) -> bool {
        self.active.iter().all(|a| match a.mode {
            Mode::Slip { magnitude, .. } => {
                let capacity = problem.contacts[a.pair].mu * a.normal_force.max(0.0);
                (capacity - magnitude).abs() <= force_tol.max(SETTLED * capacity)
            }
            _ => true,
        })
    }

    /// Release: a node whose contact force is tensile (`tensile`) leaves the set and is not
    /// pulled back in by the capture tolerance in this step.
    pub(super) fn release_tensile(&mut self, problem: &Problem, force_tol: f64) -> bool {
        let mut changed = false;
        let mut kept = Vec::with_capacity(self.active.len());
        self.let_go.clear();
        for mut a in self.active.drain(..) {
            changed |= let_go_of_fold(&mut a, force_tol);
            if tensile(&a, problem.contacts[a.pair].mu, force_tol) {
                self.let_go.push((a.slave, a.pair));
                if !self.released.contains(&(a.slave, a.pair)) {
                    self.released.push((a.slave, a.pair));
                }
                changed = true;
            } else {
                kept.push(a);
            }
        }
        self.active = kept;
        self.let_go.sort_unstable();
        self.prune_ties();
        changed
    }

    /// Coulomb's law for every constraint after a model problem: stick, onset of slip,
    /// driven slip, the reversal of slip, and the friction direction of a slipping node.
    /// The master points are those of each pair's kind in `geometry`. Returns whether a constraint changed mode.
    pub(super) fn coulomb(
        &mut self,
        problem: &Problem,
        mesh: &LocalMesh,
        (u, start): (&[Vec3], &[Vec3]),
        geometry: &Geometry<'_>,
        force_tol: f64,
    ) -> bool {
        // Coulomb: stick while the tangential force is within mu |f_n|, else slip; a slipping
        // node that moved against its friction force sticks again. A node whose slip has
        // already reversed once in this step (and slipped again) has its next reversal
        // judged only once the friction forces are settled (no node starts to slip in this
        // update and every slipping node's force is its capacity to SETTLED): while they
        // change, a node can be dragged back by its neighbours' changing forces rather than
        // its own, and would flip between stick and slip. The state is the same on every
        // rank, so every rank decides alike.
        let slipping_settled = self.friction_settled(problem, force_tol);
        let onset = self
            .active
            .iter()
            .any(|a| a.mode == Mode::Stick && exceeds(a, problem.contacts[a.pair].mu, force_tol));
        let judge_reversal = slipping_settled && !onset;
        // The step's slip and the slip prescribed motion drives, of each node (on the rank
        // that owns it), as its pair's kind measures it at its master point.
        let slips: Vec<(Option<Vec3>, Option<Vec3>)> = self
            .active
            .iter()
            .map(|a| match a.mode {
                Mode::Free => (None, None),
                _ => super::kind(problem.contacts[a.pair].discretization).slips(
                    self,
                    problem,
                    mesh,
                    (u, start),
                    geometry,
                    a,
                ),
            })
            .collect();
        // Along a direction that the node and its master point both hold at zero there is
        // no slip (`held`): the slips are measured across it, the friction force set across
        // it.
        let (common, slips) = self.across_held(problem, mesh, slips);
        let mut changed = false;
        let mut resticks = Vec::new();
        for (k, a) in self.active.iter_mut().enumerate() {
            let (measured, driven) = slips[k];
            let was_slipping = matches!(a.mode, Mode::Slip { .. });
            changed |= match a.mode {
                Mode::Free => false,
                Mode::Stick => {
                    let slips = judge_stick(a, problem, measured, driven, force_tol);
                    friction_across(a, &common[k]);
                    slips
                }
                Mode::Slip { dir, magnitude } => match measured {
                    Some(slip) => {
                        let pair = &problem.contacts[a.pair];
                        let key = (a.slave, a.pair);
                        let newton = self.tangent && !self.newton_off.contains(&key);
                        let applied =
                            newton && newton_applies(a, &slip, SLIP_NOISE * pair.face_size);
                        // The onset spring the model problem carried, as the tangent
                        // springs chose it from this same state.
                        let spring = self
                            .onset
                            .then(|| self.onset_springs.get(&key).copied())
                            .flatten();
                        let judge = (judge_reversal, applied, spring);
                        let sticks = judge_slip(a, pair, (dir, magnitude), slip, judge, force_tol);
                        friction_across(a, &common[k]);
                        if let Mode::Slip { dir: new, .. } = a.mode {
                            let turn = norm(&sub(&new, &dir));
                            let last = self.newton_turns.insert(key, turn);
                            if applied && last.is_some_and(|l| super::slip::newton_stalls(turn, l))
                            {
                                self.newton_off.insert(key);
                            }
                            if spring.is_some() {
                                let last = self.spring_turns.insert(key, turn);
                                if last.is_some_and(|l| turn > l) {
                                    self.newton_off.insert(key);
                                }
                            }
                        }
                        sticks
                    }
                    None => false,
                },
            };
            if was_slipping && a.mode == Mode::Stick {
                resticks.push(k);
            }
        }
        for k in resticks {
            let kind = super::kind(problem.contacts[self.active[k].pair].discretization);
            kind.restick(self, k, mesh, geometry);
        }
        changed
    }

    /// Per active node, the directions it and its master point both hold at zero (on the
    /// rank that owns the node; empty elsewhere and for most nodes), and the slips
    /// `slips` (of `coulomb`) across them: a driven slip no larger than round-off across
    /// them is none.
    pub(super) fn across_held(
        &mut self,
        problem: &Problem,
        mesh: &LocalMesh,
        slips: Vec<Slips>,
    ) -> (Vec<Vec<Vec3>>, Vec<Slips>) {
        let held = self
            .held_directions
            .take()
            .unwrap_or_else(|| HeldDirections::of(problem));
        let common: Vec<Vec<Vec3>> = self
            .active
            .iter()
            .map(|a| {
                let owned = mesh.owned_node(a.slave).is_some();
                if a.mode == Mode::Free || !held.holds(a.slave) || !owned {
                    Vec::new()
                } else {
                    held.common(a.slave, &self.masters(problem, a))
                }
            })
            .collect();
        self.held_directions = Some(held);
        let slips = slips
            .into_iter()
            .zip(&common)
            .zip(&self.active)
            .map(|((s, c), a)| {
                if c.is_empty() {
                    return s;
                }
                let noise = SLIP_NOISE * problem.contacts[a.pair].face_size;
                let driven = s.1.map(|d| across(c, &d)).filter(|d| norm(d) > noise);
                (s.0.map(|m| across(c, &m)), driven)
            })
            .collect();
        (common, slips)
    }

    pub(super) fn released_set(&self) -> HashSet<(u32, usize)> {
        self.released.iter().copied().collect()
    }

    /// Makes the state whole on every rank from each rank's entries for the slave nodes it
    /// owns, ordered by (slave node, pair). Collective.
    pub(super) fn share<C: Comm + ?Sized>(&mut self, comm: &C, mesh: &LocalMesh) {
        if comm.size() > 1 {
            // The whole set goes before the gather brings the new one (each 0.6 MB per rank
            // at n = 40, 1681 nodes in contact).
            let whole = std::mem::take(&mut self.active);
            let mine: Vec<Active> = whole
                .iter()
                .filter(|a| mesh.owned_node(a.slave).is_some())
                .copied()
                .collect();
            drop(whole);
            let released: Vec<(u32, usize)> = self
                .released
                .iter()
                .filter(|(s, _)| mesh.owned_node(*s).is_some())
                .copied()
                .collect();
            let ties: Vec<(usize, Tie)> = self
                .ties
                .iter()
                .filter(|(_, t)| mesh.owned_node(t.slave).is_some())
                .cloned()
                .collect();
            self.active = message::all_gather(comm, &mine);
            self.released = message::all_gather(comm, &released);
            self.ties = message::all_gather(comm, &ties);
        }
        self.ties.sort_by_key(|(p, t)| (t.slave, *p));
        self.active.sort_by_key(|a| (a.slave, a.pair));
        self.released.sort_unstable();
        self.released.dedup();
    }
}
