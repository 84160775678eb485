//! Which preconditioner a run uses under each setting, and the line that says why.
//!
//! By name: that one, or a refusal with the reason and block Jacobi instead. Under `auto`
//! (the default), by what makes one-level block Jacobi stall and what each choice costs:
//! - below TANGENT_NODES nodes with a plastic body: the full tangent (its factor follows
//!   the softened tangent where the body yields; `problem::uses_full_tangent`);
//! - at most SINGLETON_NODES nodes: block Jacobi (an iteration costs little), unless a
//!   body is nearly incompressible (Jacobi's iterations grow with K/G): multilevel;
//! - below TWO_LEVEL_NODES: multilevel from the start when a body is held by contact alone
//!   in some rigid-body motion (its stiffness there comes through the contact patch), else
//!   block Jacobi with multilevel on standby for a model problem that stalls;
//! - from TWO_LEVEL_NODES: two-level, with multilevel on standby up to
//!   MULTILEVEL_STANDBY_NODES.

use crate::comm::Comm;
use crate::mesh::local::LocalMesh;
use crate::precond::coarse::CoarseSpace;
use crate::precond::multilevel::transfer::SINGLETON_NODES;
use crate::precond::multilevel::{Multilevel, FINE_DEGREE};
use crate::problem::{
    uses_full_tangent, Preconditioner, Problem, MULTILEVEL_STANDBY_NODES, TANGENT_NODES,
    TWO_LEVEL_NODES,
};
use crate::solver::cg::SWITCH_AFTER;
use crate::solver::support::held_by_contact_alone;

/// The names of the bodies whose bulk modulus is at least NEARLY_INCOMPRESSIBLE times
/// their shear modulus.
fn nearly_incompressible(problem: &Problem) -> Vec<String> {
    problem
        .mesh
        .bodies
        .iter()
        .zip(&problem.body_models)
        .filter(|(_, model)| crate::problem::nearly_incompressible(&model.material))
        .map(|(body, _)| body.name.clone())
        .collect()
}

