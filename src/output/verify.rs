//! Reading a whole result file back to check every checksum in it, and whether it has them.

use super::error::OutputError;
use super::integrity::is_per_step;
use super::layout;
use super::reader::ResultFile;

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
