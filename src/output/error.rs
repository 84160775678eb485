//! The error type of the result file writer, reader and the `post` tools.

use std::path::{Path, PathBuf};

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

    /// The output path cannot take a result (an input of the run, not a regular file, an
    /// existing file that is not a result of this solver, a parent that is not a directory).
    #[error("{}: not usable as the result file: {message}", file.display())]
    BadOutput { file: PathBuf, message: String },

    /// The path given for a picture cannot take it (an input of the command, not a regular
    /// file, an existing file that is not a picture, an unsupported extension).
    #[error("{}: not usable as the picture: {message}", file.display())]
    BadPicture { file: PathBuf, message: String },

    /// Another run writes this result now.
    #[error(
        "{}: another run is writing this result ({holder}; lock file {}); wait for it to end or choose another output path",
        file.display(), lock.display()
    )]
    Busy {
        file: PathBuf,
        lock: PathBuf,
        holder: super::lock::LockHolder,
    },

    /// The file system is full.
    #[error("{}: no space left on device ({action})", file.display())]
    NoSpace { file: PathBuf, action: String },

    /// A write failed (a full disk, an I/O error): the run's file was not published.
    #[error("{first}; nothing was published{}", kept.as_ref().map_or(String::new(), |k| format!(", the steps written before are kept in {} (--restart continues from it)", k.display())))]
    NotPublished {
        /// The failure, as its message.
        first: String,
        /// The temporary file, when it was kept (readable, with a restart state).
        kept: Option<PathBuf>,
    },

    /// Stored data fails its checksum, or a value that can never be written is there.
    #[error("{}: damaged: {dataset}{}: {message}", file.display(), step.map_or(String::new(), |s| format!(", step {s}")))]
    Damaged {
        file: PathBuf,
        dataset: String,
        /// The step (row of the per-step datasets, 0-based as `post info` lists them).
        step: Option<usize>,
        message: String,
    },
}

impl OutputError {
    /// The exit code a command ends with on this error: 1 when writing failed (a full disk,
    /// an I/O or library error while writing), 2 for bad input (an unusable output path, a
    /// result another run writes, a missing, unreadable or damaged file).
    pub fn exit_code(&self) -> u8 {
        match self {
            OutputError::NoSpace { .. }
            | OutputError::NotPublished { .. }
            | OutputError::Io { .. }
            | OutputError::Hdf5 { .. }
            | OutputError::Plot { .. }
            | OutputError::NonFinite { .. } => 1,
            _ => 2,
        }
    }
}

/// Attaches the file and dataset names to an HDF5 library error.
pub(crate) trait Hdf5Context<T> {
    fn at(self, file: &std::path::Path, dataset: &str) -> Result<T, OutputError>;
}

impl<T> Hdf5Context<T> for Result<T, hdf5::Error> {
    fn at(self, file: &std::path::Path, dataset: &str) -> Result<T, OutputError> {
        self.map_err(|source| classify(file, dataset, source))
    }
}

/// Attaches the file and what was being done to a file-system error.
pub(crate) fn io_error(
    file: &std::path::Path,
    action: &str,
    source: std::io::Error,
) -> OutputError {
    if source.raw_os_error() == Some(libc::ENOSPC) {
        OutputError::NoSpace {
            file: file.to_path_buf(),
            action: action.to_string(),
        }
    } else {
        OutputError::Io {
            file: file.to_path_buf(),
            action: action.to_string(),
            source,
        }
    }
}

/// What an HDF5 error means for the user.
pub(crate) fn classify(file: &Path, dataset: &str, source: hdf5::Error) -> OutputError {
    let frames: Vec<String> = source
        .stack()
        .map(|s| s.iter().map(|f| f.desc().to_string()).collect())
        .unwrap_or_else(|| vec![source.to_string()]);
    let any = |needle: &str| frames.iter().any(|f| f.contains(needle));
    if any("errno = 28,") || any("No space left on device") {
        // `/ (flush)`, `/ (creating the file)`: what was done to the whole file.
        let action = match dataset
            .strip_prefix("/ (")
            .and_then(|d| d.strip_suffix(')'))
        {
            Some("flush") => "flushing the file".to_string(),
            Some(what) => what.to_string(),
            None => format!("writing {dataset}"),
        };
        OutputError::NoSpace {
            file: file.to_path_buf(),
            action,
        }
    } else if any("checksum") {
        OutputError::Damaged {
            file: file.to_path_buf(),
            dataset: dataset.to_string(),
            step: None,
            message: "its data fail their checksum: the file was changed after it was written"
                .into(),
        }
    } else {
        OutputError::Hdf5 {
            file: file.to_path_buf(),
            dataset: dataset.to_string(),
            source,
        }
    }
}
