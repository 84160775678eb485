//! The shared runner: subprocesses under time and memory limits with their peak memory
//! (`process`), the `solver` binary under `run/mpirun` with repeats, its log, its result
//! files and its comparisons (`solver`), and the text of its log (`log`). Every benchmark
//! that runs a program goes through here; the peers' own runners (`peers/`) use `process`.

pub mod log;
pub mod process;
pub mod solver;
