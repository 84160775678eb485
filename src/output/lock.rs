//! One writer per output path: an exclusive lock on `<result>.lock`, held while the run
//! writes.
//!
//! The lock is a `flock` on the lock file, so the kernel releases it when the process ends,
//! however it ends; the file itself records who holds it (process id, host, start time) so
//! that a refused run can name the first one. A lock file whose `flock` nobody holds was left
//! by a process that died (kill -9, power loss): it is stale and taken over, and the process
//! id it records is reported as no longer running. On a file system without `flock` the
//! recorded process id decides alone: a lock of a process that still runs on this host is
//! refused, any other is stale.
//!
//! A process that already holds the lock on a path (the command line claims the output before
//! the run starts, and the writer then asks again) gets a second handle that does not release
//! it.

use std::fs::File;
use std::io::{Read, Seek, SeekFrom, Write};
use std::os::unix::fs::MetadataExt;
use std::os::unix::io::AsRawFd;
use std::path::{Path, PathBuf};

/// Who holds a lock, as its lock file records it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LockHolder {
    pub pid: Option<u32>,
    pub host: String,
    pub started: String,
}

impl std::fmt::Display for LockHolder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.pid {
            Some(pid) => write!(f, "process {pid}")?,
            None => write!(f, "a process")?,
        }
        if !self.host.is_empty() {
            write!(f, " on {}", self.host)?;
        }
        if !self.started.is_empty() {
            write!(f, ", started {}", self.started)?;
        }
        Ok(())
    }
}

/// Why a lock could not be taken.
#[derive(Debug)]
pub enum LockError {
    /// Another live process holds it.
    Busy { lock: PathBuf, holder: LockHolder },
    /// The lock file could not be created, read or written.
    Io {
        lock: PathBuf,
        source: std::io::Error,
    },
}

/// A held lock; dropping it removes the lock file and releases the lock (unless it is a
/// second handle of this process, see [`OutputLock::acquire`]).
#[derive(Debug)]
pub struct OutputLock {
    path: PathBuf,
    /// `None` for a second handle of a lock this process already holds.
    file: Option<File>,
    /// The holder recorded in a stale lock file that was taken over.
    pub stale: Option<LockHolder>,
}

/// The lock file of a result path: `<result>.lock`.
pub fn lock_path(result: &Path) -> PathBuf {
    let mut s = result.as_os_str().to_owned();
    s.push(".lock");
    PathBuf::from(s)
}

fn host_name() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .map(|s| s.trim().to_string())
        .unwrap_or_default()
}

fn parse_holder(text: &str) -> LockHolder {
    let mut h = LockHolder::default();
    for line in text.lines() {
        if let Some((k, v)) = line.split_once('=') {
            match k.trim() {
                "pid" => h.pid = v.trim().parse().ok(),
                "host" => h.host = v.trim().to_string(),
                "started" => h.started = v.trim().to_string(),
                _ => {}
            }
        }
    }
    h
}

/// Whether a process of this id runs on this host (a process of another user counts).
fn process_alive(pid: u32) -> bool {
    let Ok(pid) = libc::pid_t::try_from(pid) else {
        return false;
    };
    if pid <= 0 {
        return false;
    }
    // SAFETY: signal 0 only checks that the process exists and may be signalled.
    let r = unsafe { libc::kill(pid, 0) };
    r == 0 || std::io::Error::last_os_error().raw_os_error() == Some(libc::EPERM)
}

enum Flock {
    Held,
    Busy,
    Unsupported,
}

fn try_flock(file: &File) -> std::io::Result<Flock> {
    // SAFETY: flock on a descriptor this `File` owns.
    let r = unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) };
    if r == 0 {
        return Ok(Flock::Held);
    }
    let e = std::io::Error::last_os_error();
    match e.raw_os_error() {
        Some(libc::EWOULDBLOCK) => Ok(Flock::Busy),
        Some(libc::ENOLCK) | Some(libc::EOPNOTSUPP) | Some(libc::EINVAL) => Ok(Flock::Unsupported),
        _ => Err(e),
    }
}

fn read_holder(file: &mut File) -> std::io::Result<LockHolder> {
    let mut text = String::new();
    file.seek(SeekFrom::Start(0))?;
    file.take(4096).read_to_string(&mut text)?;
    Ok(parse_holder(&text))
}

