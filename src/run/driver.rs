//! The analysis driver, phase by phase: set up (partition the mesh, build this rank's
//! part, read an earlier run to continue, open the result file, build the stepper), step
//! through time (advance, report, write the step and its restart state), finish the file.

use super::fields::{write_fields, LocalFields};
use super::gather::Gather;
use super::mesh::RunMesh;
use super::outcome::{peak_memory, ActiveConstraint, GlobalState, RunOptions, RunSummary};
use super::plastic;
use super::restart::{self, Continued};
use crate::comm::{self, message, Comm};
use crate::contact::active::Mode;
use crate::mesh::local::LocalMesh;
use crate::mesh::whole::Whole;
use crate::mesh::GlobalMesh;
use crate::output::{ResultWriter, RunInfo, StepOutput};
use crate::problem::Problem;
use crate::solver::{StepRecord, Stepper};
use partition::Decomposition;
use std::borrow::Cow;
use std::io::IsTerminal;
use std::path::Path;
use std::time::Instant;

/// Messages of rank 0 at a verbosity.
struct Log {
    root: bool,
    verbosity: u8,
}

impl Log {
    fn at(&self, level: u8, msg: &str) {
        if self.root && self.verbosity >= level {
            eprintln!("{msg}");
        }
    }
}

/// Where the run is: the records of the steps done, the first step this run takes, and
/// the rows its result file holds.
struct Progress {
    records: Vec<StepRecord>,
    /// This rank's traffic in the CG loops, and those loops' iterations.
    cg_traffic: comm::Traffic,
    cg_loop_iterations: u64,
    cg_loop_seconds: f64,
    contact_updates: u64,
    contact_seconds: f64,
    first_step: usize,
    rows_written: u64,
    started: Instant,
}

impl Progress {
    /// Nothing done yet; the clock starts now.
    fn start() -> Self {
        Progress {
            records: Vec::new(),
            first_step: 0,
            rows_written: 0,
            started: Instant::now(),
            cg_traffic: comm::Traffic::default(),
            cg_loop_iterations: 0,
            cg_loop_seconds: 0.0,
            contact_updates: 0,
            contact_seconds: 0.0,
        }
    }
}

/// Runs the scene, continuing from the last step an earlier run of it recorded in
/// `restart` when given: the result is then bitwise the one of an uninterrupted run. The
/// run reads `problem`'s outline (`Problem::outline`), its whole mesh only while set up.
pub fn run_from<C: Comm + ?Sized>(
    comm: &C,
    problem: &Problem,
    opts: &RunOptions,
    restart: Option<&Path>,
) -> Result<(RunSummary, GlobalState), String> {
    if crate::contact::adjust::wanted(problem) {
        // The adjusted reference configuration is a copy's.
        return run_owned(comm, problem.clone(), opts, restart);
    }
    let outline = problem.outline();
    let whole = comm.is_root().then_some(Cow::Borrowed(&problem.mesh));
    run_outline(comm, &outline, whole, opts, restart)
}

/// `run_from` taking the problem: its whole mesh is freed once the run is set up (every
/// rank's copy of it, 60 MB per rank at 10^6 elements): `run_from_root` of rank 0's.
pub fn run_owned<C: Comm + ?Sized>(
    comm: &C,
    problem: Problem,
    opts: &RunOptions,
    restart: Option<&Path>,
) -> Result<(RunSummary, GlobalState), String> {
    run_from_root(comm, comm.is_root().then_some(problem), opts, restart)
}

/// `run_from` of the problem rank 0 holds (None on the other ranks): only rank 0 holds its
/// whole mesh, and it frees it once the run is set up. The pairs' `adjust` moves slave
/// nodes onto their master surfaces first (`contact::adjust`); rank 0 then sends every
/// rank the problem's outline (`Problem::outline`), and makes and sends what the set-up
/// needs of the whole mesh (`mesh::whole`).
pub fn run_from_root<C: Comm + ?Sized>(
    comm: &C,
    problem: Option<Problem>,
    opts: &RunOptions,
    restart: Option<&Path>,
) -> Result<(RunSummary, GlobalState), String> {
    let log = Log {
        root: comm.is_root(),
        verbosity: opts.verbosity,
    };
    let (outline, whole) = match problem.filter(|_| comm.is_root()) {
        Some(mut problem) => {
            let adjusted = crate::contact::adjust::adjust(&mut problem);
            for line in crate::contact::adjust::describe(&problem, &adjusted) {
                log.at(1, &line);
            }
            let (outline, whole) = problem.into_outline();
            (Some(outline), Some(whole))
        }
        None => (None, None),
    };
    let outline = message::broadcast_value(comm, outline);
    run_outline(comm, &outline, whole.map(Cow::Owned), opts, restart)
}

