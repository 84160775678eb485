//! The control-contact loop of one increment (the paper's multilevel "control contact"):
//! gap removal at the predicted configuration; then, in turn, the constraint set frozen
//! while CG solves the model problem, and a contact update (release, Coulomb stick and
//! slip, search and capture); until the update changes nothing and the model problem
//! needs no iteration (the equilibrium query), closed by the penetration audit.

use super::{StepRecord, Stepper};
use crate::comm::Comm;
use crate::constraints::{Constraints, RowKind};
use crate::contact::audit;
use crate::contact::enforcement::{Enforcement, SetEntry};
use crate::math::Vec3;
use crate::problem::NonlinearSolver;
use crate::solver::cg::{
    self_coupling, CgSettings, FrictionLink, ModelOutcome, ModelProblem, SolveFailure,
};
use crate::springs::Spring;

/// A constraint set as the loop compares them: (slave, pair, face, sticking) per constraint.
type Signature = Vec<SetEntry>;

/// What the loop remembers across its updates.
#[derive(Default)]
struct Watch {
    updates: usize,
    /// The constraint set after each update, to tell a cycle.
    history: Vec<Signature>,
    /// Nodes the penetration audit tied back in this increment.
    recaptured: Vec<(u32, usize)>,
    /// What the audit last tied back, as the log says it: a failure that follows names it.
    tied_back: Option<String>,
}

impl Watch {
    /// An element that inverts once the audit has tied nodes back was most likely crushed
    /// by that tie (a node found deep inside a master body moved onto its surface in one
    /// go): the failure says so.
    fn explain(&self, e: SolveFailure) -> SolveFailure {
        match (e, &self.tied_back) {
            (SolveFailure::Element(m), Some(what)) => {
                SolveFailure::Element(format!("{m}, after the penetration audit tied back {what}"))
            }
            (e, _) => e,
        }
    }
}

impl<'a, C: Comm + ?Sized, E: Enforcement> Stepper<'a, C, E> {
    /// The control-contact loop at time `t`, from the predicted displacement `u`.
    pub(super) fn solve_step(
        &mut self,
        t: f64,
        u: &mut [Vec3],
        contact: &mut E,
        record: &mut StepRecord,
    ) -> Result<ModelOutcome, SolveFailure> {
        let settings = self.cg_settings(t);
        let contacts = !self.problem.contacts.is_empty();
        self.cg.invalidate_coarse();
        if contacts {
            self.remove_gaps(t, u, contact)?;
        }
        let mut watch = Watch::default();
        let mut changed = true;
        let started = std::time::Instant::now();
        // Nodal stiffness blocks for the slipping nodes' springs, once per step.
        let mut diag = Vec::new();
        loop {
            let (cons, extra) = self.freeze(t, u, contact).map_err(|e| watch.explain(e))?;
            let links = self.friction_links(&cons, contact);
            let (outcome, springs, tangent) = self
                .solve_model(
                    t,
                    u,
                    (&cons, &extra, &links),
                    contact,
                    &settings,
                    &mut diag,
                    record,
                )
                .map_err(|e| watch.explain(e))?;
            contact.set_tangent(tangent.newton, tangent.onset);
            self.check_bounded(u, outcome.iterations)?;
            let multipliers = self.row_multipliers(t, &cons, &extra, &springs);
            let force_tol = settings.tolerance * outcome.reference.max(settings.reference_floor);
            // Settled: the update changed nothing, the model problem needed no iteration,
            // and every friction force is mu times its normal force. (A node whose rows
            // take the whole of its friction force, a Dirichlet direction beside its normal,
            // shows a wrong magnitude in its multipliers only, not in the residual.)
            let settled = contacts && !changed && outcome.iterations == 0 && {
                contact.read_forces(self.comm, self.mesh, &cons, &multipliers);
                contact.friction_settled(self.problem, force_tol)
            };
            if settled && self.audit(t, u, contact, &mut watch)? {
                changed = true;
                continue;
            }
            if !contacts || settled {
                if contacts {
                    contact.read_forces(self.comm, self.mesh, &cons, &multipliers);
                }
                self.cons = cons;
                self.multipliers = multipliers;
                record.contact_updates = watch.updates as u64;
                return Ok(outcome);
            }
            if watch.updates >= self.problem.solver.max_contact_updates {
                return Err(self.beyond_small_sliding(watch.limit_reached(), u, contact));
            }
            contact.read_forces(self.comm, self.mesh, &cons, &multipliers);
            let at = std::time::Instant::now();
            changed = contact.update(self.comm, self.problem, self.mesh, u, &self.u, force_tol);
            self.cg.trace.contact_update(at.elapsed().as_secs_f64());
            watch.updates += 1;
            self.debug_contact(t, watch.updates, changed, outcome.iterations, contact);
            if let Some(progress) = self.progress.as_mut() {
                let c = contact.counts();
                progress(&format!(
                    "  t = {t}: contact update {}: CG {} iterations, in contact {} (stick {}, slip {}), set {}, {:.1} s into the step",
                    watch.updates,
                    outcome.iterations,
                    c.active,
                    c.stick,
                    c.slip,
                    if changed { "changed" } else { "unchanged" },
                    started.elapsed().as_secs_f64()
                ));
            }
            if let Err(e) = watch.record(contact) {
                return Err(self.beyond_small_sliding(e, u, contact));
            }
        }
    }

