//! What every METIS call of the process shares: its seed and its lock.

use metis::Idx;

/// Seed passed to METIS so the partition and the orders are reproducible.
pub(crate) const METIS_SEED: Idx = 4321;

/// METIS keeps its random-number state in process-global variables, so two threads
/// partitioning or ordering at the same time corrupt each other's sequence and the result
/// stops being reproducible. All METIS calls take this lock.
pub(crate) static METIS_LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
