//! One written step's fields on rank 0 in global order: displacement, element stress,
//! reactions and contact forces from the constraint rows' multipliers, contact status and
//! gap of the slave nodes, the nodal contact pressure, plastic strain, and the step's
//! statistics.

use super::{plastic, Gather};
use crate::comm::{self, message, Comm};
use crate::constraints::RowKind;
use crate::contact::active::Mode;
use crate::contact::Enforcement;
use crate::math::Vec3;
use crate::mesh::local::LocalMesh;
use crate::output::contact_status;
use crate::output::{ResultWriter, StepField, StepOutput, StepStats};
use crate::problem::Problem;
use crate::solver::{StepRecord, Stepper};
use std::ops::Range;

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

/// A step's fields on this rank (its owned nodes and elements), before they are gathered.
pub(super) struct Fields {
    stress: Vec<[f64; 6]>,
    reaction: Vec<Vec3>,
    contact_force: Vec<Vec3>,
    status: Vec<[f64; 1]>,
    gap: Vec<[f64; 1]>,
}

impl Fields {
    /// The fields, and an element failure of the stress recovery on this rank (collective).
    fn new<C: Comm + ?Sized>(
        comm: &C,
        problem: &Problem,
        stepper: &Stepper<C>,
        local: &LocalMesh,
    ) -> (Self, Option<String>) {
        let (stress, err) = match stepper.assembly().owned_stresses(&stepper.u) {
            Ok(s) => (s, None),
            Err(e) => (Vec::new(), Some(e.to_string())),
        };
        let (reaction, mut contact_force) = constraint_forces(stepper, local);
        let (status, gap) = contact_fields(comm, problem, stepper, local, &mut contact_force);
        let f = Fields {
            stress,
            reaction,
            contact_force,
            status,
            gap,
        };
        (f, err)
    }

    /// Every value finite (and the owned displacement and plastic strain).
    fn finite<C: Comm + ?Sized>(&self, stepper: &Stepper<C>, owned: usize) -> bool {
        finite(&self.stress) && self.nodal_finite(stepper, owned)
    }

    /// Every value but the stress finite (and the owned displacement and plastic strain).
    fn nodal_finite<C: Comm + ?Sized>(&self, stepper: &Stepper<C>, owned: usize) -> bool {
        finite(&self.reaction)
            && finite(&self.contact_force)
            && finite(&self.gap)
            && finite(&stepper.u[..owned])
            && stepper
                .assembly()
                .owned_eqps()
                .is_none_or(|v| v.iter().all(|x| x.is_finite()))
    }
}

fn finite<const W: usize>(v: &[[f64; W]]) -> bool {
    v.as_flattened().iter().all(|x| x.is_finite())
}

/// A step's fields on this rank as writing it needs them: whole (a step kept, `Whole`), or
/// only checked (`Checked`: whether every value is finite), for a step written field by
/// field, each formed again as it is written (`stream_step`), so that no rank holds the
/// whole step's fields at once (59 MB per rank at 10^6 elements).
pub(super) enum LocalFields {
    Whole(Fields),
    Checked(bool),
}

impl LocalFields {
    /// The fields (whole when `whole`), and an element failure of the stress recovery on
    /// this rank (collective).
    pub(super) fn new<C: Comm + ?Sized>(
        comm: &C,
        problem: &Problem,
        stepper: &Stepper<C>,
        local: &LocalMesh,
        whole: bool,
    ) -> (Self, Option<String>) {
        if whole {
            let (f, err) = Fields::new(comm, problem, stepper, local);
            return (LocalFields::Whole(f), err);
        }
        let (stress_finite, err) = match stepper.assembly().owned_stresses(&stepper.u) {
            Ok(s) => (finite(&s), None),
            Err(e) => (false, Some(e.to_string())),
        };
        let (reaction, mut contact_force) = constraint_forces(stepper, local);
        let (status, gap) = contact_fields(comm, problem, stepper, local, &mut contact_force);
        let nodal = Fields {
            stress: Vec::new(),
            reaction,
            contact_force,
            status,
            gap,
        };
        let ok = stress_finite && nodal.nodal_finite(stepper, local.num_owned_nodes);
        (LocalFields::Checked(ok), err)
    }
}

