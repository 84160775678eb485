//! The `solver` command line: parse, initialise MPI, run; every error becomes one message
//! and a non-zero exit code (2 for bad input, 1 for a run that failed).

use clap::{Parser, Subcommand};
use solver::comm::{Comm, MpiComm, SerialComm};
use solver::memory::available;
use solver::output::{claim_output, leftover_temps, OutputClaim, OutputError, ResultFile};
use solver::post::{run_post, PostCommand};
use solver::precond::multilevel::size::POOR_BLOCK_AGGREGATE_NODES;
use solver::run::{run_from_root, Partition, RunOptions};
use solver::scene::load_scene_refined;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// An allocation the system refuses ends the run with a one-line error, not an abort.
#[global_allocator]
static ALLOCATOR: solver::memory::guard::Guard = solver::memory::guard::Guard;

#[derive(Parser, Debug)]
#[command(
    name = "solver",
    version,
    about = "Quasi-static nonlinear finite element solver for 3-D solids with master/slave contact",
    after_help = "Examples:\n  solver check run/scenes/paper/capture_release.toml\n  solver run run/scenes/paper/capture_release.toml\n  run/mpirun -np 2 target/release/solver run run/scenes/paper/capture_release.toml -o out/capture_release-np2.h5\n  solver post info out/capture_release.h5\n  solver post compare out/capture_release.h5 out/capture_release-np2.h5\n  solver post verify out/capture_release.h5"
)]
struct Cli {
    /// More output (-v: step details); repeat for more.
    #[arg(short, long, action = clap::ArgAction::Count, global = true)]
    verbose: u8,
    /// Only errors.
    #[arg(short, long, global = true)]
    quiet: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run a scene and write its results (HDF5 + XDMF).
    Run {
        /// The scene file (TOML).
        scene: PathBuf,
        /// Result file; default out/<scene name>.h5.
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Multiply every body's element divisions by this factor (the scene is renamed
        /// <name>_r<factor>).
        #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
        refine: u32,
        /// Continue from the last step recorded in this result file of an earlier run of
        /// the same scene (also a `.tmp` file a killed run left, or a `.failed.h5`).
        #[arg(long, value_name = "RESULT.h5")]
        restart: Option<PathBuf>,
        /// CG preconditioner, overriding the scene's `solver.preconditioner`.
        #[arg(long, value_parser = solver::problem::Preconditioner::NAMES)]
        preconditioner: Option<String>,
        /// Solver of nonlinear bodies' model problems, overriding the scene's
        /// `solver.nonlinear`.
        #[arg(long, value_parser = solver::problem::NonlinearSolver::NAMES)]
        nonlinear: Option<String>,
        /// Run even when the memory estimate exceeds the memory available.
        #[arg(long)]
        force: bool,
        /// Also write the first model problem that needs a CG iteration, assembled (the
        /// constrained operator, right-hand side, rigid-body modes and our CG's iteration
        /// count on it), into this directory as NumPy arrays (one rank only).
        #[arg(long, value_name = "DIR")]
        export_operator: Option<PathBuf>,
        /// How the elements are split over the ranks: METIS on the whole mesh, or groups
        /// cut by coordinate bisection each split by METIS (no rank runs METIS on the
        /// whole mesh); auto: groups from 8 ranks. The results are the same either way.
        #[arg(long, value_parser = solver::run::Partition::NAMES, default_value = "auto")]
        partition: String,
    },
    /// Validate a scene and print a summary, without solving.
    Check {
        /// The scene file (TOML).
        scene: PathBuf,
        /// Check the scene refined by this factor.
        #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
        refine: u32,
        /// Estimate the memory per rank for this many MPI ranks, and show how the mesh
        /// splits over them: elements and nodes owned and ghosted per rank, and the master
        /// faces each rank would hold.
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
        ranks: Option<u32>,
        /// The partition `--ranks` shows (as `solver run --partition`).
        #[arg(long, value_parser = solver::run::Partition::NAMES, default_value = "auto")]
        partition: String,
    },
    /// Work with result files.
    #[command(subcommand)]
    Post(PostCommand),
}

