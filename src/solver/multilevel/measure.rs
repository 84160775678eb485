//! The first coarse operator Kc = Q^T A Q, assembled sparse from one application of the
//! (constrained, matrix-free) operator per colour and mode: the probe of colour c and mode
//! m sums mode m of every aggregate of colour c, and Q^T A probe gives, at every aggregate
//! k, column (j, m) of Kc for the one aggregate j of colour c that k sees.

use super::colouring::Colouring;
use super::prolongator::MODES;
use super::sparse::Csr;
use super::transfer::Transfer;
use crate::comm::Comm;
use crate::constraints::Constraints;
use crate::math::Vec3;

/// Buffers of the fine level used while measuring.
pub struct Probe<'b> {
    pub v: &'b mut [Vec3],
    pub av: &'b mut [Vec3],
    pub coeff: &'b mut [f64],
}

/// Measures Kc; `apply(v, av)` sets av = T^T A T v on the owned nodes (v may be changed).
/// The result is symmetrised: (Kc + Kc^T) / 2. Collective.
///
/// Kc is written straight into its rows (`Blocks`): the pattern is known from the
/// colouring before the first probe, so no triplet list is sorted, and the symmetric part
/// is taken in place. That holds 13 bytes per entry where triplets, their sort, the
/// matrix, its transpose and their symmetric part held up to 36 (the peak of a build);
/// the result is the same matrix, bit for bit: an entry is kept where either measured
/// value was non-zero, and is 0.5 a + 0.5 b of the two.
#[allow(clippy::too_many_arguments)]
pub fn measure<C: Comm + ?Sized, E>(
    comm: &C,
    tr: &mut Transfer,
    col: &Colouring,
    cons: &Constraints,
    owned: usize,
    buf: Probe,
    mut apply: impl FnMut(&mut [Vec3], &mut [Vec3]) -> Result<(), E>,
) -> Result<Csr, E> {
    let mut kc = Blocks::new(col, tr.num_aggregates);
    for c in 0..col.num_colours {
        for m in 0..MODES {
            tr.aggregates.probe(cons, &col.colour, c, m, owned, buf.v);
            apply(buf.v, buf.av)?;
            tr.aggregates.restrict(comm, buf.av, buf.coeff);
            for &(k, j) in col.pairs(c) {
                let (k, j) = (k as usize, j as usize);
                let t = kc.slot(k, j);
                for l in 0..MODES {
                    let i = kc.at(k, l, t, m);
                    kc.val[i] = buf.coeff[MODES * k + l];
                }
            }
        }
    }
    Ok(kc.symmetric_part())
}

/// Kc in rows of 6 x 6 blocks while it is measured: aggregate k couples to the aggregates
/// js[ptr[k]..ptr[k + 1]] (increasing; the pattern of the colouring made symmetric), and
/// row (k, l) holds columns (j, m) for those j in order, m = 0..5.
struct Blocks {
    ptr: Vec<usize>,
    js: Vec<u32>,
    val: Vec<f64>,
}

impl Blocks {
    fn new(col: &Colouring, na: usize) -> Self {
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        for k in 0..na {
            for &(_, j) in col.seen(k) {
                pairs.push((k as u32, j));
                pairs.push((j, k as u32));
            }
        }
        pairs.sort_unstable();
        pairs.dedup();
        let mut ptr = vec![0usize; na + 1];
        for &(k, _) in &pairs {
            ptr[k as usize + 1] += 1;
        }
        for k in 0..na {
            ptr[k + 1] += ptr[k];
        }
        let js: Vec<u32> = pairs.into_iter().map(|(_, j)| j).collect();
        let val = vec![0.0; MODES * MODES * js.len()];
        Blocks { ptr, js, val }
    }

    /// The place of aggregate j among those k couples to.
    fn slot(&self, k: usize, j: usize) -> usize {
        let row = &self.js[self.ptr[k]..self.ptr[k + 1]];
        row.binary_search(&(j as u32))
            .expect("the pattern holds every coupling of the colouring")
    }

    /// The entry of row (k, l) and column (js[ptr[k] + t], m).
    fn at(&self, k: usize, l: usize, t: usize, m: usize) -> usize {
        let n = self.ptr[k + 1] - self.ptr[k];
        MODES * MODES * self.ptr[k] + MODES * (l * n + t) + m
    }

    /// (Kc + Kc^T) / 2 as a Csr, in place: each pair of mirrored entries becomes
    /// 0.5 a + 0.5 b (the same sum either way round); pairs of which neither was measured
    /// non-zero are left out, as the triplets left them out.
    fn symmetric_part(mut self) -> Csr {
        let na = self.ptr.len() - 1;
        let mut keep = vec![false; self.val.len()];
        for k in 0..na {
            for t in 0..self.ptr[k + 1] - self.ptr[k] {
                let j = self.js[self.ptr[k] + t] as usize;
                if j < k {
                    continue;
                }
                let s = self.slot(j, k);
                for l in 0..MODES {
                    let m0 = if j == k { l } else { 0 };
                    for m in m0..MODES {
                        let (p, q) = (self.at(k, l, t, m), self.at(j, m, s, l));
                        let (a, b) = (self.val[p], self.val[q]);
                        let v = 0.5 * a + 0.5 * b;
                        self.val[p] = v;
                        self.val[q] = 0.5 * b + 0.5 * a;
                        let live = a != 0.0 || b != 0.0;
                        keep[p] = live;
                        keep[q] = live;
                    }
                }
            }
        }
        // Compaction, row by row, in place.
        let rows = MODES * na;
        let mut ptr = Vec::with_capacity(rows + 1);
        ptr.push(0usize);
        let mut idx: Vec<u32> = Vec::with_capacity(self.val.len());
        let mut out = 0usize;
        let mut from = 0usize;
        for k in 0..na {
            let blocks = &self.js[self.ptr[k]..self.ptr[k + 1]];
            for _l in 0..MODES {
                for &j in blocks {
                    for m in 0..MODES {
                        if keep[from] {
                            self.val[out] = self.val[from];
                            idx.push(MODES as u32 * j + m as u32);
                            out += 1;
                        }
                        from += 1;
                    }
                }
                ptr.push(out);
            }
        }
        drop(keep);
        self.val.truncate(out);
        self.val.shrink_to_fit();
        idx.shrink_to_fit();
        Csr {
            rows,
            cols: rows,
            ptr,
            idx,
            val: self.val,
        }
    }
}
