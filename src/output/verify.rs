//! Reading a whole result file back to check every checksum in it, and whether it has them.

use std::ops::Range;

use hdf5::H5Type;

use super::datasets::CHUNK_ROWS;
use super::error::{Hdf5Context, OutputError};
use super::integrity::{at_step, is_per_step};
use super::layout;
use super::reader::{NumericKind, ResultFile};

/// Values read at once: a round of a per-node field (`CHUNK_ROWS` entries of up to 6
/// values), so that the check holds a round and not a step of a large mesh.
const PIECE: usize = 6 * CHUNK_ROWS;

impl ResultFile {
    /// Reads every numeric dataset of the file, a piece of at most `PIECE` values at a time
    /// (a row of a per-step dataset in ranges of its entries), so that HDF5 checks every
    /// checksum; returns the number of datasets read. A damaged dataset is an
    /// [`OutputError::Damaged`] naming it (and the step, for a per-step dataset).
    pub fn verify(&self) -> Result<usize, OutputError> {
        let mut count = 0;
        for name in self.dataset_names() {
            let Some(kind) = self.numeric_kind(&name)? else {
                continue;
            };
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
            if shape.len() >= 2 && row_len > PIECE {
                let entry = shape.iter().skip(2).product::<usize>().max(1);
                let ds = self.dataset(&name)?;
                for row in 0..rows {
                    let read = |a: usize, b: usize| match kind {
                        NumericKind::Float => part::<f64>(&ds, row, a..b),
                        NumericKind::Unsigned => part::<u64>(&ds, row, a..b),
                        NumericKind::Signed => part::<i64>(&ds, row, a..b),
                    };
                    for a in (0..shape[1]).step_by((PIECE / entry).max(1)) {
                        let b = (a + (PIECE / entry).max(1)).min(shape[1]);
                        let r = read(a, b).at(self.path(), &name);
                        if is_per_step(&name) {
                            at_step(r, row)?;
                        } else {
                            r?;
                        }
                    }
                }
            } else {
                let block = (PIECE / row_len).max(1);
                let mut start = 0;
                while start < rows {
                    let end = (start + block).min(rows);
                    self.read_numeric_rows(&name, start..end)?;
                    start = end;
                }
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

/// Reads entries `entries` of row `row` of a dataset of two or three dimensions.
fn part<T: H5Type>(ds: &hdf5::Dataset, row: usize, entries: Range<usize>) -> hdf5::Result<()> {
    if ds.ndim() == 2 {
        ds.read_slice_1d::<T, _>((row, entries)).map(drop)
    } else {
        ds.read_slice_2d::<T, _>((row, entries, ..)).map(drop)
    }
}
