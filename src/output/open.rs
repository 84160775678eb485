//! Opening HDF5 files so that other processes cannot hold their locks.
//!
//! HDF5 opens files without `O_CLOEXEC` and locks them with `flock`, which belongs to the
//! open file description. A process started while a result file is open (a post-processing
//! script, a test's helper) would inherit the descriptor and keep the lock after we close
//! the file, and the next open of the same file then fails with "unable to lock file".
//! [`close_on_exec`] marks the descriptor right after the open; a process forked in the
//! instant before that, or still between its fork and its exec, holds the lock for that
//! instant only, so [`create`] and [`open`] retry a refused lock for up to a second.

use std::os::raw::{c_int, c_void};

/// Sets `FD_CLOEXEC` on the descriptor of `file` when it uses the POSIX (sec2) driver, the
/// one every result file uses. Other drivers are left alone; failures are ignored, since the
/// flag only guards against a lock left in a child process.
fn close_on_exec(file: &hdf5::File) {
    let sec2 = matches!(
        file.access_plist().and_then(|p| p.get_driver()),
        Ok(hdf5::file::FileDriver::Sec2)
    );
    if !sec2 {
        return;
    }
    let mut handle: *mut c_void = std::ptr::null_mut();
    // SAFETY: `file.id()` is a valid open file id; for the sec2 driver HDF5 sets `handle` to
    // the address of the driver's `int` descriptor, valid while the file is open. The call
    // runs under the hdf5 crate's global lock like every other library call.
    let status = hdf5::sync::sync(|| unsafe {
        hdf5_sys::h5f::H5Fget_vfd_handle(file.id(), hdf5_sys::h5p::H5P_DEFAULT, &mut handle)
    });
    if status < 0 || handle.is_null() {
        return;
    }
    // SAFETY: see above; `fd` is an open descriptor owned by HDF5, and F_GETFD/F_SETFD only
    // change its flags.
    unsafe {
        let fd = *(handle as *const c_int);
        let flags = libc::fcntl(fd, libc::F_GETFD);
        if flags >= 0 {
            libc::fcntl(fd, libc::F_SETFD, flags | libc::FD_CLOEXEC);
        }
    }
}

/// How often, and how long apart, a refused lock is retried (one second in all).
const LOCK_RETRIES: u32 = 40;
const LOCK_RETRY_PAUSE: std::time::Duration = std::time::Duration::from_millis(25);

fn retry_lock(mut attempt: impl FnMut() -> hdf5::Result<hdf5::File>) -> hdf5::Result<hdf5::File> {
    let mut tries = 0;
    loop {
        match attempt() {
            Ok(file) => {
                close_on_exec(&file);
                return Ok(file);
            }
            Err(e) if tries < LOCK_RETRIES && e.to_string().contains("unable to lock file") => {
                tries += 1;
                std::thread::sleep(LOCK_RETRY_PAUSE);
            }
            Err(e) => return Err(e),
        }
    }
}

/// Creates (truncates) `path` for writing, in the HDF5 1.8 file format (both bounds, so that
/// a newer library writes it the same way): its superblock and object headers carry
/// checksums, and every HDF5 since 1.8 reads it (h5py, ParaView). Not the 1.10 format: its
/// superblock records that a writer has the file open, and a file whose writer was killed
/// could then not be opened again (to restart from it) without `h5clear`.
///
/// Without a raw-data chunk cache: each chunk is written once, whole (a step's round of a
/// field, `super::CHUNK_ROWS` entries), and goes to the file as it is written. HDF5's
/// default cache (1 MiB per open dataset) kept the last chunk of every per-step and restart
/// dataset through the run, 8 to 12 MB on the writing rank at 10^5 nodes.
pub(super) fn create(path: &std::path::Path) -> hdf5::Result<hdf5::File> {
    use hdf5::file::LibraryVersion::V18;
    retry_lock(|| {
        hdf5::File::with_options()
            .with_fapl(|p| p.libver_bounds(V18, V18).chunk_cache(0, 0, 0.75))
            .create(path)
    })
}

/// Opens `path` read-only.
pub(super) fn open(path: &std::path::Path) -> hdf5::Result<hdf5::File> {
    retry_lock(|| hdf5::File::open(path))
}
