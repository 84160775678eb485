//! Memory: the estimate of a run's peak per rank from the scene's counts (`model`), the
//! memory the machine and the process limits leave (`available`), the decision to refuse a
//! run that does not fit (`fit`), allocations that fail with an error rather than an abort
//! (`reserve`), and the binary's allocator that ends with a one-line error where one still
//! fails (`guard`).

pub mod available;
pub mod fit;
pub mod guard;
pub mod model;
pub mod reserve;

pub use available::Bound;
pub use fit::{check_fit, estimate_line, Fit};
pub use model::{estimate, estimate_run, Counts, Estimate};
pub use reserve::{try_filled, try_with_capacity, AllocError};

/// Bytes in binary units with one decimal: "512 B", "3.4 MiB", "1.2 TiB".
pub fn format_bytes(b: f64) -> String {
    const UNITS: [&str; 6] = ["B", "KiB", "MiB", "GiB", "TiB", "PiB"];
    let mut v = b;
    let mut u = 0;
    while v >= 1024.0 && u + 1 < UNITS.len() {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{v:.0} B")
    } else {
        format!("{v:.1} {}", UNITS[u])
    }
}
