//! `ccx` on a deck: its version, one job run under limits with repeats, timed, its output
//! read by the caller.

use super::deck::Deck;
use super::output::{error_line, newton_iterations, total_time};
use crate::runner::process::{memory_available, run_limited, Finished, Limits, MIB};
use crate::stats::Stat;
use std::path::PathBuf;
use std::process::Command;

/// `ccx -v` prints "This is Version 2.20" (and exits with a non-zero code); `None` when
/// ccx does not run.
pub fn version() -> Option<String> {
    let out = Command::new("ccx").arg("-v").output().ok()?;
    let text = String::from_utf8_lossy(&out.stdout);
    let v = text
        .lines()
        .find_map(|l| l.trim().strip_prefix("This is Version "))
        .map(str::to_string);
    Some(v.unwrap_or_else(|| "unknown version".into()))
}

/// One ccx job: `<dir>/<name>.inp`, run in `dir` (log `ccx.log`, errors `ccx.err`).
pub struct Job {
    pub dir: PathBuf,
    pub name: String,
    /// `OMP_NUM_THREADS`.
    pub threads: usize,
    /// Wall-clock limit per run; the run is also stopped at 3/4 of the memory the machine
    /// had available when it started (others may be working on it).
    pub timeout_s: f64,
}

/// What one run left behind.
pub struct Output {
    pub finished: Finished,
    pub log_path: PathBuf,
    /// Its standard output.
    pub log: String,
    /// The .dat file (`*NODE PRINT` and the like).
    pub dat: String,
}

/// Timings over the repeats of a job.
pub struct Timed {
    /// Process wall time.
    pub wall: Stat,
    /// ccx's own "Total CalculiX Time" (median).
    pub own_time: Option<f64>,
    pub peak_mib: Option<f64>,
    /// Newton iterations of the first repeat.
    pub iterations: usize,
}

/// How a job went; `T` is what the caller read from its output.
pub enum Outcome<T> {
    Finished { timed: Timed, values: T },
    Stopped(String),
    Failed(String),
    Skipped(String),
}

impl Job {
    /// Writes the deck as `<dir>/<name>.inp` (creating `dir`).
    pub fn write_deck(&self, deck: &Deck) -> Result<PathBuf, String> {
        std::fs::create_dir_all(&self.dir)
            .map_err(|e| format!("cannot create {}: {e}", self.dir.display()))?;
        let path = self.dir.join(format!("{}.inp", self.name));
        std::fs::write(&path, deck.text())
            .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        Ok(path)
    }

    fn run_once(&self) -> Result<Output, String> {
        let dat = self.dir.join(format!("{}.dat", self.name));
        let _ = std::fs::remove_file(&dat);
        let log_path = self.dir.join("ccx.log");
        let mut cmd = Command::new("ccx");
        cmd.args(["-i", &self.name])
            .current_dir(&self.dir)
            .env("OMP_NUM_THREADS", self.threads.to_string());
        let limits = Limits {
            timeout_s: self.timeout_s,
            rss_limit: memory_available().map(|m| 0.75 * m),
            min_available: None,
        };
        let finished = run_limited(&mut cmd, &log_path, &self.dir.join("ccx.err"), &limits)?;
        Ok(Output {
            finished,
            log: std::fs::read_to_string(&log_path).unwrap_or_default(),
            dat: std::fs::read_to_string(&dat).unwrap_or_default(),
            log_path,
        })
    }

    /// `repeats` runs (at least one), each read by `read`; the first repeat's values are
    /// kept. A run stopped at a limit, with an `*ERROR` in its log or whose output `read`
    /// refuses ends the job.
    pub fn run_repeated<T>(
        &self,
        repeats: usize,
        read: impl Fn(&Output) -> Result<T, String>,
    ) -> Result<Outcome<T>, String> {
        let mut walls = Vec::new();
        let mut own = Vec::new();
        let mut peak: Option<f64> = None;
        let mut first: Option<(usize, T)> = None;
        for _ in 0..repeats.max(1) {
            let out = self.run_once()?;
            let f = &out.finished;
            if let Some(why) = &f.stopped {
                return Ok(Outcome::Stopped(why.clone()));
            }
            let values = match (error_line(&out.log), read(&out)) {
                (None, Ok(v)) => v,
                (error, read) => {
                    let why = error.map_or_else(|| read.err().unwrap_or_default(), str::to_string);
                    return Ok(Outcome::Failed(format!(
                        "exit code {:?}; {why} (log {})",
                        f.code,
                        out.log_path.display()
                    )));
                }
            };
            walls.push(f.wall);
            own.extend(total_time(&out.log));
            if let Some(p) = f.peak_rss {
                peak = Some(peak.map_or(p, |q| q.max(p)));
            }
            first.get_or_insert((newton_iterations(&out.log), values));
        }
        let (iterations, values) = first.expect("at least one repeat");
        let timed = Timed {
            wall: Stat::of(&walls),
            own_time: (!own.is_empty()).then(|| Stat::of(&own).median),
            peak_mib: peak.map(|p| p / MIB),
            iterations,
        };
        Ok(Outcome::Finished { timed, values })
    }
}
