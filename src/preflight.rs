//! Before a run allocates its mesh: the scene's size from its file, the memory estimate per
//! rank against what this machine and this process may use, and the refusal when it does
//! not fit (or the warning, with `--force`).

use crate::comm::{self, Comm};
use crate::memory::{self, available, check_fit, Fit};
use crate::scene::counts::SceneSize;
use std::hash::{Hash, Hasher};

/// This machine's host name.
fn host_name() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .map(|s| s.trim().to_string())
        .unwrap_or_default()
}

/// How many ranks of the run share this machine (the same host name): they share its
/// memory.
pub fn ranks_on_this_machine<C: Comm + ?Sized>(comm: &C) -> usize {
    if comm.size() == 1 {
        return 1;
    }
    let mut h = std::collections::hash_map::DefaultHasher::new();
    host_name().hash(&mut h);
    // 52 bits travel exactly as an f64.
    let mine = (h.finish() >> 12) as f64;
    comm.all_gather_f64(&[mine])
        .iter()
        .filter(|v| v.first() == Some(&mine))
        .count()
}

/// What the gate decided.
pub enum Gate {
    /// Run: the fit (this rank's), and the refusal overridden by `--force`, if any.
    Go { fit: Fit, forced: Option<String> },
    /// Do not run: the message (the same on every rank).
    Refuse(String),
}

/// Compares the scene's estimate with the memory of every rank's machine and process.
/// Collective: every rank takes the same branch.
pub fn memory_gate<C: Comm + ?Sized>(comm: &C, size: &SceneSize, mpi: bool, force: bool) -> Gate {
    let here = ranks_on_this_machine(comm);
    let fit = check_fit(&size.counts, comm.size(), mpi, here, &available::bounds());
    let refused = comm::first_error(comm, fit.refusal());
    match refused {
        None => Gate::Go { fit, forced: None },
        Some(m) if force => Gate::Go {
            fit,
            forced: Some(m),
        },
        Some(m) => Gate::Refuse(m),
    }
}

/// The estimate and the memory this rank may use, in one line for the log.
pub fn fit_line(fit: &Fit) -> String {
    let bounds: Vec<String> = available::bounds()
        .iter()
        .map(|b| format!("{} ({})", memory::format_bytes(b.bytes), b.source))
        .collect();
    format!(
        "{}; available {}",
        memory::fit::estimate_line(&fit.estimate),
        if bounds.is_empty() {
            "unknown".to_string()
        } else {
            bounds.join(", ")
        }
    )
}
