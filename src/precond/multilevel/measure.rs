//! The first coarse operator Kc = Q^T A Q, assembled sparse from one application of the
//! (constrained, matrix-free) operator per colour and mode: the probe of colour c and mode
//! m sums mode m of every aggregate of colour c, and Q^T A probe gives, at every aggregate
//! k, column (j, m) of Kc for the one aggregate j of colour c that k sees.

use super::block_rows::BlockRows;
use super::colouring::Colouring;
use super::prolongator::MODES;
use super::transfer::Transfer;
use crate::comm::Comm;
use crate::constraints::Constraints;
use crate::math::Vec3;
use std::ops::Range;

/// Buffers of the fine level used while measuring.
pub struct Probe<'b> {
    pub v: &'b mut [Vec3],
    pub av: &'b mut [Vec3],
    pub coeff: &'b mut [f64],
}

/// Measures the rows of Kc of the aggregates `held` (this rank's share; every rank probes
/// and restricts the same, so each sees every measured value); `apply(v, av)` sets
/// av = T^T A T v on the owned nodes (v may be changed). The result is the symmetric part
/// (Kc + Kc^T) / 2, its rows numbered from the first held one, columns global. Collective.
///
/// Kc is written straight into its rows (`Blocks`): the pattern is known from the
/// colouring before the first probe, so no triplet list is sorted, and the symmetric part
/// is formed as the values arrive: an entry (k, l; j, m) is measured at aggregate k when
/// j's colour is probed in mode m, and its mirror (j, m; k, l), at aggregate j when k's
/// colour is probed in mode l; the entry is 0.5 a + 0.5 b of the two (a value never
/// measured counts 0) and is kept where either was non-zero. A rank holds only its rows
/// (13 bytes per entry), where every rank held the whole Kc.
#[allow(clippy::too_many_arguments)]
pub fn measure<C: Comm + ?Sized, E>(
    comm: &C,
    tr: &mut Transfer,
    col: &Colouring,
    cons: &Constraints,
    owned: usize,
    buf: Probe,
    held: Range<usize>,
    mut apply: impl FnMut(&mut [Vec3], &mut [Vec3]) -> Result<(), E>,
) -> Result<BlockRows, E> {
    let mut kc = Blocks::new(col, tr.num_aggregates, held);
    for c in 0..col.num_colours {
        for m in 0..MODES {
            tr.aggregates.probe(cons, &col.colour, c, m, owned, buf.v);
            apply(buf.v, buf.av)?;
            tr.aggregates.restrict(comm, buf.av, buf.coeff);
            for &(k, j) in col.pairs(c) {
                let (k, j) = (k as usize, j as usize);
                let coeff = &buf.coeff[MODES * k..MODES * (k + 1)];
                if kc.holds(k) {
                    let t = kc.slot(k, j);
                    for (l, &x) in coeff.iter().enumerate() {
                        let p = kc.at(k, l, t, m);
                        kc.arrive(p, x, MEASURED);
                    }
                }
                if kc.holds(j) {
                    let s = kc.slot(j, k);
                    for (l, &x) in coeff.iter().enumerate() {
                        let q = kc.at(j, m, s, l);
                        kc.arrive(q, x, MIRRORED);
                    }
                }
            }
        }
    }
    Ok(kc.finish())
}

/// An entry's own measured value has arrived.
const MEASURED: u8 = 1;
/// Its mirror's has.
const MIRRORED: u8 = 2;
/// Both have, and the entry is kept (either was non-zero).
const KEPT: u8 = 4;

/// The held rows of Kc in 6 x 6 blocks while it is measured: aggregate k couples to the
/// aggregates js[ptr[k - lo]..ptr[k - lo + 1]] (increasing; the pattern of the colouring
/// made symmetric), and row (k, l) holds columns (j, m) for those j in order, m = 0..5.
struct Blocks {
    /// Aggregates in all (columns: six per aggregate).
    total: usize,
    lo: usize,
    ptr: Vec<usize>,
    js: Vec<u32>,
    val: Vec<f64>,
    state: Vec<u8>,
}

