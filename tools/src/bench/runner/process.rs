//! A subprocess run to its end or stopped at a limit, with its wall time and peak memory.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

pub const MIB: f64 = 1024.0 * 1024.0;

/// How a subprocess ended.
pub struct Finished {
    /// Exit code; `None` when a signal ended it.
    pub code: Option<i32>,
    /// Why the bench stopped it (time or memory limit), if it did.
    pub stopped: Option<String>,
    /// Wall-clock seconds from spawn to exit.
    pub wall: f64,
    /// Largest VmHWM of the process itself (not its children) seen while it ran, bytes.
    pub peak_rss: Option<f64>,
}

/// When the bench stops a subprocess.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Wall-clock seconds.
    pub timeout_s: f64,
    /// Resident memory of the process itself (not its children), bytes.
    pub rss_limit: Option<f64>,
    /// The machine's MemAvailable falling below this many bytes (the process tree under
    /// mpirun is not followed: this guards the machine, whoever holds the memory).
    pub min_available: Option<f64>,
}

impl Limits {
    pub fn timeout(timeout_s: f64) -> Self {
        Limits {
            timeout_s,
            rss_limit: None,
            min_available: None,
        }
    }
}

/// (VmHWM, VmRSS) of a process in bytes, from /proc/<pid>/status.
fn process_memory(pid: u32) -> Option<(f64, f64)> {
    let s = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let field = |name: &str| -> Option<f64> {
        let l = s.lines().find(|l| l.starts_with(name))?;
        let kb: f64 = l.split_whitespace().nth(1)?.parse().ok()?;
        Some(kb * 1024.0)
    };
    Some((field("VmHWM:")?, field("VmRSS:")?))
}

/// MemAvailable of /proc/meminfo in bytes.
pub fn memory_available() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/meminfo").ok()?;
    let l = s.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: f64 = l.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0)
}

/// Why `limits` stop a process now, if they do; records its peak memory in `peak`.
fn limit_reached(
    pid: u32,
    limits: &Limits,
    elapsed: f64,
    peak: &mut Option<f64>,
) -> Option<String> {
    let mut stopped = None;
    if let Some((hwm, rss)) = process_memory(pid) {
        *peak = Some(peak.map_or(hwm, |p| p.max(hwm)));
        if let Some(limit) = limits.rss_limit.filter(|&l| rss > l) {
            stopped = Some(format!(
                "stopped at {:.0} MiB resident (limit {:.0} MiB)",
                rss / MIB,
                limit / MIB
            ));
        }
    }
    if let Some(floor) = limits.min_available {
        if let Some(avail) = memory_available().filter(|&a| a < floor) {
            stopped.get_or_insert(format!(
                "stopped when the machine had {:.0} MiB available (floor {:.0} MiB)",
                avail / MIB,
                floor / MIB
            ));
        }
    }
    if stopped.is_none() && elapsed > limits.timeout_s {
        stopped = Some(format!("stopped after {:.0} s", limits.timeout_s));
    }
    stopped
}

/// Runs `cmd` with its standard output and error in the given files, stopping it at
/// `limits`.
pub fn run_limited(
    cmd: &mut Command,
    stdout: &Path,
    stderr: &Path,
    limits: &Limits,
) -> Result<Finished, String> {
    let open = |p: &Path| {
        std::fs::File::create(p).map_err(|e| format!("cannot create {}: {e}", p.display()))
    };
    cmd.stdin(Stdio::null())
        .stdout(open(stdout)?)
        .stderr(open(stderr)?);
    let start = Instant::now();
    let mut child = cmd
        .spawn()
        .map_err(|e| format!("cannot start {:?}: {e}", cmd.get_program()))?;
    let pid = child.id();
    let mut peak: Option<f64> = None;
    let mut stopped = None;
    let status = loop {
        if let Some(s) = child
            .try_wait()
            .map_err(|e| format!("waiting for {pid}: {e}"))?
        {
            break s;
        }
        let elapsed = start.elapsed().as_secs_f64();
        stopped = limit_reached(pid, limits, elapsed, &mut peak);
        if stopped.is_some() {
            break stop(&mut child)?;
        }
        // Sleep about 1 % of the time so far: the wall time is exact to about that.
        std::thread::sleep(Duration::from_secs_f64((0.01 * elapsed).clamp(0.002, 0.1)));
    };
    Ok(Finished {
        code: status.code(),
        stopped,
        wall: start.elapsed().as_secs_f64(),
        peak_rss: peak,
    })
}

/// SIGTERM (mpirun passes it on to its ranks), then SIGKILL if it has not ended in 10 s.
fn stop(child: &mut Child) -> Result<std::process::ExitStatus, String> {
    let pid = child.id();
    let _ = Command::new("kill")
        .args(["-TERM", &pid.to_string()])
        .stderr(Stdio::null())
        .status();
    let t = Instant::now();
    while t.elapsed() < Duration::from_secs(10) {
        if let Some(s) = child
            .try_wait()
            .map_err(|e| format!("waiting for {pid}: {e}"))?
        {
            return Ok(s);
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let _ = child.kill();
    child.wait().map_err(|e| format!("waiting for {pid}: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_process_past_its_time_limit_is_stopped() {
        let dir = std::env::temp_dir();
        let out = dir.join(format!("bench-test-{}.out", std::process::id()));
        let f = run_limited(
            Command::new("sleep").arg("30"),
            &out,
            &out,
            &Limits::timeout(0.3),
        )
        .unwrap();
        let _ = std::fs::remove_file(&out);
        assert!(f.stopped.is_some() && f.code.is_none(), "{:?}", f.stopped);
        assert!(f.wall < 5.0, "stopped after {} s", f.wall);
    }

    #[test]
    fn a_finished_process_gives_its_exit_code_and_output() {
        let dir = std::env::temp_dir();
        let out = dir.join(format!("bench-test-exit-{}.out", std::process::id()));
        let f = run_limited(
            Command::new("sh").args(["-c", "echo hello; exit 3"]),
            &out,
            &out,
            &Limits::timeout(60.0),
        )
        .unwrap();
        let text = std::fs::read_to_string(&out).unwrap();
        let _ = std::fs::remove_file(&out);
        assert_eq!(
            (f.code, f.stopped.as_deref(), text.as_str()),
            (Some(3), None, "hello\n")
        );
    }
}
