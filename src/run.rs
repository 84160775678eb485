//! One analysis from a validated problem to a result file: decompose, build the rank's
//! local mesh, step through time, gather each step's results on rank 0 and write them.

use crate::comm::{self, Comm};
use crate::constraints::RowKind;
use crate::contact::state::{ContactState, Mode};
use crate::math::Vec3;
use crate::mesh::local::LocalMesh;
use crate::output::contact_status;
use crate::output::{
    OutputBody, OutputMesh, RestartState, ResultFile, ResultWriter, RunInfo, StepOutput, StepStats,
};
use crate::problem::Problem;
use crate::solver::{StepRecord, Stepper};
use partition::Decomposition;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

mod gather;
mod plastic;
use gather::Gather;

#[derive(Clone, Debug)]
pub struct RunOptions {
    /// Result file; None writes nothing (tests that only need the numbers).
    pub output: Option<PathBuf>,
    /// 0 quiet, 1 step lines, 2 more.
    pub verbosity: u8,
}

/// The run's outcome as every rank sees it.
#[derive(Clone, Debug)]
pub struct RunSummary {
    pub steps: Vec<StepRecord>,
    pub wall_time: f64,
    pub output: Option<PathBuf>,
    /// Set when a step failed: the diagnostic (the result file then holds the steps before).
    pub failure: Option<String>,
    /// Largest peak resident memory of any rank, bytes (0 where the system does not say).
    pub peak_memory: f64,
}

/// This process's peak resident memory in bytes (Linux: VmHWM), if known.
pub fn peak_memory() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0)
}

