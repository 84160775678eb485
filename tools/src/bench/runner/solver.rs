//! The `solver` binary as the bench runs it: `solver run` under `run/mpirun` with a time
//! limit and repeats, its log read back, its result file's contact force, `solver post
//! compare` of two result files and `solver check`.

use super::log::{last_line, parse_solver_log, SolverLog};
use super::process::{run_limited, Limits, MIB};
use crate::api::{add, ResultFile, Vec3};
use crate::stats::Stat;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The repository the bench was built from (the parent of tools/): scenes and `run/mpirun`
/// are found there.
pub fn repo_root() -> PathBuf {
    let tools = Path::new(env!("CARGO_MANIFEST_DIR"));
    tools.parent().unwrap_or(tools).to_path_buf()
}

/// The `solver` binary built beside this one (`run/bench` builds both).
pub fn solver_exe() -> Result<PathBuf, String> {
    let exe =
        std::env::current_exe().map_err(|e| format!("cannot locate the bench binary: {e}"))?;
    let solver = exe.with_file_name("solver");
    if solver.is_file() {
        Ok(solver)
    } else {
        Err(format!(
            "{} not found: build it first (`cargo build --release -p solver --bin solver`; run/bench does)",
            solver.display()
        ))
    }
}

/// A CG preconditioner (`solver run --preconditioner`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Precond {
    Jacobi,
    TwoLevel,
    Multilevel,
    /// The solver's own choice (`auto`, the default): whatever it uses counts.
    Auto,
}

impl Precond {
    /// The value of `--preconditioner`.
    pub fn arg(self) -> &'static str {
        match self {
            Precond::Jacobi => "jacobi",
            Precond::TwoLevel => "two_level",
            Precond::Multilevel => "multilevel",
            Precond::Auto => "auto",
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            Precond::Jacobi => "Jacobi",
            Precond::TwoLevel => "two-level",
            Precond::Multilevel => "multilevel",
            Precond::Auto => "auto",
        }
    }

    /// Whether the solver's `preconditioner:` line (without the prefix) says it used this
    /// one: a two-level run whose coarse space cannot be built falls back to Jacobi.
    pub fn used(self, line: &str) -> bool {
        match self {
            Precond::Jacobi => line == "nodal block Jacobi",
            Precond::TwoLevel => line.starts_with("two-level"),
            Precond::Multilevel => line.starts_with("multilevel"),
            Precond::Auto => true,
        }
    }
}

/// One `solver run` under `run/mpirun`.
pub struct Job {
    pub scene: PathBuf,
    /// `--refine F`, if any.
    pub refine: Option<usize>,
    pub ranks: usize,
    /// `--preconditioner`; a run that used another one (the solver says so in its log)
    /// fails.
    pub preconditioner: Precond,
    /// The result file; the log (standard error) goes beside it as `.log`, standard
    /// output as `.out`.
    pub result: PathBuf,
}

impl Job {
    pub fn command(&self, exe: &Path) -> Command {
        let mut cmd = Command::new(repo_root().join("run/mpirun"));
        cmd.args(["-np", &self.ranks.to_string()])
            .arg(exe)
            .args(["-vv", "run"])
            .arg(&self.scene);
        if let Some(f) = self.refine {
            cmd.args(["--refine", &f.to_string()]);
        }
        cmd.args(["--preconditioner", self.preconditioner.arg(), "-o"])
            .arg(&self.result);
        cmd
    }

    /// One run: its log and the wall time of the mpirun process.
    pub fn run_once(&self, exe: &Path, limits: &Limits) -> Result<(SolverLog, f64), String> {
        let log = self.result.with_extension("log");
        let f = run_limited(
            &mut self.command(exe),
            &self.result.with_extension("out"),
            &log,
            limits,
        )?;
        let text = std::fs::read_to_string(&log)
            .map_err(|e| format!("cannot read {}: {e}", log.display()))?;
        if let Some(why) = f.stopped {
            return Err(format!("{why} (log {})", log.display()));
        }
        if f.code != Some(0) {
            return Err(format!(
                "exit code {}: {} (log {})",
                f.code.map_or("none (signal)".into(), |c| c.to_string()),
                last_line(&text),
                log.display()
            ));
        }
        let parsed = parse_solver_log(&text).map_err(|e| format!("{}: {e}", log.display()))?;
        let precond = self.preconditioner;
        match parsed.preconditioner.as_deref() {
            Some(line) if precond.used(line) => Ok((parsed, f.wall)),
            Some(line) => Err(format!(
                "asked for --preconditioner {}, the solver used: {line} (log {})",
                precond.arg(),
                log.display()
            )),
            None => Err(format!("no 'preconditioner:' line in {}", log.display())),
        }
    }

