//! The exact dot product by error-free extraction, four products at a time (AVX2).
//!
//! The superaccumulator's `add` costs about 25 integer instructions a term, two terms a
//! product (`p = a b` and `e = fma(a, b, -p)`): the dot products of a CG iteration on a
//! large mesh spent more time there than in the preconditioner's vector updates. Here a
//! block of products is first summed exactly in floating point, and only a few partial
//! sums per block reach the superaccumulator.
//!
//! # Extraction
//!
//! An accumulator `S` starts at `C = 1.5 x 2^b`, so its unit in the last place is
//! `u = 2^(b-52)`. Adding `x` with `|x| <= 2^(b-12)` gives `t = fl(S + x)`;
//! `q = t - S` is `x` rounded to a multiple of `u` and is computed exactly (both in the
//! binade `[2^b, 2^(b+1))`), and `r = x - q` (`|r| <= u / 2`) is exact too (Rump, Ogita
//! and Oishi's ExtractScalar). So `x = q + r` exactly, `S` keeps the exact sum of the
//! `q`s, and `r` goes on to the next level, whose `b` is 41 lower (`u / 2 = 2^(b-53)`,
//! the next level's `2^(b'-12)`). With at most 1024 terms per accumulator the `q`s sum to
//! at most `2^(b-2)` in magnitude: `S` stays within `[1.25, 1.75] x 2^b`, in its binade,
//! and `S - C` is exact at the block's end (Sterbenz).
//!
//! A block's products lie below `2^E` (`E` from their largest magnitude), their error
//! terms below `2^(E-53)`; three levels for each (top `b` = `E + 12` and `E - 41`) take
//! every bit of a product within `2^-70` of the block's largest. A remainder left below
//! the third level (a product smaller than that, rare) is added to the superaccumulator
//! on its own. Blocks whose largest product is non-finite, below `2^-890` or at least
//! `2^1000` (the constants would leave the normal range) take the superaccumulator term by
//! term, as the scalar dot does. Each term is added exactly either way, so the value is the
//! same exact sum as `scalar_dot`'s, bit for bit, whatever the processor.

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

/// An exact accumulator (the superaccumulator, `ExactSum`) as this file adds to it.
pub trait Exact {
    /// Adds `x` exactly.
    fn add(&mut self, x: f64);
    /// Adds `p = a b` and `e = fma(a, b, -p)` exactly.
    fn add_product(&mut self, a: f64, b: f64);
}

/// Products per vector lane in a block (the extraction's headroom: 2^10 terms of at most
/// `2^(b-12)` each).
const PER_LANE: usize = 1024;
/// Products per block (four lanes).
const BLOCK: usize = 4 * PER_LANE;
/// The top level's exponent above the block's bound `2^E`.
const HEADROOM: i32 = 12;
/// Exponent step from one level to the next.
const SPACING: i32 = 41;
/// Levels for the products and (separately) for their error terms.
const LEVELS: usize = 3;
/// The block's largest product must lie in `[2^MIN_EXP, 2^MAX_EXP)` for the fast path.
const MIN_EXP: i32 = -890;
const MAX_EXP: i32 = 1000;

/// Adds the exact `sum_i a[i] b[i]` to `total` where the processor has AVX2 and FMA and
/// says so; false (nothing added) where it has not.
pub fn add_dot(a: &[f64], b: &[f64], total: &mut impl Exact) -> bool {
    assert_eq!(a.len(), b.len(), "exact_dot: length mismatch");
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        for (ca, cb) in a.chunks(BLOCK).zip(b.chunks(BLOCK)) {
            // SAFETY: the processor has AVX2 and FMA, checked just above.
            unsafe { block(ca, cb, total) };
        }
        return true;
    }
    false
}

/// The block's bound exponent `E` (every product below `2^E`), or `None` where the fast
/// path does not apply (`largest` non-finite, too small or too large) or is not needed
/// (every product zero: nothing to add).
fn bound_exponent(largest: f64, finite: bool) -> Option<Option<i32>> {
    if !finite || largest.is_nan() {
        return None;
    }
    if largest == 0.0 {
        return Some(None);
    }
    let exp = ((largest.to_bits() >> 52) & 0x7FF) as i32 - 1023;
    if !(MIN_EXP..MAX_EXP).contains(&exp) {
        return None;
    }
    Some(Some(exp + 1))
}

