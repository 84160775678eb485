//! Tests of the exact sum: rounding against a big-integer reference, order and rank
//! independence, headroom, non-finite values.
use super::*;
use std::cmp::Ordering;

// ------------------------------------------------------------------
// Tiny PRNG (xorshift64*)
// ------------------------------------------------------------------

struct Rng(u64);

impl Rng {
    fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n
    }
    /// Random sign, random 52-bit fraction, exponent uniform in
    /// `[emin, emax]` (normal numbers, `-1022 <= emin <= emax <= 1023`).
    fn f64_exp(&mut self, emin: i32, emax: i32) -> f64 {
        let e = emin + self.below((emax - emin + 1) as u64) as i32;
        let sign = self.next_u64() & (1 << 63);
        let frac = self.next_u64() & FRAC_MASK;
        f64::from_bits(sign | (((e + 1023) as u64) << 52) | frac)
    }
    /// Random subnormal (or zero) with random sign.
    fn subnormal(&mut self) -> f64 {
        let sign = self.next_u64() & (1 << 63);
        f64::from_bits(sign | (self.next_u64() & FRAC_MASK))
    }
    fn shuffle<T>(&mut self, v: &mut [T]) {
        for i in (1..v.len()).rev() {
            let j = self.below(i as u64 + 1) as usize;
            v.swap(i, j);
        }
    }
}

// ------------------------------------------------------------------
// Slow reference: fixed-width two's-complement big integer in units of
// 2^-UNIT (covers exact products of subnormals, 2^-2148, and values up
// to ~2^1380).
// ------------------------------------------------------------------

const W: usize = 112;
const UNIT: i32 = 2200;

#[derive(Clone, PartialEq, Eq, Debug)]
struct Big([u32; W]);

impl Big {
    fn zero() -> Self {
        Big([0; W])
    }
    /// mag * 2^pos (non-negative).
    fn from_mag(mag: u128, pos: i32) -> Self {
        let mut r = Big::zero();
        let sh = pos + UNIT;
        assert!(sh >= 0);
        for i in 0..128 {
            if (mag >> i) & 1 == 1 {
                let b = sh as usize + i;
                assert!(b < 32 * W - 1, "reference bignum overflow");
                r.0[b / 32] |= 1 << (b % 32);
            }
        }
        r
    }
    fn decompose(x: f64) -> (u128, i32) {
        let bits = x.to_bits();
        let biased = ((bits >> 52) & 0x7FF) as i32;
        let frac = bits & FRAC_MASK;
        if biased == 0 {
            (frac as u128, -1074)
        } else {
            ((frac | (1 << 52)) as u128, biased - 1075)
        }
    }
    fn from_f64(x: f64) -> Self {
        assert!(x.is_finite());
        let (m, e) = Big::decompose(x);
        let r = Big::from_mag(m, e);
        if x.is_sign_negative() {
            r.neg()
        } else {
            r
        }
    }
    /// Exact product, computed with integers (independent of fma).
    fn product(a: f64, b: f64) -> Self {
        let (ma, ea) = Big::decompose(a);
        let (mb, eb) = Big::decompose(b);
        let r = Big::from_mag(ma * mb, ea + eb);
        if a.is_sign_negative() != b.is_sign_negative() {
            r.neg()
        } else {
            r
        }
    }
    fn add(&mut self, o: &Big) {
        let mut c = 0u64;
        for i in 0..W {
            let v = self.0[i] as u64 + o.0[i] as u64 + c;
            self.0[i] = v as u32;
            c = v >> 32;
        }
    }
    fn plus(&self, o: &Big) -> Big {
        let mut r = self.clone();
        r.add(o);
        r
    }
    fn neg(&self) -> Big {
        let mut r = Big::zero();
        for i in 0..W {
            r.0[i] = !self.0[i];
        }
        r.add(&Big::from_mag(1, -UNIT));
        r
    }
    fn is_neg(&self) -> bool {
        self.0[W - 1] >> 31 == 1
    }
    fn is_zero(&self) -> bool {
        self.0.iter().all(|&w| w == 0)
    }
    fn cmp(&self, o: &Big) -> Ordering {
        let d = self.plus(&o.neg());
        if d.is_zero() {
            Ordering::Equal
        } else if d.is_neg() {
            Ordering::Less
        } else {
            Ordering::Greater
        }
    }
    fn sum(xs: &[f64]) -> Big {
        let mut r = Big::zero();
        for &x in xs {
            r.add(&Big::from_f64(x));
        }
        r
    }
}