/// A reader that closes standard output early (`solver post info R.h5 | head`) ends the
/// process quietly, as it ends other command-line tools, instead of a panic in `println!`.
/// Only for the commands that use no MPI (whose transports expect SIGPIPE ignored).
fn default_sigpipe() {
    // SAFETY: setting a signal's disposition to its default has no preconditions.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// The command line, or its usage error (or the help) printed and the process ended with
/// its code. Under mpirun every rank parses the same line: only the first prints and ends
/// with the code, so the message comes once and is mpirun's exit code; the others end
/// quietly with 0 (ending with the code too would let mpirun stop the first rank before it
/// has printed).
fn parse_cli() -> Cli {
    Cli::try_parse().unwrap_or_else(|e| {
        if launched_rank().is_some_and(|rank| rank != 0) {
            std::process::exit(0);
        }
        e.exit()
    })
}

/// This process's rank as the MPI launcher's environment gives it (before MPI starts).
fn launched_rank() -> Option<u32> {
    ["OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"]
        .iter()
        .find_map(|v| std::env::var(v).ok()?.parse().ok())
}

fn main() -> ExitCode {
    solver::memory::guard::return_freed_memory();
    let cli = parse_cli();
    let verbosity = if cli.quiet { 0 } else { 1 + cli.verbose };
    if matches!(cli.command, Command::Post(_) | Command::Check { .. }) {
        default_sigpipe();
    }
    match cli.command {
        Command::Post(cmd) => match run_post(&cmd) {
            Ok(code) => ExitCode::from(code as u8),
            Err(e) => {
                eprintln!("error: {e}");
                ExitCode::from(2)
            }
        },
        Command::Check {
            scene,
            refine,
            ranks,
            partition,
        } => ExitCode::from(check_command(
            &scene,
            refine,
            ranks,
            partition_of(&partition),
        )),
        Command::Run {
            scene,
            output,
            refine,
            restart,
            preconditioner,
            nonlinear,
            force,
            export_operator,
            partition,
        } => with_comm(|comm| {
            let args = RunArgs {
                scene: &scene,
                output,
                refine,
                restart: restart.as_deref(),
                preconditioner: preconditioner.as_deref().map(preconditioner_of),
                nonlinear: nonlinear
                    .as_deref()
                    .and_then(solver::problem::NonlinearSolver::from_name),
                force,
                verbosity,
                export_operator,
                partition: partition_of(&partition),
            };
            run_command(comm, &args)
        }),
    }
}

/// `solver run`'s arguments.
struct RunArgs<'a> {
    scene: &'a Path,
    output: Option<PathBuf>,
    refine: u32,
    restart: Option<&'a Path>,
    preconditioner: Option<solver::problem::Preconditioner>,
    nonlinear: Option<solver::problem::NonlinearSolver>,
    force: bool,
    verbosity: u8,
    export_operator: Option<PathBuf>,
    partition: Partition,
}

/// `solver run`: the memory check (before the mesh is built when the counts allow), the
/// scene, the restart file, the output claimed, the run, and its summary. Returns the exit
/// code: 0 done, 1 the run failed, 2 bad input or too big.
fn run_command(comm: &dyn Comm, args: &RunArgs) -> u8 {
    if args.export_operator.is_some() && comm.size() != 1 {
        if comm.is_root() {
            eprintln!(
                "error: --export-operator works on one rank only (this run has {})",
                comm.size()
            );
        }
        return 2;
    }
    let (problem, name, estimate) = match prepare(comm, args) {
        Ok(p) => p,
        Err(code) => return code,
    };
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(format!("{name}.h5")));
    // `-o NAME.e`: the run writes NAME.h5 (the restart carrier) and then NAME.e from it.
    let exodus = solver::output::exodus::is_exodus_path(&output).then(|| output.clone());
    let output = if exodus.is_some() {
        output.with_extension("h5")
    } else {
        output
    };
    // The output is checked and locked before any work (rank 0 writes it).
    let inputs = problem.as_ref().map(|problem| RunInputs {
        scene: args.scene,
        problem,
        restart: args.restart,
    });
    let claimed = match claim_on_root(
        comm,
        inputs.as_ref(),
        &output,
        exodus.as_deref(),
        args.verbosity,
    ) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let opts = RunOptions {
        output: Some(output),
        verbosity: args.verbosity,
        export_operator: args.export_operator.clone(),
        final_state: false,
        partition: args.partition,
    };
    // The run frees rank 0's whole mesh once set up.
    match run_from_root(comm, problem, &opts, args.restart) {
        Ok((summary, _)) if summary.failure.is_some() => {
            if comm.is_root() {
                eprintln!("error: {}", summary.failure.as_deref().unwrap_or_default());
                if let Some(p) = &summary.output {
                    eprintln!("the completed steps are in {}", p.display());
                }
                earlier_run_note(claimed.as_ref().map(|c| &c.paths.result));
            }
            1
        }
        Ok((summary, _)) => {
            let code = match (&exodus, &summary.output) {
                (Some(e), Some(h5)) if comm.is_root() => write_exodus(h5, e, args.verbosity),
                _ => 0,
            };
            if comm.is_root() && args.verbosity > 0 && code == 0 {
                eprintln!("{}", done_line(&summary, estimate));
                eprintln!("{}", communication_line(&summary, comm.size()));
                if summary.contact_updates > 0 {
                    eprintln!("{}", contact_line(&summary));
                }
                earlier_run_note(claimed.as_ref().map(|c| &c.paths.failed));
            }
            solver::comm::first_error(comm, (code != 0).then(|| code.to_string()))
                .and_then(|c| c.parse().ok())
                .unwrap_or(0)
        }
        Err(e) => {
            if comm.is_root() {
                eprintln!("error: {e}");
            }
            1
        }
    }
}