/// The final state on rank 0 in global order (for tests and the verification checks).
#[derive(Clone, Debug, Default)]
pub struct GlobalState {
    pub displacement: Vec<Vec3>,
    pub stress: Vec<[f64; 6]>,
    pub reaction: Vec<Vec3>,
    pub contact_force: Vec<Vec3>,
    pub contact_status: Vec<u8>,
    /// Per element: equivalent plastic strain (empty without plastic bodies).
    pub plastic_strain: Vec<f64>,
    /// Active contact constraints at the end (one-rank runs): (slave node, pair, master
    /// body, stick).
    pub constraints: Vec<ActiveConstraint>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ActiveConstraint {
    /// 0-based global node id of the slave node.
    pub slave: u32,
    pub pair: usize,
    /// Index of the body the master face belongs to.
    pub master_body: usize,
    pub stick: bool,
    pub normal: Vec3,
    pub normal_force: f64,
}

/// How a scene splits over `ranks` ranks: the decomposition's balance, edge cut and per-rank
/// element and node counts, and the master faces each rank holds for its slave nodes at the
/// reference configuration (the ghosted faces of the contact search).
pub fn decomposition_report(problem: &Problem, ranks: usize) -> Result<String, String> {
    use std::fmt::Write;
    let mesh = &problem.mesh;
    let d = Decomposition::partition(mesh.num_nodes(), &mesh.elements, ranks).map_err(|e| {
        format!(
            "{}: cannot partition the mesh over {ranks} ranks: {e}",
            problem.file
        )
    })?;
    let mut s = d.stats().to_string();
    if !problem.contacts.is_empty() {
        let counts = crate::contact::ghost::face_counts(problem, &d);
        let owned = |r: usize, p: usize| {
            problem.contacts[p]
                .master_faces
                .iter()
                .filter(|(e, _)| d.element_part()[*e as usize] as usize == r)
                .count()
        };
        let _ = writeln!(
            s,
            "contact: master faces per rank (owned / held for the rank's slave nodes)"
        );
        for (p, pair) in problem.contacts.iter().enumerate() {
            let per: Vec<String> = (0..ranks)
                .map(|r| format!("rank {r}: {} / {}", owned(r, p), counts[r][p]))
                .collect();
            let _ = writeln!(
                s,
                "  {} ({} faces, {} slave nodes): {}",
                pair.name,
                pair.master_faces.len(),
                pair.slave_nodes.len(),
                per.join(", ")
            );
        }
    }
    Ok(s)
}

/// The whole mesh as the result file records it.
pub fn output_mesh(problem: &Problem) -> OutputMesh {
    let m = &problem.mesh;
    OutputMesh {
        coordinates: m.coords.clone(),
        node_ids: (1..=m.num_nodes() as u64).collect(),
        bodies: m
            .bodies
            .iter()
            .map(|b| OutputBody {
                name: b.name.clone(),
                connectivity: m.elements[b.first_element..b.first_element + b.num_elements]
                    .iter()
                    .map(|el| el.map(|n| n as u64))
                    .collect(),
                element_ids: (b.first_element as u64 + 1
                    ..=(b.first_element + b.num_elements) as u64)
                    .collect(),
            })
            .collect(),
        node_sets: problem
            .node_sets
            .iter()
            .map(|s| {
                (
                    s.name.clone(),
                    s.nodes.iter().map(|&n| n as u64 + 1).collect(),
                )
            })
            .collect(),
        side_sets: problem
            .side_sets
            .iter()
            .map(|s| {
                (
                    s.name.clone(),
                    s.faces.iter().map(|&(e, f)| (e as u64 + 1, f)).collect(),
                )
            })
            .collect(),
    }
}

pub fn run<C: Comm + ?Sized>(
    comm: &C,
    problem: &Problem,
    opts: &RunOptions,
) -> Result<(RunSummary, GlobalState), String> {
    run_from(comm, problem, opts, None)
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
    if ContactState::decode(problem, &state.contact, &state.released).is_none() {
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
        r.contact.len() as f64,
        r.released.len() as f64,
        r.history.len() as f64,
    ];
    v.extend(r.displacement.iter().flatten());
    v.extend(r.previous_displacement.iter().flatten());
    v.extend(&r.contact);
    v.extend(&r.released);
    v.extend(&r.history);
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
    let (nc, nr, nh) = (v[5] as usize, v[6] as usize, v[7] as usize);
    let mut at = 8;
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
    let state = RestartState {
        history,
        step: v[0] as u64,
        time: v[1],
        dt_prev: v[2],
        reference_floor: v[3],
        rows: v[4] as u64,
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

/// Runs the scene, continuing from the last step an earlier run of it recorded in
/// `restart` when given: the result is then bitwise the one of an uninterrupted run.
pub fn run_from<C: Comm + ?Sized>(
    comm: &C,
    problem: &Problem,
    opts: &RunOptions,
    restart: Option<&Path>,
) -> Result<(RunSummary, GlobalState), String> {
    let start = Instant::now();
    let root = comm.is_root();
    let log = |level: u8, msg: &str| {
        if root && opts.verbosity >= level {
            eprintln!("{msg}");
        }
    };
    let mesh = &problem.mesh;
    let decomposition = Decomposition::partition(mesh.num_nodes(), &mesh.elements, comm.size())
        .map_err(|e| {
            format!(
                "{}: cannot partition the mesh over {} ranks: {e}",
                problem.file,
                comm.size()
            )
        })?;
    let local = LocalMesh::new(mesh, &decomposition, comm.rank());
    log(
        1,
        &format!(
            "{}: {} bodies, {} elements, {} nodes, {} steps, {} rank(s)",
            problem.name,
            mesh.bodies.len(),
            mesh.num_elements(),
            mesh.num_nodes(),
            problem.step_times.len(),
            comm.size()
        ),
    );
    if comm.size() > 1 {
        log(2, &format!("{}", decomposition.stats()));
    }

    let mut local_err = None;
    // The earlier run to continue: read on rank 0 before this run's file replaces it.
    let mut earlier_steps = Vec::new();
    let mut resumed = None;
    if let Some(path) = restart {
        let mut bytes = Vec::new();
        if root {
            match read_restart(path, problem) {
                Ok(r) => {
                    bytes = encode_restart(&r.state, &r.steps);
                    earlier_steps = r.steps;
                }
                Err(e) => local_err = Some(e),
            }
        }
        if let Some(e) = comm::first_error(comm, local_err.take()) {
            return Err(e);
        }
        comm.broadcast_bytes(0, &mut bytes);
        let (state, records) = decode_restart(&bytes, mesh.num_nodes());
        let contact =
            ContactState::decode(problem, &state.contact, &state.released).ok_or_else(|| {
                format!(
                    "{}: the restart state's contact constraints do not fit {}",
                    path.display(),
                    problem.file
                )
            })?;
        resumed = Some((state, records, contact));
    }

    let mut writer = None;
    if root {
        if let Some(path) = &opts.output {
            let info = RunInfo {
                solver_version: env!("CARGO_PKG_VERSION").to_string(),
                ranks: comm.size() as u64,
                scene_text: problem.text.clone(),
                scene_name: problem.name.clone(),
                start_time: crate::output::rfc3339_now(),
                element_rank: decomposition.element_part().to_vec(),
            };
            if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                if let Err(e) = std::fs::create_dir_all(dir) {
                    local_err = Some(format!(
                        "{}: cannot create the output directory: {e}",
                        dir.display()
                    ));
                }
            }
            if local_err.is_none() {
                match ResultWriter::create(path, &info, &output_mesh(problem)) {
                    Ok(w) => writer = Some(w),
                    Err(e) => local_err = Some(e.to_string()),
                }
            }
        }
    }
    if let Some(e) = comm::first_error(comm, local_err.take()) {
        return Err(e);
    }

    let gather = Gather::new(comm, &local, mesh.num_nodes(), mesh.num_elements());
    let mut stepper = Stepper::new(comm, problem, &local)?;
    let refused = stepper.coarse_note.starts_with("preconditioner: refused");
    log(if refused { 1 } else { 2 }, &stepper.coarse_note);
    let mut records = Vec::new();
    let mut first_step = 0;
    if let Some((state, earlier, contact)) = resumed {
        stepper.restore(
            &state.displacement,
            &state.previous_displacement,
            (state.time, state.dt_prev, state.reference_floor),
            contact,
        );
        plastic::restore(&mut stepper, problem, &state.history);
        first_step = state.step as usize;
        for (time, s) in earlier {
            let step = problem
                .step_times
                .iter()
                .position(|&t| t == time)
                .map_or(0, |k| k + 1);
            records.push(StepRecord {
                step,
                time,
                cg_iterations: s.cg_iterations,
                contact_updates: s.contact_updates,
                residual: s.residual,
                cutbacks: s.cutbacks,
                wall_time: s.wall_time,
                ..Default::default()
            });
        }
        if let Some(w) = writer.as_mut() {
            // The earlier steps and their restart state: from here on this run's own file
            // is one a further restart can continue.
            local_err = earlier_steps
                .iter()
                .try_for_each(|s| w.append_step(s))
                .and_then(|()| w.write_restart(&state))
                .err()
                .map(|e| e.to_string());
        }
        if let Some(e) = comm::first_error(comm, local_err.take()) {
            return Err(e);
        }
        log(
            1,
            &format!(
                "continuing from step {first_step} (t = {}) of {}",
                state.time,
                restart.map(|p| p.display().to_string()).unwrap_or_default()
            ),
        );
    }
    let mut rows_written = earlier_steps.len() as u64;
    let mut failure = None;
    let nsteps = problem.step_times.len();
    let progress = (root && opts.verbosity >= 1 && std::io::stderr().is_terminal()).then(|| {
        let bar = indicatif::ProgressBar::new(nsteps as u64);
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:30} step {pos}/{len}  {msg}  [{elapsed} elapsed, ~{eta} left]",
            )
            .expect("a valid progress template"),
        );
        bar
    });
    let mut state = GlobalState::default();
    if let Some(bar) = &progress {
        bar.set_position(first_step as u64);
    }
    for (k, &t) in problem.step_times.iter().enumerate().skip(first_step) {
        let step = k + 1;
        let advanced = stepper.advance(step, t);
        if let Some(note) = stepper.take_rebuild_note() {
            log(2, &note);
        }
        match advanced {
            Ok(rec) => {
                let mut line = format!(
                    "step {step}/{nsteps}  t = {t:<10.6}  CG {:>6}  residual {:.3e} (reference {:.3e})  cut-backs {}  {:.3} s",
                    rec.cg_iterations, rec.residual, rec.reference, rec.cutbacks, rec.wall_time
                );
                if !problem.contacts.is_empty() {
                    let c = rec.contact;
                    line += &format!(
                        "  contact updates {}, in contact {} (stick {}, slip {}), released {}, max penetration {:.2e}",
                        rec.contact_updates, c.active, c.stick, c.slip, c.released, c.max_penetration
                    );
                }
                // Time left, from the pace of the steps this run has done so far.
                let done = (step - first_step) as f64;
                let left = (nsteps - step) as f64 * start.elapsed().as_secs_f64() / done;
                line += &format!("  ~{left:.0} s left");
                match &progress {
                    Some(bar) => {
                        bar.set_message(format!("t = {t:.4}  CG {}", rec.cg_iterations));
                        bar.inc(1);
                        if opts.verbosity >= 2 {
                            bar.println(&line);
                        }
                    }
                    None => log(1, &line),
                }
                records.push(rec);
                let last = step == nsteps;
                let write = opts.output.is_some() && (step % problem.output_every == 0 || last);
                if write || last {
                    let (s, err) = step_output(comm, problem, &stepper, &gather, &local, rec);
                    if let Some(e) = comm::first_error(comm, err) {
                        failure = Some(e);
                        break;
                    }
                    if root {
                        if let Some(w) = writer.as_mut().filter(|_| write) {
                            local_err = w.append_step(&s).err().map(|e| e.to_string());
                        }
                    }
                    if write {
                        rows_written += 1;
                        let r = restart_state(comm, &stepper, &gather, &local, step, rows_written);
                        if let Some(w) = writer.as_mut().filter(|_| local_err.is_none()) {
                            local_err = w.write_restart(&r).err().map(|e| e.to_string());
                        }
                    }
                    if let Some(e) = comm::first_error(comm, local_err.take()) {
                        failure = Some(e);
                        break;
                    }
                    // Test hook: die here as a killed run would (the restart test).
                    if std::env::var("SOLVER_TEST_ABORT_AFTER_STEP").ok() == Some(step.to_string())
                    {
                        std::process::abort();
                    }
                    if last {
                        state = GlobalState {
                            displacement: s.displacement,
                            stress: s.stress,
                            reaction: s.reaction,
                            contact_force: s.contact_force,
                            contact_status: s.contact_status,
                            plastic_strain: s.plastic_strain,
                            constraints: stepper
                                .contact
                                .active
                                .iter()
                                .map(|a| {
                                    let pair = &problem.contacts[a.pair];
                                    let (e, _) = pair.master_faces[a.face as usize];
                                    ActiveConstraint {
                                        slave: a.slave,
                                        pair: a.pair,
                                        master_body: problem.mesh.element_body[e as usize] as usize,
                                        stick: a.mode == Mode::Stick,
                                        normal: a.normal,
                                        normal_force: a.normal_force,
                                    }
                                })
                                .collect(),
                        };
                    }
                }
            }
            Err(f) => {
                failure = Some(format!("{}: {f}", problem.file));
                break;
            }
        }
    }
    if let Some(bar) = progress {
        bar.finish_and_clear();
    }
    let wall_time = start.elapsed().as_secs_f64();
    let peak_memory = comm::max_f64(comm, peak_memory().unwrap_or(0.0));
    let mut output = None;
    if let Some(w) = writer {
        let r = match &failure {
            None => w.finish(wall_time),
            Some(m) => w.finish_failed(wall_time, m),
        };
        match r {
            Ok(p) => output = Some(p),
            Err(e) => local_err = Some(e.to_string()),
        }
    }
    if let Some(e) = comm::first_error(comm, local_err) {
        return Err(e);
    }
    Ok((
        RunSummary {
            steps: records,
            wall_time,
            output,
            failure,
            peak_memory,
        },
        state,
    ))
}

