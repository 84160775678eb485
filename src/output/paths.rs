//! Where a result may be written, checked before a run starts.
//!
//! A run writes (for the result path `out/run.h5`) `out/run.h5`, `out/run.xmf`,
//! `out/run.failed.h5`, `out/run.failed.xmf`, the lock `out/run.h5.lock` and temporary files
//! `out/run.h5.tmp` / `out/run.xmf.tmp` (`out/run.h5.2.tmp`, ... when a file of that name is
//! there already). Each of those names must be a new path or a regular file; an existing one
//! must be a file of an earlier run (a result file of this solver, an XDMF file, a lock file),
//! never an input of the run (the scene, its mesh, a restart file: compared by device and
//! inode, so another name of the same file is caught too), and the parent must be a
//! directory or a path that can be created as one.

use std::os::unix::fs::{FileTypeExt, MetadataExt};
use std::path::{Path, PathBuf};

use super::error::{io_error, OutputError};
use super::layout::{self, temp_name, ResultPaths};
use super::lock::{LockError, LockHolder, OutputLock};

/// The output of a run, checked and locked: no other run can write it while this is held.
#[derive(Debug)]
pub struct OutputClaim {
    pub paths: ResultPaths,
    lock: OutputLock,
}

impl OutputClaim {
    /// The holder recorded in a stale lock file this claim took over (a run that was killed).
    pub fn stale_lock(&self) -> Option<&LockHolder> {
        self.lock.stale.as_ref()
    }
}

fn bad(file: &Path, message: impl Into<String>) -> OutputError {
    OutputError::BadOutput {
        file: file.to_path_buf(),
        message: message.into(),
    }
}

pub(super) fn kind(m: &std::fs::Metadata) -> &'static str {
    let t = m.file_type();
    if t.is_dir() {
        "a directory"
    } else if t.is_symlink() {
        "a symbolic link"
    } else if t.is_fifo() {
        "a FIFO (named pipe)"
    } else if t.is_char_device() {
        "a character device"
    } else if t.is_block_device() {
        "a block device"
    } else if t.is_socket() {
        "a socket"
    } else if t.is_file() {
        "a regular file"
    } else {
        "not a regular file"
    }
}

/// The parent must be a directory, or not exist under an existing directory.
pub(super) fn check_parent(result: &Path) -> Result<(), OutputError> {
    if result.file_name().is_none() {
        return Err(bad(result, "the path names no file"));
    }
    let parent = result.parent().unwrap_or(Path::new(""));
    for dir in parent.ancestors() {
        let dir_shown = if dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            dir
        };
        match std::fs::metadata(dir_shown) {
            Ok(m) if m.is_dir() => return Ok(()),
            Ok(m) => {
                return Err(bad(
                    result,
                    format!("{} is {}, not a directory", dir_shown.display(), kind(&m)),
                ))
            }
            // Not there, or under a file (ENOTDIR): the file is found further up.
            Err(e)
                if e.kind() == std::io::ErrorKind::NotFound
                    || e.raw_os_error() == Some(libc::ENOTDIR) =>
            {
                continue
            }
            Err(e) => return Err(bad(result, format!("{}: {e}", dir_shown.display()))),
        }
    }
    Ok(())
}

pub(super) fn same_file(a: &std::fs::Metadata, b: &std::fs::Metadata) -> bool {
    a.dev() == b.dev() && a.ino() == b.ino()
}

