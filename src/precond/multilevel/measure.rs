//! The first coarse operator Kc = Q^T A Q, assembled sparse from one application of the
//! (constrained, matrix-free) operator per colour and mode: the probe of colour c and mode
//! m sums mode m of every aggregate of colour c, and Q^T A probe gives, at every aggregate
//! k, column (j, m) of Kc for the one aggregate j of colour c that k sees.

use super::block_rows::{BlockRows, MIRROR};
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
/// (an f64 and a state byte per entry stored), where every rank held the whole Kc, and of
/// a block below the diagonal whose transpose is in its rows, none: the two entries of a
/// pair receive the same two values (each value goes to both), so they are the same bits,
/// and the block is read from its transpose (`BlockRows`' mirrored blocks) from the start.
#[allow(clippy::too_many_arguments)]
pub fn measure<C: Comm + ?Sized, E>(
    comm: &C,
    tr: &mut Transfer,
    col: &Colouring,
    cons: &Constraints,
    (owned, x): (usize, &[Vec3]),
    buf: Probe,
    held: Range<usize>,
    mut apply: impl FnMut(&mut [Vec3], &mut [Vec3]) -> Result<(), E>,
) -> Result<BlockRows, E> {
    let mut kc = Blocks::new(col, tr.num_aggregates, held);
    let mut slots = Vec::new();
    for c in 0..col.num_colours {
        // The places of the colour's pairs, found once for its six probes.
        slots.clear();
        slots.extend(
            col.pairs(c)
                .iter()
                .map(|&(k, j)| kc.slots(k as usize, j as usize)),
        );
        for m in 0..MODES {
            tr.aggregates
                .probe(cons, &col.colour, c, m, (owned, x), buf.v);
            apply(buf.v, buf.av)?;
            tr.aggregates.restrict(comm, x, buf.av, buf.coeff);
            for (&(k, j), &places) in col.pairs(c).iter().zip(&slots) {
                let (k, j) = (k as usize, j as usize);
                kc.take((k, j), places, m, &buf.coeff[MODES * k..MODES * (k + 1)]);
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
    /// Where each block's values are, in blocks of `val`; with `MIRROR` set, a block below
    /// the diagonal whose transpose is held, and that block's place.
    place: Vec<u32>,
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
        Blocks::of_pairs(pairs, total, held)
    }

    /// The blocks of the couplings `pairs` (row aggregate, column aggregate; the rows
    /// `held`, the pattern symmetric where both are held), every value yet to come.
    fn of_pairs(mut pairs: Vec<(u32, u32)>, total: usize, held: Range<usize>) -> Self {
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
        let mut place = vec![0u32; js.len()];
        let mut stored = 0u32;
        for k in held.clone() {
            for b in ptr[k - held.start]..ptr[k - held.start + 1] {
                let j = js[b] as usize;
                place[b] = if j < k && held.contains(&j) {
                    let row = &js[ptr[j - held.start]..ptr[j - held.start + 1]];
                    let t = row
                        .binary_search(&(k as u32))
                        .expect("the pattern of held rows is symmetric");
                    place[ptr[j - held.start] + t] | MIRROR
                } else {
                    stored += 1;
                    stored - 1
                };
            }
        }
        assert!(stored < MIRROR, "Kc: blocks to number");
        let n = MODES * MODES * stored as usize;
        Blocks {
            total,
            lo: held.start,
            ptr,
            js,
            place,
            val: vec![0.0; n],
            state: vec![0; n],
        }
    }

    /// The coefficients `coeff` (six) at aggregate k of the probe of j's colour in mode m:
    /// column (j, m) of row k and, as its mirror, row (j, m) at column k, where held and
    /// stored (not read from a transpose, which takes the same values).
    /// `places` are `slots(k, j)`.
    fn take(&mut self, (k, j): (usize, usize), places: [usize; 2], m: usize, coeff: &[f64]) {
        let [t, s] = places;
        if t != usize::MAX {
            for (l, &x) in coeff.iter().enumerate() {
                if let Some(p) = self.at(k, l, t, m) {
                    self.arrive(p, x, MEASURED);
                }
            }
        }
        if s != usize::MAX {
            for (l, &x) in coeff.iter().enumerate() {
                if let Some(q) = self.at(j, m, s, l) {
                    self.arrive(q, x, MIRRORED);
                }
            }
        }
    }

    /// The place of j among the couplings of row k and of k among those of row j, each
    /// where the row is held (usize::MAX where it is not).
    fn slots(&self, k: usize, j: usize) -> [usize; 2] {
        [
            if self.holds(k) {
                self.slot(k, j)
            } else {
                usize::MAX
            },
            if self.holds(j) {
                self.slot(j, k)
            } else {
                usize::MAX
            },
        ]
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
    /// row-major, as `BlockRows` holds them; None in a block read from its transpose.
    fn at(&self, k: usize, l: usize, t: usize, m: usize) -> Option<usize> {
        let place = self.place[self.ptr[k - self.lo] + t];
        (place & MIRROR == 0).then(|| MODES * MODES * place as usize + MODES * l + m)
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
    /// out (a zero the sparse rows do not have), and a block left with none goes (a block
    /// read from its transpose goes with it: their entries came alike). The same rows, bit
    /// for bit, as the sparse rows of these entries put into blocks (`BlockRows::of_rows`,
    /// whose mirrored blocks are these), without holding both.
    fn finish(mut self) -> BlockRows {
        const NONE: u32 = u32::MAX;
        let na = self.ptr.len() - 1;
        let bb = MODES * MODES;
        let mut ptr = Vec::with_capacity(na + 1);
        ptr.push(0usize);
        let mut present = vec![0u64; self.val.len().div_ceil(64)];
        // The place of every stored block among those kept (NONE: it went).
        let mut kept_place = vec![NONE; self.val.len() / bb];
        let mut slot = Vec::with_capacity(self.js.len());
        let (mut kept, mut stored) = (0usize, 0u32);
        for k in 0..na {
            for b in self.ptr[k]..self.ptr[k + 1] {
                let place = self.place[b];
                if place & MIRROR != 0 {
                    let at = kept_place[(place & !MIRROR) as usize];
                    if at != NONE {
                        slot.push(at | MIRROR);
                        self.js[kept] = self.js[b];
                        kept += 1;
                    }
                    continue;
                }
                let p = place as usize;
                let mut block = [0.0f64; MODES * MODES];
                let mut bits = [false; MODES * MODES];
                for e in 0..bb {
                    let (s, x) = (self.state[bb * p + e], self.val[bb * p + e]);
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
                // stored <= p: the block moves forward over ones already read.
                let at = stored as usize;
                self.val[bb * at..bb * (at + 1)].copy_from_slice(&block);
                for (e, _) in bits.iter().enumerate().filter(|(_, &p)| p) {
                    let i = bb * at + e;
                    present[i / 64] |= 1 << (i % 64);
                }
                kept_place[p] = stored;
                slot.push(stored);
                self.js[kept] = self.js[b];
                stored += 1;
                kept += 1;
            }
            ptr.push(kept);
        }
        drop((self.state, self.place, kept_place));
        self.val.truncate(bb * stored as usize);
        self.val.shrink_to_fit();
        self.js.truncate(kept);
        self.js.shrink_to_fit();
        present.truncate((bb * stored as usize).div_ceil(64));
        present.shrink_to_fit();
        BlockRows::from_placed(
            (MODES * self.lo, MODES * na),
            ptr,
            (self.js, slot),
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
    use std::collections::HashMap;

    type Came = HashMap<(usize, usize, usize, usize), f64>;

    /// The specification's sparse rows (every row of the `sees.len()` aggregates, those
    /// outside `held` empty) from the value that came first at each (k, l; j, m).
    fn spec_rows(came: &Came, sees: &[Vec<bool>], held: &Range<usize>) -> Csr {
        let total = sees.len();
        let mut sparse = Csr::empty(MODES * total);
        for k in 0..total {
            for l in 0..MODES {
                for j in (0..total).filter(|&j| held.contains(&k) && (sees[k][j] || sees[j][k])) {
                    for m in 0..MODES {
                        let a = came.get(&(k, l, j, m));
                        let b = came.get(&(j, m, k, l));
                        let v = match (a, b) {
                            (Some(&a), Some(&b)) => {
                                (a != 0.0 || b != 0.0).then_some(0.5 * a + 0.5 * b)
                            }
                            (Some(&x), None) | (None, Some(&x)) => {
                                (x != 0.0).then_some(0.5 * x + 0.5 * 0.0)
                            }
                            (None, None) => None,
                        };
                        if let Some(v) = v {
                            sparse.idx.push((MODES * j + m) as u32);
                            sparse.val.push(v);
                        }
                    }
                }
                sparse.end_row();
            }
        }
        sparse
    }

    /// Aggregates 1..5 of 7 held (one rank's rows: couplings to rows held elsewhere too);
    /// a pattern where some aggregates see each other one way only, values that round when
    /// halved (odd mantissas, subnormals) and zeros, one event sent twice, and the blocks
    /// of aggregates 2 and 4 all zero (they must go, and their mirror with them). The
    /// specification, entry by entry from the events: both values 0.5 a + 0.5 b, kept
    /// where either is non-zero; one value x, 0.5 x + 0.5 * 0, kept where non-zero; none,
    /// left out; those sparse rows put into blocks by `BlockRows::of_rows` (which mirrors a
    /// block below the diagonal where its values are those of its transpose, checked).
    #[test]
    fn the_measured_blocks_are_the_sparse_rows_of_the_events_bit_for_bit() {
        let (total, held) = (7usize, 1..5usize);
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            seed >> 33
        };
        let mut sees = vec![vec![false; total]; total];
        for k in 0..total {
            sees[k][k] = true;
            for j in k + 1..total {
                match next() % 4 {
                    0 => {}
                    1 => sees[k][j] = true,
                    _ => (sees[k][j], sees[j][k]) = (true, true),
                }
            }
        }
        (sees[2][4], sees[4][2]) = (true, true);
        let mut pairs = Vec::new();
        for k in 0..total {
            for j in 0..total {
                if sees[k][j] {
                    if held.contains(&k) {
                        pairs.push((k as u32, j as u32));
                    }
                    if held.contains(&j) {
                        pairs.push((j as u32, k as u32));
                    }
                }
            }
        }
        let mut blocks = Blocks::of_pairs(pairs, total, held.clone());
        let stored = blocks.val.len() / (MODES * MODES);
        assert!(
            stored < blocks.js.len(),
            "some blocks are read from their transposes"
        );
        // The value at (k, l; j, m), the first that came.
        let mut came: Came = HashMap::new();
        let mut events = Vec::new();
        for k in 0..total {
            for j in 0..total {
                if sees[k][j] {
                    events.extend((0..MODES).map(|m| (k, j, m)));
                }
            }
        }
        events.push(events[events.len() / 2]);
        for &(k, j, m) in &events {
            let coeff: Vec<f64> = (0..MODES)
                .map(|_| {
                    let r = next();
                    match r % 7 {
                        _ if (k, j) == (2, 4) || (k, j) == (4, 2) => 0.0,
                        0 => 0.0,
                        1 => f64::from_bits(1 + 2 * (r % 1000)),
                        _ => (r as f64 / 3.0) * if r % 2 == 0 { 1.0 } else { -1.0 },
                    }
                })
                .collect();
            for (l, &x) in coeff.iter().enumerate() {
                came.entry((k, l, j, m)).or_insert(x);
            }
            let places = blocks.slots(k, j);
            blocks.take((k, j), places, m, &coeff);
        }
        let sparse = spec_rows(&came, &sees, &held);
        let (first, len) = (MODES * held.start, MODES * held.len());
        let n = MODES * total;
        let expected = BlockRows::of_rows(|r| sparse.row(r), (n, n), first, len).unwrap();
        let got = blocks.finish();
        let (e, g) = (expected.to_csr(), got.to_csr());
        assert_eq!(e.ptr, g.ptr);
        assert_eq!(e.idx, g.idx);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&e.val), bits(&g.val));
        assert_eq!(expected.nnz(), got.nnz());
        assert_eq!(
            expected.bytes(),
            got.bytes(),
            "the same blocks, mirrored alike"
        );
        let row2 = g.row(MODES * (2 - held.start)).0;
        assert!(
            row2.iter().all(|&c| !(24..30).contains(&c)),
            "the zero block went"
        );
        let x: Vec<f64> = (0..n).map(|i| 1.0 / (i as f64 + 3.0)).collect();
        let (mut ye, mut yg) = (vec![0.0; len], vec![0.0; len]);
        expected.mul_rows_into(&x, first, &mut ye);
        got.mul_rows_into(&x, first, &mut yg);
        assert_eq!(bits(&ye), bits(&yg));
    }
}