/// The memory check, the scene loaded on rank 0 (with the preconditioner asked for) and
/// the restart file checked: the problem (on rank 0, the only rank that holds its whole
/// mesh; None on the others), its name (every rank's) and the estimate of the peak memory
/// per rank. An error is printed on rank 0 and given as the exit code.
fn prepare(
    comm: &dyn Comm,
    args: &RunArgs,
) -> Result<(Option<solver::problem::Problem>, String, Option<f64>), u8> {
    let sized = solver::scene::counts::scene_size(args.scene, args.refine)
        .map(|s| s.with_override(args.preconditioner));
    let mut estimate = None;
    if let Some(size) = &sized {
        // Where the blocks aggregate otherwise than counted, this gate only keeps a mesh
        // too large from being built: the estimate follows once it is loaded.
        let verbosity = if on_mesh(size) { 0 } else { args.verbosity };
        estimate = Some(memory_gate(comm, size, args.force, verbosity)?);
    }
    let loaded = comm
        .is_root()
        .then(|| load_scene_refined(args.scene, args.refine));
    let err = loaded
        .as_ref()
        .and_then(|l| l.as_ref().err())
        .map(|e| e.to_string());
    if let Some(e) = solver::comm::first_error(comm, err) {
        if comm.is_root() {
            eprintln!("error: {e}");
        }
        return Err(2);
    }
    let mut problem = loaded.and_then(Result::ok);
    if let Some(p) = problem.as_mut() {
        if let Some(n) = args.nonlinear {
            p.solver.nonlinear = n;
        }
        if let Some(pre) = args.preconditioner {
            p.solver.preconditioner = pre;
        }
    }
    let name =
        solver::comm::message::broadcast_value(comm, problem.as_ref().map(|p| p.name.clone()));
    // Counted from the divisions, whether `auto` passes over the full tangent is known only
    // now: checked again with what runs instead. Rank 0 counts the loaded mesh; every rank
    // checks the count against its memory.
    let again = problem
        .as_ref()
        .and_then(|p| loaded_size(p, sized.as_ref()));
    if let Some(size) =
        solver::comm::message::broadcast_value(comm, comm.is_root().then_some(again))
    {
        estimate = Some(memory_gate(comm, &size, args.force, args.verbosity)?);
    }
    if let Some(path) = args.restart {
        let err = problem
            .as_ref()
            .and_then(|p| solver::run::check_restart(path, p).err());
        if let Some(e) = solver::comm::first_error(comm, err) {
            if comm.is_root() {
                eprintln!("error: {e}");
            }
            return Err(2);
        }
    }
    Ok((problem, name, estimate))
}

/// The size of the loaded problem `problem` the memory is checked against again, if any:
/// where the scene's size could not be counted from its divisions (`sized` None), where
/// `auto` passes over the full tangent, or where the blocks aggregate otherwise than
/// counted (`on_mesh`).
fn loaded_size(
    problem: &solver::problem::Problem,
    sized: Option<&solver::scene::counts::SceneSize>,
) -> Option<solver::scene::counts::SceneSize> {
    let refused =
        sized.is_some_and(|s| solver::preflight::tangent_passed_over(problem, s).is_some());
    if sized.is_none() || refused {
        Some(solver::preflight::loaded_size(problem))
    } else {
        sized.filter(|s| on_mesh(s)).map(|size| {
            solver::preflight::with_first_level(problem, size.clone(), POOR_BLOCK_AGGREGATE_NODES)
        })
    }
}

