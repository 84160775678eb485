//! The machine a run measured, and how busy it was: the report's first lines.

use crate::api::rfc3339_now;
use std::time::Instant;

pub struct Machine {
    pub cpu_model: String,
    pub cache: String,
    pub logical_cpus: usize,
    pub physical_cores: Option<usize>,
    pub date: String,
    pub git_commit: Option<String>,
    pub git_dirty: Option<bool>,
    pub load_start: Option<String>,
    pub jiffies_start: Option<(u64, u64)>,
}

/// The machine and the whole run's clock, as the report gives them.
pub struct RunInfo {
    pub machine: Machine,
    /// Wall-clock seconds of the whole run.
    pub total_wall: f64,
    pub load_end: Option<String>,
    /// Fraction of the machine's CPU time stolen by the hypervisor during the run.
    pub steal: Option<f64>,
}

impl RunInfo {
    /// The run that started at `start` on `machine` ends now.
    pub fn finish(machine: Machine, start: Instant) -> RunInfo {
        let steal = steal_since(&machine);
        RunInfo {
            machine,
            total_wall: start.elapsed().as_secs_f64(),
            load_end: load_average(),
            steal,
        }
    }
}

fn command_output(cmd: &str, args: &[&str]) -> Option<String> {
    let out = std::process::Command::new(cmd).args(args).output().ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

/// Physical cores: distinct (physical id, core id) pairs, when the kernel reports them.
fn physical_cores(cpuinfo: &str) -> Option<usize> {
    let mut cores = std::collections::BTreeSet::new();
    let mut phys = String::new();
    for l in cpuinfo.lines() {
        if let Some((k, v)) = l.split_once(':') {
            match k.trim() {
                "physical id" => phys = v.trim().to_string(),
                "core id" => {
                    cores.insert((phys.clone(), v.trim().to_string()));
                }
                _ => {}
            }
        }
    }
    (!cores.is_empty()).then_some(cores.len())
}

pub fn machine() -> Machine {
    let info = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    let field = |name: &str| -> Option<String> {
        info.lines()
            .filter_map(|l| l.split_once(':'))
            .find(|(k, _)| k.trim() == name)
            .map(|(_, v)| v.trim().to_string())
    };
    let processors = info
        .lines()
        .filter(|l| l.split(':').next().map(str::trim) == Some("processor"))
        .count();
    let logical_cpus = if processors > 0 {
        processors
    } else {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    };
    let git_commit = command_output("git", &["rev-parse", "--short", "HEAD"]);
    let git_dirty = git_commit
        .as_ref()
        .and_then(|_| command_output("git", &["status", "--porcelain", "--untracked-files=no"]))
        .map(|s| !s.is_empty());
    Machine {
        cpu_model: field("model name").unwrap_or_else(|| "unknown".into()),
        cache: field("cache size").unwrap_or_else(|| "unknown".into()),
        logical_cpus,
        physical_cores: physical_cores(&info),
        date: rfc3339_now(),
        git_commit,
        git_dirty,
        load_start: load_average(),
        jiffies_start: cpu_jiffies(),
    }
}

/// (all, steal) jiffies of the whole machine from the `cpu` line of /proc/stat: time the
/// hypervisor gave to other guests shows as steal, which thread CPU clocks do not see.
fn cpu_jiffies() -> Option<(u64, u64)> {
    let s = std::fs::read_to_string("/proc/stat").ok()?;
    let line = s.lines().find(|l| l.starts_with("cpu "))?;
    let v: Vec<u64> = line
        .split_whitespace()
        .skip(1)
        .filter_map(|x| x.parse().ok())
        .collect();
    // user nice system idle iowait irq softirq steal [guest guest_nice, included in user]
    let all: u64 = v.iter().take(8).sum();
    Some((all, v.get(7).copied().unwrap_or(0)))
}

/// The 1-, 5- and 15-minute load averages, as /proc/loadavg gives them.
pub fn load_average() -> Option<String> {
    let s = std::fs::read_to_string("/proc/loadavg").ok()?;
    Some(s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
}

/// Fraction of the machine's CPU time the hypervisor gave to other guests since `m` was
/// taken.
fn steal_since(m: &Machine) -> Option<f64> {
    match (m.jiffies_start, cpu_jiffies()) {
        (Some((a0, s0)), Some((a1, s1))) if a1 > a0 => {
            Some(s1.saturating_sub(s0) as f64 / (a1 - a0) as f64)
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn physical_cores_are_distinct_core_ids_per_package() {
        let info = "processor : 0\nphysical id : 0\ncore id : 0\n\n\
                    processor : 1\nphysical id : 0\ncore id : 0\n\n\
                    processor : 2\nphysical id : 1\ncore id : 0\n";
        assert_eq!(physical_cores(info), Some(2));
        assert_eq!(physical_cores("processor : 0\n"), None);
    }
}
