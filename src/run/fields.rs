//! One written step's fields on rank 0 in global order: displacement, element stress,
//! reactions and contact forces from the constraint rows' multipliers, contact status and
//! gap of the slave nodes, the nodal contact pressure, plastic strain, and the step's
//! statistics.

use super::{plastic, Gather};
use crate::comm::Comm;
use crate::constraints::RowKind;
use crate::contact::state::Mode;
use crate::contact::Enforcement;
use crate::math::Vec3;
use crate::mesh::local::LocalMesh;
use crate::output::contact_status;
use crate::output::{StepOutput, StepStats};
use crate::problem::Problem;
use crate::solver::{StepRecord, Stepper};

/// Per owned node: reactions (Dirichlet rows) and contact forces on slave nodes (contact
/// rows), from the row multipliers.
fn constraint_forces<C: Comm + ?Sized>(
    stepper: &Stepper<C>,
    local: &LocalMesh,
) -> (Vec<Vec3>, Vec<Vec3>) {
    let cons = stepper.constraints();
    let mult = stepper.multipliers();
    let mut reaction = vec![[0.0; 3]; local.num_owned_nodes];
    let mut contact_force = vec![[0.0; 3]; local.num_owned_nodes];
    for a in 0..local.num_owned_nodes {
        for (i, row) in cons.rows(a) {
            let target = match row.kind {
                RowKind::Dirichlet(_) => &mut reaction[a],
                RowKind::Contact { .. } => &mut contact_force[a],
            };
            for d in 0..3 {
                target[d] += mult[i] * row.dir[d];
            }
        }
    }
    (reaction, contact_force)
}

/// Status and gap of the slave nodes this rank owns; adds the friction force of slipping
/// nodes (a load, not a row) to `contact_force`.
fn contact_fields<C: Comm + ?Sized>(
    comm: &C,
    problem: &Problem,
    stepper: &Stepper<C>,
    local: &LocalMesh,
    contact_force: &mut [Vec3],
) -> (Vec<[f64; 1]>, Vec<[f64; 1]>) {
    let mut status = vec![[0.0; 1]; local.num_owned_nodes];
    let mut gap = vec![[0.0; 1]; local.num_owned_nodes];
    if stepper.contact.active.is_empty()
        && stepper.contact.released().is_empty()
        && problem.contacts.is_empty()
    {
        return (status, gap);
    }
    let owned = |s: u32| local.local_node(s).filter(|&l| l < local.num_owned_nodes);
    for &(s, _) in stepper.contact.released() {
        if let Some(l) = owned(s) {
            status[l][0] = contact_status::RELEASED as f64;
        }
    }
    for a in &stepper.contact.active {
        if let Some(l) = owned(a.slave) {
            if let Mode::Slip { dir, magnitude } = a.mode {
                for d in 0..3 {
                    contact_force[l][d] += magnitude * dir[d];
                }
            }
            status[l][0] = match a.mode {
                Mode::Stick => contact_status::STICK,
                _ => contact_status::SLIP,
            } as f64;
        }
    }
    for (s, g) in stepper.contact.gaps(comm, problem, local, &stepper.u) {
        if let Some(l) = owned(s) {
            gap[l][0] = g;
        }
    }
    (status, gap)
}

/// The step's results in global order on rank 0 (collective), and an element failure of
/// the stress recovery on this rank.
pub(super) fn step_output<C: Comm + ?Sized>(
    comm: &C,
    problem: &Problem,
    stepper: &Stepper<C>,
    gather: &Gather,
    local: &LocalMesh,
    rec: StepRecord,
) -> (StepOutput, Option<String>) {
    let (stress, err) = match stepper.assembly().owned_stresses(&stepper.u) {
        Ok(s) => (s, None),
        Err(e) => (Vec::new(), Some(e.to_string())),
    };
    let (reaction, mut contact_force) = constraint_forces(stepper, local);
    let (status, gap) = contact_fields(comm, problem, stepper, local, &mut contact_force);
    let n = gather.num_nodes;
    let displacement = gather.nodes(comm, local, &stepper.u);
    // The active set is whole on every rank; the pressure is computed on rank 0 from the
    // global displacement, so it does not depend on the number of ranks.
    let contact_pressure = if comm.is_root() {
        crate::contact::area::contact_pressure(problem, &stepper.contact.active, &displacement)
    } else {
        Vec::new()
    };
    let out = StepOutput {
        time: rec.time,
        displacement,
        stress: gather.elements(comm, &stress),
        reaction: gather.nodes(comm, local, &reaction),
        contact_force: gather.nodes(comm, local, &contact_force),
        contact_status: gather
            .place(comm, &status, &gather.node_ids, n)
            .iter()
            .map(|v| v[0] as u8)
            .collect(),
        contact_gap: gather
            .place(comm, &gap, &gather.node_ids, n)
            .iter()
            .map(|v| v[0])
            .collect(),
        contact_pressure,
        plastic_strain: plastic::plastic_strain(comm, stepper, gather),
        stats: step_stats(&rec),
    };
    (out, err)
}

fn step_stats(rec: &StepRecord) -> StepStats {
    StepStats {
        cg_iterations: rec.cg_iterations,
        contact_updates: rec.contact_updates,
        residual: rec.residual,
        wall_time: rec.wall_time,
        cutbacks: rec.cutbacks,
        contact_active: rec.contact.active,
        contact_stick: rec.contact.stick,
        contact_slip: rec.contact.slip,
        contact_released: rec.contact.released,
        max_penetration: rec.contact.max_penetration,
    }
}