/// Where the gathered fields go on rank 0: written one at a time as they come (`writer`),
/// kept for a whole [`StepOutput`] (`kept`), or both.
struct Sink<'w> {
    writer: Option<&'w mut ResultWriter>,
    err: Option<String>,
    kept: Option<StepOutput>,
}

impl Sink<'_> {
    fn put(&mut self, f: StepField<'_>) {
        if let (Some(w), None) = (self.writer.as_deref_mut(), &self.err) {
            self.err = w.write_field(f).err().map(|e| e.to_string());
        }
    }

    fn put_part(&mut self, f: StepField<'_>, first: usize) {
        if let (Some(w), None) = (self.writer.as_deref_mut(), &self.err) {
            self.err = w.write_field_part(f, first).err().map(|e| e.to_string());
        }
    }
}

/// The step gathered onto rank 0 in global order and written when `write` (collective).
/// When every value is finite (`fields` checked) each field goes to the file a range of
/// entries at a time as it is gathered (`stream_step`), so that rank 0 holds a part of one
/// field and not the whole step; a step kept (`fields` whole) is written field by field as
/// each is gathered whole; otherwise the whole step is gathered and given to
/// [`ResultWriter::append_step`], whose checks name what is not finite. Returns the whole
/// step with `keep`, and rank 0's write error.
#[allow(clippy::too_many_arguments)]
pub(super) fn write_fields<C: Comm + ?Sized>(
    comm: &C,
    problem: &Problem,
    stepper: &Stepper<C>,
    (gather, local): (&Gather, &LocalMesh),
    fields: LocalFields,
    rec: &StepRecord,
    writer: Option<&mut ResultWriter>,
    (write, keep): (bool, bool),
) -> (Option<StepOutput>, Option<String>) {
    if !(write || keep) {
        return (None, None);
    }
    let stats = step_stats(rec);
    let contact_pressure = root_contact_pressure(comm, problem, stepper, local);
    let root_finite = contact_pressure
        .iter()
        .flatten()
        .all(|(_, p)| p.is_finite())
        && stats.writable(rec.time);
    let finite = match &fields {
        LocalFields::Whole(f) => f.finite(stepper, local.num_owned_nodes),
        LocalFields::Checked(ok) => *ok,
    } && root_finite;
    let stream = write && !comm::any(comm, !finite);
    let whole = !stream && (write || keep);
    let mut writer = writer.filter(|_| write && comm.is_root());
    let fields = match fields {
        LocalFields::Checked(_) if stream => {
            let err = stream_step(
                comm,
                problem,
                stepper,
                (gather, local),
                writer,
                contact_pressure,
                rec,
            );
            return (None, err);
        }
        // Formed again whole: a value is not finite, and the whole step's check names it.
        LocalFields::Checked(_) => Fields::new(comm, problem, stepper, local).0,
        LocalFields::Whole(f) => f,
    };
    let contact_pressure = match contact_pressure {
        Some(p) => {
            let mut whole = vec![0.0; problem.mesh.num_nodes()];
            for (n, v) in p {
                whole[n as usize] = v;
            }
            whole
        }
        None => Vec::new(),
    };
    let mut sink = Sink {
        writer: writer.as_deref_mut().filter(|_| stream),
        err: None,
        kept: (whole || keep).then(StepOutput::default),
    };
    let kept = gather_step(
        comm,
        stepper,
        (gather, local),
        fields,
        contact_pressure,
        &mut sink,
        (rec.time, stats),
    );
    let mut err = sink.err;
    if let (Some(w), Some(s)) = (writer.filter(|_| whole), &kept) {
        err = w.append_step(s).err().map(|e| e.to_string());
    }
    (kept.filter(|_| keep), err)
}