/// `1.5 x 2^b` for a normal `b`.
fn anchor(b: i32) -> f64 {
    debug_assert!((-1022..=1022).contains(&b));
    f64::from_bits((((b + 1023) as u64) << 52) | (1 << 51))
}

/// The levels' starting values: products from `2^(E + HEADROOM)` down, error terms 53
/// lower.
fn anchors(e: i32) -> ([f64; LEVELS], [f64; LEVELS]) {
    let top = e + HEADROOM;
    let p = std::array::from_fn(|l| anchor(top - SPACING * l as i32));
    let q = std::array::from_fn(|l| anchor(top - 53 - SPACING * l as i32));
    (p, q)
}

/// The block term by term into the superaccumulator (the scalar dot's way).
fn slow(a: &[f64], b: &[f64], total: &mut impl Exact) {
    for (&x, &y) in a.iter().zip(b) {
        total.add_product(x, y);
    }
}

/// Adds the exact sum of a block's products (at most `BLOCK`) to `total`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn block(a: &[f64], b: &[f64], total: &mut impl Exact) {
    let n4 = a.len() / 4 * 4;
    let (largest, finite) = largest_product(&a[..n4], &b[..n4]);
    let e = match bound_exponent(largest, finite) {
        None => return slow(a, b, total),
        Some(None) => return slow(&a[n4..], &b[n4..], total),
        Some(Some(e)) => e,
    };
    let (cp, ce) = anchors(e);
    let mut sp = cp.map(|c| _mm256_set1_pd(c));
    let mut se = ce.map(|c| _mm256_set1_pd(c));
    let zero = _mm256_setzero_pd();
    for (xa, xb) in a[..n4].chunks_exact(4).zip(b[..n4].chunks_exact(4)) {
        // SAFETY: each chunk holds four f64 (unaligned loads).
        let (x, y) = unsafe { (_mm256_loadu_pd(xa.as_ptr()), _mm256_loadu_pd(xb.as_ptr())) };
        let p = _mm256_mul_pd(x, y);
        let err = _mm256_fmsub_pd(x, y, p);
        let rp = extract(&mut sp, p);
        let re = extract(&mut se, err);
        let left = _mm256_or_pd(
            _mm256_cmp_pd::<_CMP_NEQ_OQ>(rp, zero),
            _mm256_cmp_pd::<_CMP_NEQ_OQ>(re, zero),
        );
        if _mm256_movemask_pd(left) != 0 {
            add_lanes(rp, total);
            add_lanes(re, total);
        }
    }
    for (s, c) in sp.iter().zip(&cp).chain(se.iter().zip(&ce)) {
        add_lanes(_mm256_sub_pd(*s, _mm256_set1_pd(*c)), total);
    }
    slow(&a[n4..], &b[n4..], total);
}

/// The largest `|a_i b_i|` and whether every product is finite.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn largest_product(a: &[f64], b: &[f64]) -> (f64, bool) {
    let sign = _mm256_set1_pd(-0.0);
    let max = _mm256_set1_pd(f64::MAX);
    let mut m = _mm256_setzero_pd();
    let mut bad = _mm256_setzero_pd();
    for (xa, xb) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        // SAFETY: each chunk holds four f64 (unaligned loads).
        let (x, y) = unsafe { (_mm256_loadu_pd(xa.as_ptr()), _mm256_loadu_pd(xb.as_ptr())) };
        let p = _mm256_andnot_pd(sign, _mm256_mul_pd(x, y));
        m = _mm256_max_pd(m, p);
        bad = _mm256_or_pd(bad, _mm256_cmp_pd::<_CMP_NLE_UQ>(p, max));
    }
    let lanes = to_array(m);
    let largest = lanes.iter().fold(0.0f64, |acc, &v| acc.max(v));
    (largest, _mm256_movemask_pd(bad) == 0)
}