impl OutputLock {
    /// Takes the lock of `result` (the file `<result>.lock`), or says who holds it.
    pub fn acquire(result: &Path) -> Result<OutputLock, LockError> {
        let path = lock_path(result);
        let io = |source| LockError::Io {
            lock: path.clone(),
            source,
        };
        let me = std::process::id();
        // A lock file that is removed by its holder between our open and our flock is not
        // the lock any more: try again with the new file (a few times at most).
        for _ in 0..20 {
            let mut file = std::fs::OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&path)
                .map_err(io)?;
            let previous = read_holder(&mut file).map_err(io)?;
            match try_flock(&file).map_err(io)? {
                Flock::Busy if previous.pid == Some(me) && previous.host == host_name() => {
                    return Ok(OutputLock {
                        path,
                        file: None,
                        stale: None,
                    });
                }
                Flock::Busy => {
                    // The holder writes its id right after taking the lock: wait for it
                    // (a tenth of a second at most) to name it.
                    let mut holder = previous;
                    for _ in 0..50 {
                        if holder.pid.is_some() {
                            break;
                        }
                        std::thread::sleep(std::time::Duration::from_millis(2));
                        holder = read_holder(&mut file).map_err(io)?;
                    }
                    return Err(LockError::Busy { lock: path, holder });
                }
                Flock::Unsupported => {
                    let ours = previous.host.is_empty() || previous.host == host_name();
                    if let Some(pid) = previous.pid.filter(|&p| p != me) {
                        if !ours || process_alive(pid) {
                            return Err(LockError::Busy {
                                lock: path,
                                holder: previous,
                            });
                        }
                    }
                }
                Flock::Held => {}
            }
            let same = match (file.metadata(), std::fs::metadata(&path)) {
                (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
                _ => false,
            };
            if !same {
                continue;
            }
            let stale = previous.pid.is_some().then_some(previous);
            let text = format!(
                "pid = {me}\nhost = {}\nstarted = {}\n",
                host_name(),
                super::rfc3339_now()
            );
            file.set_len(0).map_err(io)?;
            file.seek(SeekFrom::Start(0)).map_err(io)?;
            file.write_all(text.as_bytes()).map_err(io)?;
            file.flush().map_err(io)?;
            return Ok(OutputLock {
                path,
                file: Some(file),
                stale,
            });
        }
        Err(io(std::io::Error::other(
            "the lock file keeps being replaced by other processes",
        )))
    }

    /// The lock file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for OutputLock {
    fn drop(&mut self) {
        if let Some(file) = self.file.take() {
            // Remove the file only while it is still ours, then release the lock by closing.
            let ours = match (file.metadata(), std::fs::metadata(&self.path)) {
                (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
                _ => false,
            };
            if ours {
                let _ = std::fs::remove_file(&self.path);
            }
            drop(file);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh directory for one test, removed when the test ends (passed or not).
    struct Dir(PathBuf);

    impl std::ops::Deref for Dir {
        type Target = Path;
        fn deref(&self) -> &Path {
            &self.0
        }
    }

    impl AsRef<Path> for Dir {
        fn as_ref(&self) -> &Path {
            &self.0
        }
    }

    impl Drop for Dir {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    fn dir(name: &str) -> Dir {
        let d = std::env::temp_dir().join(format!("solver-lock-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Dir(d)
    }

    #[test]
    fn a_stale_lock_of_a_dead_process_is_taken_over() {
        let d = dir("stale");
        let result = d.join("r.h5");
        // No process has id 0x7fff_fff0 (above Linux's pid_max of 2^22).
        std::fs::write(lock_path(&result), "pid = 2147483632\nhost = x\n").unwrap();
        let lock = OutputLock::acquire(&result).unwrap();
        assert_eq!(lock.stale.as_ref().and_then(|h| h.pid), Some(2147483632));
        let text = std::fs::read_to_string(lock_path(&result)).unwrap();
        assert!(
            text.contains(&format!("pid = {}", std::process::id())),
            "{text}"
        );
        drop(lock);
        assert!(
            !lock_path(&result).exists(),
            "the lock file goes with the lock"
        );
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn a_second_handle_of_this_process_keeps_the_lock() {
        let d = dir("again");
        let result = d.join("r.h5");
        let first = OutputLock::acquire(&result).unwrap();
        let second = OutputLock::acquire(&result).unwrap();
        drop(second);
        assert!(
            lock_path(&result).exists(),
            "the first handle still holds it"
        );
        drop(first);
        assert!(!lock_path(&result).exists());
        let _ = std::fs::remove_dir_all(&d);
    }
}
