//! Runs the solver on a scene as the suites always have: under `timeout -k 10 <limit>`
//! (exit 124 when stopped, 137 when killed after the grace period), on 1 rank directly and
//! on more under `run/mpirun`, within a time budget for the whole suite; and the other
//! `solver` commands whose output goes to a log file. Every run leaves
//! `logs/<name>.np<N>.stderr`, `.rc` (its exit code, `127` for a missing scene, `skipped`
//! past the budget), `.time` (seconds, 3 decimals) and `.limit` (when stopped).

use std::fs::File;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

/// The suite's clock, its budget and its layout on disk.
pub struct Suite {
    /// `paper` or `extreme`: names the suite in its messages.
    pub name: &'static str,
    pub solver: PathBuf,
    /// `out/<suite>`.
    pub out: PathBuf,
    /// No run starts after this many seconds from `start`.
    pub budget: i64,
    /// Seconds a run may take.
    pub run_limit: i64,
    pub start: Instant,
    /// Width of the scene column in the progress lines.
    pub name_width: usize,
    /// Width of the time column in the progress lines.
    pub time_width: usize,
}

impl Suite {
    pub fn logs(&self) -> PathBuf {
        self.out.join("logs")
    }

    /// Whole seconds since the suite started, as `printf "%.0f"` rounds them.
    pub fn elapsed(&self) -> i64 {
        format!("{:.0}", self.start.elapsed().as_secs_f64())
            .parse()
            .expect("a formatted integer")
    }

    pub fn say(&self, msg: &str) {
        println!("run/{}: {msg}", self.name);
    }

    /// Removes and recreates `out/<suite>/{np1,np2,logs}`.
    pub fn fresh_dirs(&self) -> Result<(), String> {
        if self.out.exists() {
            std::fs::remove_dir_all(&self.out)
                .map_err(|e| format!("cannot remove {}: {e}", self.out.display()))?;
        }
        for d in [self.out.join("np1"), self.out.join("np2"), self.logs()] {
            std::fs::create_dir_all(&d)
                .map_err(|e| format!("cannot create {}: {e}", d.display()))?;
        }
        Ok(())
    }

    /// Runs `scene` on `np` ranks into `np<np>/<name>.h5`, recording how it ended.
    pub fn run_one(&self, name: &str, np: usize, scene: &Path) {
        let log = self.logs().join(format!("{name}.np{np}"));
        let with = |ext: &str| PathBuf::from(format!("{}.{ext}", log.display()));
        let write = |ext: &str, text: &str| {
            if let Err(e) = std::fs::write(with(ext), text) {
                eprintln!(
                    "run/{}: cannot write {}: {e}",
                    self.name,
                    with(ext).display()
                );
            }
        };
        if !scene.is_file() {
            write(
                "stderr",
                &format!("scene file {} not found\n", scene.display()),
            );
            write("rc", "127\n");
            return;
        }
        let left = self.budget - self.elapsed();
        let limit = left.min(self.run_limit);
        if left < 5 {
            write(
                "stderr",
                &format!(
                    "not run: the time budget of run/{} ({} s) was spent\n",
                    self.name, self.budget
                ),
            );
            write("rc", "skipped\n");
            return;
        }
        let result = self.out.join(format!("np{np}")).join(format!("{name}.h5"));
        let mut cmd = Command::new("timeout");
        cmd.args(["-k", "10", &limit.to_string()]);
        if np > 1 {
            cmd.args(["run/mpirun", "-np", &np.to_string()]);
        }
        cmd.arg(&self.solver)
            .args(["-q", "run"])
            .arg(scene)
            .arg("-o")
            .arg(&result);
        let t0 = Instant::now();
        let rc = run_to_files(&mut cmd, None, &with("stderr"));
        let secs = format!("{:.3}", t0.elapsed().as_secs_f64());
        if rc == 124 || rc == 137 {
            write("limit", &format!("{limit}\n"));
        }
        write("time", &format!("{secs}\n"));
        write("rc", &format!("{rc}\n"));
        println!(
            "run/{}: {name:<nw$} {np} rank{}  exit {rc:<3} {secs:>tw$} s",
            self.name,
            if np == 1 { "" } else { "s" },
            nw = self.name_width,
            tw = self.time_width
        );
    }

    /// The result of a run: the completed file, else the failed run's file.
    pub fn result_of(&self, name: &str, np: usize) -> Option<PathBuf> {
        result_of(&self.out, name, np)
    }

    /// Runs `solver <args>` with its standard output (and error, unless `stderr` names a
    /// file of its own) in `stdout`; writes its exit code to `rc` when given.
    pub fn solver_to(
        &self,
        args: &[&str],
        stdout: &Path,
        stderr: Option<&Path>,
        rc: Option<&Path>,
    ) -> i32 {
        let mut cmd = Command::new(&self.solver);
        cmd.args(args);
        let code = match stderr {
            Some(e) => run_to_files(&mut cmd, Some(stdout), e),
            None => run_merged(&mut cmd, stdout),
        };
        if let Some(rc) = rc {
            let _ = std::fs::write(rc, format!("{code}\n"));
        }
        code
    }
}