impl Blocks {
    fn new(col: &Colouring, total: usize, held: Range<usize>) -> Self {
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        for k in 0..total {
            for &(_, j) in col.seen(k) {
                if held.contains(&k) {
                    pairs.push((k as u32, j));
                }
                if held.contains(&(j as usize)) {
                    pairs.push((j, k as u32));
                }
            }
        }
        pairs.sort_unstable();
        pairs.dedup();
        let mut ptr = vec![0usize; held.len() + 1];
        for &(k, _) in &pairs {
            ptr[k as usize - held.start + 1] += 1;
        }
        for k in 0..held.len() {
            ptr[k + 1] += ptr[k];
        }
        let js: Vec<u32> = pairs.into_iter().map(|(_, j)| j).collect();
        let n = MODES * MODES * js.len();
        Blocks {
            total,
            lo: held.start,
            ptr,
            js,
            val: vec![0.0; n],
            state: vec![0; n],
        }
    }

    fn holds(&self, k: usize) -> bool {
        k >= self.lo && k - self.lo < self.ptr.len() - 1
    }

    /// The place of aggregate j among those k couples to.
    fn slot(&self, k: usize, j: usize) -> usize {
        let k = k - self.lo;
        let row = &self.js[self.ptr[k]..self.ptr[k + 1]];
        row.binary_search(&(j as u32))
            .expect("the pattern holds every coupling of the colouring")
    }

    /// The entry of row (k, l) and column (js[ptr[k] + t], m): block by block, each 6 x 6
    /// row-major, as `BlockRows` holds them.
    fn at(&self, k: usize, l: usize, t: usize, m: usize) -> usize {
        let k = k - self.lo;
        MODES * MODES * (self.ptr[k] + t) + MODES * l + m
    }

    /// Value x of kind `kind` (MEASURED or MIRRORED) for entry p: the first of the two is
    /// kept until the second comes, then the entry is 0.5 a + 0.5 b (the same sum in
    /// either order). A value that came already is not taken again.
    fn arrive(&mut self, p: usize, x: f64, kind: u8) {
        let s = self.state[p];
        if s & kind != 0 {
            return;
        }
        if s == 0 {
            self.val[p] = x;
            self.state[p] = kind;
        } else {
            let y = self.val[p];
            self.val[p] = 0.5 * y + 0.5 * x;
            self.state[p] = MEASURED | MIRRORED | if x != 0.0 || y != 0.0 { KEPT } else { 0 };
        }
    }