    /// `repeats` runs (at least one), each reported on standard error after `label`.
    pub fn run_repeated(
        &self,
        exe: &Path,
        repeats: usize,
        limits: &Limits,
        label: &str,
    ) -> Result<Runs, String> {
        let repeats = repeats.max(1);
        let mut logs = Vec::new();
        let mut process = Vec::new();
        for r in 0..repeats {
            let (log, wall) = self.run_once(exe, limits)?;
            eprintln!(
                "bench:   {label}, run {}/{repeats}: {} CG iterations, {} contact updates, {:.2} s, {:.1} MiB per rank",
                r + 1,
                log.cg_iterations,
                log.contact_updates,
                log.wall,
                log.peak_mib
            );
            logs.push(log);
            process.push(wall);
        }
        Ok(Runs::of(&logs, &process))
    }
}

/// The repeats of one job.
pub struct Runs {
    /// The first repeat's log (the counts are the same in every repeat unless
    /// `consistent` is false).
    pub log: SolverLog,
    pub consistent: bool,
    /// Solver-reported wall time.
    pub wall: Stat,
    /// Wall time of the `run/mpirun` process (MPI start-up and scene loading included).
    pub process_wall: Stat,
    /// Peak memory per rank, MiB.
    pub peak_mib: Stat,
}

impl Runs {
    /// Peak memory per element a rank holds (bytes), on `ranks` ranks.
    pub fn bytes_per_element(&self, ranks: usize) -> f64 {
        self.peak_mib.median * MIB / (self.log.elements as f64 / ranks as f64)
    }

    /// `logs` (at least one) and the process wall times of the same runs.
    pub fn of(logs: &[SolverLog], process_walls: &[f64]) -> Runs {
        let walls: Vec<f64> = logs.iter().map(|l| l.wall).collect();
        let mibs: Vec<f64> = logs.iter().map(|l| l.peak_mib).collect();
        Runs {
            log: logs[0].clone(),
            consistent: SolverLog::consistent(logs),
            wall: Stat::of(&walls),
            process_wall: Stat::of(process_walls),
            peak_mib: Stat::of(&mibs),
        }
    }
}

/// Sum over all nodes of the contact force at the last step of a result file.
pub fn total_contact_force(path: &Path) -> Result<Vec3, String> {
    let file = ResultFile::open(path).map_err(|e| e.to_string())?;
    let last = file
        .num_steps()
        .checked_sub(1)
        .ok_or_else(|| format!("{}: no steps", path.display()))?;
    let force = file.contact_force(last).map_err(|e| e.to_string())?;
    Ok(force.iter().fold([0.0; 3], |a, f| add(&a, f)))
}

/// `solver post compare A B`: exit code 0 when bitwise identical.
pub struct Compare {
    pub code: Option<i32>,
    /// Its last line ("result: ...").
    pub summary: String,
}

impl Compare {
    pub fn identical(&self) -> bool {
        self.code == Some(0)
    }
}

pub fn compare_results(exe: &Path, a: &Path, b: &Path) -> Result<Compare, String> {
    let out = Command::new(exe)
        .args(["post", "compare"])
        .arg(a)
        .arg(b)
        .output()
        .map_err(|e| format!("cannot run {} post compare: {e}", exe.display()))?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    Ok(Compare {
        code: out.status.code(),
        summary: last_line(if stdout.trim().is_empty() {
            &stderr
        } else {
            &stdout
        })
        .to_string(),
    })
}

/// The standard output of `solver check SCENE --refine F --ranks R`.
pub fn solver_check(
    exe: &Path,
    scene: &Path,
    refine: usize,
    ranks: usize,
) -> Result<String, String> {
    let out = Command::new(exe)
        .arg("check")
        .arg(scene)
        .args([
            "--refine",
            &refine.to_string(),
            "--ranks",
            &ranks.to_string(),
        ])
        .output()
        .map_err(|e| format!("cannot run {} check: {e}", exe.display()))?;
    if !out.status.success() {
        return Err(format!(
            "solver check --refine {refine} --ranks {ranks}: {}",
            last_line(&String::from_utf8_lossy(&out.stderr))
        ));
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn preconditioner_lines() {
        let two = "two-level; coarse space: 128 aggregates (768 unknowns), cell size 2.8e-1, \
                   54 colours";
        assert!(Precond::TwoLevel.used(two) && !Precond::Jacobi.used(two));
        assert!(Precond::Jacobi.used("nodal block Jacobi"));
        assert!(!Precond::TwoLevel.used("nodal block Jacobi (no coarse space: why)"));
    }

    /// The command line the README documents.
    #[test]
    fn job_command_line() {
        let job = Job {
            scene: PathBuf::from("s.toml"),
            refine: Some(2),
            ranks: 3,
            preconditioner: Precond::TwoLevel,
            result: PathBuf::from("o/r.h5"),
        };
        let cmd = job.command(Path::new("bin/solver"));
        assert_eq!(
            cmd.get_program(),
            repo_root().join("run/mpirun").as_os_str()
        );
        let args: Vec<_> = cmd.get_args().map(|a| a.to_str().unwrap()).collect();
        assert_eq!(
            args,
            [
                "-np",
                "3",
                "bin/solver",
                "-vv",
                "run",
                "s.toml",
                "--refine",
                "2",
                "--preconditioner",
                "two_level",
                "-o",
                "o/r.h5"
            ]
        );
    }
}