    /// CG's settings at time `t`.
    fn cg_settings(&self, t: f64) -> CgSettings {
        CgSettings {
            tolerance: self.problem.solver.tolerance,
            max_iterations: self.problem.solver.max_iterations,
            reference_floor: self.reference_floor,
            length_scale: self.length_scale,
            // Over the whole scene, not this rank's nodes: every rank judges alike.
            stiffness_floor: self.stiffness_scale
                * self
                    .problem
                    .dirichlet
                    .iter()
                    .filter(|bc| !self.problem.node_sets[bc.node_set].nodes.is_empty())
                    .map(|bc| bc.function.eval(t).abs())
                    .fold(0.0, f64::max),
            // `auto` is the nonlinear CG: Newton-Krylov measured slower on every plastic
            // scene tried (docs/plasticity-solve.md).
            newton: self.problem.solver.nonlinear == NonlinearSolver::Newton,
        }
    }

    /// Gap removal at the predicted configuration, before the first model problem.
    fn remove_gaps(&mut self, t: f64, u: &mut [Vec3], contact: &mut E) -> Result<(), SolveFailure> {
        let cons = self.build_constraints(t, contact)?;
        cons.impose(self.comm, self.mesh, u);
        // The predicted slide moves the slipping nodes' contact points where friction
        // follows the normal force within the model problem (linear bodies; measured: the
        // dragged block over a deformable base 125 -> 78 contact updates). Under large
        // deformation it changed the ironing die's steady force by 2% (F_x below mu F_y in
        // some steps of 300): left out there.
        let slide = self.asm.linear && !self.loads.is_follower();
        contact.capture(self.comm, self.problem, self.mesh, u, slide);
        Ok(())
    }

    /// Freezes the constraint set: its rows (imposed on `u`) and the slipping nodes'
    /// friction forces, a load of the model problem.
    fn freeze(
        &mut self,
        t: f64,
        u: &mut [Vec3],
        contact: &E,
    ) -> Result<(Constraints, Vec<Vec3>), SolveFailure> {
        let cons = self.build_constraints(t, contact)?;
        let n = if contact.slipping() {
            self.mesh.num_nodes()
        } else {
            0
        };
        let mut extra = vec![[0.0; 3]; n];
        contact.friction_forces(self.problem, self.mesh, &mut extra);
        cons.impose(self.comm, self.mesh, u);
        Ok((cons, extra))
    }

    /// The slipping nodes whose friction follows their normal force within the model
    /// problem (cg/coupled.rs), with this rank's local indices and rows.
    fn friction_links(&self, cons: &Constraints, contact: &E) -> Vec<FrictionLink> {
        if !contact.slipping() {
            return Vec::new();
        }
        contact
            .slip_links(self.problem)
            .into_iter()
            .map(|l| {
                let (row, own) = self
                    .mesh
                    .owned_node(l.slave)
                    .and_then(|s| {
                        let rows: Vec<_> = cons.rows(s).collect();
                        let k = rows.iter().position(|(_, r)| {
                            matches!(r.kind, RowKind::Contact { constraint, component: 0 }
                                if constraint == l.constraint)
                        })?;
                        let dirs: Vec<_> = rows.iter().map(|(_, r)| r.dir).collect();
                        Some((rows[k].0, self_coupling(&dirs, k, &l.dir)))
                    })
                    .map_or((None, 0.0), |(i, m)| (Some(i), m));
                FrictionLink {
                    row,
                    slave: self.mesh.local_node(l.slave),
                    masters: l
                        .masters
                        .iter()
                        .filter_map(|&(m, w)| self.mesh.local_node(m).map(|x| (x, w)))
                        .collect(),
                    mu: l.mu,
                    dir: l.dir,
                    held: l.held,
                    own,
                }
            })
            .collect()
    }