/// Extracts `x` level by level; returns what is left below the last.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn extract(s: &mut [__m256d; LEVELS], mut x: __m256d) -> __m256d {
    for level in s.iter_mut() {
        let t = _mm256_add_pd(*level, x);
        let q = _mm256_sub_pd(t, *level);
        *level = t;
        x = _mm256_sub_pd(x, q);
    }
    x
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn to_array(v: __m256d) -> [f64; 4] {
    let mut out = [0.0; 4];
    // SAFETY: `out` holds four f64 (unaligned store).
    unsafe { _mm256_storeu_pd(out.as_mut_ptr(), v) };
    out
}

/// Adds the non-zero lanes of `v` to `total`, exactly.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn add_lanes(v: __m256d, total: &mut impl Exact) {
    for x in to_array(v) {
        if x != 0.0 {
            total.add(x);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{exact_dot as dot, scalar_dot};

    /// xorshift64*: a reproducible stream of test values.
    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
        }
        /// A value of random sign and fraction with its exponent in `[lo, hi]`.
        fn value(&mut self, lo: i32, hi: i32) -> f64 {
            let e = lo + (self.next() % (hi - lo + 1) as u64) as i32;
            let bits = (self.next() & ((1 << 52) - 1)) | (((e + 1023) as u64) << 52);
            let v = f64::from_bits(bits);
            if self.next() & 1 == 0 {
                v
            } else {
                -v
            }
        }
    }

    fn same(a: &[f64], b: &[f64]) {
        let fast = dot(a, b);
        let reference = scalar_dot(a, b);
        // The exact sums compared as values (the limbs may differ in normalisation),
        // and their roundings bit for bit.
        assert_eq!(fast, reference);
        assert_eq!(fast.to_f64().to_bits(), reference.to_f64().to_bits());
    }

    /// Vectors as a CG iteration has them: a smooth field over a few decades with exact
    /// zeros (held nodes), values near round-off beside large ones (the remainder path),
    /// lengths not a multiple of four or of a block.
    #[test]
    fn the_fast_dot_is_the_scalar_dots_exact_sum() {
        let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
        for &n in &[0, 1, 3, 4, 5, 4095, 4096, 4097, 10_001, 3 * 4096 + 7] {
            for spread in [(-3, 3), (-30, 30), (-300, 300)] {
                let mut a: Vec<f64> = (0..n).map(|_| rng.value(spread.0, spread.1)).collect();
                let b: Vec<f64> = (0..n).map(|_| rng.value(spread.0, spread.1)).collect();
                same(&a, &b);
                same(&a, &a);
                for (i, v) in a.iter_mut().enumerate() {
                    if i % 7 == 0 {
                        *v = 0.0;
                    } else if i % 11 == 0 {
                        *v *= 1e-40;
                    }
                }
                same(&a, &b);
                // Cancellation: b against a's negation sums to zero exactly.
                let neg: Vec<f64> = a.iter().map(|x| -x).collect();
                let twice: Vec<f64> = a.iter().chain(&neg).copied().collect();
                let bb: Vec<f64> = b.iter().chain(&b).copied().collect();
                same(&twice, &bb);
                assert_eq!(dot(&twice, &bb).to_f64().to_bits(), 0);
            }
        }
    }

    /// Blocks outside the fast path's range, subnormal products and non-finite values.
    #[test]
    fn extreme_blocks_take_the_term_by_term_path() {
        let mut rng = Rng(12345);
        let n = 2 * 4096 + 3;
        for (lo, hi) in [(-520, -440), (490, 511), (-1022, -1000), (-600, 500)] {
            let a: Vec<f64> = (0..n).map(|_| rng.value(lo, hi)).collect();
            let b: Vec<f64> = (0..n).map(|_| rng.value(lo, hi)).collect();
            same(&a, &b);
        }
        let mut a: Vec<f64> = (0..n).map(|_| rng.value(-3, 3)).collect();
        let b: Vec<f64> = (0..n).map(|_| rng.value(-3, 3)).collect();
        a[5000] = f64::from_bits(3);
        same(&a, &b);
        for bad in [f64::NAN, f64::INFINITY, 1e300] {
            let mut c = a.clone();
            c[4100] = bad;
            let mut d = b.clone();
            d[4100] = 1e10;
            assert!(dot(&c, &d).to_f64().is_nan(), "{bad}");
        }
        // A block whose products are all zero (underflowed) adds nothing.
        let tiny = vec![1e-200; 4096];
        same(&tiny, &tiny);
    }
}