/// Exact value of an accumulator, read from its raw limbs as documented:
/// sum_k limb[k] * 2^(32k - 1074), k = 0..=66.
fn acc_to_big(acc: &ExactSum) -> Big {
    let l = acc.limbs();
    assert_eq!(l[NONFINITE], 0);
    let mut r = Big::zero();
    for (k, &v) in l[..=TOP].iter().enumerate() {
        let b = Big::from_mag(v.unsigned_abs() as u128, 32 * k as i32 - 1074);
        r.add(&if v < 0 { b.neg() } else { b });
    }
    r
}

/// Checks that `r` is the round-to-nearest-even value of the exact `x`
/// (and `+0.0` for an exact zero), by bracketing `x` between the
/// midpoints of `r` and its neighbours.
fn check_rounding(x: &Big, r: f64) {
    assert!(!r.is_nan(), "unexpected NaN");
    if x.is_zero() {
        assert_eq!(r.to_bits(), 0, "exact zero must give +0.0, got {r:e}");
        return;
    }
    let (xa, ra) = if x.is_neg() {
        (x.neg(), -r)
    } else {
        (x.clone(), r)
    };
    assert!(ra.is_sign_positive(), "wrong sign: {r:e}");
    let max_plus_half_ulp = Big::from_f64(f64::MAX).plus(&Big::from_mag(1, 970));
    if ra.is_infinite() {
        assert_ne!(xa.cmp(&max_plus_half_ulp), Ordering::Less, "spurious inf");
        return;
    }
    let bits = ra.to_bits();
    let two_x = xa.plus(&xa);
    let rb = Big::from_f64(ra);
    let next = if ra == f64::MAX {
        Big::from_mag(1, 1024)
    } else {
        Big::from_f64(f64::from_bits(bits + 1))
    };
    let odd = bits & 1 == 1;
    match two_x.cmp(&rb.plus(&next)) {
        Ordering::Greater => panic!("{ra:e} rounded down too far"),
        Ordering::Equal if odd => panic!("{ra:e}: tie not rounded to even"),
        _ => {}
    }
    if bits > 0 {
        let prev = Big::from_f64(f64::from_bits(bits - 1));
        match two_x.cmp(&rb.plus(&prev)) {
            Ordering::Less => panic!("{ra:e} rounded up too far"),
            Ordering::Equal if odd => panic!("{ra:e}: tie not rounded to even"),
            _ => {}
        }
    }
}

fn sum_of(xs: &[f64]) -> ExactSum {
    let mut s = ExactSum::new();
    for &x in xs {
        s.add(x);
    }
    s
}

/// Elementwise (MPI_SUM-like) combination of raw limbs, with overflow
/// checks.
fn allreduce(parts: &[ExactSum]) -> ExactSum {
    let mut l = vec![0i64; ExactSum::LIMBS];
    for p in parts {
        for (a, b) in l.iter_mut().zip(p.limbs()) {
            *a = a.checked_add(*b).expect("limb overflow in allreduce");
        }
    }
    ExactSum::from_limbs(&l)
}

fn wide_values(rng: &mut Rng, n: usize, emin: i32, emax: i32) -> Vec<f64> {
    (0..n).map(|_| rng.f64_exp(emin, emax)).collect()
}

// ------------------------------------------------------------------
// Tests
// ------------------------------------------------------------------

