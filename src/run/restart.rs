//! Restart: the state a result file keeps after each written step (displacements, the
//! contact constraints, the plastic history, the step records), read back and checked
//! against the scene, and sent from rank 0 to every rank.

use super::gather::Gather;
use super::plastic;
use crate::comm::{self, message, Comm};
use crate::contact::active::ContactState;
use crate::math::Vec3;
use crate::mesh::local::LocalMesh;
use crate::output::{RestartState, ResultFile, ResultWriter, StepOutput, StepStats};
use crate::problem::Problem;
use crate::solver::Stepper;
use partition::{Decomposition, RankPart};
use std::path::Path;

/// An earlier run to continue, as every rank holds it: its restart state (its
/// displacements and plastic history those of the rank's local nodes and elements), the
/// records of its steps, the contact state decoded, and (rank 0 only) its step results.
pub(super) struct Continued {
    pub(super) state: RestartState,
    pub(super) records: Vec<(f64, StepStats)>,
    pub(super) contact: ContactState,
    pub(super) steps: Vec<StepOutput>,
}

/// Reads the earlier run on rank 0 (before this run's file can replace it) and sends its
/// state to every rank: the contact state, the preconditioner's rows and the records to
/// every rank, the displacements and plastic history of each rank's local nodes and
/// elements to that rank alone (`decomposition`, rank 0's, says which), so that no rank
/// but 0 holds the whole mesh's. Collective.
pub(super) fn resume<C: Comm + ?Sized>(
    comm: &C,
    problem: &Problem,
    path: &Path,
    decomposition: Option<&Decomposition>,
) -> Result<Continued, String> {
    let mut bytes = Vec::new();
    let mut steps = Vec::new();
    let mut whole = None;
    let mut local_err = None;
    if comm.is_root() {
        match read_restart(path, problem) {
            Ok(r) => {
                let mut state = r.state;
                whole = Some(Fields {
                    displacement: std::mem::take(&mut state.displacement),
                    previous: std::mem::take(&mut state.previous_displacement),
                    history: std::mem::take(&mut state.history),
                });
                bytes = encode_restart(&state, &r.steps);
                steps = r.steps;
            }
            Err(e) => local_err = Some(e),
        }
    }
    if let Some(e) = comm::first_error(comm, local_err) {
        return Err(e);
    }
    comm.broadcast_bytes(0, &mut bytes);
    let (mut state, records) = decode_restart(&bytes, 0);
    drop(bytes);
    let starts = whole.as_ref().map(|_| plastic::history_starts(problem));
    let mine: Fields = message::scatter(comm, |r| {
        let (Some(w), Some(d), Some(starts)) = (&whole, decomposition, &starts) else {
            unreachable!("rank 0 holds the restart state and the decomposition")
        };
        w.of(d.part(r), starts)
    });
    drop(whole);
    state.displacement = mine.displacement;
    state.previous_displacement = mine.previous;
    state.history = mine.history;
    let contact = ContactState::decode(problem, &state.contact, &state.released, &state.ties)
        .ok_or_else(|| {
            format!(
                "{}: the restart state's contact constraints do not fit {}",
                path.display(),
                problem.file
            )
        })?;
    Ok(Continued {
        state,
        records,
        contact,
        steps,
    })
}

/// A restart state's fields of nodes and elements: the whole mesh's on rank 0, or a rank's
/// part (its local nodes' displacements, in `LocalMesh`'s order, and its local plastic
/// elements' history, in local element order).
struct Fields {
    displacement: Vec<Vec3>,
    previous: Vec<Vec3>,
    history: Vec<f64>,
}

impl Fields {
    /// The part of rank part `part` (`starts`: `plastic::history_starts`).
    fn of(&self, part: &RankPart, starts: &[Option<std::ops::Range<usize>>]) -> Fields {
        let nodes = part.local_nodes();
        Fields {
            displacement: nodes
                .iter()
                .map(|&g| self.displacement[g as usize])
                .collect(),
            previous: nodes.iter().map(|&g| self.previous[g as usize]).collect(),
            history: part
                .local_elements()
                .iter()
                .filter_map(|&e| starts[e as usize].clone())
                .flat_map(|range| self.history[range].iter().copied())
                .collect(),
        }
    }
}

