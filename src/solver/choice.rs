//! Which preconditioner a run uses under each setting, and the line that says why.
//!
//! By name: that one, or a refusal with the reason and block Jacobi instead. Under `auto`
//! (the default), by what makes one-level block Jacobi stall and what each choice costs:
//! - below TANGENT_NODES nodes with a plastic body: the full tangent (its factor follows
//!   the softened tangent where the body yields; `problem::uses_full_tangent`), unless its
//!   factorization would cost more than FACTOR_WORK_LIMIT (a 3-D mesh: then as below);
//! - at most SINGLETON_NODES nodes: block Jacobi (an iteration costs little), unless a
//!   body is nearly incompressible (Jacobi's iterations grow with K/G): multilevel;
//! - below MULTILEVEL_NODES: multilevel from the start when a body is held by contact alone
//!   in some rigid-body motion (its stiffness there comes through the contact patch), else
//!   block Jacobi with multilevel on standby for a model problem that stalls;
//! - from MULTILEVEL_NODES up: multilevel from the start.
//!
//! The two-level preconditioner runs when asked for by name only.

use crate::comm::Comm;
use crate::mesh::local::LocalMesh;
use crate::mesh::whole::Whole;
use crate::mesh::GlobalMesh;

/// This rank's part of the mesh and, on rank 0, the whole mesh (the run's set-up has it).
pub type At<'m> = (&'m LocalMesh, Option<&'m Whole<'m>>);
use crate::precond::coarse::CoarseSpace;
use crate::precond::multilevel::sparse_cholesky::SparseCholesky;
use crate::precond::multilevel::transfer::SINGLETON_NODES;
use crate::precond::multilevel::{Multilevel, FINE_DEGREE};
use crate::problem::{uses_full_tangent, Preconditioner, Problem, MULTILEVEL_NODES, TANGENT_NODES};
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
/// `tangent` is `tangent_decision`'s, made on the whole mesh.
pub fn choose_preconditioner<C: Comm + ?Sized>(
    comm: &C,
    problem: &Problem,
    mesh: At,
    tangent: &TangentDecision,
) -> Choice {
    let nodes = problem.mesh.num_nodes();
    match problem.solver.preconditioner {
        Preconditioner::Jacobi => (None, None, "preconditioner: nodal block Jacobi".into()),
        Preconditioner::Multilevel => {
            let m = multilevel(comm, mesh);
            let note = format!("preconditioner: multilevel; {}", m.summary);
            (None, Some((m, false)), note)
        }
        Preconditioner::TwoLevel => two_level(comm, problem, mesh),
        Preconditioner::Tangent => (
            None,
            None,
            "preconditioner: full tangent (the model problem's tangent assembled and factored)"
                .into(),
        ),
        Preconditioner::Auto => {
            if let Some(Ok(fill)) = tangent {
                return (None, None, tangent_note(problem, fill.unwrap_or(0.0)));
            }
            let (coarse, ml, mut note) = if nodes <= SINGLETON_NODES {
                small_mesh(comm, problem, mesh)
            } else if nodes < MULTILEVEL_NODES {
                medium_mesh(comm, problem, mesh)
            } else {
                large_mesh(comm, mesh, nodes)
            };
            if let Some(Err(why)) = tangent {
                note.push_str(&format!("; not the full tangent: {why}"));
            }
            (coarse, ml, note)
        }
    }
}

/// The line of a run under `auto` that factors the full tangent (`work`: its
/// factorization's, see FACTOR_WORK_LIMIT).
fn tangent_note(problem: &Problem, work: f64) -> String {
    let plastic: Vec<String> = problem
        .mesh
        .bodies
        .iter()
        .zip(&problem.body_models)
        .filter(|(_, model)| model.material.is_plastic())
        .map(|(body, _)| body.name.clone())
        .collect();
    format!(
        "preconditioner: full tangent (plastic: {}; {} nodes, below {TANGENT_NODES}; \
         factorization work {work:.1e}, at most {FACTOR_WORK_LIMIT:.0e})",
        named(&plastic),
        problem.mesh.num_nodes()
    )
}

/// The factorization work (the sum of the squares of the node graph factor's column
/// counts, in METIS's nested-dissection order) above which `auto` does not factor the full
/// tangent: a few seconds a factorization. Measured: the plane-strain punch at 80 x 80 and
/// the contact punch at n = 96 count 1.3e8 and 2.3e8 (their factors build in seconds); a
/// cube of tetrahedra of 4679 nodes 1.1e8 (4.0 million entries, 0.58 s a factorization; the
/// run 2.8 s with it), of 16194 nodes above the limit (26.3 million entries, 8.4 s a
/// factorization; the run 24.7 s and 456 MiB with it, 36.4 s and 86 MiB under `auto`): a
/// 3-D mesh's nested dissection fills in far more than a plane-strain slab's.
const FACTOR_WORK_LIMIT: f64 = 5e8;

/// Whether `auto` factors the full tangent: its factor's work (see FACTOR_WORK_LIMIT),
/// counted on the whole mesh's node graph in the factor's own order without factoring, or
/// Err saying why not.
fn factor_fits(mesh: &GlobalMesh) -> Result<f64, String> {
    match node_factor(mesh) {
        Some((_, work)) if work <= FACTOR_WORK_LIMIT => Ok(work),
        _ => Err(format!(
            "its factorization would take more than {FACTOR_WORK_LIMIT:e} units of work (a 3-D \
             mesh's fill; several seconds a factorization): it costs more than the iterations it saves"
        )),
    }
}