/// Whether a scene counted from its divisions is estimated again once loaded, its
/// multilevel hierarchy counted on the mesh: a block whose elements aggregate otherwise
/// than the count assumes (`preflight::aggregated_as_counted`).
fn on_mesh(size: &solver::scene::counts::SceneSize) -> bool {
    size.counts.multilevel
        && !size.counts.tangent
        && !solver::preflight::aggregated_as_counted(size)
}

/// The closing line of a completed run.
fn done_line(summary: &solver::run::RunSummary, estimate: Option<f64>) -> String {
    let iters: u64 = summary.steps.iter().map(|s| s.cg_iterations).sum();
    format!(
        "done: {} steps, {} CG iterations, {:.3} s, peak memory {:.1} MiB per rank{}; results in {}",
        summary.steps.len(),
        iters,
        summary.wall_time,
        summary.peak_memory / (1024.0 * 1024.0),
        estimate
            .map(|e| format!(" (estimated {:.1} MiB)", e / (1024.0 * 1024.0)))
            .unwrap_or_default(),
        summary
            .output
            .as_ref()
            .map(|p| p.display().to_string())
            .unwrap_or_default()
    )
}

/// The contact updates' count and time (`bench --general` reads it).
fn contact_line(summary: &solver::run::RunSummary) -> String {
    let n = summary.contact_updates;
    format!(
        "contact updates: {n}, {:.3} s ({:.2} ms each; the search with its ghost exchange, \
         capture, release and slip; largest rank)",
        summary.contact_seconds,
        1e3 * summary.contact_seconds / n as f64
    )
}

/// What the ranks sent during the steps and in the CG loops alone, per rank (the largest
/// and the mean over the ranks), and per CG iteration with what the collectives brought
/// (`bench --scaling` reads it).
fn communication_line(summary: &solver::run::RunSummary, ranks: usize) -> String {
    let counts = |max: &solver::comm::Traffic, sum: &solver::comm::Traffic| {
        let mean = |v: u64| v as f64 / ranks as f64;
        format!(
            "{} messages ({:.0}), {} bytes ({:.0}), {} collectives ({:.0}) of {} bytes ({:.0})",
            max.messages,
            mean(sum.messages),
            max.bytes,
            mean(sum.bytes),
            max.collectives,
            mean(sum.collectives),
            max.collective_bytes,
            mean(sum.collective_bytes),
        )
    };
    let cg = &summary.cg_traffic_max;
    let per = |v: u64| v as f64 / summary.cg_loop_iterations.max(1) as f64;
    format!(
        "communication per rank (largest; mean): during the steps {}; in the CG loops ({} \
         iterations, {:.3} s) {}; per CG iteration: {:.2} messages, {:.0} bytes, {:.2} collectives, {:.0} \
         collective bytes, {:.0} bytes received in collectives (largest rank)",
        counts(&summary.traffic_max, &summary.traffic_sum),
        summary.cg_loop_iterations,
        summary.cg_loop_seconds,
        counts(cg, &summary.cg_traffic_sum),
        per(cg.messages),
        per(cg.bytes),
        per(cg.collectives),
        per(cg.collective_bytes),
        per(cg.collective_received),
    )
}

fn partition_of(name: &str) -> Partition {
    // clap accepts only Partition::NAMES.
    Partition::from_name(name).unwrap_or_default()
}

fn preconditioner_of(name: &str) -> solver::problem::Preconditioner {
    use solver::problem::Preconditioner;
    // clap accepts only Preconditioner::NAMES.
    Preconditioner::from_name(name).unwrap_or_default()
}