/// `run_from` of a problem's outline, with its whole mesh for the set-up on rank 0 (None
/// on the other ranks).
fn run_outline<C: Comm + ?Sized>(
    comm: &C,
    problem: &Problem,
    whole: Option<Cow<'_, GlobalMesh>>,
    opts: &RunOptions,
    restart: Option<&Path>,
) -> Result<(RunSummary, GlobalState), String> {
    let log = Log {
        root: comm.is_root(),
        verbosity: opts.verbosity,
    };
    let mut progress = Progress::start();
    let (decomposition, local) = partition(comm, problem, whole.as_deref(), opts, &log)?;
    let continued = restart
        .map(|path| restart::resume(comm, problem, path, decomposition.as_ref()))
        .transpose()?;
    let mut writer = open_writer(
        comm,
        (problem, whole.as_deref()),
        opts,
        decomposition.as_ref(),
    )?;
    let gather = Gather::new(
        &local,
        problem.mesh.num_nodes(),
        problem.mesh.num_elements(),
    );
    // The stepper frees an owned whole mesh once read (the steps read the outline), and the
    // decomposition goes once the stepper is built (21 MB of lists at n = 80).
    let whole = whole
        .zip(decomposition.as_ref())
        .map(|(w, d)| Whole::new(w, d));
    let mut stepper = new_stepper(comm, problem, (&local, whole), opts, &log)?;
    drop(decomposition);
    if let Some((c, path)) = continued.zip(restart) {
        let with_pressure = continue_from(
            comm,
            (problem, &local),
            &mut stepper,
            writer.as_mut(),
            c,
            &mut progress,
        )?;
        log.at(
            1,
            &continuing_line(&progress, stepper.time, path, with_pressure),
        );
    }
    let sent_before = comm.traffic();
    let (mut failure, state) = step_through(
        comm,
        problem,
        opts,
        &log,
        &mut stepper,
        (&gather, &local),
        writer.as_mut(),
        &mut progress,
    );
    if let Some(dir) = opts
        .export_operator
        .as_ref()
        .filter(|_| stepper.export_pending())
    {
        failure.get_or_insert_with(|| {
            format!(
                "--export-operator {}: no model problem needed a CG iteration; nothing exported",
                dir.display()
            )
        });
    }
    let (traffic_max, traffic_sum) = over_the_ranks(comm, comm.traffic().since(&sent_before));
    let (cg_traffic_max, cg_traffic_sum) = over_the_ranks(comm, progress.cg_traffic);
    let wall_time = progress.started.elapsed().as_secs_f64();
    // Closing the file reads it back (rank 0 checks every dataset): the solver's state,
    // preconditioner and work vectors are not needed for it and not held through it.
    drop(stepper);
    let output = finish(comm, writer, &failure, wall_time);
    // The peak of the whole run, the file's closing check included.
    let peak_memory = comm::max_f64(comm, peak_memory().unwrap_or(0.0));
    let output = output?;
    Ok((
        RunSummary {
            steps: progress.records,
            wall_time,
            output,
            failure,
            peak_memory,
            traffic_max,
            traffic_sum,
            cg_traffic_max,
            cg_traffic_sum,
            cg_loop_iterations: progress.cg_loop_iterations,
            cg_loop_seconds: comm::max_f64(comm, progress.cg_loop_seconds),
            contact_updates: progress.contact_updates,
            contact_seconds: comm::max_f64(comm, progress.contact_seconds),
        },
        state,
    ))
}

