//! Exact, reproducible summation of `f64` values (superaccumulator).
//!
//! Global dot products and norms in the parallel CG solver must be bitwise
//! identical whatever the number of MPI ranks and however the terms are
//! distributed among them.  Floating-point addition is not associative, so
//! instead every term is added *exactly* into a fixed-point accumulator; two
//! accumulators are combined by plain integer addition (associative and
//! commutative), and the exact total is rounded to `f64` only once, at the end
//! ([`ExactSum::to_f64`]), with round-to-nearest-even.
//!
//! # Representation
//!
//! The accumulator is an array of [`ExactSum::LIMBS`] = 69 `i64` limbs:
//!
//! * limbs `0..=66` hold the value
//!   `sum_k limb[k] * 2^(32*k - 1074)`.
//!   Bit 0 of limb 0 is the smallest subnormal, `2^-1074`; the largest finite
//!   `f64` has its top bit at position `1023 + 1074 = 2097`, i.e. in limb 65.
//!   Adding a double touches at most three consecutive limbs among `0..=65`;
//!   limb 66 only ever receives carries and holds the sign and the high part of
//!   the value (it has room for totals far beyond `f64::MAX`, which round to
//!   `±inf`).
//! * limb 67 is the *load*: an upper bound on `max_k |limb[k]| / (2^32 - 1)`
//!   over the value limbs `0..=65`.  Adding `x = ±mant * 2^(32*k + s - 1074)`
//!   (`mant < 2^53`, `0 <= s < 32`) splits the signed 84-bit integer
//!   `±mant << s` in two's-complement fashion into two unsigned 32-bit chunks
//!   (added to limbs `k`, `k+1`) and a signed chunk in `[-2^20, 2^20)` (added
//!   to limb `k+2`), so each limb changes by less than `2^32` in magnitude,
//!   and the load grows by 1.  A normalised accumulator (value limbs `0..=65`
//!   in `[0, 2^32)`, carries propagated into limb 66) has load 1.
//! * limb 68 counts the non-finite values that were added (NaN or `±inf`, or a
//!   product that overflowed); if it is non-zero, `to_f64` returns NaN.
//!
//! All three parts are *additive*: the elementwise sum of the limb arrays of
//! several accumulators represents exactly the sum of their values, the sum of
//! their loads and the sum of their non-finite counts.  This is precisely what
//! an `MPI_SUM` allreduce of [`ExactSum::limbs`] (as `MPI_INT64_T`) computes,
//! and it is exactly what [`ExactSum::merge`] does (merge may additionally
//! normalise, which does not change the value).  No limb is assumed to be
//! normalised for this to hold.
//!
//! # Headroom and limits
//!
//! A value limb stays below `load * (2^32 - 1)` in magnitude, which fits in an
//! `i64` for any load up to `2^31`.  Each accumulator produced by [`new`],
//! [`add`], [`add_product`], [`merge`], [`exact_dot`] and [`exact_sum`] keeps
//! its load at most `2^11 = 2048`: carries are propagated ("normalisation",
//! about 66 integer operations) lazily, once per ~2048 additions, which is
//! negligible.  Consequently:
//!
//! * any number of `add`s / `merge`s can be performed on one accumulator;
//! * an elementwise integer sum (MPI allreduce) of the limbs of up to
//!   **`2^20` = 1,048,576 accumulators** (ranks) is exact without any overflow,
//!   whatever values they hold.  (An accumulator obtained from `from_limbs` of
//!   an allreduce result may carry a load up to `2^31`; before contributing it
//!   to another allreduce, bring its load back to 1 by merging it into
//!   `ExactSum::new()`, which normalises whenever the load exceeds 2048.)
//! * the result of such an allreduce, passed to [`from_limbs`], can be used
//!   freely (`to_f64`, `add`, `merge` normalise as needed).
//!
//! The non-finite counter cannot overflow in practice (`2^63` additions).
//!
//! Typical use in a distributed dot product (rsmpi):
//!
//! ```ignore
//! use mpi::collective::SystemOperation;
//! let local = exact_dot(&x_owned, &y_owned);
//! let mut global = vec![0i64; ExactSum::LIMBS];
//! world.all_reduce_into(local.limbs(), &mut global[..], SystemOperation::sum());
//! let dot = ExactSum::from_limbs(&global).to_f64(); // identical on all ranks
//! ```
//!
//! # Cost
//!
//! `add` is about 25 integer instructions (bit-level decomposition of the
//! double, one 128-bit shift, three limb additions) plus one predictable
//! branch for the load check.  [`exact_dot`] and [`exact_sum`] interleave the
//! terms over 4 independent partial accumulators to avoid store-to-load
//! dependency chains on the limbs, then merge them.  `to_f64` costs about a
//! hundred nanoseconds (two carry propagations over 67 limbs).
//!
//! # Exactness of products
//!
//! [`add_product`] uses the error-free transformation `p = a*b`,
//! `e = fma(a, b, -p)` and adds `p` and `e`.  `a*b == p + e` exactly whenever
//! the exact product is a multiple of `2^-1074` — in particular whenever
//! `|a*b| >= 2^-969` (or the product is zero).  For smaller products (down to
//! `2^-2148` for products of two subnormals) the exact product cannot be
//! represented by two doubles: `e` is then the *correctly rounded* error, so
//! the added term differs from the exact product by at most `2^-1075`.  This is
//! a deterministic function of `(a, b)` only, so bitwise reproducibility is not
//! affected.  If `|a*b|` overflows (`p` infinite) the product counts as a
//! non-finite value and the total becomes NaN.
//!
//! Without the `fma` target feature enabled at compile time, `f64::mul_add`
//! is a call into libm's (correctly rounded) `fma`; with `-C target-cpu=native`
//! or `-C target-feature=+fma` it is a single instruction.  Results are the
//! same either way.
//!
//! [`new`]: ExactSum::new
//! [`add`]: ExactSum::add
//! [`add_product`]: ExactSum::add_product
//! [`merge`]: ExactSum::merge
//! [`from_limbs`]: ExactSum::from_limbs