/// `solver check`: the scene's size and memory estimate from its divisions (before any
/// mesh is built), then, when its mesh can be built here, the full validation.
fn check_command(scene: &Path, refine: u32, ranks: Option<u32>, partition: Partition) -> u8 {
    let r = ranks.unwrap_or(1) as usize;
    let sized = solver::scene::counts::scene_size(scene, refine);
    if let Some(size) = &sized {
        let c = &size.counts;
        println!(
            "{} elements, {} nodes (counted from the divisions)",
            c.elements, c.nodes
        );
        let fit = solver::memory::check_fit(c, r, ranks.is_some(), (r, true), &available::bounds());
        println!("{}", solver::preflight::fit_line(&fit));
        if on_mesh(size) {
            println!(
                "a block's elements are too elongated to aggregate as counted (their diagonal \
                 beyond twice their shortest edge): the multilevel hierarchy is counted again \
                 on the mesh"
            );
        }
        // Checked as `solver run` would check it, and the mesh not built when the run
        // would be refused.
        if let Some(why) = fit.refusal() {
            eprintln!("error: {why}");
            if let Err(e) = size.ids() {
                eprintln!("error: {e}");
            }
            println!("the mesh is not built, so its sets, loads and contacts are not checked");
            return 2;
        }
        if let Err(e) = size.ids() {
            eprintln!("error: {e}");
            return 2;
        }
    }
    let mut p = match load_scene_refined(scene, refine) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("error: {e}");
            return 2;
        }
    };
    println!("{}", solver::problem::summary(&p));
    let adjusted = solver::contact::adjust::adjust(&mut p);
    for line in solver::contact::adjust::describe(&p, &adjusted) {
        println!("{line}");
    }
    let counted = solver::scene::counts::problem_size(&p);
    let tangent = solver::preflight::tangent_passed_over(&p, sized.as_ref().unwrap_or(&counted));
    if let Some(why) = &tangent {
        println!("{why}: counted with what runs instead");
    }
    let refused = tangent.is_some();
    let recounted = match &sized {
        Some(size) if !refused && on_mesh(size) => Some(solver::preflight::with_first_level(
            &p,
            size.clone(),
            POOR_BLOCK_AGGREGATE_NODES,
        )),
        _ => None,
    };
    if sized.is_none() || refused || recounted.is_some() {
        let size = recounted.unwrap_or_else(|| solver::preflight::loaded_size(&p));
        let fit = solver::memory::check_fit(
            &size.counts,
            r,
            ranks.is_some(),
            (r, true),
            &available::bounds(),
        );
        println!("{}", solver::preflight::fit_line(&fit));
        if let Some(why) = fit.refusal() {
            eprintln!("error: {why}");
            return 2;
        }
    }
    if let Some(n) = ranks {
        match solver::run::decomposition_report(&p, n as usize, partition) {
            Ok(text) => print!("{text}"),
            Err(e) => {
                eprintln!("error: {e}");
                return 2;
            }
        }
    }
    0
}

/// Refuses a run whose memory estimate exceeds what a rank's machine or process may use
/// (exit 2), or warns and goes on with `--force`; refuses counts beyond the 32-bit ids.
/// Returns the estimated peak per rank, bytes.
fn memory_gate(
    comm: &dyn Comm,
    size: &solver::scene::counts::SceneSize,
    force: bool,
    verbosity: u8,
) -> Result<f64, u8> {
    use solver::preflight::Gate;
    let mpi = solver::comm::mpi_comm::launched_by_mpirun();
    let root = comm.is_root();
    match solver::preflight::memory_gate(comm, size, mpi, force) {
        Gate::Refuse(m) => {
            if root {
                eprintln!("error: {m}");
                if let Err(e) = size.ids() {
                    eprintln!("error: {e}");
                }
            }
            Err(2)
        }
        Gate::Go { fit, forced } => {
            if let Err(e) = size.ids() {
                if root {
                    eprintln!("error: {e}");
                }
                return Err(2);
            }
            if root && verbosity > 1 {
                eprintln!("{}", solver::preflight::fit_line(&fit));
            }
            if let (Some(m), true) = (forced, root) {
                eprintln!("warning: --force: {m}");
            }
            Ok(fit.estimate.per_rank())
        }
    }
}

/// What a run reads: the scene file, the problem made of it, the restart file.
struct RunInputs<'a> {
    scene: &'a Path,
    problem: &'a solver::problem::Problem,
    restart: Option<&'a Path>,
}

/// Writes the Exodus II file `exodus` from the run's published HDF5 file (rank 0); the exit
/// code: 0, or the error's.
fn write_exodus(h5: &Path, exodus: &Path, verbosity: u8) -> u8 {
    match solver::output::exodus::write_exodus(h5, exodus) {
        Ok(()) => {
            if verbosity > 0 {
                eprintln!("wrote {} from {}", exodus.display(), h5.display());
            }
            0
        }
        Err(e) => {
            eprintln!("error: {e}");
            e.exit_code()
        }
    }
}

