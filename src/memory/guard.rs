//! The allocator of the `solver` binary: the system's, except that an allocation the
//! system refuses ends the process with a one-line error and exit code 1 instead of Rust's
//! abort (a message, a backtrace and signal 6). Allocations made through
//! [`super::reserve`] are fallible and get their null back instead, to report it as an
//! error the run handles. The result file written so far stays as its `.tmp` file, which
//! `--restart` continues.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

thread_local! {
    /// Set while `reserve` makes a fallible allocation on this thread.
    static FALLIBLE: Cell<bool> = const { Cell::new(false) };
}

/// Runs `f` with this thread's allocation failures returned rather than fatal.
pub(super) fn fallible<T>(f: impl FnOnce() -> T) -> T {
    let before = FALLIBLE.with(|c| c.replace(true));
    let out = f();
    FALLIBLE.with(|c| c.set(before));
    out
}

/// The system allocator with a clean exit when it refuses.
pub struct Guard;

/// Every allocation of 1 MiB or more gets pages of its own, given back to the system when
/// it is freed. glibc's default raises that threshold to the size of the largest block
/// freed so far (up to 32 MiB), after which the multilevel build's many temporary buffers
/// of a few MiB come from the heap and stay resident once freed: block on block n = 80
/// on 2 ranks, 161 MiB more resident at the second hierarchy build than at the first, and
/// a peak 1285 MiB per rank instead of 1230. Call once, first thing in `main`.
pub fn return_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only sets a parameter of the C allocator; called before any thread
    // or allocation of the program's own.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 1 << 20);
    }
}

/// Gives the free pages of the heap segment back to the system (glibc's `malloc_trim`).
/// Blocks below the 1 MiB threshold come from that segment, and a structure of many of
/// them freed before its replacement is built (a sparse factor's supernodes, a hierarchy's
/// rows) leaves its pages resident through the build unless given back: the full tangent
/// of a J2 L-bracket of 13910 nodes, rebuilt at every increment, peaked at 304.6, 245.5
/// and 225.3 MiB per rank on 1, 3 and 16 ranks where its live heap never exceeded 164 MiB
/// (heaptrack); given back once the old factor is dropped, 248.9, 188.3 and 166.2. Once the
/// old multilevel hierarchy is dropped, less: a Gmsh sphere on a block (17 builds) 71.0 ->
/// 69.5 MiB per rank on 2 ranks.
pub fn give_back_freed() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only hands free pages of the C allocator's heap to the system;
    // no block in use moves.
    unsafe {
        libc::malloc_trim(0);
    }
}

/// Writes the error without allocating (the allocator just failed) and exits with 1.
fn refused(size: usize) -> ! {
    let mut buf = [0u8; 200];
    let mut n = 0;
    let mut put = |bytes: &[u8]| {
        for &b in bytes {
            if n < buf.len() {
                buf[n] = b;
                n += 1;
            }
        }
    };
    put(b"error: out of memory: an allocation of ");
    let mut digits = [0u8; 20];
    let (mut v, mut k) = (size, digits.len());
    loop {
        k -= 1;
        digits[k] = b'0' + (v % 10) as u8;
        v /= 10;
        if v == 0 {
            break;
        }
    }
    put(&digits[k..]);
    put(b" bytes failed (the memory estimate was too low; run on more ranks or machines)\n");
    // SAFETY: writes `n` initialised bytes of `buf` to standard error, then ends the
    // process without running destructors or allocating.
    unsafe {
        libc::write(2, buf.as_ptr().cast(), n);
        libc::_exit(1)
    }
}

fn check(p: *mut u8, size: usize) -> *mut u8 {
    if p.is_null() && !FALLIBLE.try_with(Cell::get).unwrap_or(false) {
        refused(size);
    }
    p
}

// SAFETY: every call is forwarded to the system allocator with the same arguments; only
// what happens after it refused changes.
unsafe impl GlobalAlloc for Guard {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        check(System.alloc(layout), layout.size())
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        check(System.alloc_zeroed(layout), layout.size())
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        check(System.realloc(ptr, layout, new_size), new_size)
    }
}
