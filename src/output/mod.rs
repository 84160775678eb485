//! The result file: one HDF5 file per run, written by rank 0 in global node and element
//! order, plus an XDMF 3 file beside it for ParaView.
//!
//! * [`claim_output`] checks an output path before a run (not an input of the run, a regular
//!   file or a new path, an existing file only when a run of ours wrote it) and locks it.
//! * [`ResultWriter`] writes a new temporary file, appends finished steps (flushing each),
//!   and on [`ResultWriter::finish`] checks it and renames it to `<path>` with `<stem>.xmf`;
//!   on [`ResultWriter::finish_failed`] to `<stem>.failed.h5` instead.
//! * [`ResultFile`] reads a result file back; every dataset carries checksums
//!   ([`integrity`]) that every read checks.
//! * [`layout`] names every dataset and attribute; the README documents them.

pub mod cells;
mod data;
mod datasets;
mod error;
pub mod exodus;
mod header;
pub mod integrity;
pub mod layout;
pub mod lock;
pub mod npy;
mod open;
pub mod paths;
mod picture;
mod publish;
mod reader;
mod restart;
pub mod shutdown;
mod source;
mod timestamp;
mod verify;
mod writer;
mod xdmf;

pub use cells::ElementNodes;
pub use data::{
    contact_status, OutputBody, OutputMesh, RestartState, RunInfo, StepField, StepOutput, StepStats,
};
pub use datasets::CHUNK_ROWS;
pub use error::OutputError;
pub use layout::ResultPaths;
pub use paths::{claim_output, leftover_temps, OutputClaim};
pub use picture::{check_picture_output, write_picture};
pub use reader::{FileAttributes, NumericData, NumericKind, ResultFile};
pub use source::{BodyRows, MeshSource};
pub use timestamp::{rfc3339_from_unix, rfc3339_now};
pub use writer::ResultWriter;
pub use xdmf::XdmfDescription;