/// The state to resume from after `step` (complete on rank 0).
fn restart_state<C: Comm + ?Sized>(
    comm: &C,
    stepper: &Stepper<C>,
    gather: &Gather,
    local: &LocalMesh,
    step: usize,
    rows: u64,
) -> RestartState {
    let (time, dt_prev, reference_floor) = stepper.scalars();
    let (contact, released) = stepper.contact.encode();
    RestartState {
        step: step as u64,
        time,
        dt_prev,
        reference_floor,
        rows,
        displacement: gather.nodes(comm, local, &stepper.u),
        previous_displacement: gather.nodes(comm, local, stepper.previous_displacement()),
        contact,
        released,
        history: plastic::gather_history(comm, stepper),
    }
}

fn step_output<C: Comm + ?Sized>(
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
    // Constraint forces from the row multipliers: Dirichlet rows give reactions, contact
    // rows the contact force on the slave node.
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
    // Status and gap of the slave nodes this rank owns.
    let mut status = vec![[0.0; 1]; local.num_owned_nodes];
    let mut gap = vec![[0.0; 1]; local.num_owned_nodes];
    if !stepper.contact.active.is_empty()
        || !stepper.contact.released().is_empty()
        || !problem.contacts.is_empty()
    {
        for &(s, _) in stepper.contact.released() {
            if let Some(l) = local.local_node(s).filter(|&l| l < local.num_owned_nodes) {
                status[l][0] = contact_status::RELEASED as f64;
            }
        }
        for a in &stepper.contact.active {
            if let Some(l) = local
                .local_node(a.slave)
                .filter(|&l| l < local.num_owned_nodes)
            {
                // A slipping node's friction force is applied as a load, not by a row.
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
            if let Some(l) = local.local_node(s).filter(|&l| l < local.num_owned_nodes) {
                gap[l][0] = g;
            }
        }
    }
    let n = gather.num_nodes;
    let out = StepOutput {
        time: rec.time,
        displacement: gather.nodes(comm, local, &stepper.u),
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
        plastic_strain: plastic::plastic_strain(comm, stepper, gather),
        stats: StepStats {
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
        },
    };
    (out, err)
}