/// This rank's counts `sent` over the ranks: each count's largest and its sum.
fn over_the_ranks<C: Comm + ?Sized>(
    comm: &C,
    sent: comm::Traffic,
) -> (comm::Traffic, comm::Traffic) {
    let sent = sent.as_array();
    let mut largest = sent.map(|v| v as f64);
    comm.max_f64(&mut largest);
    let mut sum = sent.map(|v| v as i64);
    comm.sum_i64(&mut sum);
    (
        comm::Traffic::from_array(largest.map(|v| v as u64)),
        comm::Traffic::from_array(sum.map(|v| v as u64)),
    )
}

/// The stepper of this rank's part of the mesh, asked for the operator export when the
/// options ask (one rank only), its preconditioner's and element matrices' notes logged.
fn new_stepper<'a, C: Comm + ?Sized>(
    comm: &'a C,
    problem: &'a Problem,
    (local, whole): (&'a LocalMesh, Option<Whole<'_>>),
    opts: &RunOptions,
    log: &Log,
) -> Result<Stepper<'a, C>, String> {
    let mut stepper = Stepper::with_enforcement(comm, problem, local, whole)?;
    if opts.export_operator.is_some() {
        if comm.size() != 1 {
            return Err(format!(
                "the operator export works on one rank only (this run has {})",
                comm.size()
            ));
        }
        stepper.request_export();
    }
    let refused = stepper.coarse_note.starts_with("preconditioner: refused");
    log.at(if refused { 1 } else { 2 }, &stepper.coarse_note);
    if let Some(note) = &stepper.shapes_note {
        log.at(2, note);
    }
    Ok(stepper)
}

/// The decomposition over the ranks (on rank 0, which holds the whole mesh `whole`) and
/// this rank's part of the mesh: rank 0 partitions the mesh and makes every rank's part,
/// one at a time, and sends it (collective; rank 0's failure is every rank's).
fn partition<C: Comm + ?Sized>(
    comm: &C,
    problem: &Problem,
    whole: Option<&GlobalMesh>,
    opts: &RunOptions,
    log: &Log,
) -> Result<(Option<Decomposition>, LocalMesh), String> {
    let parts =
        super::decompose::element_parts(comm, whole, problem.mesh.num_elements(), opts.partition);
    let decomposition = whole.map(|mesh| {
        Decomposition::try_new(mesh.num_nodes(), &mesh.elements, &parts?, comm.size())
            .map_err(|e| e.to_string())
    });
    let failure = match &decomposition {
        Some(Err(e)) => Some(format!(
            "{}: cannot partition the mesh over {} ranks: {e}",
            problem.file,
            comm.size()
        )),
        Some(Ok(_)) => None,
        None if comm.is_root() => Some(format!(
            "{}: the run's set-up has no whole mesh on rank 0",
            problem.file
        )),
        None => None,
    };
    if let Some(e) = comm::first_error(comm, failure) {
        return Err(e);
    }
    let decomposition = decomposition.and_then(Result::ok);
    let local = message::scatter(comm, |rank| {
        let (Some(mesh), Some(d)) = (whole, &decomposition) else {
            unreachable!("rank 0 holds the whole mesh and its decomposition")
        };
        LocalMesh::new(mesh, d, rank)
    });
    log.at(
        1,
        &format!(
            "{}: {} bodies, {} elements, {} nodes, {} steps, {} rank(s)",
            problem.name,
            problem.mesh.bodies.len(),
            problem.mesh.num_elements(),
            problem.mesh.num_nodes(),
            problem.step_times.len(),
            comm.size()
        ),
    );
    if let Some(d) = decomposition.as_ref().filter(|_| comm.size() > 1) {
        log.at(2, &format!("{}", d.stats()));
    }
    Ok((decomposition, local))
}

/// The result file, on rank 0 when an output is asked for (creating its directory).
/// Collective: an error on rank 0 is every rank's.
fn open_writer<C: Comm + ?Sized>(
    comm: &C,
    (problem, whole): (&Problem, Option<&GlobalMesh>),
    opts: &RunOptions,
    decomposition: Option<&Decomposition>,
) -> Result<Option<ResultWriter>, String> {
    let mut writer = None;
    let mut local_err = None;
    let root = whole.zip(decomposition).filter(|_| comm.is_root());
    if let Some((path, (whole, decomposition))) = opts.output.as_ref().zip(root) {
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
            match ResultWriter::create(
                path,
                &info,
                &RunMesh {
                    problem,
                    mesh: whole,
                },
            ) {
                Ok(w) => writer = Some(w),
                Err(e) => local_err = Some(e.to_string()),
            }
        }
    }
    match comm::first_error(comm, local_err) {
        Some(e) => Err(e),
        None => Ok(writer),
    }
}

