//! STREAM-like memory bandwidth: copy and triad over arrays much larger than the caches,
//! the yardstick of the element kernels' throughput.

use crate::config::Config;
use crate::stats::{time_it, Stat};
use std::hint::black_box;

pub struct Stream {
    pub kernel: &'static str,
    pub threads: usize,
    pub array_bytes: usize,
    /// Bytes counted per pass (STREAM convention: no write-allocate traffic).
    pub bytes_per_pass: usize,
    pub gbs: Stat,
}

fn copy(dst: &mut [f64], src: &[f64]) {
    for (d, s) in dst.iter_mut().zip(src) {
        *d = *s;
    }
}

fn triad(a: &mut [f64], b: &[f64], c: &[f64], s: f64) {
    for ((a, b), c) in a.iter_mut().zip(b).zip(c) {
        *a = b + s * c;
    }
}

fn triad_threads(a: &mut [f64], b: &[f64], c: &[f64], s: f64, threads: usize) {
    let chunk = a.len().div_ceil(threads);
    std::thread::scope(|scope| {
        for ((a, b), c) in a
            .chunks_mut(chunk)
            .zip(b.chunks(chunk))
            .zip(c.chunks(chunk))
        {
            scope.spawn(move || triad(a, b, c, s));
        }
    });
}

/// Copy and triad on one thread, and triad on `threads` threads when there are several.
pub fn run(cfg: &Config, threads: usize) -> Vec<Stream> {
    eprintln!(
        "bench: memory bandwidth ({:.0} MB arrays, {} repeats)",
        cfg.stream_len as f64 * 8.0 / 1e6,
        cfg.stream_repeats
    );
    let stream = memory_bandwidth(cfg, threads);
    for s in &stream {
        eprintln!(
            "bench:   {} x{}: {:.2} GB/s",
            s.kernel, s.threads, s.gbs.median
        );
    }
    stream
}

fn memory_bandwidth(cfg: &Config, threads: usize) -> Vec<Stream> {
    let n = cfg.stream_len;
    let mut a = vec![1.0f64; n];
    let mut b = vec![2.0f64; n];
    let c = vec![0.5f64; n];
    let bytes = n * 8;
    let mut out = Vec::new();
    let mut record = |kernel, threads, arrays: usize, t: Stat| {
        out.push(Stream {
            kernel,
            threads,
            array_bytes: bytes,
            bytes_per_pass: arrays * bytes,
            gbs: t.rate(arrays as f64 * bytes as f64 / 1e9),
        })
    };
    let t = time_it(cfg.stream_repeats, || {
        copy(black_box(&mut b), black_box(&a));
    })
    .wall;
    record("copy", 1, 2, t);
    let t = time_it(cfg.stream_repeats, || {
        triad(black_box(&mut a), black_box(&b), black_box(&c), 3.0);
    })
    .wall;
    record("triad", 1, 3, t);
    if threads > 1 {
        let t = time_it(cfg.stream_repeats, || {
            triad_threads(
                black_box(&mut a),
                black_box(&b),
                black_box(&c),
                3.0,
                threads,
            );
        })
        .wall;
        record("triad", threads, 3, t);
    }
    black_box((&a, &b));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The threaded triad computes what the serial one does, on lengths that do not split
    /// evenly.
    #[test]
    fn threaded_triad_is_the_triad() {
        let b: Vec<f64> = (0..11).map(f64::from).collect();
        let c: Vec<f64> = (0..11).map(|i| f64::from(i) * 0.5).collect();
        let (mut serial, mut threaded) = (vec![0.0; 11], vec![0.0; 11]);
        triad(&mut serial, &b, &c, 3.0);
        triad_threads(&mut threaded, &b, &c, 3.0, 3);
        assert_eq!(serial, threaded);
        assert_eq!(serial[4], 4.0 + 3.0 * 2.0);
    }
}