#[test]
fn simple_cases() {
    assert_eq!(sum_of(&[1e16, 1.0, -1e16]).to_f64(), 1.0);
    assert_eq!(sum_of(&[1e100, 1.0, -1e100, 1e-100]).to_f64(), 1.0 + 1e-100);
    assert_eq!(sum_of(&[0.1, 0.2]).to_f64(), 0.1 + 0.2);
    check_rounding(&Big::sum(&[0.1, 0.2]), sum_of(&[0.1, 0.2]).to_f64());
    // Naive left-to-right summation gives 0.6000000000000001; the exact
    // sum 0.60000000000000000555... rounds to 0.6.
    assert_eq!(sum_of(&[0.1, 0.2, 0.3]).to_f64(), 0.6);
    check_rounding(
        &Big::sum(&[0.1, 0.2, 0.3]),
        sum_of(&[0.1, 0.2, 0.3]).to_f64(),
    );
    assert_eq!(ExactSum::new().to_f64().to_bits(), 0);
    assert_eq!(sum_of(&[-3.5]).to_f64(), -3.5);
    assert_eq!(sum_of(&[f64::MAX]).to_f64(), f64::MAX);
    assert_eq!(sum_of(&[-f64::MIN_POSITIVE]).to_f64(), -f64::MIN_POSITIVE);
    // The sum of two doubles, correctly rounded, is what IEEE addition
    // gives: compare on random pairs over the whole range.
    let mut rng = Rng::new(1);
    for i in 0..200_000 {
        let (a, b) = match i % 4 {
            0 => (rng.f64_exp(-1022, 1022), rng.f64_exp(-1022, 1022)),
            1 => {
                let a = rng.f64_exp(-60, 60);
                (a, -a * (1.0 + rng.f64_exp(-60, -1).abs()))
            }
            2 => (rng.subnormal(), rng.f64_exp(-1022, -1000)),
            _ => (rng.f64_exp(-1022, 1023), rng.f64_exp(-1022, 1023)),
        };
        let s = sum_of(&[a, b]).to_f64();
        let expect = a + b;
        if expect == 0.0 {
            assert_eq!(s.to_bits(), 0);
        } else {
            assert_eq!(s.to_bits(), expect.to_bits(), "{a:e} + {b:e}");
        }
    }
}

#[test]
fn ties_and_sticky_bits() {
    let u = f64::EPSILON; // 2^-52
    let tiny = f64::from_bits(1); // 2^-1074
    let p500 = 2f64.powi(500);
    let cases: Vec<(Vec<f64>, f64)> = vec![
        (vec![1.0, u / 2.0], 1.0),
        (vec![1.0 + u, u / 2.0], 1.0 + 2.0 * u),
        (vec![1.0, u / 2.0, tiny], 1.0 + u),
        (vec![1.0 + u, u / 2.0, -tiny], 1.0 + u),
        (vec![-1.0, -u / 2.0, -tiny], -(1.0 + u)),
        (vec![p500, 2f64.powi(447)], p500),
        (vec![p500, 2f64.powi(447), tiny], p500 * (1.0 + u)),
        (vec![p500, 2f64.powi(447), -tiny], p500),
        (vec![p500, -2f64.powi(446), tiny], p500),
    ];
    for (xs, expect) in cases {
        let r = sum_of(&xs).to_f64();
        assert_eq!(r.to_bits(), expect.to_bits(), "{xs:?}");
        check_rounding(&Big::sum(&xs), r);
    }
}

#[test]
fn order_and_rank_independence() {
    let mut rng = Rng::new(42);
    let xs = wide_values(&mut rng, 100_000, -300, 300);
    let reference = Big::sum(&xs);

    let forward = sum_of(&xs);
    let mut rev = xs.clone();
    rev.reverse();
    let backward = exact_sum(&rev);
    let mut shuffled = xs.clone();
    rng.shuffle(&mut shuffled);
    let mixed = sum_of(&shuffled);

    // The exact value, read from the raw limbs, is the exact sum.
    assert_eq!(acc_to_big(&forward), reference);
    let r = forward.to_f64();
    check_rounding(&reference, r);
    for s in [&backward, &mixed] {
        assert_eq!(s.to_f64().to_bits(), r.to_bits());
        assert_eq!(*s, forward);
        assert_eq!(acc_to_big(s), reference);
    }

    for (order, v) in [&xs, &rev, &shuffled].into_iter().enumerate() {
        for nranks in [1usize, 2, 3, 7] {
            // Uneven random split into `nranks` contiguous pieces.
            let mut cuts: Vec<usize> = (1..nranks)
                .map(|_| rng.below(v.len() as u64) as usize)
                .collect();
            cuts.push(0);
            cuts.push(v.len());
            cuts.sort_unstable();
            let parts: Vec<ExactSum> = cuts
                .windows(2)
                .enumerate()
                .map(|(i, w)| {
                    let piece = &v[w[0]..w[1]];
                    // Mix the entry points.
                    if (i + order) % 2 == 0 {
                        sum_of(piece)
                    } else {
                        exact_sum(piece)
                    }
                })
                .collect();
            let reduced = allreduce(&parts);
            assert_eq!(reduced.to_f64().to_bits(), r.to_bits());
            assert_eq!(reduced, forward);
            let mut merged = ExactSum::new();
            for p in parts.iter().rev() {
                merged.merge(p);
            }
            assert_eq!(merged.to_f64().to_bits(), r.to_bits());
            assert_eq!(merged, reduced);
            assert_eq!(acc_to_big(&merged), reference);
            // Round-robin distribution as well.
            let mut rr = vec![ExactSum::new(); nranks];
            for (i, &x) in v.iter().enumerate() {
                rr[i % nranks].add(x);
            }
            assert_eq!(allreduce(&rr).to_f64().to_bits(), r.to_bits());
        }
    }
}