/// Checks and locks the output path on rank 0 (see [`claim`]); every rank learns the error
/// and its exit code.
fn claim_on_root(
    comm: &dyn Comm,
    inputs: Option<&RunInputs>,
    output: &Path,
    exodus: Option<&Path>,
    verbosity: u8,
) -> Result<Option<OutputClaim>, u8> {
    let claimed = inputs
        .filter(|_| comm.is_root())
        .map(|inputs| claim(inputs, output, exodus, verbosity));
    // The exit code travels as the message's first character.
    let err = match &claimed {
        Some(Err(e)) => Some(format!("{}{e}", e.exit_code())),
        _ => None,
    };
    if let Some(e) = solver::comm::first_error(comm, err) {
        let (code, message) = e.split_at(1);
        if comm.is_root() {
            eprintln!("error: {message}");
        }
        return Err(code.parse().unwrap_or(2));
    }
    Ok(claimed.and_then(Result::ok))
}

/// Checks and locks the output path of a run: not the scene, its mesh or the restart file,
/// a regular file or a new path, no other run writing it. Notes a stale lock taken over and
/// the temporary files of earlier runs that did not finish.
fn claim(
    inputs: &RunInputs,
    output: &Path,
    exodus: Option<&Path>,
    verbosity: u8,
) -> Result<OutputClaim, OutputError> {
    let (problem, restart) = (inputs.problem, inputs.restart);
    let meshes = solver::scene::mesh_files(&problem.file, &problem.text);
    let mut files: Vec<(&Path, &str)> = vec![(inputs.scene, "the scene file")];
    files.extend(meshes.iter().map(|m| (m.as_path(), "the mesh file")));
    files.extend(restart.map(|r| (r, "the restart file")));
    if let Some(e) = exodus {
        solver::output::exodus::check_exodus_output(e, &files)?;
    }
    files.truncate(files.len() - usize::from(restart.is_some()));
    let claim = claim_output(output, &files, restart)?;
    if verbosity > 0 {
        if let Some(holder) = claim.stale_lock() {
            eprintln!(
                "note: {}: took over the lock of {holder}, which no longer runs",
                claim.paths.lock.display()
            );
        }
        let left: Vec<String> = leftover_temps(output)
            .iter()
            .filter(|t| Some(t.as_path()) != restart)
            .map(|t| t.display().to_string())
            .collect();
        if !left.is_empty() {
            eprintln!(
                "note: runs that did not finish left {}; continue one with --restart, or remove them",
                left.join(", ")
            );
        }
    }
    Ok(claim)
}

/// Names a file an earlier run left under the other name of this run's output.
fn earlier_run_note(other: Option<&PathBuf>) {
    let Some(path) = other.filter(|p| p.exists()) else {
        return;
    };
    let started = ResultFile::open(path)
        .and_then(|f| f.attributes())
        .map(|a| format!(", started {}", a.start_time))
        .unwrap_or_default();
    eprintln!(
        "note: {} is from an earlier run{started}, left as it was",
        path.display()
    );
}

/// Runs `f` with the MPI communicator when started under mpirun, else serially.
fn with_comm(f: impl FnOnce(&dyn Comm) -> u8) -> ExitCode {
    if solver::comm::mpi_comm::launched_by_mpirun() {
        match MpiComm::init() {
            Some(comm) => {
                let code = f(&comm);
                if solver::output::shutdown::open_objects() > 0 {
                    // An object HDF5 could not close (a full disk, reported already): its
                    // shutdown in MPI_Finalize would crash on it (output::shutdown). This
                    // rank leaves with its exit code; mpirun ends the others.
                    use std::io::Write;
                    let _ = std::io::stderr().flush();
                    let _ = std::io::stdout().flush();
                    // SAFETY: ends the process at once; nothing is needed after.
                    unsafe { libc::_exit(i32::from(code.max(1))) }
                }
                drop(comm);
                ExitCode::from(code)
            }
            None => {
                eprintln!("error: MPI could not be initialised");
                ExitCode::from(1)
            }
        }
    } else {
        ExitCode::from(f(&SerialComm))
    }
}