/// Number of value limbs that receive chunks directly (`0..=65`).
const CHUNK_LIMBS: usize = 66;
/// Index of the top (carry / sign) value limb.
const TOP: usize = CHUNK_LIMBS;
/// Index of the load counter.
const LOAD: usize = TOP + 1;
/// Index of the non-finite counter.
const NONFINITE: usize = LOAD + 1;
/// Total number of limbs.
const NLIMBS: usize = NONFINITE + 1;

/// Low 32 bits.
const MASK32: i64 = 0xFFFF_FFFF;
/// Largest load an accumulator keeps after any operation other than
/// `from_limbs`.
const LOCAL_MAX_LOAD: i64 = 1 << 11;
/// Largest load for which the value limbs cannot overflow an `i64`.
const MAX_LOAD: i64 = 1 << 31;
/// Number of independent partial accumulators used by `exact_dot` and
/// `exact_sum` (interleaved terms; merged exactly at the end).
const LANES: usize = 4;
/// Products per lane between load checks in `exact_dot` (each product is two
/// additions).
const DOT_BLOCK: usize = 512;
/// Values per lane between load checks in `exact_sum`.
const SUM_BLOCK: usize = 1024;

const FRAC_MASK: u64 = (1 << 52) - 1;
const INF_BITS: u64 = 0x7FF0_0000_0000_0000;

/// Exact accumulator for sums of f64 values.
///
/// See the [module documentation](self) for the representation and limits.
/// Equality compares the exact values (and non-finite counts), not the raw
/// (possibly unnormalised) limbs.
#[derive(Clone, Debug)]
pub struct ExactSum {
    limbs: [i64; NLIMBS],
}

impl Default for ExactSum {
    fn default() -> Self {
        Self::new()
    }
}