#[test]
fn merge_equals_elementwise_sum_of_unnormalised_limbs() {
    let mut rng = Rng::new(7);
    for trial in 0..50 {
        let n1 = rng.below(3000) as usize;
        let n2 = rng.below(3000) as usize;
        let a = sum_of(&wide_values(&mut rng, n1, -1022, 1023));
        let b = exact_sum(&wide_values(&mut rng, n2, -200, 200));
        let mut m = a.clone();
        m.merge(&b);
        let e = allreduce(&[a.clone(), b.clone()]);
        assert_eq!(m, e, "trial {trial}");
        assert_eq!(m.to_f64().to_bits(), e.to_f64().to_bits());
        assert_eq!(acc_to_big(&m), acc_to_big(&a).plus(&acc_to_big(&b)));
        // Raw limbs agree exactly unless merge had to normalise.
        if a.limbs()[LOAD] + b.limbs()[LOAD] <= LOCAL_MAX_LOAD {
            assert_eq!(m.limbs(), e.limbs());
        }
    }
}

#[test]
fn correct_rounding_random_sets() {
    let mut rng = Rng::new(2024);
    for trial in 0..400 {
        let n = 1 + rng.below(400) as usize;
        let mut xs: Vec<f64> = match trial % 5 {
            0 => wide_values(&mut rng, n, -1022, 1023),
            1 => wide_values(&mut rng, n, -30, 30),
            2 => (0..n)
                .map(|_| {
                    if rng.below(2) == 0 {
                        rng.subnormal()
                    } else {
                        rng.f64_exp(-1022, -1010)
                    }
                })
                .collect(),
            3 => wide_values(&mut rng, n, 900, 1023),
            _ => wide_values(&mut rng, n, -600, 600),
        };
        // Massive cancellation: append the negations of a random subset
        // plus a few small perturbations.
        if trial % 2 == 1 {
            let neg: Vec<f64> = xs
                .iter()
                .filter(|_| rng.below(8) != 0)
                .map(|x| -x)
                .collect();
            xs.extend(neg);
            for _ in 0..rng.below(4) {
                let e = -1022 + rng.below(1000) as i32;
                xs.push(rng.f64_exp(e, e));
            }
            rng.shuffle(&mut xs);
        }
        let reference = Big::sum(&xs);
        let s = exact_sum(&xs);
        assert_eq!(acc_to_big(&s), reference, "trial {trial}");
        check_rounding(&reference, s.to_f64());
        let mut rev = xs.clone();
        rev.reverse();
        assert_eq!(sum_of(&rev).to_f64().to_bits(), s.to_f64().to_bits());
    }
}

#[test]
fn products_and_dot() {
    let mut rng = Rng::new(99);
    // Single products in the exact range: the result is the correctly
    // rounded product, i.e. a*b.
    for _ in 0..100_000 {
        let a = rng.f64_exp(-480, 500);
        let b = rng.f64_exp(-480, 500);
        let mut s = ExactSum::new();
        s.add_product(a, b);
        assert_eq!(acc_to_big(&s), Big::product(a, b));
        assert_eq!(s.to_f64().to_bits(), (a * b).to_bits(), "{a:e}*{b:e}");
    }
    // Dot products against the integer reference.
    for trial in 0..40 {
        let n = 1 + rng.below(5000) as usize;
        let (lo, hi) = if trial % 2 == 0 {
            (-480, 500)
        } else {
            (-20, 20)
        };
        let a = wide_values(&mut rng, n, lo, hi);
        let mut b = wide_values(&mut rng, n, lo, hi);
        if trial % 4 == 1 {
            // Orthogonal-ish: force heavy cancellation.
            for i in (0..n - 1).step_by(2) {
                b[i + 1] = -a[i] * b[i] / a[i + 1];
            }
        }
        let mut reference = Big::zero();
        for (&x, &y) in a.iter().zip(&b) {
            reference.add(&Big::product(x, y));
        }
        let d = exact_dot(&a, &b);
        assert_eq!(acc_to_big(&d), reference, "trial {trial}");
        check_rounding(&reference, d.to_f64());
        let mut s = ExactSum::new();
        for (&x, &y) in a.iter().zip(&b).rev() {
            s.add_product(x, y);
        }
        assert_eq!(s, d);
        assert_eq!(exact_dot(&b, &a), d);
    }
}

