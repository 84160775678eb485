//! A run as its log files tell it (`logs/<name>.np<N>.rc`, `.time`, `.limit`, `.stderr`),
//! and the message it stopped with.

use std::path::Path;

/// One run of a scene on some ranks, read back from its logs.
#[derive(Clone, Debug, Default)]
pub struct Record {
    pub np: usize,
    /// The scene path as given to the solver (its messages start with it).
    pub scene: String,
    /// Exit code as written (`0`, `1`, `124`, `skipped`, `127`, ...); `None` when not run.
    pub rc: Option<String>,
    /// Wall time of the process in seconds.
    pub time: Option<f64>,
    /// The time limit that stopped it.
    pub limit: String,
    pub stderr: String,
}

/// The file's text, or `None`.
pub fn read(path: &Path) -> Option<String> {
    std::fs::read_to_string(path).ok()
}

/// The file's text without surrounding white space, or empty.
pub fn read_trim(path: &Path) -> String {
    read(path).map(|s| s.trim().to_string()).unwrap_or_default()
}

impl Record {
    pub fn load(logs: &Path, name: &str, np: usize, scene: &str) -> Record {
        let base = |ext: &str| logs.join(format!("{name}.np{np}.{ext}"));
        let rc = read_trim(&base("rc"));
        Record {
            np,
            scene: scene.into(),
            rc: (!rc.is_empty()).then_some(rc),
            time: read(&base("time")).and_then(|t| t.trim().parse().ok()),
            limit: read_trim(&base("limit")),
            stderr: read(&base("stderr")).unwrap_or_default(),
        }
    }

    pub fn rc_is(&self, code: &str) -> bool {
        self.rc.as_deref() == Some(code)
    }

    /// Not started (`None` or past the budget).
    pub fn not_run(&self) -> bool {
        matches!(self.rc.as_deref(), None | Some("skipped"))
    }

    /// Stopped by the time limit.
    pub fn timed_out(&self) -> bool {
        matches!(self.rc.as_deref(), Some("124") | Some("137"))
    }

    /// The solver's `error:` line (else the first line that is not mpirun's), without the
    /// prefix and the scene path.
    pub fn error_line(&self) -> String {
        let lines: Vec<&str> = self
            .stderr
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty())
            .collect();
        let msg = lines
            .iter()
            .find(|l| l.starts_with("error:"))
            .or_else(|| {
                lines
                    .iter()
                    .find(|l| !l.starts_with('-') && !l.contains("mpirun"))
            })
            .copied()
            .unwrap_or("");
        let msg = msg.strip_prefix("error:").map_or(msg, |m| m.trim_start());
        let prefix = format!("{}: ", self.scene);
        msg.strip_prefix(&prefix).unwrap_or(msg).to_string()
    }

    /// The message a run ended with, plainly (the paper's wording).
    pub fn message(&self) -> String {
        match self.rc.as_deref() {
            None => "not run".into(),
            Some("skipped") => self.stderr.trim().into(),
            Some("124") | Some("137") => format!("timed out after {} s", self.limit),
            Some(rc) => {
                let m = self.error_line();
                if m.is_empty() {
                    format!("exit code {rc}, no message")
                } else {
                    m
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec(rc: &str, stderr: &str) -> Record {
        Record {
            np: 1,
            scene: "run/scenes/paper/s.toml".into(),
            rc: Some(rc.into()),
            limit: "120".into(),
            stderr: stderr.into(),
            ..Record::default()
        }
    }

    #[test]
    fn the_message_is_the_error_line_without_the_scene() {
        let r = rec(
            "1",
            "--------\nerror: run/scenes/paper/s.toml: step 1 (to t = 0.1) failed\nthe completed steps\n",
        );
        assert_eq!(r.message(), "step 1 (to t = 0.1) failed");
        let m = rec("1", "-----\nmpirun noted\nsomething broke\n");
        assert_eq!(m.message(), "something broke");
        assert_eq!(rec("3", "").message(), "exit code 3, no message");
        assert_eq!(rec("124", "").message(), "timed out after 120 s");
        assert_eq!(
            rec("skipped", "not run: budget\n").message(),
            "not run: budget"
        );
        let none = Record {
            rc: None,
            ..rec("0", "")
        };
        assert_eq!(none.message(), "not run");
    }
}