/// The contact pressure on rank 0 where it may differ from zero (`area::node_pressures`),
/// from the displacements it reads gathered in global order, so that it does not depend
/// on the number of ranks (the active set is whole on every rank); None elsewhere
/// (collective).
fn root_contact_pressure<C: Comm + ?Sized>(
    comm: &C,
    problem: &Problem,
    stepper: &Stepper<C>,
    local: &LocalMesh,
) -> Option<Vec<(u32, f64)>> {
    let active = &stepper.contact.active;
    let surface = surface_displacement(comm, problem, stepper, local);
    comm.is_root().then(|| {
        crate::contact::area::node_pressures(problem, active, |g| {
            let i = surface.binary_search_by_key(&g, |e| e.0);
            surface[i.expect("every slave face node is owned by a rank")].1
        })
    })
}

/// Gathers the step's `fields` onto rank 0 one at a time, each put into `sink` once
/// gathered and then dropped unless the sink keeps the step; the step ends in the writer
/// at `time` with `stats`. Returns the whole step when kept (collective).
fn gather_step<C: Comm + ?Sized>(
    comm: &C,
    stepper: &Stepper<C>,
    (gather, local): (&Gather, &LocalMesh),
    fields: Fields,
    contact_pressure: Vec<f64>,
    sink: &mut Sink<'_>,
    (time, stats): (f64, StepStats),
) -> Option<StepOutput> {
    let displacement = gather.nodes(comm, local, &stepper.u);
    sink.put(StepField::Displacement(&displacement));
    if !contact_pressure.is_empty() {
        sink.put(StepField::ContactPressure(&contact_pressure));
    }
    let displacement = sink.kept.is_some().then_some(displacement);
    let contact_pressure = sink.kept.is_some().then_some(contact_pressure);
    let Fields {
        stress,
        reaction,
        contact_force,
        status,
        gap,
    } = fields;
    // Each local field goes once gathered, each gathered one once written (unless kept).
    let all = gather.elements(comm, &stress);
    drop(stress);
    sink.put(StepField::Stress(&all));
    let stress = sink.kept.is_some().then_some(all);
    let all = gather.place(comm, &reaction, &gather.nodes);
    drop(reaction);
    sink.put(StepField::Reaction(&all));
    let reaction = sink.kept.is_some().then_some(all);
    let all = gather.place(comm, &contact_force, &gather.nodes);
    drop(contact_force);
    sink.put(StepField::ContactForce(&all));
    let contact_force = sink.kept.is_some().then_some(all);
    let all = gather.place(comm, &status, &gather.nodes);
    drop(status);
    let status: Vec<u8> = all.iter().map(|v| v[0] as u8).collect();
    drop(all);
    sink.put(StepField::ContactStatus(&status));
    let all = gather.place(comm, &gap, &gather.nodes);
    drop(gap);
    let gap: Vec<f64> = all.iter().map(|v| v[0]).collect();
    drop(all);
    sink.put(StepField::ContactGap(&gap));
    let plastic_strain = plastic::plastic_strain(comm, stepper, gather);
    if !plastic_strain.is_empty() {
        sink.put(StepField::PlasticStrain(&plastic_strain));
    }
    if let (Some(w), None) = (sink.writer.as_deref_mut(), &sink.err) {
        sink.err = w.end_step(time, &stats).err().map(|e| e.to_string());
    }
    sink.kept.take().map(|_| StepOutput {
        time,
        displacement: displacement.unwrap_or_default(),
        stress: stress.unwrap_or_default(),
        reaction: reaction.unwrap_or_default(),
        contact_force: contact_force.unwrap_or_default(),
        contact_status: status,
        contact_gap: gap,
        contact_pressure: contact_pressure.unwrap_or_default(),
        plastic_strain,
        stats,
    })
}

