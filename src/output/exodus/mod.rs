//! Exodus II results: a finished HDF5 result file rewritten as an Exodus II file (netCDF
//! 64-bit offset, written through Debian's libnetcdf by the `netcdf` crate) for Sierra's,
//! MOOSE's and Cubit's tools (`exodiff`, ParaView's and VisIt's Exodus readers).
//!
//! The Exodus file is made from the HDF5 file rank 0 published, read back whole (every
//! checksum checked), so it holds the same bits in the same global order on any number of
//! ranks; the HDF5 file stays the restart carrier. Nothing rank-dependent (the partition,
//! the rank count, wall times, the start time) goes into it. docs/exodus.md lists the
//! variables.

mod names;
mod shape;
mod steps;
mod text;
mod write;

pub use names::{ELEMENT_VARIABLES, GLOBAL_VARIABLES, NODAL_VARIABLES};
pub use text::{rows_to_names, NcChar};
pub use write::{check_exodus_output, write_exodus};

/// Whether `path` names an Exodus file by its extension (`.e`, `.exo`, `.exii`, `.g`).
pub fn is_exodus_path(path: &std::path::Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| matches!(e, "e" | "exo" | "exii" | "g"))
}