    /// A body that is not held (a mechanism, or a slave body pushed off its master) runs
    /// away instead of failing to converge: stop it with that diagnosis.
    fn check_bounded(&self, u: &[Vec3], iterations: usize) -> Result<(), SolveFailure> {
        let owned = self.mesh.num_owned_nodes;
        let umax = u[..owned]
            .iter()
            .flatten()
            .fold(0.0f64, |m, v| m.max(v.abs()));
        let umax = crate::comm::max_f64(self.comm, umax);
        if !(umax <= 1e3 * self.length_scale) {
            return Err(SolveFailure::Unbounded {
                iterations,
                max_displacement: umax,
            });
        }
        Ok(())
    }

    /// The constraint rows' multipliers (the forces they carry) of the model problem.
    fn row_multipliers(
        &mut self,
        t: f64,
        cons: &Constraints,
        extra: &[Vec3],
        springs: &[Spring],
    ) -> Vec<f64> {
        let pb = ModelProblem {
            comm: self.comm,
            global: &self.problem.mesh,
            asm: &self.asm,
            loads: &self.loads,
            cons,
            extra,
            springs,
            time: t,
        };
        let mut multipliers = Vec::new();
        self.cg.multipliers(&pb, &mut multipliers);
        multipliers
    }

    /// The penetration audit: a node the search lost inside a master body is tied back to
    /// the master surface (gap removal) and the loop goes on (true); one that the step
    /// already tied back once fails it, to be cut back. Records the deepest finding.
    fn audit(
        &mut self,
        t: f64,
        u: &[Vec3],
        contact: &mut E,
        watch: &mut Watch,
    ) -> Result<bool, SolveFailure> {
        let findings = contact.audit(self.comm, self.problem, self.mesh, u);
        let deep = audit::too_deep(self.problem, &findings);
        if let Some(f) = deep
            .iter()
            .find(|f| watch.recaptured.contains(&(f.slave, f.pair)))
        {
            let pair = &self.problem.contacts[f.pair];
            return Err(SolveFailure::Penetration {
                node: f.slave as u64 + 1,
                pair: pair.name.clone(),
                depth: f.depth,
                tolerance: pair.capture_tolerance,
                small_kinematics: self
                    .problem
                    .body_models
                    .iter()
                    .all(|m| !m.material.is_large()),
                entry: f
                    .entry
                    .map(|e| Box::new((e.element as u64 + 1, e.face, e.distance))),
                adjusted: pair.adjust > 0.0,
            });
        }
        if !deep.is_empty() {
            let d = deep
                .iter()
                .fold(deep[0], |a, &f| if f.depth > a.depth { f } else { a });
            let mut what = format!(
                "{} slave node(s) found inside a master body (deepest: node {} of contact '{}' by {:.3e})",
                deep.len(),
                d.slave as u64 + 1,
                self.problem.contacts[d.pair].name,
                d.depth
            );
            if let Some(e) = d.entry {
                what += &format!(
                    ", nearer ({:.3e}) to faces = [[{}, {}]], which is not in the master surface",
                    e.distance,
                    e.element as u64 + 1,
                    e.face
                );
            }
            if let Some(progress) = self.progress.as_mut() {
                progress(&format!("  t = {t}: penetration audit: {what}, tied back"));
            }
            watch.tied_back = Some(what);
            contact.recapture(self.comm, self.problem, self.mesh, u, &deep);
            watch
                .recaptured
                .extend(deep.iter().map(|f| (f.slave, f.pair)));
            watch.updates += 1;
            return Ok(true);
        }
        self.audit_depth = findings.iter().map(|f| f.depth).fold(0.0, f64::max);
        Ok(false)
    }

