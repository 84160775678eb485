//! Memory: the estimate of a run's peak per rank from the scene's counts (`model`), the
//! memory the machine and the process limits leave (`available`), the decision to refuse a
//! run that does not fit (`fit`), allocations that fail with an error rather than an abort
//! (`reserve`), and the binary's allocator that ends with a one-line error where one still
//! fails (`guard`).

pub mod available;
mod bytes;
pub mod fit;
pub mod guard;
pub mod model;
pub mod reserve;

pub use available::Bound;
pub use bytes::format_bytes;
pub use fit::{check_fit, estimate_line, Fit};
pub use model::{estimate, estimate_run, Counts, Estimate};
pub use reserve::{try_filled, try_with_capacity, AllocError};
