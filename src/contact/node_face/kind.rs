//! Node-to-face as a `PairKind`: a slave node's master point is a point of one bilinear
//! master face, found by the search over the ghosted master surfaces.

use crate::contact::active::{Active, ContactState};
use crate::contact::audit::Finding;
use crate::contact::coulomb::step_slip;
use crate::contact::discretisation::{Geometry, PairKind};
use crate::contact::ghost;
use crate::contact::mortar::surfaces::Positions;
use crate::contact::slip::driven_slip;
use crate::math::Vec3;
use crate::mesh::local::LocalMesh;
use crate::problem::{Discretization, Problem};

/// Node-to-face contact (the paper's).
pub(crate) struct NodeFace;

impl PairKind for NodeFace {
    fn discretization(&self) -> Discretization {
        Discretization::NodeFace
    }

    /// The face's shape functions at the contact point.
    fn masters(&self, _state: &ContactState, problem: &Problem, a: &Active) -> Vec<(u32, f64)> {
        let nodes = &problem.contacts[a.pair].face_nodes[a.face as usize];
        let w = crate::contact::facet::shape_of(nodes, &a.s);
        nodes.iter().copied().zip(w).collect()
    }

    fn slips(
        &self,
        _state: &ContactState,
        problem: &Problem,
        mesh: &LocalMesh,
        (u, start): (&[Vec3], &[Vec3]),
        geometry: &Geometry<'_>,
        a: &Active,
    ) -> (Option<Vec3>, Option<Vec3>) {
        let surface = &geometry.surfaces[a.pair];
        (
            step_slip(a, mesh, u, start, surface),
            driven_slip(surface, problem, mesh, u, a),
        )
    }

    fn capture(
        &self,
        state: &mut ContactState,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
        geometry: &Geometry<'_>,
        slide: bool,
    ) -> bool {
        if slide {
            state.slide_to(problem, mesh, u, &geometry.surfaces);
        }
        state.capture_node_face(problem, mesh, u, &geometry.surfaces)
    }

    fn search(
        &self,
        state: &mut ContactState,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
        geometry: &Geometry<'_>,
    ) -> bool {
        state.search(problem, mesh, u, &geometry.surfaces)
    }

    fn gaps(
        &self,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
        p: usize,
        geometry: &Geometry<'_>,
        out: &mut Vec<(u32, f64)>,
    ) {
        let pair = &problem.contacts[p];
        for (i, &s) in pair.slave_nodes.iter().enumerate() {
            let Some(l) = mesh.owned_node(s) else {
                continue;
            };
            let x = ghost::position(mesh, u, l);
            // A self contact node's gap is to a face facing it, not to its own.
            let facing = pair.is_self().then(|| pair.facing(i)).flatten();
            let surface = &geometry.surfaces[p];
            let found = surface.search_near(&x, facing, pair.skipped(i));
            if let Some(it) = found.map(|it| surface.symmetrise(it, &x, s)) {
                out.push((s, it.gap));
            }
        }
    }

    fn recapture(
        &self,
        state: &mut ContactState,
        problem: &Problem,
        _mesh: &LocalMesh,
        _positions: &dyn Fn() -> Positions,
        findings: &[Finding],
    ) -> bool {
        super::recapture(state, problem, findings);
        false
    }
}