/// The factor of the whole mesh's node graph in METIS's nested-dissection order, counted
/// without factoring: its entries below the diagonal (node pairs) and its work (the sum of
/// the squares of its column counts). None when the work exceeds FACTOR_WORK_LIMIT (the
/// count stops there).
pub fn node_factor(mesh: &GlobalMesh) -> Option<(usize, f64)> {
    let mut edges = Vec::new();
    for e in mesh.elements.iter() {
        for (k, &a) in e.iter().enumerate() {
            edges.extend(e[k + 1..].iter().map(|&b| (a.min(b), a.max(b))));
        }
    }
    let g = crate::precond::multilevel::aggregation::Graph::from_edges(mesh.num_nodes(), &edges);
    drop(edges);
    // Entries E over n columns cost at least E^2 / n: beyond this many the work exceeds the
    // limit whatever their spread, and counting stops.
    let budget = (FACTOR_WORK_LIMIT * g.len() as f64).sqrt() as usize;
    SparseCholesky::graph_factor_entries(&g, budget).filter(|&(_, work)| work <= FACTOR_WORK_LIMIT)
}

/// Whether the run uses the full tangent preconditioner (`tangent` is `tangent_decision`'s):
/// by name, or under `auto` where a body is plastic on fewer than TANGENT_NODES nodes
/// (`problem::uses_full_tangent`) and its factor fits (`factor_fits`).
pub fn full_tangent(tangent: &TangentDecision) -> bool {
    matches!(tangent, Some(Ok(_)))
}

/// Why `auto` does not factor the full tangent though a body is plastic on fewer than
/// TANGENT_NODES nodes (its factorization's work), if so.
pub fn tangent_refused(problem: &Problem, whole: &GlobalMesh) -> Option<String> {
    tangent_decision(problem, whole).and_then(Result::err)
}

/// None where the full tangent is not considered; else whether it is used (with its
/// factorization's work under `auto`), or why not.
pub type TangentDecision = Option<Result<Option<f64>, String>>;

/// The full tangent's `TangentDecision` on the whole mesh.
pub fn tangent_decision(problem: &Problem, whole: &GlobalMesh) -> TangentDecision {
    let plastic = problem.body_models.iter().any(|m| m.material.is_plastic());
    let p = problem.solver.preconditioner;
    if !uses_full_tangent(p, plastic, problem.mesh.num_nodes() as u64) {
        return None;
    }
    Some(match p {
        Preconditioner::Auto => factor_fits(whole).map(Some),
        _ => Ok(None),
    })
}

/// The coarse space, the multilevel preconditioner (with `true` when on standby) and the
/// line that says which.
type Choice = (Option<CoarseSpace>, Option<(Multilevel, bool)>, String);

fn multilevel<C: Comm + ?Sized>(comm: &C, mesh: At) -> Multilevel {
    Multilevel::new(comm, mesh.1, mesh.0, FINE_DEGREE)
}

/// `auto` on at most SINGLETON_NODES nodes: Jacobi, as an iteration costs little there,
/// while a model problem that stalls (a stiffness contrast below round-off) would pay a
/// factored preconditioner in every one of its iterations (contrast_stiff_on_soft, 250
/// nodes: 21 s -> 117 s with the switch). Except where a body is nearly incompressible:
/// Jacobi's iterations grow with K/G there whatever the size (incompressible_mean, 189
/// nodes, nu = 0.4999: 16634 CG iterations with Jacobi, 67 with multilevel).
fn small_mesh<C: Comm + ?Sized>(comm: &C, problem: &Problem, mesh: At) -> Choice {
    let stiff = nearly_incompressible(problem);
    if stiff.is_empty() {
        let nodes = problem.mesh.num_nodes();
        return (
            None,
            None,
            format!("preconditioner: nodal block Jacobi ({nodes} nodes)"),
        );
    }
    let m = multilevel(comm, mesh);
    let note = format!(
        "preconditioner: multilevel (nearly incompressible: {}); {}",
        named(&stiff),
        m.summary
    );
    (None, Some((m, false)), note)
}

/// `auto` from MULTILEVEL_NODES up: multilevel from the start (see there).
fn large_mesh<C: Comm + ?Sized>(comm: &C, mesh: At, nodes: usize) -> Choice {
    let m = multilevel(comm, mesh);
    let note = format!(
        "preconditioner: multilevel ({nodes} nodes, from {MULTILEVEL_NODES} up); {}",
        m.summary
    );
    (None, Some((m, false)), note)
}

/// `auto` below MULTILEVEL_NODES: multilevel from the start where a body is held by contact
/// alone in some rigid-body motion, which stalls Jacobi from the first model problem on
/// (Hertz x2: 791 CG iterations with the switch at 300, 496 with multilevel from the
/// start); otherwise Jacobi with multilevel on standby.
fn medium_mesh<C: Comm + ?Sized>(comm: &C, problem: &Problem, mesh: At) -> Choice {
    let m = multilevel(comm, mesh);
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

/// Two-level, asked for by name; refused (block Jacobi instead) where no coarse space can
/// be built (several bodies in one of its cells).
fn two_level<C: Comm + ?Sized>(comm: &C, problem: &Problem, mesh: At) -> Choice {
    match CoarseSpace::new(comm, problem, mesh.1, mesh.0) {
        Ok(c) => {
            let note = format!("preconditioner: two-level; {}", c.summary);
            (Some(c), None, note)
        }
        Err(why) => (
            None,
            None,
            format!("preconditioner: refused two_level ({why}); nodal block Jacobi instead"),
        ),
    }
}