/// The result of a run under `out`: `np<N>/<name>.h5`, else `np<N>/<name>.failed.h5`.
pub fn result_of(out: &Path, name: &str, np: usize) -> Option<PathBuf> {
    let dir = out.join(format!("np{np}"));
    [".h5", ".failed.h5"]
        .iter()
        .map(|s| dir.join(format!("{name}{s}")))
        .find(|p| p.is_file())
}

/// A shell's exit code for a process status: the code, or 128 + the signal.
fn code_of(status: std::process::ExitStatus) -> i32 {
    use std::os::unix::process::ExitStatusExt;
    status
        .code()
        .unwrap_or_else(|| 128 + status.signal().unwrap_or(0))
}

/// Runs `cmd`, standard output to `stdout` (or discarded), standard error to `stderr`.
pub fn run_to_files(cmd: &mut Command, stdout: Option<&Path>, stderr: &Path) -> i32 {
    let (Ok(err), out) = (File::create(stderr), stdout.map(File::create)) else {
        return 126;
    };
    let out = match out {
        Some(Ok(f)) => Stdio::from(f),
        Some(Err(_)) => return 126,
        None => Stdio::null(),
    };
    match cmd.stdin(Stdio::null()).stdout(out).stderr(err).status() {
        Ok(s) => code_of(s),
        Err(e) => {
            let _ = std::fs::write(
                stderr,
                format!("cannot start {:?}: {e}\n", cmd.get_program()),
            );
            127
        }
    }
}

/// Runs `cmd` with standard output and error both in `path` (as `>file 2>&1`).
pub fn run_merged(cmd: &mut Command, path: &Path) -> i32 {
    let Ok(f) = File::create(path) else {
        return 126;
    };
    let Ok(g) = f.try_clone() else { return 126 };
    match cmd.stdin(Stdio::null()).stdout(f).stderr(g).status() {
        Ok(s) => code_of(s),
        Err(e) => {
            let _ = std::fs::write(path, format!("cannot start {:?}: {e}\n", cmd.get_program()));
            127
        }
    }
}

/// Standard output of a command, trimmed, or empty.
pub fn output_of(cmd: &str, args: &[&str]) -> String {
    Command::new(cmd)
        .args(args)
        .stderr(Stdio::null())
        .output()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim_end().to_string())
        .unwrap_or_default()
}

/// The first line of a command's standard output, or empty.
pub fn first_line_of(cmd: &str, args: &[&str]) -> String {
    output_of(cmd, args)
        .lines()
        .next()
        .unwrap_or("")
        .to_string()
}

/// The git commit, marked when tracked files have uncommitted changes.
pub fn commit() -> String {
    let c = output_of("git", &["rev-parse", "HEAD"]);
    if c.is_empty() {
        return "unknown".into();
    }
    if output_of("git", &["status", "--porcelain", "--untracked-files=no"]).is_empty() {
        c
    } else {
        format!("{c} (with uncommitted changes to tracked files)")
    }
}

/// The date and time now, as `date -u '+%Y-%m-%d %H:%M:%S UTC'` writes it.
pub fn date_utc() -> String {
    output_of("date", &["-u", "+%Y-%m-%d %H:%M:%S UTC"])
}

/// The scene names of `dir` (`*.toml`), sorted as the shell's glob sorts them.
pub fn scenes_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map(|d| {
            d.filter_map(|e| e.ok())
                .filter_map(|e| e.file_name().to_str().map(str::to_string))
                .filter_map(|f| f.strip_suffix(".toml").map(str::to_string))
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    names
}

/// `order` first, then the other scenes of `found` in their order.
pub fn in_order(order: &[&str], found: &[String]) -> Vec<String> {
    let mut all: Vec<String> = order.iter().map(|s| s.to_string()).collect();
    for f in found {
        if !all.contains(f) {
            all.push(f.clone());
        }
    }
    all
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_scenes_come_first_and_the_rest_in_directory_order() {
        let found = vec!["a".to_string(), "z".into(), "b".into()];
        assert_eq!(in_order(&["z", "y"], &found), ["z", "y", "a", "b"]);
    }

    #[test]
    fn a_completed_result_wins_over_a_failed_one() {
        let dir = std::env::temp_dir().join(format!("suite-result-of-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("np1")).unwrap();
        assert_eq!(result_of(&dir, "s", 1), None);
        std::fs::write(dir.join("np1/s.failed.h5"), "").unwrap();
        assert_eq!(result_of(&dir, "s", 1), Some(dir.join("np1/s.failed.h5")));
        std::fs::write(dir.join("np1/s.h5"), "").unwrap();
        assert_eq!(result_of(&dir, "s", 1), Some(dir.join("np1/s.h5")));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