impl PartialEq for ExactSum {
    fn eq(&self, other: &Self) -> bool {
        let (mut a, mut b) = (self.clone(), other.clone());
        a.normalise();
        b.normalise();
        a.limbs[..=TOP] == b.limbs[..=TOP] && a.limbs[NONFINITE] == b.limbs[NONFINITE]
    }
}

impl Eq for ExactSum {}

impl ExactSum {
    /// Number of `i64` limbs of the raw representation ([`limbs`](Self::limbs)).
    pub const LIMBS: usize = NLIMBS;

    /// A zero accumulator.
    #[inline]
    pub fn new() -> Self {
        ExactSum { limbs: [0; NLIMBS] }
    }

    /// Adds `x` exactly.
    ///
    /// A non-finite `x` (NaN or `±inf`) is not added to the value; it
    /// increments a sticky counter instead (no panic, also in debug builds),
    /// which makes [`to_f64`](Self::to_f64) return NaN.
    #[inline]
    pub fn add(&mut self, x: f64) {
        self.reserve_load(1);
        self.limbs[LOAD] += 1;
        self.add_value(x);
    }

    /// Adds the product `a*b` (exactly, unless it underflows below `2^-969`;
    /// see the [module documentation](self)).
    #[inline]
    pub fn add_product(&mut self, a: f64, b: f64) {
        self.reserve_load(2);
        self.limbs[LOAD] += 2;
        self.add_product_value(a, b);
    }

    /// Adds the exact value of `other` to `self`.
    ///
    /// The raw result is the elementwise sum of the two limb arrays, possibly
    /// followed by a normalisation (which does not change the value).
    pub fn merge(&mut self, other: &ExactSum) {
        let sum_load = self.limbs[LOAD] + other.limbs[LOAD];
        if sum_load <= MAX_LOAD {
            self.add_limbs(&other.limbs);
        } else {
            // Only reachable with `from_limbs` results of big allreduces.
            self.normalise();
            let mut o = other.clone();
            o.normalise();
            self.add_limbs(&o.limbs);
        }
        if self.limbs[LOAD] > LOCAL_MAX_LOAD {
            self.normalise();
        }
    }

    /// The exact sum, correctly rounded to the nearest `f64` (ties to even).
    ///
    /// Returns `+0.0` for an exact zero, `±inf` if the sum is at least
    /// `f64::MAX + ulp(f64::MAX)/2` in magnitude, and NaN if a non-finite
    /// value was added.
    pub fn to_f64(&self) -> f64 {
        if self.limbs[NONFINITE] != 0 {
            return f64::NAN;
        }
        let mut t = self.clone();
        t.normalise();
        let negative = t.limbs[TOP] < 0;
        if negative {
            for l in &mut t.limbs[..=TOP] {
                *l = -*l;
            }
            t.normalise();
        }
        let m = round_magnitude(&t.limbs[..=TOP]);
        if negative {
            -m
        } else {
            m
        }
    }

    /// Raw representation, for an elementwise-sum (`MPI_SUM` on
    /// `MPI_INT64_T`) allreduce.  Its length is [`LIMBS`](Self::LIMBS).
    #[inline]
    pub fn limbs(&self) -> &[i64] {
        &self.limbs
    }

    /// Inverse of [`limbs`](Self::limbs); also accepts the elementwise sum of
    /// the limbs of several accumulators (up to `2^20` of them).
    ///
    /// # Panics
    /// If `limbs.len() != ExactSum::LIMBS`.
    pub fn from_limbs(limbs: &[i64]) -> Self {
        assert_eq!(
            limbs.len(),
            NLIMBS,
            "ExactSum::from_limbs: expected {NLIMBS} limbs"
        );
        let mut s = ExactSum::new();
        s.limbs.copy_from_slice(limbs);
        debug_assert!(
            (0..=MAX_LOAD).contains(&s.limbs[LOAD]),
            "ExactSum::from_limbs: invalid load {}",
            s.limbs[LOAD]
        );
        s
    }

    // ----------------------------------------------------------------------
    // Internals
    // ----------------------------------------------------------------------

