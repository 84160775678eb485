//! Integrity of result files: every dataset is written with HDF5's Fletcher-32 checksum
//! filter (one checksum per chunk, and a per-step dataset has one step per chunk), and the
//! file's metadata uses the HDF5 1.8 format, whose superblock and object headers carry
//! checksums of their own. HDF5 checks them on every read; here its errors
//! become messages that name the dataset and the step, and [`ResultFile::verify`] reads a
//! whole file to check every checksum in it.

use std::path::Path;

use super::error::OutputError;
use super::layout;
use super::reader::ResultFile;

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

/// Whether a dataset has one row per step (`/results/...`, `/stats/...`).
pub(crate) fn is_per_step(dataset: &str) -> bool {
    dataset.starts_with("/results/") || dataset.starts_with("/stats/")
}

/// Puts the step into a [`OutputError::Damaged`] error that lacks one.
pub(crate) fn at_step<T>(r: Result<T, OutputError>, step: usize) -> Result<T, OutputError> {
    r.map_err(|e| match e {
        OutputError::Damaged {
            file,
            dataset,
            step: None,
            message,
        } => OutputError::Damaged {
            file,
            dataset,
            step: Some(step),
            message,
        },
        e => e,
    })
}

/// Reads rows `range` with `read`; when that fails a checksum in a per-step dataset, reads
/// them one at a time to name the step that does.
pub(crate) fn locate<T>(
    dataset: &str,
    range: std::ops::Range<usize>,
    read: impl Fn(std::ops::Range<usize>) -> Result<T, OutputError>,
) -> Result<T, OutputError> {
    match read(range.clone()) {
        Err(OutputError::Damaged { step: None, .. }) if is_per_step(dataset) => {
            for i in range.clone() {
                at_step(read(i..i + 1), i)?;
            }
            read(range)
        }
        r => r,
    }
}

impl ResultFile {
    /// Reads every numeric dataset of the file whole, so that HDF5 checks every checksum;
    /// returns the number of datasets read. A damaged dataset is an
    /// [`OutputError::Damaged`] naming it (and the step, for a per-step dataset).
    pub fn verify(&self) -> Result<usize, OutputError> {
        let mut count = 0;
        for name in self.dataset_names() {
            if self.numeric_kind(&name)?.is_none() {
                continue;
            }
            let shape = self.shape(&name)?;
            let rows = shape.first().copied().unwrap_or(1);
            // Per-step datasets count only their complete steps (a `.tmp` file of a run that
            // died inside a step may hold part of the next one, never checked).
            let rows = if is_per_step(&name) {
                rows.min(self.num_steps())
            } else {
                rows
            };
            let row_len: usize = shape.iter().skip(1).product::<usize>().max(1);
            let block = ((1 << 20) / row_len).max(1);
            let mut start = 0;
            while start < rows {
                let end = (start + block).min(rows);
                self.read_numeric_rows(&name, start..end)?;
                start = end;
            }
            count += 1;
        }
        Ok(count)
    }

    /// Whether the file was written with checksums (format version 2 and later).
    pub fn has_checksums(&self) -> bool {
        self.format_version() >= 2
    }

    /// The file's `format_version` attribute (0 when it has none).
    pub fn format_version(&self) -> u64 {
        let root: &hdf5::Location = self.hdf5();
        root.attr(layout::ATTR_FORMAT_VERSION)
            .and_then(|a| a.read_scalar::<u64>())
            .unwrap_or(0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn per_step_datasets_are_recognised() {
        assert!(is_per_step(layout::DISPLACEMENT));
        assert!(is_per_step(layout::STATS_RESIDUAL));
        assert!(!is_per_step(layout::COORDINATES));
        assert!(!is_per_step("/restart/slot0/displacement"));
    }
}
