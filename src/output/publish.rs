//! Publishing a closed result file: its XDMF file is written to a temporary name, the result
//! file is read back whole (every checksum, the step count), and only then are both renamed
//! to their names. An existing file under those names is replaced by the rename and by
//! nothing else; a failure before the renames publishes nothing.

use std::io::Write;
use std::path::{Path, PathBuf};

use super::error::{io_error, OutputError};
use super::layout::ResultPaths;
use super::lock::OutputLock;
use super::reader::ResultFile;
use super::xdmf::XdmfDescription;

/// Ends a run whose file could not be completed: the temporary file is kept when it still
/// reads as a result with a restart state (a restart can continue it), removed otherwise.
pub(super) fn abandon(tmp: &Path, first: String) -> OutputError {
    let readable = ResultFile::open(tmp)
        .and_then(|f| f.restart_state().map(|s| s.is_some()))
        .unwrap_or(false);
    if !readable {
        let _ = std::fs::remove_file(tmp);
    }
    OutputError::NotPublished {
        first,
        kept: readable.then(|| tmp.to_path_buf()),
    }
}

/// Writes `text` to a new temporary file beside `target` and flushes it to the disk.
fn write_temp(target: &Path, text: &str) -> Result<PathBuf, OutputError> {
    let (name, mut f) = super::paths::create_temp(target)?;
    let written = f.write_all(text.as_bytes()).and_then(|()| f.sync_all());
    if let Err(e) = written {
        drop(f);
        let _ = std::fs::remove_file(&name);
        return Err(io_error(&name, "writing the XDMF file", e));
    }
    Ok(name)
}

/// Reads the closed file back: it must open, hold every step written, and pass every
/// checksum.
fn check_written(tmp: &Path, steps: usize) -> Result<(), OutputError> {
    let f = ResultFile::open(tmp)?;
    if f.num_steps() != steps {
        return Err(OutputError::Invalid {
            file: tmp.to_path_buf(),
            dataset: super::layout::TIME.into(),
            message: format!(
                "reads back with {} steps, {steps} were written",
                f.num_steps()
            ),
        });
    }
    f.verify()?;
    drop(f);
    std::fs::File::open(tmp)
        .and_then(|f| f.sync_all())
        .map_err(|e| io_error(tmp, "flushing the file to the disk", e))
}

/// A closed temporary file, ready to be checked and published.
pub(super) struct Closed {
    pub(super) paths: ResultPaths,
    pub(super) tmp: PathBuf,
    pub(super) times: Vec<f64>,
    pub(super) nodes: usize,
    pub(super) elements: usize,
    pub(super) topology: super::xdmf::Topology,
    /// The file has a plastic strain dataset.
    pub(super) plastic: bool,
    /// The file has a contact pressure dataset.
    pub(super) pressure: bool,
    /// Held until the file is published.
    pub(super) _lock: OutputLock,
}

impl Closed {
    /// Publishes the file as `<path>` (or `<stem>.failed.h5` when `failed`), with its XDMF
    /// file; returns the published path.
    pub(super) fn publish(self, failed: bool) -> Result<PathBuf, OutputError> {
        let p = &self.paths;
        let (target, xdmf) = if failed {
            (&p.failed, &p.failed_xdmf)
        } else {
            (&p.result, &p.xdmf)
        };
        let h5_name = target
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let text = XdmfDescription {
            h5_name: &h5_name,
            nodes: self.nodes,
            elements: self.elements,
            topology: self.topology,
            times: &self.times,
            plastic: self.plastic,
            pressure: self.pressure,
        }
        .render();
        let kept = |first: OutputError| OutputError::NotPublished {
            first: first.to_string(),
            kept: Some(self.tmp.clone()),
        };
        let xtmp = write_temp(xdmf, &text).map_err(kept)?;
        let renamed = check_written(&self.tmp, self.times.len()).and_then(|()| {
            std::fs::rename(&self.tmp, target)
                .map_err(|e| io_error(&self.tmp, &format!("renaming to {}", target.display()), e))
        });
        if let Err(e) = renamed {
            let _ = std::fs::remove_file(&xtmp);
            return Err(kept(e));
        }
        std::fs::rename(&xtmp, xdmf)
            .map_err(|e| io_error(&xtmp, &format!("renaming to {}", xdmf.display()), e))?;
        // The renames reach the disk with the directory.
        if let Some(dir) = target.parent().filter(|d| !d.as_os_str().is_empty()) {
            let _ = std::fs::File::open(dir).and_then(|d| d.sync_all());
        }
        Ok(target.clone())
    }
}
