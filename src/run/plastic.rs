//! The integration-point history of plastic bodies in the run's files: the element-mean
//! equivalent plastic strain of each written step, and the committed states a restart
//! continues from, both in global element order so that they do not depend on the ranks.

use super::Gather;
use crate::comm::{message, Comm};
use crate::fem::history;
use crate::material::{PlasticState, STATE_LEN};
use crate::problem::Problem;
use crate::solver::Stepper;

/// Values the history of `problem` takes in a restart state (0 without plastic bodies).
pub(super) fn history_len(problem: &Problem) -> usize {
    problem
        .mesh
        .bodies
        .iter()
        .zip(&problem.body_models)
        .filter(|(_, m)| m.material.is_plastic())
        .map(|(b, m)| b.num_elements * history::points_of(b.kind, m.formulation) * STATE_LEN)
        .sum()
}

/// The committed history of every plastic element, on rank 0 in global element order
/// (empty elsewhere and without plastic bodies).
pub(super) fn gather_history<C: Comm + ?Sized>(comm: &C, stepper: &Stepper<C>) -> Vec<f64> {
    if !stepper.assembly().has_history() {
        return Vec::new();
    }
    // (global id, the values of each integration point) per owned plastic element.
    let mine: Vec<(u32, Vec<[f64; STATE_LEN]>)> = stepper
        .assembly()
        .owned_history()
        .into_iter()
        .map(|(g, states)| (g as u32, states.iter().map(|s| s.to_array()).collect()))
        .collect();
    let mut elements = message::gather(comm, &mine);
    if !comm.is_root() {
        return Vec::new();
    }
    elements.sort_by_key(|e| e.0);
    elements
        .iter()
        .flat_map(|e| e.1.iter().flatten().copied())
        .collect()
}

/// Sets the stepper's committed history from a restart state's `history` (of length
/// `history_len`, checked when the state was read).
pub(super) fn restore<C: Comm + ?Sized>(stepper: &mut Stepper<C>, problem: &Problem, flat: &[f64]) {
    if flat.is_empty() {
        return;
    }
    let mut start = vec![usize::MAX; problem.mesh.num_elements()];
    let mut at = 0;
    for (e, s) in start.iter_mut().enumerate() {
        let b = problem.mesh.body_of_element(e);
        let m = &problem.body_models[b];
        if m.material.is_plastic() {
            *s = at;
            at += history::points_of(problem.mesh.bodies[b].kind, m.formulation) * STATE_LEN;
        }
    }
    stepper.assembly_mut().set_history(|g| {
        let e = g as usize;
        let s = *start.get(e)?;
        if s == usize::MAX {
            return None;
        }
        let b = problem.mesh.body_of_element(e);
        let n = history::points_of(
            problem.mesh.bodies[b].kind,
            problem.body_models[b].formulation,
        );
        Some(
            (0..n)
                .map(|q| PlasticState::from_slice(&flat[s + q * STATE_LEN..]))
                .collect(),
        )
    });
}

/// The element-mean equivalent plastic strain on rank 0 in global element order; empty
/// without plastic bodies.
pub(super) fn plastic_strain<C: Comm + ?Sized>(
    comm: &C,
    stepper: &Stepper<C>,
    gather: &Gather,
) -> Vec<f64> {
    match stepper.assembly().owned_eqps() {
        None => Vec::new(),
        Some(v) => {
            let rows: Vec<[f64; 1]> = v.iter().map(|&x| [x]).collect();
            gather
                .place(comm, &rows, &gather.elements)
                .iter()
                .map(|r| r[0])
                .collect()
        }
    }
}