/// The log's line on a run continued from `path`.
fn continuing_line(progress: &Progress, time: f64, path: &Path, with_pressure: bool) -> String {
    format!(
        "continuing from step {} (t = {time}) of {}{}",
        progress.first_step,
        path.display(),
        if with_pressure { "" } else { NO_PRESSURE }
    )
}

/// The note on a continued run whose earlier file has no contact pressure.
const NO_PRESSURE: &str = "; that file has no contact pressure (written before the solver \
                           recorded it), so this run's file has none either";

/// Restores the stepper to the earlier run's last written step, takes its records, and
/// copies its steps and restart state into this run's file, which a further restart can
/// then continue from. Returns (on rank 0, which holds the earlier steps) whether they
/// have the contact pressure: a file without it gives a continued file without it (see
/// `output::datasets`). Collective.
fn continue_from<C: Comm + ?Sized>(
    comm: &C,
    (problem, local): (&Problem, &LocalMesh),
    stepper: &mut Stepper<C>,
    writer: Option<&mut ResultWriter>,
    c: Continued,
    progress: &mut Progress,
) -> Result<bool, String> {
    let state = &c.state;
    stepper.restore(
        &state.displacement,
        &state.previous_displacement,
        (state.time, state.dt_prev, state.reference_floor),
        (state.multilevel_switched, c.state.hierarchy.clone()),
        c.contact,
    );
    plastic::restore(stepper, problem, local, &state.history);
    progress.first_step = state.step as usize;
    progress.rows_written = c.steps.len() as u64;
    let with_pressure = c
        .steps
        .first()
        .is_none_or(|s| !s.contact_pressure.is_empty());
    for (time, s) in c.records {
        let step = problem
            .step_times
            .iter()
            .position(|&t| t == time)
            .map_or(0, |k| k + 1);
        progress.records.push(StepRecord {
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
    let local_err = writer.and_then(|w| {
        c.steps
            .iter()
            .try_for_each(|s| w.append_step(s))
            .and_then(|()| w.write_restart(state))
            .err()
            .map(|e| e.to_string())
    });
    match comm::first_error(comm, local_err) {
        Some(e) => Err(e),
        None => Ok(with_pressure),
    }
}

/// Every remaining load step: advance, report, write. Returns the failure that stopped
/// the run, if any, and the final state (after the last step).
#[allow(clippy::too_many_arguments)]
fn step_through<C: Comm + ?Sized>(
    comm: &C,
    problem: &Problem,
    opts: &RunOptions,
    log: &Log,
    stepper: &mut Stepper<C>,
    (gather, local): (&Gather, &LocalMesh),
    mut writer: Option<&mut ResultWriter>,
    progress: &mut Progress,
) -> (Option<String>, GlobalState) {
    let nsteps = problem.step_times.len();
    let bar = progress_bar(log, nsteps, progress.first_step);
    if log.root && log.verbosity >= 2 {
        // A line per contact update: a step of a large contact problem can take minutes.
        let bar = bar.clone();
        stepper.progress = Some(Box::new(move |line: &str| match &bar {
            Some(b) => b.println(line),
            None => eprintln!("{line}"),
        }));
    }
    let mut state = GlobalState::default();
    let mut failure = None;
    for (k, &t) in problem
        .step_times
        .iter()
        .enumerate()
        .skip(progress.first_step)
    {
        let step = k + 1;
        let advanced = stepper.advance(step, t);
        if let Some(note) = stepper.take_rebuild_note() {
            log.at(2, &note);
        }
        let trace = stepper.take_cg_trace();
        progress.cg_traffic += trace.traffic;
        progress.cg_loop_iterations += trace.iterations as u64;
        progress.cg_loop_seconds += trace.loop_seconds;
        progress.contact_updates += trace.contact_updates as u64;
        progress.contact_seconds += trace.contact_seconds;
        if log.root && log.verbosity >= 2 {
            log.at(2, &trace.summary());
        }
        if let Err(e) = write_export(problem, opts, log, stepper) {
            failure = Some(e);
            break;
        }
        let rec = match advanced {
            Ok(rec) => rec,
            Err(f) => {
                failure = Some(stop_message(problem, progress, &f));
                break;
            }
        };
        report_step(problem, opts, log, bar.as_ref(), progress, step, t, &rec);
        warn_of_folds(log, bar.as_ref(), progress, t, &rec);
        progress.records.push(rec);
        let last = step == nsteps;
        let write = opts.output.is_some() && (step % problem.output_every == 0 || last);
        if !(write || last) {
            continue;
        }
        let keep = last && opts.final_state;
        let (fields, err) = LocalFields::new(comm, problem, stepper, local, keep);
        if let Some(e) = comm::first_error(comm, err) {
            failure = Some(e);
            break;
        }
        let kept = match write_step(
            comm,
            (problem, stepper),
            (gather, local),
            writer.as_deref_mut(),
            progress,
            (step, write, keep),
            (fields, &rec),
        ) {
            Ok(kept) => kept,
            Err(e) => {
                failure = Some(e);
                break;
            }
        };
        // Test hook: die here as a killed run would (the restart test).
        if std::env::var("SOLVER_TEST_ABORT_AFTER_STEP").ok() == Some(step.to_string()) {
            std::process::abort();
        }
        if let Some(s) = kept {
            state = final_state(problem, stepper, s);
        }
    }
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    (failure, state)
}

/// A progress bar on a terminal at verbosity 1 and above (rank 0).
fn progress_bar(log: &Log, nsteps: usize, first: usize) -> Option<indicatif::ProgressBar> {
    (log.root && log.verbosity >= 1 && std::io::stderr().is_terminal()).then(|| {
        let bar = indicatif::ProgressBar::new(nsteps as u64);
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:30} step {pos}/{len}  {msg}  [{elapsed} elapsed, ~{eta} left]",
            )
            .expect("a valid progress template"),
        );
        bar.set_position(first as u64);
        bar
    })
}

