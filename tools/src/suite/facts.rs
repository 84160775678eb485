//! The facts a report's "How this was produced" section gives: date, commit, versions and
//! the machine, gathered as the suites' scripts did (`nproc`, /proc, `uname`, `--version`).

use crate::runner::{commit, date_utc, first_line_of, output_of, Suite};

pub struct Facts {
    pub date: String,
    pub commit: String,
    pub cores: String,
    pub cpu: String,
    pub mem: String,
    pub os: String,
    pub kernel: String,
    pub rustc: String,
    pub mpi: String,
    pub solver: String,
    pub paraview: String,
    /// Seconds since the suite started, when the facts were gathered.
    pub elapsed: i64,
}

/// The model name of the first CPU in /proc/cpuinfo (after the line's last `: `).
pub fn cpu_model(cpuinfo: &str) -> String {
    cpuinfo
        .lines()
        .find(|l| l.contains("model name"))
        .map(|l| l.rsplit_once(": ").map_or(l, |(_, m)| m).to_string())
        .unwrap_or_default()
}

/// MemTotal of /proc/meminfo in GiB, one decimal.
pub fn memory(meminfo: &str) -> String {
    meminfo
        .lines()
        .find(|l| l.contains("MemTotal"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|kb| kb.parse::<f64>().ok())
        .map(|kb| format!("{:.1} GiB", kb / 1048576.0))
        .unwrap_or_default()
}

impl Facts {
    pub fn gather(suite: &Suite) -> Facts {
        let solver = suite.solver.to_str().unwrap_or("target/release/solver");
        let os = output_of(
            "sh",
            &[
                "-c",
                ". /etc/os-release 2>/dev/null && echo \"$PRETTY_NAME\"",
            ],
        );
        Facts {
            date: date_utc(),
            commit: commit(),
            cores: output_of("nproc", &[]),
            cpu: cpu_model(&std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default()),
            mem: memory(&std::fs::read_to_string("/proc/meminfo").unwrap_or_default()),
            os: if os.is_empty() {
                output_of("uname", &["-s"])
            } else {
                os
            },
            kernel: output_of("uname", &["-r"]),
            rustc: output_of("rustc", &["--version"]),
            mpi: first_line_of("mpirun", &["--version"]),
            solver: output_of(solver, &["--version"]),
            paraview: first_line_of("pvpython", &["--version"]),
            elapsed: suite.elapsed(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cpu_and_memory_are_read_from_proc() {
        let cpu = "processor\t: 0\nmodel name\t: AMD EPYC 7B13: x\nmodel name\t: other\n";
        assert_eq!(cpu_model(cpu), "x");
        assert_eq!(memory("MemTotal:        8148012 kB\n"), "7.8 GiB");
        assert_eq!(memory(""), "");
    }
}
