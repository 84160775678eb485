//! Gap removal after the penetration audit for node-to-face pairs: the nodes found inside
//! a master body tied again to the nearest master face.

use crate::contact::active::{Active, ContactState, Mode};
use crate::contact::audit::Finding;
use crate::problem::Problem;

/// Gap removal for the node-to-face nodes found inside a master body: each is tied to the
/// nearest master face (an active constraint on another face moves there), sticking where
/// the pair has friction. Every rank holds the same findings and the same active set, so
/// every rank changes it alike.
pub(super) fn recapture(state: &mut ContactState, problem: &Problem, findings: &[Finding]) {
    for f in findings {
        let it = &f.interaction;
        if let Some(a) = state
            .active
            .iter_mut()
            .find(|a| a.slave == f.slave && a.pair == f.pair)
        {
            a.face = it.face;
            a.s = it.s;
            a.normal = it.normal;
            a.fold = None;
            continue;
        }
        state.active.push(Active {
            pair: f.pair,
            slave: f.slave,
            face: it.face,
            s: it.s,
            normal: it.normal,
            offset: it.offset,
            mode: if problem.contacts[f.pair].mu > 0.0 {
                Mode::Stick
            } else {
                Mode::Free
            },
            normal_force: 0.0,
            tangential_force: [0.0; 3],
            slip_stiffness: 0.0,
            secant: None,
            start: None,
            reversals: 0,
            fold: None,
            left: None,
        });
    }
    state.active.sort_by_key(|a| (a.slave, a.pair));
}