/// The error of a step that failed, and when the last completed step ended with folded
/// mean-integrated elements, that it did.
fn stop_message(problem: &Problem, progress: &Progress, f: &impl std::fmt::Display) -> String {
    let mut message = format!("{}: {f}", problem.file);
    if let Some(last) = progress.records.last().filter(|r| r.folded > 0) {
        message += &format!(
            "\nthe last completed step (t = {}) ended with {} mean-integrated element(s) folded at a corner (the warning above): the failure may follow from them",
            last.time, last.folded
        );
    }
    message
}

/// The warning of the first step that ends with folded mean-integrated elements (`rec`,
/// not yet among the records), on the progress bar's line when there is one.
fn warn_of_folds(
    log: &Log,
    bar: Option<&indicatif::ProgressBar>,
    progress: &Progress,
    t: f64,
    rec: &StepRecord,
) {
    if rec.folded == 0 || progress.records.iter().any(|r| r.folded > 0) {
        return;
    }
    let warning = folded_warning(t, rec);
    match bar {
        Some(bar) => bar.println(&warning),
        None => log.at(0, &warning),
    }
}

/// The warning's text.
fn folded_warning(t: f64, rec: &StepRecord) -> String {
    let (id, ratio) = rec.most_folded;
    format!(
        "warning: t = {t}: {} element(s) of mean-integrated bodies folded at a corner (the \
         Jacobian at a corner is not positive while the centre's, the element's one \
         integration point, is; the most folded: element {}, its smallest Jacobian {ratio:.2} \
         times its mean): their stress and the contact on them are not to be trusted; refine \
         the mesh there or use integration = \"full\" (said once; each step's line gives the \
         count)",
        rec.folded,
        id as u64 + 1
    )
}

