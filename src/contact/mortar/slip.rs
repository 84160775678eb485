//! The slip of a mortar node along the master: its motion relative to the point its tie
//! weights out of the master nodes, which the contact update (state.rs) judges as it
//! judges a node-to-face node's.

use super::surfaces::Positions;
use super::ties::{relative, Tie};
use crate::contact::active::Active;
use crate::math::{dot, norm, scale, sub, Vec3};
use crate::mesh::local::LocalMesh;

/// The tangential part of `d` for the constraint's normal.
fn tangential(a: &Active, d: &Vec3) -> Vec3 {
    sub(d, &scale(&a.normal, dot(d, &a.normal)))
}

/// The slip since the start of the step of a mortar node relative to its master point
/// (the tie's weights applied to the step's master motion), on the rank that owns it.
pub(super) fn mortar_step_slip(
    a: &Active,
    t: &Tie,
    mesh: &LocalMesh,
    positions: &Positions,
) -> Option<Vec3> {
    mesh.owned_node(a.slave)?;
    let now = relative(t, &positions.now(a.slave), &|g| positions.now(g));
    let then = relative(t, &positions.start(a.slave), &|g| positions.start(g));
    Some(tangential(a, &sub(&now, &then)))
}

/// How far a sticking mortar node sits from where its tie holds it along the master,
/// when more than `noise` (see `driven_slip`), on the rank that owns it.
pub(super) fn mortar_driven_slip(
    a: &Active,
    t: &Tie,
    mesh: &LocalMesh,
    positions: &Positions,
    noise: f64,
) -> Option<Vec3> {
    mesh.owned_node(a.slave)?;
    let now = relative(t, &positions.now(a.slave), &|g| positions.now(g));
    let d = tangential(a, &sub(&now, &t.offset));
    (norm(&d) > noise).then_some(d)
}