    /// A contact loop that did not settle under small kinematics, with a slave node slid
    /// more than a face size along its master (where reference normals no longer describe
    /// the surfaces): says so, naming the node. Collective.
    fn beyond_small_sliding(&self, e: SolveFailure, u: &[Vec3], contact: &E) -> SolveFailure {
        let SolveFailure::ContactNotSettled { updates, detail } = e else {
            return e;
        };
        let small = self
            .problem
            .body_models
            .iter()
            .all(|m| !m.material.is_large());
        let detail = match contact.largest_slide(self.comm, self.problem, self.mesh, u) {
            Some((node, slid)) if small && slid > 1.0 => format!(
                "{detail}; small sliding was exceeded: slave node {node} has slid {slid:.1} face sizes along its master surface, whose normals kinematics = \"small\" keeps at their reference directions"
            ),
            _ => detail,
        };
        SolveFailure::ContactNotSettled { updates, detail }
    }

    /// The active set after an update, on standard error, when SOLVER_DEBUG_CONTACT is set.
    fn debug_contact(&self, t: f64, update: usize, changed: bool, iterations: usize, contact: &E) {
        if std::env::var_os("SOLVER_DEBUG_CONTACT").is_none() || !self.comm.is_root() {
            return;
        }
        eprintln!("t = {t}: update {update}: changed {changed}, CG {iterations} iterations");
        eprintln!("{}", contact.describe());
    }
}

impl Watch {
    /// Records the set after an update. Two states that alternate are not yet a cycle when
    /// each has come back once (A B A B): a node that slips, sticks, and slips again while
    /// the friction forces settle has its next reversal judged only once they have settled
    /// (`coulomb`), so the alternation may stop at the next update. One that goes on
    /// (A B A B A) is a cycle. (Declared at A B A B, the extreme suite's drag was cut back
    /// twice at its first drag step: four nodes released, captured again, then stick, slip,
    /// stick, slip; given the one update more the rule of reversals needs, they slip on.)
    fn record(&mut self, contact: &impl Enforcement) -> Result<(), SolveFailure> {
        self.record_set(contact.set())
    }

    /// `record` for a given set. Besides the alternation above, a longer cycle: the set
    /// comes back to the same state after the same number of updates twice over, with
    /// stretches in between where it holds while the friction forces settle (runs of equal
    /// sets A^a B^b A^a B^b, then A again, with the first A run complete). A slipping node
    /// whose slip settles along its friction force is stuck by the reversal rule, slips
    /// again and settles into the same state: the block die of run/scenes/sliding/ at 300
    /// drag steps repeated a period of 10 updates until the update limit.
    fn record_set(&mut self, signature: Signature) -> Result<(), SolveFailure> {
        let h = &self.history;
        let n = h.len();
        if n >= 4
            && h[n - 2] == signature
            && h[n - 4] == signature
            && h[n - 1] != signature
            && h[n - 3] == h[n - 1]
        {
            return Err(SolveFailure::ContactNotSettled {
                updates: self.updates,
                detail: cycling_detail(&h[n - 1], &signature),
            });
        }
        if let Some(period) = repeats(&self.history, &signature) {
            let n = self.history.len();
            return Err(SolveFailure::ContactNotSettled {
                updates: self.updates,
                detail: format!(
                    "the constraint set comes back to the same states every {period} contact updates: {}",
                    cycling_nodes(&self.history[n - 1], &signature)
                ),
            });
        }
        self.history.push(signature);
        Ok(())
    }

    /// The failure at the update limit, naming what still changes.
    fn limit_reached(&self) -> SolveFailure {
        let h = &self.history;
        let detail = match h.len() {
            n if n >= 2 && h[n - 1] != h[n - 2] => format!(
                "the update limit was reached; still changing: {}",
                cycling_nodes(&h[n - 2], &h[n - 1])
            ),
            _ => "the update limit was reached while the contact forces were still changing"
                .to_string(),
        };
        SolveFailure::ContactNotSettled {
            updates: self.updates,
            detail,
        }
    }
}