#[test]
fn underflowing_products_within_documented_bound() {
    let mut rng = Rng::new(5);
    let bound = Big::from_mag(1, -1075);
    for i in 0..20_000 {
        let (a, b) = match i % 3 {
            0 => (rng.f64_exp(-700, -300), rng.f64_exp(-700, -300)),
            1 => (rng.subnormal(), rng.f64_exp(-60, 60)),
            _ => (rng.subnormal(), rng.subnormal()),
        };
        let mut s = ExactSum::new();
        s.add_product(a, b);
        let diff = acc_to_big(&s).plus(&Big::product(a, b).neg());
        let diff = if diff.is_neg() { diff.neg() } else { diff };
        assert_ne!(diff.cmp(&bound), Ordering::Greater, "{a:e}*{b:e}");
        // Exact whenever |a*b| >= 2^-969.
        if (a * b).abs() >= 2f64.powi(-969) {
            assert!(diff.is_zero());
        }
    }
}

#[test]
fn zero_subnormal_overflow_nan() {
    let mut rng = Rng::new(3);
    // Cancellation to zero gives +0.0.
    let mut xs = wide_values(&mut rng, 5000, -1022, 1023);
    xs.extend(xs.clone().iter().map(|x| -x));
    rng.shuffle(&mut xs);
    let z = exact_sum(&xs).to_f64();
    assert_eq!(z.to_bits(), 0);
    assert_eq!(sum_of(&[-0.0]).to_f64().to_bits(), 0);
    assert_eq!(sum_of(&[-1.5, 1.5]).to_f64().to_bits(), 0);
    let mut p = ExactSum::new();
    p.add_product(-3.0, 0.0);
    assert_eq!(p.to_f64().to_bits(), 0);

    // Subnormal totals.
    let tiny = f64::from_bits(1);
    let mn = f64::MIN_POSITIVE;
    assert_eq!(sum_of(&[mn + 5.0 * tiny, -mn]).to_f64(), f64::from_bits(5));
    assert_eq!(sum_of(&[-mn, mn - tiny]).to_f64(), -tiny);
    assert_eq!(sum_of(&[1e-300, 1.0, -1e-300, -1.0, tiny]).to_f64(), tiny);
    let big_sub = f64::from_bits((1 << 52) - 1);
    assert_eq!(sum_of(&[big_sub, tiny]).to_f64(), mn);
    assert_eq!(sum_of(&[1.0, -mn, big_sub, -1.0]).to_f64(), -tiny);

    // Overflow.
    let max = f64::MAX;
    let half_ulp = 2f64.powi(970);
    assert_eq!(sum_of(&[max, max]).to_f64(), f64::INFINITY);
    assert_eq!(sum_of(&[-max, -max]).to_f64(), f64::NEG_INFINITY);
    assert_eq!(sum_of(&[max, max, -max]).to_f64(), max);
    assert_eq!(sum_of(&[max, half_ulp]).to_f64(), f64::INFINITY);
    assert_eq!(sum_of(&[max, half_ulp, -tiny]).to_f64(), max);
    assert_eq!(sum_of(&[max, half_ulp / 2.0]).to_f64(), max);
    assert_eq!(sum_of(&[-max, -half_ulp]).to_f64(), f64::NEG_INFINITY);
    let mut huge = ExactSum::new();
    for _ in 0..1_000_000 {
        huge.add(max);
    }
    assert_eq!(huge.to_f64(), f64::INFINITY);
    for _ in 0..1_000_000 {
        huge.add(-max);
    }
    assert_eq!(huge.to_f64().to_bits(), 0);
    huge.add(-1.0);
    assert_eq!(huge.to_f64(), -1.0);
    for _ in 0..3_000_000 {
        huge.add(-max);
    }
    assert_eq!(huge.to_f64(), f64::NEG_INFINITY);

    // Non-finite inputs.
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let mut s = sum_of(&[1.0, 2.0]);
        s.add(bad);
        s.add(3.0);
        assert!(s.to_f64().is_nan());
        let r = ExactSum::from_limbs(s.limbs());
        assert!(r.to_f64().is_nan());
        let mut m = sum_of(&[1.0]);
        m.merge(&s);
        assert!(m.to_f64().is_nan());
        assert!(allreduce(&[sum_of(&[1.0]), s]).to_f64().is_nan());
        assert!(exact_sum(&[0.5, bad]).to_f64().is_nan());
        assert!(exact_dot(&[1.0, bad], &[1.0, 1.0]).to_f64().is_nan());
    }
    // A product that overflows counts as non-finite.
    let mut s = ExactSum::new();
    s.add_product(1e200, 1e200);
    assert!(s.to_f64().is_nan());
}