    /// The held rows in blocks, compacted in place: an entry of which only one value came
    /// is 0.5 x + 0.5 * 0 and is kept when x is non-zero; one of which none came is left
    /// out (a zero the sparse rows do not have), and a block left with none goes. The same
    /// rows, bit for bit, as the sparse rows of these entries put into blocks
    /// (`BlockRows::of_rows`), without holding both.
    fn finish(mut self) -> BlockRows {
        let na = self.ptr.len() - 1;
        let bb = MODES * MODES;
        let mut ptr = Vec::with_capacity(na + 1);
        ptr.push(0usize);
        let mut present = vec![0u64; self.val.len().div_ceil(64)];
        let mut kept = 0usize;
        for k in 0..na {
            for b in self.ptr[k]..self.ptr[k + 1] {
                let mut block = [0.0f64; MODES * MODES];
                let mut bits = [false; MODES * MODES];
                for e in 0..bb {
                    let (s, x) = (self.state[bb * b + e], self.val[bb * b + e]);
                    let keep = match s {
                        0 => None,
                        MEASURED | MIRRORED => (x != 0.0).then_some(0.5 * x + 0.5 * 0.0),
                        _ => (s & KEPT != 0).then_some(x),
                    };
                    if let Some(v) = keep {
                        block[e] = v;
                        bits[e] = true;
                    }
                }
                if !bits.contains(&true) {
                    continue;
                }
                // kept <= b: the block moves forward over ones already read.
                self.val[bb * kept..bb * (kept + 1)].copy_from_slice(&block);
                for (e, _) in bits.iter().enumerate().filter(|(_, &p)| p) {
                    let at = bb * kept + e;
                    present[at / 64] |= 1 << (at % 64);
                }
                self.js[kept] = self.js[b];
                kept += 1;
            }
            ptr.push(kept);
        }
        drop(self.state);
        self.val.truncate(bb * kept);
        self.val.shrink_to_fit();
        self.js.truncate(kept);
        self.js.shrink_to_fit();
        present.truncate((bb * kept).div_ceil(64));
        present.shrink_to_fit();
        BlockRows::from_blocks(
            (MODES * self.lo, MODES * na),
            ptr,
            self.js,
            self.val,
            present,
            MODES * self.total,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::precond::multilevel::sparse::Csr;

    /// The rows as sparse rows, entry by entry in column order (what the measurement gave
    /// before it kept blocks): the specification `finish` must meet bit for bit.
    fn sparse_rows(b: &Blocks) -> Csr {
        let mut out = Csr::empty(MODES * b.total);
        for k in 0..b.ptr.len() - 1 {
            for l in 0..MODES {
                for t in 0..b.ptr[k + 1] - b.ptr[k] {
                    let j = b.js[b.ptr[k] + t];
                    for m in 0..MODES {
                        let p = b.at(b.lo + k, l, t, m);
                        let (s, x) = (b.state[p], b.val[p]);
                        let keep = match s {
                            0 => None,
                            MEASURED | MIRRORED => (x != 0.0).then_some(0.5 * x + 0.5 * 0.0),
                            _ => (s & KEPT != 0).then_some(x),
                        };
                        if let Some(v) = keep {
                            out.idx.push(MODES as u32 * j + m as u32);
                            out.val.push(v);
                        }
                    }
                }
                out.end_row();
            }
        }
        out
    }

    #[test]
    fn the_measured_blocks_are_the_sparse_rows_put_into_blocks_bit_for_bit() {
        // Aggregates 1..4 of 5 held; aggregate 2's block with 4 is all unmeasured or zero
        // and must go, as the sparse rows have none of it.
        let (ptr, js) = (vec![0, 3, 5, 8], vec![0, 1, 3, 2, 4, 0, 3, 4]);
        let n = MODES * MODES * js.len();
        let mut val = Vec::with_capacity(n);
        let mut state = Vec::with_capacity(n);
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            seed >> 33
        };
        for p in 0..n {
            let r = next();
            // Values that round when halved (odd mantissas, subnormal among them) and zeros.
            let x = match r % 7 {
                0 => 0.0,
                1 => f64::from_bits(1 + 2 * (r % 1000)),
                _ => (r as f64 / 3.0) * if r % 2 == 0 { 1.0 } else { -1.0 },
            };
            let s = [
                0,
                MEASURED,
                MIRRORED,
                MEASURED | MIRRORED,
                MEASURED | MIRRORED | KEPT,
            ][(next() % 5) as usize];
            let dropped = (4 * MODES * MODES..5 * MODES * MODES).contains(&p);
            val.push(if dropped && s != 0 { 0.0 } else { x });
            state.push(if dropped && s & KEPT != 0 {
                MEASURED
            } else {
                s
            });
        }
        let b = Blocks {
            total: 5,
            lo: 1,
            ptr,
            js,
            val,
            state,
        };
        let sparse = sparse_rows(&b);
        let (first, len) = (MODES, 3 * MODES);
        let expected = BlockRows::of_rows(|r| sparse.row(r - first), (30, 30), first, len).unwrap();
        let got = b.finish();
        let (e, g) = (expected.to_csr(), got.to_csr());
        assert_eq!(e.ptr, g.ptr);
        assert_eq!(e.idx, g.idx);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&e.val), bits(&g.val));
        assert_eq!(bits(&sparse.val), bits(&g.val));
        assert_eq!(expected.bytes(), got.bytes(), "the same blocks");
        assert_eq!(
            got.bytes(),
            // A column and a slot per block; these rows are not symmetric, so no block is
            // read from another.
            8 * (4 + 7 * 36 + (7 * 36usize).div_ceil(64)) + 4 * (7 + 7)
        );
        let x: Vec<f64> = (0..30).map(|i| 1.0 / (i as f64 + 3.0)).collect();
        let (mut ye, mut yg) = (vec![0.0; len], vec![0.0; len]);
        expected.mul_rows_into(&x, first, &mut ye);
        got.mul_rows_into(&x, first, &mut yg);
        assert_eq!(bits(&ye), bits(&yg));
    }
}
