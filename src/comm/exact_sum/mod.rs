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
//! branch for the load check.  [`exact_sum`] interleaves the terms over 4
//! independent partial accumulators to avoid store-to-load dependency chains on
//! the limbs, then merges them.  [`exact_dot`] first sums blocks of products
//! exactly in floating point by error-free extraction (`dot.rs`, AVX2), so only a
//! few partial sums per block reach the limbs.  `to_f64` costs about a
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
    #[inline(always)]
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
/// exactness of products below `2^-969`): blocks of products summed exactly in floating
/// point, four at a time where the processor has AVX2 (`dot.rs`), otherwise term by term;
/// the same exact sum either way.
///
/// # Panics
/// If `a.len() != b.len()`.
pub fn exact_dot(a: &[f64], b: &[f64]) -> ExactSum {
    let mut total = ExactSum::new();
    if dot::add_dot(a, b, &mut total) {
        return total;
    }
    scalar_dot(a, b)
}

impl dot::Exact for ExactSum {
    #[inline(always)]
    fn add(&mut self, x: f64) {
        ExactSum::add(self, x);
    }

    #[inline(always)]
    fn add_product(&mut self, a: f64, b: f64) {
        ExactSum::add_product(self, a, b);
    }
}

/// The exact dot product term by term into interleaved superaccumulators: the reference
/// `exact_dot` is checked against, and its path without AVX2.
#[inline(always)]
fn scalar_dot(a: &[f64], b: &[f64]) -> ExactSum {
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

mod dot;
#[cfg(test)]
mod tests;
