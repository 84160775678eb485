//! The result file: one HDF5 file per run, written by rank 0 in global node and element
//! order, plus an XDMF 3 file beside it for ParaView.
//!
//! * [`ResultWriter`] creates `<path>.tmp`, appends finished steps (flushing each), and on
//!   [`ResultWriter::finish`] renames it to `<path>` and writes `<stem>.xmf`; on
//!   [`ResultWriter::finish_failed`] it renames it to `<stem>.failed.h5` instead.
//! * [`ResultFile`] reads a result file back.
//! * [`layout`] names every dataset and attribute; `README-section.md` beside this file
//!   documents them.

mod data;
mod error;
pub mod layout;
mod open;
mod reader;
mod timestamp;
mod writer;
mod xdmf;

pub use data::{
    contact_status, OutputBody, OutputMesh, RestartState, RunInfo, StepOutput, StepStats,
};
pub use error::OutputError;
pub use layout::ResultPaths;
pub use reader::{FileAttributes, NumericData, NumericKind, ResultFile};
pub use timestamp::{rfc3339_from_unix, rfc3339_now};
pub use writer::ResultWriter;
pub use xdmf::XdmfDescription;