/// The period of a cycle of `history` followed by `next` (see `Watch::record_set`): the
/// runs of equal sets end A^a B^b A^a B^b, preceded by another run, and `next` is A again.
fn repeats(history: &[Signature], next: &Signature) -> Option<usize> {
    if history.last() == Some(next) {
        return None;
    }
    // The runs (first index, length) of the last five, from the end.
    let mut runs: Vec<(usize, usize)> = Vec::new();
    let mut end = history.len();
    while end > 0 && runs.len() < 5 {
        let mut start = end - 1;
        while start > 0 && history[start - 1] == history[end - 1] {
            start -= 1;
        }
        runs.push((start, end - start));
        end = start;
    }
    if runs.len() < 5 {
        return None;
    }
    let [b2, a2, b1, a1] = [runs[0], runs[1], runs[2], runs[3]];
    let same = |x: (usize, usize), y: (usize, usize)| history[x.0] == history[y.0] && x.1 == y.1;
    (history[a2.0] == *next && same(a1, a2) && same(b1, b2)).then_some(a2.1 + b2.1)
}

/// Names the nodes whose constraints differ between two states.
fn cycling_nodes(a: &[(u32, usize, u32, u8)], b: &[(u32, usize, u32, u8)]) -> String {
    let mut nodes: Vec<u32> = a
        .iter()
        .filter(|x| !b.contains(x))
        .chain(b.iter().filter(|x| !a.contains(x)))
        .map(|x| x.0 + 1)
        .collect();
    nodes.sort_unstable();
    nodes.dedup();
    let shown: Vec<String> = nodes.iter().take(8).map(|n| n.to_string()).collect();
    format!(
        "slave node{} {}{} (between master faces, in and out of contact, or stick and slip)",
        if nodes.len() == 1 { "" } else { "s" },
        shown.join(", "),
        if nodes.len() > 8 { ", ..." } else { "" }
    )
}

fn cycling_detail(a: &[(u32, usize, u32, u8)], b: &[(u32, usize, u32, u8)]) -> String {
    format!(
        "the constraint set cycles between two states: {}; normal smoothing may help",
        cycling_nodes(a, b)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_set_that_comes_back_after_the_same_stretches_twice_is_a_cycle() {
        let a: Signature = vec![(336, 0, 14, 0)];
        let b: Signature = vec![(336, 0, 14, 1)];
        let c: Signature = vec![(336, 0, 13, 0)];
        let mut watch = Watch::default();
        // C (the approach), then A A A B, A A A B: the next A closes two equal periods.
        let mut seq = vec![c.clone()];
        for _ in 0..2 {
            seq.extend([a.clone(), a.clone(), a.clone(), b.clone()]);
        }
        for s in &seq {
            assert!(watch.record_set(s.clone()).is_ok());
        }
        let e = watch.record_set(a.clone()).expect_err("a cycle");
        assert!(e
            .to_string()
            .contains("comes back to the same states every 4 contact updates: slave node 337"));
        // Stretches of different lengths (still settling): not yet a cycle; nor is a first
        // A run that is not known to be complete (no run before it).
        let mut watch = Watch::default();
        let seq = [&c, &a, &a, &a, &b, &a, &a, &b];
        for s in seq {
            assert!(watch.record_set(s.clone()).is_ok());
        }
        assert!(watch.record_set(a.clone()).is_ok());
        let mut watch = Watch::default();
        for s in [&a, &a, &b, &a, &a, &b] {
            assert!(watch.record_set(s.clone()).is_ok());
        }
        assert!(watch.record_set(a.clone()).is_ok());
    }

    #[test]
    fn an_element_failure_after_a_tie_back_names_the_tie_back() {
        let mut watch = Watch::default();
        let inverted = || SolveFailure::Element("element 159: inverted element".into());
        // Nothing tied back: the failure as it was.
        assert_eq!(
            watch.explain(inverted()).to_string(),
            "element 159: inverted element"
        );
        watch.tied_back = Some(
            "8 slave node(s) found inside a master body (deepest: node 319 of contact 'a/b' by 3.293e-1)"
                .into(),
        );
        assert_eq!(
            watch.explain(inverted()).to_string(),
            "element 159: inverted element, after the penetration audit tied back 8 slave node(s) \
             found inside a master body (deepest: node 319 of contact 'a/b' by 3.293e-1)"
        );
        // Other failures are not the tie's doing: unchanged.
        let other = SolveFailure::NonFinite { iterations: 3 };
        let said = other.to_string();
        assert_eq!(watch.explain(other).to_string(), said);
    }
}
