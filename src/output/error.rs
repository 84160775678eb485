//! The error type of the result file writer, reader and the `post` tools.

use std::path::PathBuf;

/// Everything that can go wrong writing, reading or post-processing a result file.
///
/// Every message names the file and, where there is one, the dataset concerned.
#[derive(thiserror::Error, Debug)]
pub enum OutputError {
    /// The file does not exist.
    #[error("{}: no such file", file.display())]
    NotFound { file: PathBuf },

    /// The file exists but is not an HDF5 file (no HDF5 signature).
    #[error("{}: not an HDF5 file ({reason})", file.display())]
    NotHdf5 { file: PathBuf, reason: String },

    /// The file has an HDF5 signature but the library cannot open it.
    #[error(
        "{}: HDF5 file cannot be opened, it is probably truncated or corrupt: {message}",
        file.display()
    )]
    Corrupt { file: PathBuf, message: String },

    /// A dataset or attribute the format requires is absent.
    #[error("{}: missing {what} {name}", file.display())]
    Missing {
        file: PathBuf,
        /// "dataset", "attribute" or "group".
        what: &'static str,
        name: String,
    },

    /// A dataset has a shape other than the format prescribes.
    #[error("{}: dataset {dataset} has shape {found:?}, expected {expected}", file.display())]
    Shape {
        file: PathBuf,
        dataset: String,
        expected: String,
        found: Vec<usize>,
    },

    /// A value handed to the writer is NaN or infinite; no such value is ever written.
    #[error("{}: refusing to write non-finite value {value} to {dataset} at {location}", file.display())]
    NonFinite {
        file: PathBuf,
        dataset: String,
        /// e.g. "node 12 (id 13), component 1".
        location: String,
        value: f64,
    },

    /// Data handed to the writer is inconsistent (wrong lengths, bad names, bad indices).
    #[error("{}: invalid data for {dataset}: {message}", file.display())]
    Invalid {
        file: PathBuf,
        dataset: String,
        message: String,
    },

    /// An error reported by the HDF5 library.
    #[error("{}: HDF5 error at {dataset}: {source}", file.display())]
    Hdf5 {
        file: PathBuf,
        dataset: String,
        #[source]
        source: hdf5::Error,
    },

    /// A file-system error (rename, XDMF writing, plot output).
    #[error("{}: {action}: {source}", file.display())]
    Io {
        file: PathBuf,
        action: String,
        #[source]
        source: std::io::Error,
    },

    /// A step index beyond the steps in the file.
    #[error("{}: step {step} out of range, the file has {steps} steps", file.display())]
    StepOutOfRange {
        file: PathBuf,
        step: usize,
        steps: usize,
    },

    /// Two result files cannot be compared (different meshes or dataset shapes).
    #[error("cannot compare {} and {}: {message}", a.display(), b.display())]
    Mismatch {
        a: PathBuf,
        b: PathBuf,
        message: String,
    },

    /// A bad request to a `post` subcommand (unknown node set, bad step list, ...).
    #[error("{}: {message}", file.display())]
    Usage { file: PathBuf, message: String },

    /// Drawing a plot failed.
    #[error("{}: plotting failed: {message}", file.display())]
    Plot { file: PathBuf, message: String },
}

/// Attaches the file and dataset names to an HDF5 library error.
pub(crate) trait Hdf5Context<T> {
    fn at(self, file: &std::path::Path, dataset: &str) -> Result<T, OutputError>;
}

impl<T> Hdf5Context<T> for Result<T, hdf5::Error> {
    fn at(self, file: &std::path::Path, dataset: &str) -> Result<T, OutputError> {
        self.map_err(|source| OutputError::Hdf5 {
            file: file.to_path_buf(),
            dataset: dataset.to_string(),
            source,
        })
    }
}
