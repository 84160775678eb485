//! Integrity of result files: every dataset is written with HDF5's Fletcher-32 checksum
//! filter (one checksum per chunk, and a per-step dataset has one step per chunk), and the
//! file's metadata uses the HDF5 1.8 format, whose superblock and object headers carry
//! checksums of their own. HDF5 checks them on every read; here its errors
//! become messages that name the dataset and the step, and `ResultFile::verify` (verify.rs)
//! reads a whole file to check every checksum in it.

use super::error::OutputError;

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::layout;

    #[test]
    fn per_step_datasets_are_recognised() {
        assert!(is_per_step(layout::DISPLACEMENT));
        assert!(is_per_step(layout::STATS_RESIDUAL));
        assert!(!is_per_step(layout::COORDINATES));
        assert!(!is_per_step("/restart/slot0/displacement"));
    }
}