/// "body 'a', body 'b'".
fn named(bodies: &[String]) -> String {
    bodies
        .iter()
        .map(|b| format!("body '{b}'"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The preconditioner a run uses, with the line that says so: the multilevel one (with
/// `true` when it waits on standby for a model problem that stalls), the two-level one,
/// or nodal block Jacobi. A preconditioner asked for by name that cannot
/// be used says why in the line, which starts with "preconditioner: refused" then.
pub fn choose_preconditioner<C: Comm + ?Sized>(
    comm: &C,
    problem: &Problem,
    mesh: &LocalMesh,
) -> Choice {
    let nodes = problem.mesh.num_nodes();
    match problem.solver.preconditioner {
        Preconditioner::Jacobi => (None, None, "preconditioner: nodal block Jacobi".into()),
        Preconditioner::Multilevel => {
            let m = multilevel(comm, problem, mesh);
            let note = format!("preconditioner: multilevel; {}", m.summary);
            (None, Some((m, false)), note)
        }
        Preconditioner::TwoLevel => two_level(comm, problem, mesh, true),
        Preconditioner::Tangent => (
            None,
            None,
            "preconditioner: full tangent (the model problem's tangent assembled and factored)"
                .into(),
        ),
        Preconditioner::Auto if full_tangent(problem) => {
            let plastic: Vec<String> = problem
                .mesh
                .bodies
                .iter()
                .zip(&problem.body_models)
                .filter(|(_, model)| model.material.is_plastic())
                .map(|(body, _)| body.name.clone())
                .collect();
            let note = format!(
                "preconditioner: full tangent (plastic: {}; {nodes} nodes, below {TANGENT_NODES})",
                named(&plastic)
            );
            (None, None, note)
        }
        Preconditioner::Auto if nodes <= SINGLETON_NODES => small_mesh(comm, problem, mesh),
        Preconditioner::Auto if nodes < TWO_LEVEL_NODES => medium_mesh(comm, problem, mesh),
        Preconditioner::Auto => two_level(comm, problem, mesh, false),
    }
}

/// Whether the run uses the full tangent preconditioner (`problem::uses_full_tangent`).
pub fn full_tangent(problem: &Problem) -> bool {
    let plastic = problem.body_models.iter().any(|m| m.material.is_plastic());
    uses_full_tangent(
        problem.solver.preconditioner,
        plastic,
        problem.mesh.num_nodes() as u64,
    )
}

/// The coarse space, the multilevel preconditioner (with `true` when on standby) and the
/// line that says which.
type Choice = (Option<CoarseSpace>, Option<(Multilevel, bool)>, String);

fn multilevel<C: Comm + ?Sized>(comm: &C, problem: &Problem, mesh: &LocalMesh) -> Multilevel {
    Multilevel::new(comm, &problem.mesh, mesh, FINE_DEGREE)
}

/// `auto` on at most SINGLETON_NODES nodes: Jacobi, as an iteration costs little there,
/// while a model problem that stalls (a stiffness contrast below round-off) would pay a
/// factored preconditioner in every one of its iterations (contrast_stiff_on_soft, 250
/// nodes: 21 s -> 117 s with the switch). Except where a body is nearly incompressible:
/// Jacobi's iterations grow with K/G there whatever the size (incompressible_mean, 189
/// nodes, nu = 0.4999: 16634 CG iterations with Jacobi, 67 with multilevel).
fn small_mesh<C: Comm + ?Sized>(comm: &C, problem: &Problem, mesh: &LocalMesh) -> Choice {
    let stiff = nearly_incompressible(problem);
    if stiff.is_empty() {
        let nodes = problem.mesh.num_nodes();
        return (
            None,
            None,
            format!("preconditioner: nodal block Jacobi ({nodes} nodes)"),
        );
    }
    let m = multilevel(comm, problem, mesh);
    let note = format!(
        "preconditioner: multilevel (nearly incompressible: {}); {}",
        named(&stiff),
        m.summary
    );
    (None, Some((m, false)), note)
}

/// `auto` below TWO_LEVEL_NODES: multilevel from the start where a body is held by contact
/// alone in some rigid-body motion, which stalls Jacobi from the first model problem on
/// (Hertz x2: 791 CG iterations with the switch at 300, 496 with multilevel from the
/// start); otherwise Jacobi with multilevel on standby.
fn medium_mesh<C: Comm + ?Sized>(comm: &C, problem: &Problem, mesh: &LocalMesh) -> Choice {
    let m = multilevel(comm, problem, mesh);
    let held = held_by_contact_alone(problem);
    if !held.is_empty() {
        let note = format!(
            "preconditioner: multilevel (held by contact alone: {}); {}",
            named(&held),
            m.summary
        );
        return (None, Some((m, false)), note);
    }
    let note = format!(
        "preconditioner: nodal block Jacobi, multilevel from CG iteration {SWITCH_AFTER} of a model problem on; {}",
        m.summary
    );
    (None, Some((m, true)), note)
}

/// Two-level, asked for by name or under `auto` from TWO_LEVEL_NODES; under `auto` on
/// meshes up to MULTILEVEL_STANDBY_NODES with multilevel on standby: a model problem that
/// two-level does not solve in SWITCH_AFTER iterations goes on with multilevel (Hertz x4,
/// a cylinder held only by contact: no first model problem in 400 s with two-level; 584 CG
/// iterations in all, 36 s, with multilevel).
fn two_level<C: Comm + ?Sized>(
    comm: &C,
    problem: &Problem,
    mesh: &LocalMesh,
    asked: bool,
) -> Choice {
    let nodes = problem.mesh.num_nodes();
    let standby =
        (!asked && nodes <= MULTILEVEL_STANDBY_NODES).then(|| multilevel(comm, problem, mesh));
    match CoarseSpace::new(comm, problem, mesh) {
        Ok(c) => {
            let note = match &standby {
                Some(m) => format!(
                    "preconditioner: two-level, multilevel from CG iteration {SWITCH_AFTER} of a model problem on; {}; {}",
                    c.summary,
                    m.summary
                ),
                None => format!("preconditioner: two-level; {}", c.summary),
            };
            (Some(c), standby.map(|m| (m, true)), note)
        }
        Err(why) if asked => (
            None,
            None,
            format!("preconditioner: refused two_level ({why}); nodal block Jacobi instead"),
        ),
        Err(why) => (
            None,
            None,
            format!("preconditioner: nodal block Jacobi ({why})"),
        ),
    }
}