impl message::Message for Fields {
    fn write(&self, w: &mut message::Writer<'_>) {
        w.put(&self.displacement);
        w.put(&self.previous);
        w.put(&self.history);
    }
    fn read(r: &mut message::Reader) -> Option<Self> {
        Some(Fields {
            displacement: r.get()?,
            previous: r.get()?,
            history: r.get()?,
        })
    }
}

/// The steps an earlier run finished, read from its result file on rank 0.
struct Resumed {
    state: RestartState,
    /// The earlier file's step results (rank 0 only).
    steps: Vec<StepOutput>,
}

/// Checks that a result file holds a restart state this scene can continue from: every
/// checksum of what a restart reads, and every value finite.
pub fn check_restart(path: &Path, problem: &Problem) -> Result<(), String> {
    read_restart(path, problem).map(|_| ())
}

/// Reads the restart state and the finished steps of an earlier run of the same scene.
fn read_restart(path: &Path, problem: &Problem) -> Result<Resumed, String> {
    let file = ResultFile::open(path).map_err(|e| e.to_string())?;
    let state = restart_of(&file, path, problem)?;
    let stats = file.stats().map_err(|e| e.to_string())?;
    let times = file.time().map_err(|e| e.to_string())?;
    let steps = (0..state.rows as usize)
        .map(|i| file.step_output(i, times[i], stats[i]))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| e.to_string())?;
    Ok(Resumed { state, steps })
}

fn restart_of(file: &ResultFile, path: &Path, problem: &Problem) -> Result<RestartState, String> {
    let shown = path.display();
    let attrs = file.attributes().map_err(|e| e.to_string())?;
    if attrs.scene_text != problem.text {
        return Err(format!(
            "{shown}: written by a different scene (or refinement) than {}; a restart continues the same scene",
            problem.file
        ));
    }
    let state = file
        .restart_state()
        .map_err(|e| e.to_string())?
        .ok_or_else(|| format!("{shown}: holds no restart state (no step was written)"))?;
    let step = state.step as usize;
    if step == 0
        || step > problem.step_times.len()
        || problem.step_times[step - 1] != state.time
        || state.rows as usize > file.num_steps()
    {
        return Err(format!(
            "{shown}: the restart state (step {step}, t = {}, {} rows) does not fit the scene's {} steps and the file's {} rows",
            state.time,
            state.rows,
            problem.step_times.len(),
            file.num_steps()
        ));
    }
    if state.history.len() != plastic::history_len(problem) {
        return Err(format!(
            "{shown}: the restart state's plastic history ({} values) does not fit {} ({} values)",
            state.history.len(),
            problem.file,
            plastic::history_len(problem)
        ));
    }
    if !state.hierarchy.is_empty()
        && !crate::solver::cg::hierarchy_words_fit(&state.hierarchy, problem.mesh.num_nodes())
    {
        return Err(format!(
            "{shown}: the restart state's preconditioner rows (dataset `{}`) do not fit {}",
            crate::output::layout::SLOT_HIERARCHY,
            problem.file
        ));
    }
    if ContactState::decode(problem, &state.contact, &state.released, &state.ties).is_none() {
        return Err(format!(
            "{shown}: the restart state's contact constraints do not fit {}",
            problem.file
        ));
    }
    Ok(state)
}

