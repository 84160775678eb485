//! The integration-point history of plastic bodies in the run's files: the element-mean
//! equivalent plastic strain of each written step, and the committed states a restart
//! continues from, both in global element order so that they do not depend on the ranks.

use super::Gather;
use crate::comm::Comm;
use crate::fem::history;
use crate::material::{PlasticState, STATE_LEN};
use crate::mesh::local::LocalMesh;
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

/// The committed history of every plastic element in global element order (the layout of
/// `history_len`), given to rank 0's `put` a round of element ids at a time
/// (`Gather::element_rounds`), so that rank 0 holds a round's states, not every element's
/// several times over (a cube of 10356 tet10 elements: five copies of 4.3 MB at the
/// restart's write). `put(total, first, values)`: the number of values in all, and the
/// round's values, entries `first..` of them. Collective.
pub(super) fn stream_history<C: Comm + ?Sized>(
    comm: &C,
    stepper: &Stepper<C>,
    gather: &Gather,
    mut put: impl FnMut(usize, usize, &[f64]),
) {
    if !stepper.assembly().has_history() {
        return;
    }
    let mut total = [stepper.assembly().owned_history_len() as i64];
    comm.sum_i64(&mut total);
    let total = total[0] as usize;
    let mut send = Vec::new();
    let mut round = Vec::new();
    let mut written = 0;
    for range in gather.element_rounds() {
        send.clear();
        stepper.assembly().owned_history_words(&range, &mut send);
        let parts = comm.gather_f64(&send);
        if !comm.is_root() {
            continue;
        }
        // Each part: (global id, n, n values) per element.
        let mut entries: Vec<(u32, &[f64])> = Vec::new();
        for part in &parts {
            let mut at = 0;
            while at < part.len() {
                let n = part[at + 1] as usize;
                entries.push((part[at] as u32, &part[at + 2..at + 2 + n]));
                at += 2 + n;
            }
        }
        entries.sort_unstable_by_key(|e| e.0);
        round.clear();
        for (_, values) in entries {
            round.extend_from_slice(values);
        }
        put(total, written, &round);
        written += round.len();
    }
}

/// Where each element's history lies in a restart state's `history` (of length
/// `history_len`, in global element order): None for an element of a body that is not
/// plastic.
pub(super) fn history_starts(problem: &Problem) -> Vec<Option<std::ops::Range<usize>>> {
    let mut at = 0;
    (0..problem.mesh.num_elements())
        .map(|e| {
            let b = problem.mesh.body_of_element(e);
            let m = &problem.body_models[b];
            m.material.is_plastic().then(|| {
                let n = history::points_of(problem.mesh.bodies[b].kind, m.formulation) * STATE_LEN;
                at += n;
                at - n..at
            })
        })
        .collect()
}

/// Sets the stepper's committed history from a restart state's history of this rank's
/// local elements (`local`'s, in local element order, the plastic ones only; `Fields`).
pub(super) fn restore<C: Comm + ?Sized>(
    stepper: &mut Stepper<C>,
    problem: &Problem,
    local: &LocalMesh,
    flat: &[f64],
) {
    if flat.is_empty() {
        return;
    }
    let points = |e: u32| {
        let b = problem.mesh.body_of_element(e as usize);
        let m = &problem.body_models[b];
        m.material
            .is_plastic()
            .then(|| history::points_of(problem.mesh.bodies[b].kind, m.formulation))
    };
    let mut at = 0;
    // (global element, first value) of each local plastic element, ascending.
    let starts: Vec<(u32, usize, usize)> = local
        .element_global
        .iter()
        .filter_map(|&g| {
            let n = points(g)?;
            at += n * STATE_LEN;
            Some((g, at - n * STATE_LEN, n))
        })
        .collect();
    stepper.assembly_mut().set_history(|g| {
        let k = starts.binary_search_by_key(&g, |s| u64::from(s.0)).ok()?;
        let (_, s, n) = starts[k];
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
