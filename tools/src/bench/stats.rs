//! Repeated measurements: their statistics, and the clocks they are taken with.

use std::time::Instant;

/// Median, minimum and maximum of repeated measurements.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stat {
    pub median: f64,
    pub min: f64,
    pub max: f64,
    pub repeats: usize,
}

impl Stat {
    pub fn of(samples: &[f64]) -> Stat {
        let mut s = samples.to_vec();
        s.sort_by(f64::total_cmp);
        let n = s.len();
        let median = if n == 0 {
            f64::NAN
        } else if n % 2 == 1 {
            s[n / 2]
        } else {
            0.5 * (s[n / 2 - 1] + s[n / 2])
        };
        Stat {
            median,
            min: s.first().copied().unwrap_or(f64::NAN),
            max: s.last().copied().unwrap_or(f64::NAN),
            repeats: n,
        }
    }

    /// `k / t` of a time statistic (the minimum rate comes from the maximum time).
    pub fn rate(&self, k: f64) -> Stat {
        Stat {
            median: k / self.median,
            min: k / self.max,
            max: k / self.min,
            repeats: self.repeats,
        }
    }

    /// `k * t`.
    pub fn scaled(&self, k: f64) -> Stat {
        Stat {
            median: k * self.median,
            min: k * self.min,
            max: k * self.max,
            repeats: self.repeats,
        }
    }
}

/// `a / b` of two time statistics: the minimum from the fastest `a` over the slowest `b`.
pub fn ratio(a: &Stat, b: &Stat) -> Stat {
    Stat {
        median: a.median / b.median,
        min: a.min / b.max,
        max: a.max / b.min,
        repeats: a.repeats.min(b.repeats),
    }
}

/// Wall time per call, and the calling thread's CPU time over wall time.
#[derive(Clone, Copy, Debug)]
pub struct Timing {
    pub wall: Stat,
    /// Median of CPU time / wall time over the samples: about 1 when the core was ours,
    /// lower when other processes took it (the wall time is then inflated).
    pub cpu_share: f64,
}

impl Timing {
    fn of(samples: &[(f64, f64)]) -> Timing {
        let wall: Vec<f64> = samples.iter().map(|s| s.0).collect();
        let share: Vec<f64> = samples.iter().map(|s| s.1 / s.0).collect();
        Timing {
            wall: Stat::of(&wall),
            cpu_share: Stat::of(&share).median,
        }
    }
}

/// Times `f` `repeats` times after one untimed warm-up call.
pub fn time_it(repeats: usize, mut f: impl FnMut()) -> Timing {
    f();
    let samples: Vec<(f64, f64)> = (0..repeats).map(|_| measure(&mut f)).collect();
    Timing::of(&samples)
}

/// (wall seconds, thread CPU seconds) of one call.
pub fn measure(f: &mut impl FnMut()) -> (f64, f64) {
    let c = thread_cpu_time();
    let t = Instant::now();
    f();
    (t.elapsed().as_secs_f64(), thread_cpu_time() - c)
}

/// CPU time of the calling thread in seconds (`CLOCK_THREAD_CPUTIME_ID`); NaN elsewhere
/// than on Linux or when the call fails.
#[cfg(target_os = "linux")]
pub fn thread_cpu_time() -> f64 {
    use std::ffi::{c_int, c_long};
    #[repr(C)]
    struct Timespec {
        tv_sec: c_long,
        tv_nsec: c_long,
    }
    extern "C" {
        fn clock_gettime(clock: c_int, ts: *mut Timespec) -> c_int;
    }
    const CLOCK_THREAD_CPUTIME_ID: c_int = 3;
    let mut ts = Timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime only writes the timespec it is given, which lives on our stack
    // and has the C layout of `struct timespec` on 64-bit Linux (two longs).
    let rc = unsafe { clock_gettime(CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    if rc == 0 {
        ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
    } else {
        f64::NAN
    }
}

#[cfg(not(target_os = "linux"))]
pub fn thread_cpu_time() -> f64 {
    f64::NAN
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stat(median: f64, min: f64, max: f64, repeats: usize) -> Stat {
        Stat {
            median,
            min,
            max,
            repeats,
        }
    }

    #[test]
    fn statistics_of_samples() {
        assert_eq!(Stat::of(&[3.0, 1.0, 2.0]), stat(2.0, 1.0, 3.0, 3));
        assert_eq!(Stat::of(&[4.0, 1.0, 2.0, 3.0]), stat(2.5, 1.0, 4.0, 4));
        let empty = Stat::of(&[]);
        assert!(empty.median.is_nan() && empty.min.is_nan() && empty.repeats == 0);
    }

    /// A rate's minimum comes from the slowest run; a ratio's extremes pair the fastest
    /// numerator with the slowest denominator and the other way round. The samples are
    /// powers of two, so every quotient below is exact.
    #[test]
    fn rates_and_ratios_take_the_opposite_extremes() {
        let t = stat(2.0, 1.0, 4.0, 3);
        assert_eq!(t.rate(8.0), stat(4.0, 2.0, 8.0, 3));
        assert_eq!(t.scaled(0.5), stat(1.0, 0.5, 2.0, 3));
        let one = stat(8.0, 4.0, 16.0, 3);
        let two = stat(4.0, 2.0, 8.0, 2);
        // The speed-up of one rank over two: 8 / 4, fastest 4 / 8, slowest 16 / 2.
        assert_eq!(ratio(&one, &two), stat(2.0, 0.5, 8.0, 2));
    }

    #[test]
    fn timing_counts_the_repeats_after_a_warm_up() {
        let mut calls = 0;
        let t = time_it(3, || calls += 1);
        assert_eq!(calls, 4);
        assert_eq!(t.wall.repeats, 3);
        assert!(t.wall.min >= 0.0 && t.wall.min <= t.wall.max);
    }
}