#[test]
fn limbs_round_trip() {
    let mut rng = Rng::new(11);
    for n in [0usize, 1, 7, 2047, 2048, 2049, 10_000] {
        let s = sum_of(&wide_values(&mut rng, n, -1022, 1023));
        assert_eq!(s.limbs().len(), ExactSum::LIMBS);
        let r = ExactSum::from_limbs(s.limbs());
        assert_eq!(r.limbs(), s.limbs());
        assert_eq!(r, s);
        assert_eq!(r.to_f64().to_bits(), s.to_f64().to_bits());
        assert!(s.limbs()[LOAD] <= LOCAL_MAX_LOAD);
    }
}

/// Worst case for the headroom: every addition puts a full 2^32 - 1 chunk
/// into the same limb, and the accumulator is at the maximum local load.
/// An allreduce over 2^20 such ranks still fits; over 2^21 it would not.
#[test]
fn headroom_worst_case() {
    for sign in [1.0, -1.0] {
        // mant = 2^53 - 1 with its lsb at a limb boundary (s = 0).
        let x = sign * ((1u64 << 53) - 1) as f64 * 2f64.powi(32 * 33 - 1074);
        let mut s = ExactSum::new();
        for _ in 0..LOCAL_MAX_LOAD {
            s.add(x);
        }
        assert_eq!(s.limbs()[LOAD], LOCAL_MAX_LOAD);
        // Documented invariant |limb| <= load * (2^32 - 1), and it is
        // (nearly) attained.
        let bound = LOCAL_MAX_LOAD * MASK32;
        assert!(s.limbs()[..=TOP].iter().all(|v| v.abs() <= bound));
        let biggest = s.limbs()[..=TOP].iter().map(|v| v.abs()).max().unwrap();
        assert!(biggest >= LOCAL_MAX_LOAD * 0xFFE0_0000);
        if sign > 0.0 {
            assert_eq!(s.limbs()[33], bound);
        }
        let single = s.to_f64();
        assert_eq!(single, x * LOCAL_MAX_LOAD as f64);

        // Allreduce of 2^20 identical ranks == multiplication by 2^20.
        let ranks: i64 = 1 << 20;
        let l: Vec<i64> = s
            .limbs()
            .iter()
            .map(|&v| v.checked_mul(ranks).expect("overflow"))
            .collect();
        assert!(s.limbs().iter().any(|v| v.checked_mul(2 * ranks).is_none()));
        let r = ExactSum::from_limbs(&l);
        assert_eq!(r.limbs()[LOAD], MAX_LOAD);
        assert_eq!(r.to_f64(), single * ranks as f64);

        // Further use of such an allreduce result.
        let mut r2 = r.clone();
        r2.merge(&r); // load 2^32 > MAX_LOAD: normalises first
        assert_eq!(r2.to_f64(), single * (2 * ranks) as f64);
        let mut r3 = r.clone();
        r3.add(-x);
        assert_eq!(acc_to_big(&r3), acc_to_big(&r).plus(&Big::from_f64(-x)));
        let mut fresh = ExactSum::new();
        fresh.merge(&r);
        assert_eq!(fresh.limbs()[LOAD], 1);
        assert_eq!(fresh, r);

        // Repeated self-merging (doubling) stays exact.
        let mut d = s.clone();
        for i in 1..=40 {
            let c = d.clone();
            d.merge(&c);
            assert!(d.limbs()[LOAD] <= LOCAL_MAX_LOAD);
            assert_eq!(d.to_f64(), single * 2f64.powi(i));
        }
    }
}