fn encode_restart(r: &RestartState, steps: &[StepOutput]) -> Vec<u8> {
    let mut v = vec![
        r.step as f64,
        r.time,
        r.dt_prev,
        r.reference_floor,
        r.rows as f64,
        r.multilevel_switched as u8 as f64,
        r.contact.len() as f64,
        r.released.len() as f64,
        r.history.len() as f64,
        r.ties.len() as f64,
        r.hierarchy.len() as f64,
    ];
    v.extend(r.displacement.iter().flatten());
    v.extend(r.previous_displacement.iter().flatten());
    v.extend(&r.contact);
    v.extend(&r.released);
    v.extend(&r.history);
    v.extend(&r.ties);
    v.extend(&r.hierarchy);
    for s in steps {
        let t = &s.stats;
        v.extend([
            s.time,
            t.cg_iterations as f64,
            t.contact_updates as f64,
            t.residual,
            t.wall_time,
            t.cutbacks as f64,
            t.contact_active as f64,
            t.contact_stick as f64,
            t.contact_slip as f64,
            t.contact_released as f64,
            t.max_penetration,
        ]);
    }
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// The restart state and the earlier steps' records, as every rank receives them.
fn decode_restart(bytes: &[u8], nodes: usize) -> (RestartState, Vec<(f64, StepStats)>) {
    let v: Vec<f64> = bytes
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
        .collect();
    let (nc, nr, nh, nt) = (v[6] as usize, v[7] as usize, v[8] as usize, v[9] as usize);
    let nk = v[10] as usize;
    let mut at = 11;
    let mut take = |n: usize| {
        let out = v[at..at + n].to_vec();
        at += n;
        out
    };
    let rows = |flat: Vec<f64>| -> Vec<Vec3> {
        flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
    };
    let displacement = rows(take(3 * nodes));
    let previous_displacement = rows(take(3 * nodes));
    let contact = take(nc);
    let released = take(nr);
    let history = take(nh);
    let ties = take(nt);
    let hierarchy = take(nk);
    let state = RestartState {
        history,
        ties,
        hierarchy,
        step: v[0] as u64,
        time: v[1],
        dt_prev: v[2],
        reference_floor: v[3],
        rows: v[4] as u64,
        multilevel_switched: v[5] != 0.0,
        displacement,
        previous_displacement,
        contact,
        released,
    };
    let records = v[at..]
        .chunks_exact(11)
        .map(|w| {
            (
                w[0],
                StepStats {
                    cg_iterations: w[1] as u64,
                    contact_updates: w[2] as u64,
                    residual: w[3],
                    wall_time: w[4],
                    cutbacks: w[5] as u64,
                    contact_active: w[6] as u64,
                    contact_stick: w[7] as u64,
                    contact_slip: w[8] as u64,
                    contact_released: w[9] as u64,
                    max_penetration: w[10],
                },
            )
        })
        .collect();
    (state, records)
}

/// Writes the state to resume from after `step` (collective): the displacement and the
/// previous one given to rank 0's `writer` a range of nodes at a time as they are gathered
/// (`Gather::stream`: rank 0 holds neither whole, 51 MB at 10^6 elements), then the rest.
/// Returns rank 0's write error.
pub(super) fn write_restart<C: Comm + ?Sized>(
    comm: &C,
    stepper: &Stepper<C>,
    (gather, local): (&Gather, &LocalMesh),
    (step, rows): (usize, u64),
    mut writer: Option<&mut ResultWriter>,
) -> Option<String> {
    let mut err = None;
    let owned = local.num_owned_nodes;
    for (previous, u) in [
        (false, &stepper.u[..]),
        (true, stepper.previous_displacement()),
    ] {
        gather.stream(comm, &u[..owned], &gather.nodes, |first, part| {
            if let (Some(w), None) = (writer.as_deref_mut(), &err) {
                err = w
                    .write_restart_part(rows, previous, first, part)
                    .err()
                    .map(|e| e.to_string());
            }
        });
    }
    plastic::stream_history(comm, stepper, gather, |total, first, part| {
        if let (Some(w), None) = (writer.as_deref_mut(), &err) {
            err = w
                .write_restart_history_part(rows, (total, first), part)
                .err()
                .map(|e| e.to_string());
        }
    });
    let (time, dt_prev, reference_floor) = stepper.scalars();
    let hierarchy = stepper.hierarchy_words();
    // Every rank holds the contact state whole; only the writing rank needs its words.
    let (contact, released, ties) = match writer {
        Some(_) => stepper.contact.encode(),
        None => Default::default(),
    };
    let r = RestartState {
        step: step as u64,
        time,
        dt_prev,
        reference_floor,
        rows,
        multilevel_switched: stepper.multilevel_switched(),
        // Written above.
        displacement: Vec::new(),
        previous_displacement: Vec::new(),
        contact,
        released,
        ties,
        hierarchy,
        // Written above.
        history: Vec::new(),
    };
    match (writer, err) {
        (Some(w), None) => w.write_restart(&r).err().map(|e| e.to_string()),
        (_, err) => err,
    }
}