    /// Makes room for `n` (`<= LOCAL_MAX_LOAD - 1`) further additions
    /// (normalises if needed; the caller then adds `n` to the load).
    #[inline(always)]
    fn reserve_load(&mut self, n: i64) {
        if self.limbs[LOAD] + n > LOCAL_MAX_LOAD {
            self.normalise();
        }
    }

    /// Adds `x` to the value limbs; the caller accounts for the load (one
    /// unit per call).
    #[inline(always)]
    fn add_value(&mut self, x: f64) {
        let bits = x.to_bits();
        let biased = (bits >> 52) & 0x7FF;
        if biased == 0x7FF {
            self.add_nonfinite();
            return;
        }
        // x = mant * 2^(offset - 1074) with mant < 2^53, 0 <= offset <= 2045.
        let normal = u64::from(biased != 0);
        let mant = (bits & FRAC_MASK) | (normal << 52);
        let offset = biased - normal;
        // `& 63` is a no-op (offset >> 5 <= 63) that lets the compiler drop
        // the bounds check below.
        let k = ((offset >> 5) & 63) as usize;
        let s = offset & 31;
        // Signed mantissa (neg is 0 or -1), shifted: |v| < 2^84.  Split it in
        // two's-complement fashion into two unsigned 32-bit chunks and a
        // signed top chunk in [-2^20, 2^20): every chunk is < 2^32 in
        // magnitude.
        let neg = (bits as i64) >> 63;
        let sm = (mant as i64 ^ neg) - neg;
        let v = i128::from(sm) << s;
        let c0 = v as i64 & MASK32;
        let c1 = (v as u64 >> 32) as i64;
        let c2 = (v >> 64) as i64;
        let l = &mut self.limbs[k..k + 3];
        l[0] += c0;
        l[1] += c1;
        l[2] += c2;
    }

    /// Adds `p = a*b` and `e = fma(a, b, -p)` to the value limbs (two units of
    /// load, accounted for by the caller).
    #[inline(always)]
    fn add_product_value(&mut self, a: f64, b: f64) {
        let p = a * b;
        let e = a.mul_add(b, -p);
        self.add_value(p);
        self.add_value(e);
    }

    #[cold]
    #[inline(never)]
    fn add_nonfinite(&mut self) {
        self.limbs[NONFINITE] += 1;
    }

    /// Elementwise sum of all limbs (value, load and non-finite count).
    #[inline]
    fn add_limbs(&mut self, other: &[i64; NLIMBS]) {
        for (l, o) in self.limbs.iter_mut().zip(other) {
            *l += *o;
        }
    }

    /// Propagates carries: value limbs `0..=65` end in `[0, 2^32)`, limb 66
    /// takes the (signed) rest.  Sets the load to 1.  Requires the load to be
    /// at most `2^31` (no intermediate overflow: `|carry| <= 2^31 + 1`).
    #[inline(never)]
    fn normalise(&mut self) {
        let mut carry: i64 = 0;
        for l in &mut self.limbs[..CHUNK_LIMBS] {
            let v = (*l & MASK32) + carry;
            carry = (*l >> 32) + (v >> 32);
            *l = v & MASK32;
        }
        self.limbs[TOP] += carry;
        self.limbs[LOAD] = 1;
    }
}