/// The step's line (or the progress bar's message): CG, residual, cut-backs, time, the
/// contact counts, the time left at the pace so far.
#[allow(clippy::too_many_arguments)]
fn report_step(
    problem: &Problem,
    opts: &RunOptions,
    log: &Log,
    bar: Option<&indicatif::ProgressBar>,
    progress: &Progress,
    step: usize,
    t: f64,
    rec: &StepRecord,
) {
    let nsteps = problem.step_times.len();
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
    if rec.folded > 0 {
        line += &format!("  folded elements {}", rec.folded);
    }
    // Time left, from the pace of the steps this run has done so far.
    let done = (step - progress.first_step) as f64;
    let left = (nsteps - step) as f64 * progress.started.elapsed().as_secs_f64() / done;
    line += &format!("  ~{left:.0} s left");
    match bar {
        Some(bar) => {
            bar.set_message(format!("t = {t:.4}  CG {}", rec.cg_iterations));
            bar.inc(1);
            if opts.verbosity >= 2 {
                bar.println(&line);
            }
        }
        None => log.at(1, &line),
    }
}

/// Appends the step to the result file (when `write`; field by field as it is gathered,
/// see [`write_fields`]) with the restart state after it, and gives the step back when
/// `keep`. Collective: an error on rank 0 is every rank's.
fn write_step<C: Comm + ?Sized>(
    comm: &C,
    (problem, stepper): (&Problem, &Stepper<C>),
    (gather, local): (&Gather, &LocalMesh),
    mut writer: Option<&mut ResultWriter>,
    progress: &mut Progress,
    (step, write, keep): (usize, bool, bool),
    (fields, rec): (LocalFields, &StepRecord),
) -> Result<Option<StepOutput>, String> {
    let (kept, mut local_err) = write_fields(
        comm,
        problem,
        stepper,
        (gather, local),
        fields,
        rec,
        writer.as_deref_mut(),
        (write, keep),
    );
    if write {
        progress.rows_written += 1;
        let writer = writer.filter(|_| local_err.is_none());
        let err = restart::write_restart(
            comm,
            stepper,
            (gather, local),
            (step, progress.rows_written),
            writer,
        );
        local_err = local_err.or(err);
    }
    match comm::first_error(comm, local_err) {
        Some(e) => Err(e),
        None => Ok(kept),
    }
}

/// The state after the last step, as `run` returns it.
fn final_state<C: Comm + ?Sized>(
    problem: &Problem,
    stepper: &Stepper<C>,
    s: StepOutput,
) -> GlobalState {
    GlobalState {
        displacement: s.displacement,
        stress: s.stress,
        reaction: s.reaction,
        contact_force: s.contact_force,
        contact_status: s.contact_status,
        contact_pressure: s.contact_pressure,
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
                    master_body: problem.mesh.body_of_element(e as usize),
                    stick: a.mode == Mode::Stick,
                    normal: a.normal,
                    normal_force: a.normal_force,
                }
            })
            .collect(),
    }
}

/// Closes the result file: complete, or marked failed with the message. Collective.
fn finish<C: Comm + ?Sized>(
    comm: &C,
    writer: Option<ResultWriter>,
    failure: &Option<String>,
    wall_time: f64,
) -> Result<Option<std::path::PathBuf>, String> {
    let mut output = None;
    let mut local_err = None;
    if let Some(w) = writer {
        let r = match failure {
            None => w.finish(wall_time),
            Some(m) => w.finish_failed(wall_time, m),
        };
        match r {
            Ok(p) => output = Some(p),
            Err(e) => local_err = Some(e.to_string()),
        }
    }
    match comm::first_error(comm, local_err) {
        Some(e) => Err(e),
        None => Ok(output),
    }
}

/// Writes the assembled model problem once CG finished it (`--export-operator`); a
/// refusal is an error of the run.
fn write_export<C: Comm + ?Sized>(
    problem: &Problem,
    opts: &RunOptions,
    log: &Log,
    stepper: &mut Stepper<C>,
) -> Result<(), String> {
    let Some(dir) = &opts.export_operator else {
        return Ok(());
    };
    match stepper.take_export() {
        None => Ok(()),
        Some(Err(why)) => Err(format!("--export-operator {}: {why}", dir.display())),
        Some(Ok(e)) => {
            super::export::write_export(dir, &problem.name, &e)?;
            log.at(
                1,
                &format!(
                    "model problem at t = {} exported to {}: {} unknowns, {} non-zeros, assembly check {:.1e}, {} CG iterations",
                    e.time,
                    dir.display(),
                    e.rhs.len(),
                    e.matrix.nnz(),
                    e.check_error,
                    e.iterations.map_or("-".to_string(), |i| i.to_string())
                ),
            );
            Ok(())
        }
    }
}
