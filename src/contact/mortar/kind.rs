//! Mortar as a `PairKind`: a slave node's master point is its tie's (weights over several
//! master nodes), refreshed from the mortar surfaces gathered on every rank.

use super::slip::{mortar_driven_slip, mortar_step_slip};
use super::surfaces::Positions;
use crate::contact::active::{Active, ContactState};
use crate::contact::audit::Finding;
use crate::contact::coulomb::step_slip;
use crate::contact::discretisation::{Geometry, PairKind};
use crate::contact::slip::{driven_slip, SLIP_NOISE};
use crate::math::Vec3;
use crate::mesh::local::LocalMesh;
use crate::problem::{Discretization, Problem};

/// Mortar (segment-to-segment) contact with a dual Lagrange multiplier basis.
pub(crate) struct Mortar;

impl PairKind for Mortar {
    fn discretization(&self) -> Discretization {
        Discretization::Mortar
    }

    /// The tie's weights (none without a tie).
    fn masters(&self, state: &ContactState, _problem: &Problem, a: &Active) -> Vec<(u32, f64)> {
        state
            .tie(a.slave, a.pair)
            .map(|t| t.masters.clone())
            .unwrap_or_default()
    }

    /// Against the tie's master point; a node without a tie (or without gathered
    /// surfaces) measures at its master face's point as node-to-face does.
    fn slips(
        &self,
        state: &ContactState,
        problem: &Problem,
        mesh: &LocalMesh,
        (u, start): (&[Vec3], &[Vec3]),
        geometry: &Geometry<'_>,
        a: &Active,
    ) -> (Option<Vec3>, Option<Vec3>) {
        match (state.tie(a.slave, a.pair), geometry.positions.as_ref()) {
            (Some(t), Some(pos)) => {
                let noise = SLIP_NOISE * problem.contacts[a.pair].face_size;
                (
                    mortar_step_slip(a, t, mesh, pos),
                    mortar_driven_slip(a, t, mesh, pos, noise),
                )
            }
            _ => {
                let surface = &geometry.surfaces[a.pair];
                (
                    step_slip(a, mesh, u, start, surface),
                    driven_slip(surface, problem, mesh, u, a),
                )
            }
        }
    }

    fn restick(&self, state: &mut ContactState, k: usize, mesh: &LocalMesh, g: &Geometry<'_>) {
        if let Some(pos) = &g.positions {
            state.restick_mortar(k, mesh, pos);
        }
    }

    fn capture(
        &self,
        state: &mut ContactState,
        problem: &Problem,
        mesh: &LocalMesh,
        _u: &[Vec3],
        geometry: &Geometry<'_>,
        _slide: bool,
    ) -> bool {
        state.mortar_pairs(problem, mesh, geometry.positions.as_ref(), false)
    }

    fn search(
        &self,
        state: &mut ContactState,
        problem: &Problem,
        mesh: &LocalMesh,
        _u: &[Vec3],
        geometry: &Geometry<'_>,
    ) -> bool {
        state.mortar_pairs(problem, mesh, geometry.positions.as_ref(), true)
    }

    /// The weighted gaps of the pair's ties at the gathered surfaces.
    fn gaps(
        &self,
        problem: &Problem,
        mesh: &LocalMesh,
        _u: &[Vec3],
        p: usize,
        geometry: &Geometry<'_>,
        out: &mut Vec<(u32, f64)>,
    ) {
        if let Some(pos) = &geometry.positions {
            out.extend(pos.ties(problem, p, mesh).iter().map(|t| (t.slave, t.gap)));
        }
    }

    /// A tie holds the node's weighted gap, not its point, so a tied node may sit inside
    /// a curved master by the discretisation's error.
    fn audit_tied(&self) -> bool {
        true
    }

    fn recapture(
        &self,
        state: &mut ContactState,
        problem: &Problem,
        mesh: &LocalMesh,
        positions: &dyn Fn() -> Positions,
        findings: &[Finding],
    ) -> bool {
        // Every rank holds the same findings, so every rank gathers alike.
        if findings.is_empty() {
            return false;
        }
        state.mortar_recapture(problem, mesh, &positions(), findings);
        true
    }
}