/// The displacements `contact_pressure` reads (`area::pressure_nodes`) as (global id,
/// displacement) on rank 0, sorted by id; empty elsewhere (collective).
fn surface_displacement<C: Comm + ?Sized>(
    comm: &C,
    problem: &Problem,
    stepper: &Stepper<C>,
    local: &LocalMesh,
) -> Vec<(u32, Vec3)> {
    let nodes = crate::contact::area::pressure_nodes(problem, &stepper.contact.active);
    let mine: Vec<(u32, Vec3)> = nodes
        .iter()
        .filter_map(|&g| local.owned_node(g).map(|l| (g, stepper.u[l])))
        .collect();
    let mut all = message::gather(comm, &mine);
    all.sort_unstable_by_key(|e| e.0);
    all
}

/// Writes a step whose values are all finite field by field (collective): each field is
/// formed again on every rank and written on rank 0 a range of entries at a time as it is
/// gathered (`Gather::stream`, `ResultWriter::write_field_part`); rank 0 holds the contact
/// pressure of the nodes in contact and writes it a chunk of nodes at a time. Returns
/// rank 0's write error.
fn stream_step<C: Comm + ?Sized>(
    comm: &C,
    problem: &Problem,
    stepper: &Stepper<C>,
    (gather, local): (&Gather, &LocalMesh),
    writer: Option<&mut ResultWriter>,
    contact_pressure: Option<Vec<(u32, f64)>>,
    rec: &StepRecord,
) -> Option<String> {
    let mut sink = Sink {
        writer,
        err: None,
        kept: None,
    };
    let owned = local.num_owned_nodes;
    gather.stream(comm, &stepper.u[..owned], &gather.nodes, |first, part| {
        sink.put_part(StepField::Displacement(part), first)
    });
    if let Some(p) = contact_pressure {
        let nodes = problem.mesh.num_nodes();
        let mut at = 0;
        for first in (0..nodes).step_by(crate::output::CHUNK_ROWS) {
            let end = (first + crate::output::CHUNK_ROWS).min(nodes);
            let mut part = vec![0.0; end - first];
            while at < p.len() && (p[at].0 as usize) < end {
                part[p[at].0 as usize - first] = p[at].1;
                at += 1;
            }
            sink.put_part(StepField::ContactPressure(&part), first);
        }
    }
    // The stress of a round's elements at a time. Recovered once already from the same
    // displacement (`LocalFields::new`), so it does not fail here; were it to, its values
    // are not finite and the writer refuses them.
    let asm = stepper.assembly();
    let stress = |range: &Range<u32>, n: usize| {
        let s = asm.owned_stresses_of(&stepper.u, |g| range.contains(&g));
        let s = s.unwrap_or_else(|_| vec![[f64::NAN; 6]; n]);
        s.into_flattened()
    };
    gather.stream_with(comm, &gather.elements, stress, |first, part| {
        sink.put_part(StepField::Stress(part), first)
    });
    let (reaction, mut contact_force) = constraint_forces(stepper, local);
    let (status, gap) = contact_fields(comm, problem, stepper, local, &mut contact_force);
    gather.stream(comm, &reaction, &gather.nodes, |first, part| {
        sink.put_part(StepField::Reaction(part), first)
    });
    drop(reaction);
    gather.stream(comm, &contact_force, &gather.nodes, |first, part| {
        sink.put_part(StepField::ContactForce(part), first)
    });
    drop(contact_force);
    gather.stream(comm, &status, &gather.nodes, |first, part| {
        let s: Vec<u8> = part.iter().map(|v| v[0] as u8).collect();
        sink.put_part(StepField::ContactStatus(&s), first)
    });
    drop(status);
    gather.stream(comm, &gap, &gather.nodes, |first, part| {
        let g: Vec<f64> = part.iter().map(|v| v[0]).collect();
        sink.put_part(StepField::ContactGap(&g), first)
    });
    drop(gap);
    let plastic_strain = plastic::plastic_strain(comm, stepper, gather);
    if !plastic_strain.is_empty() {
        sink.put(StepField::PlasticStrain(&plastic_strain));
    }
    if let (Some(w), None) = (sink.writer.as_deref_mut(), &sink.err) {
        sink.err = w
            .end_step(rec.time, &step_stats(rec))
            .err()
            .map(|e| e.to_string());
    }
    sink.err
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