/// Every name the run writes is a new path or a regular file, and none is an input.
/// `inputs` are (path, what it is); the restart file may be the `.failed.h5` name, which a
/// failed run replaces by renaming a complete file onto it, never by writing into it.
fn check_names(
    paths: &ResultPaths,
    inputs: &[(&Path, &str)],
    restart: Option<&Path>,
) -> Result<(), OutputError> {
    let names = [
        (&paths.result, "result"),
        (&paths.xdmf, "XDMF"),
        (&paths.failed, "failed-run result"),
        (&paths.failed_xdmf, "failed-run XDMF"),
        (&paths.lock, "lock"),
    ];
    let input_meta: Vec<(std::fs::Metadata, &Path, &str)> = inputs
        .iter()
        .copied()
        .chain(restart.map(|r| (r, "the restart file")))
        .filter_map(|(p, what)| std::fs::metadata(p).ok().map(|m| (m, p, what)))
        .collect();
    for (name, what) in names {
        let m = match std::fs::symlink_metadata(name) {
            Ok(m) => m,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => continue,
            Err(e) => return Err(bad(name, e.to_string())),
        };
        if !m.file_type().is_file() {
            return Err(bad(
                name,
                format!(
                    "it is {}; the {what} file must be a regular file or a new path",
                    kind(&m)
                ),
            ));
        }
        for (im, ip, iwhat) in &input_meta {
            let allowed = *iwhat == "the restart file" && name == &paths.failed;
            if same_file(&m, im) && !allowed {
                return Err(bad(
                    name,
                    format!(
                        "it is {iwhat} of this run ({}); choose another output path",
                        ip.display()
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Whether `path` is a result file of this solver (one it may replace).
fn is_result_file(path: &Path) -> Result<(), String> {
    let file = super::open::open(path).map_err(|e| e.to_string())?;
    let root: &hdf5::Location = &file;
    root.attr(layout::ATTR_FORMAT_VERSION)
        .map_err(|_| format!("no {} attribute", layout::ATTR_FORMAT_VERSION))?;
    if !file.link_exists(layout::TIME) {
        return Err(format!("no {} dataset", layout::TIME));
    }
    Ok(())
}

pub(super) fn head(path: &Path) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let mut buf = Vec::new();
    std::fs::File::open(path)?
        .take(4096)
        .read_to_end(&mut buf)?;
    Ok(buf)
}

/// Existing files under the run's names must be files a run of this solver wrote.
fn check_contents(paths: &ResultPaths) -> Result<(), OutputError> {
    let remove = "remove it or choose another output path";
    for name in [&paths.result, &paths.failed] {
        if name.exists() {
            is_result_file(name).map_err(|why| {
                bad(
                    name,
                    format!("it exists and is not a result file of this solver ({why}); {remove}"),
                )
            })?;
        }
    }
    for name in [&paths.xdmf, &paths.failed_xdmf] {
        if name.exists() {
            let text = head(name).map_err(|e| bad(name, e.to_string()))?;
            if !text.windows(6).any(|w| w == b"<Xdmf ") {
                return Err(bad(
                    name,
                    format!("it exists and is not an XDMF file; {remove}"),
                ));
            }
        }
    }
    Ok(())
}

/// Checks the output names against the run's inputs and takes the lock.
pub(super) fn check_and_lock(
    result: &Path,
    inputs: &[(&Path, &str)],
    restart: Option<&Path>,
) -> Result<(ResultPaths, OutputLock), OutputError> {
    let paths = ResultPaths::new(result);
    check_parent(result)?;
    check_names(&paths, inputs, restart)?;
    if let Some(dir) = result.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| {
            match io_error(dir, "creating the directory", e) {
                OutputError::Io { source, .. } => {
                    bad(result, format!("cannot create {}: {source}", dir.display()))
                }
                other => other,
            }
        })?;
    }
    if paths.lock.exists() {
        let text = head(&paths.lock).map_err(|e| bad(&paths.lock, e.to_string()))?;
        if !text.is_empty() && !String::from_utf8_lossy(&text).contains("pid =") {
            return Err(bad(
                &paths.lock,
                "it exists and is not a lock file of this solver; remove it or choose another output path",
            ));
        }
    }
    let lock = OutputLock::acquire(result).map_err(|e| match e {
        LockError::Busy { lock, holder } => OutputError::Busy {
            file: result.to_path_buf(),
            lock,
            holder,
        },
        LockError::Io { lock, source } => io_error(&lock, "taking the lock", source),
    })?;
    check_contents(&paths)?;
    Ok((paths, lock))
}

/// Checks that `result` can take this run's result and locks it for the run: `inputs` are
/// the scene file and mesh files (path and what it is), `restart` the restart file. Errors
/// are [`OutputError::BadOutput`] and [`OutputError::Busy`] (exit code 2), or a file-system
/// error.
pub fn claim_output(
    result: &Path,
    inputs: &[(&Path, &str)],
    restart: Option<&Path>,
) -> Result<OutputClaim, OutputError> {
    let (paths, lock) = check_and_lock(result, inputs, restart)?;
    Ok(OutputClaim { paths, lock })
}

/// Creates a new, empty temporary file for `target` under the first free candidate name:
/// no file that exists (a `.tmp` a killed run left, which may be restarted from) is ever
/// opened, truncated or replaced.
pub(crate) fn create_temp(target: &Path) -> Result<(PathBuf, std::fs::File), OutputError> {
    for k in 1..=1000 {
        let name = temp_name(target, k);
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&name)
        {
            Ok(f) => return Ok((name, f)),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(io_error(&name, "creating the temporary file", e)),
        }
    }
    Err(bad(
        target,
        "1000 temporary files of earlier runs are in the way; remove them",
    ))
}

/// The temporary files earlier runs of `target` left (runs that were killed, or that stopped
/// on a full disk), sorted by name.
pub fn leftover_temps(target: &Path) -> Vec<PathBuf> {
    let Some(name) = target.file_name().map(|n| n.to_string_lossy().into_owned()) else {
        return Vec::new();
    };
    let dir = target.parent().filter(|d| !d.as_os_str().is_empty());
    let Ok(entries) = std::fs::read_dir(dir.unwrap_or(Path::new("."))) else {
        return Vec::new();
    };
    let mut found: Vec<PathBuf> = entries
        .filter_map(|e| e.ok())
        .filter_map(|e| {
            let f = e.file_name().to_string_lossy().into_owned();
            let middle = f.strip_prefix(&name)?.strip_suffix(".tmp")?;
            let ok = middle.is_empty()
                || middle
                    .strip_prefix('.')
                    .is_some_and(|k| !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()));
            ok.then(|| target.with_file_name(f))
        })
        .collect();
    found.sort();
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temporary_names_keep_the_target_name_in_front() {
        let t = Path::new("out/run.h5");
        assert_eq!(temp_name(t, 1), Path::new("out/run.h5.tmp"));
        assert_eq!(temp_name(t, 3), Path::new("out/run.h5.3.tmp"));
    }
}