/// Rounds the non-negative normalised value `limbs[..=TOP]` (units of
/// `2^-1074`) to the nearest `f64`, ties to even.
fn round_magnitude(limbs: &[i64]) -> f64 {
    debug_assert!(limbs[TOP] >= 0);
    if limbs[TOP] != 0 {
        // >= 2^(32*66 - 1074) = 2^1038.
        return f64::INFINITY;
    }
    let Some(hi) = limbs[..CHUNK_LIMBS].iter().rposition(|&l| l != 0) else {
        return 0.0;
    };
    let limb = |i: usize| limbs[i] as u128;
    // w: the top (up to) three limbs; base: index of the lowest of them;
    // sticky: whether anything non-zero lies below them.
    let (w, base, sticky) = if hi >= 2 {
        let w = (limb(hi) << 64) | (limb(hi - 1) << 32) | limb(hi - 2);
        let sticky = limbs[..hi - 2].iter().any(|&l| l != 0);
        (w, hi - 2, sticky)
    } else {
        let w = if hi == 1 {
            (limb(1) << 32) | limb(0)
        } else {
            limb(0)
        };
        (w, 0, false)
    };
    let nbits = 128 - w.leading_zeros();
    if nbits <= 53 {
        // Only possible with base == 0: the value is w * 2^-1074, exactly
        // representable; its bit pattern is w itself (subnormal or the first
        // normal binade).
        return f64::from_bits(w as u64);
    }
    let sh = nbits - 53;
    let q = (w >> sh) as u64; // 2^52 <= q < 2^53
    let rem = w & ((1u128 << sh) - 1);
    let half = 1u128 << (sh - 1);
    let round_up = rem > half || (rem == half && (sticky || q & 1 == 1));
    // q may become 2^53; this then carries into the exponent field below.
    let q = q + u64::from(round_up);
    // value = q * 2^(shift - 1074); for q in [2^52, 2^53) the biased exponent
    // is shift + 1, so the bit pattern is ((shift + 1) << 52) + (q - 2^52).
    let shift = u64::from(sh) + 32 * base as u64;
    let bits = (shift << 52) + q;
    if bits >= INF_BITS {
        f64::INFINITY
    } else {
        f64::from_bits(bits)
    }
}

/// Exact dot product `sum_i a[i]*b[i]` (see [`ExactSum::add_product`] for the
/// exactness of products below `2^-969`).
///
/// # Panics
/// If `a.len() != b.len()`.
pub fn exact_dot(a: &[f64], b: &[f64]) -> ExactSum {
    assert_eq!(a.len(), b.len(), "exact_dot: length mismatch");
    let mut lanes: [ExactSum; LANES] = std::array::from_fn(|_| ExactSum::new());
    for (ca, cb) in a.chunks(LANES * DOT_BLOCK).zip(b.chunks(LANES * DOT_BLOCK)) {
        let per_lane = 2 * ca.len().div_ceil(LANES) as i64;
        for l in &mut lanes {
            l.reserve_load(per_lane);
            l.limbs[LOAD] += per_lane;
        }
        let (qa, qb) = (ca.chunks_exact(LANES), cb.chunks_exact(LANES));
        let (ra, rb) = (qa.remainder(), qb.remainder());
        for (xa, xb) in qa.zip(qb) {
            for ((l, &x), &y) in lanes.iter_mut().zip(xa).zip(xb) {
                l.add_product_value(x, y);
            }
        }
        for ((l, &x), &y) in lanes.iter_mut().zip(ra).zip(rb) {
            l.add_product_value(x, y);
        }
    }
    combine(lanes)
}

/// Exact sum of the elements of `a`.
pub fn exact_sum(a: &[f64]) -> ExactSum {
    let mut lanes: [ExactSum; LANES] = std::array::from_fn(|_| ExactSum::new());
    for c in a.chunks(LANES * SUM_BLOCK) {
        let per_lane = c.len().div_ceil(LANES) as i64;
        for l in &mut lanes {
            l.reserve_load(per_lane);
            l.limbs[LOAD] += per_lane;
        }
        let q = c.chunks_exact(LANES);
        let r = q.remainder();
        for xs in q {
            for (l, &x) in lanes.iter_mut().zip(xs) {
                l.add_value(x);
            }
        }
        for (l, &x) in lanes.iter_mut().zip(r) {
            l.add_value(x);
        }
    }
    combine(lanes)
}

/// Merges independent partial accumulators (used to break the
/// store-to-load dependency chains on the limbs in the bulk loops).
fn combine(lanes: [ExactSum; LANES]) -> ExactSum {
    let [mut first, rest @ ..] = lanes;
    for l in &rest {
        first.merge(l);
    }
    first
}

#[cfg(test)]
mod tests {
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
}
