//! P^T A P, the Galerkin product of a coarse level, without holding A P: the rows of P^T in
//! blocks, each block's rows of A P formed once while consecutive blocks need them; and the
//! part of it a range of rows of A contributes, so that ranks can sum it in turns (each
//! entry the one sum the whole product forms). P may be given by only the rows the product
//! reaches (`Picked`).

use super::sparse::{Csr, Offset, RowProduct, Rows};

/// Rows handed out by shared reference (a matrix, or some of its rows).
pub trait RowsOf {
    fn row_of(&self, r: usize) -> (&[u32], &[f64]);
}

impl RowsOf for Csr {
    fn row_of(&self, r: usize) -> (&[u32], &[f64]) {
        self.row(r)
    }
}

/// Some rows of a matrix: row r is `rows.row(slot[r])` for the
/// rows picked (slot u32::MAX for the others, which must not be asked for).
pub struct Picked {
    slot: Vec<u32>,
    rows: Csr,
}

impl Picked {
    /// Rows of a matrix of `n` rows: row r is `rows.row(slot[r])` (u32::MAX: not held).
    pub fn new(slot: Vec<u32>, rows: Csr) -> Picked {
        Picked { slot, rows }
    }
}

impl RowsOf for Picked {
    fn row_of(&self, r: usize) -> (&[u32], &[f64]) {
        self.rows.row(self.slot[r] as usize)
    }
}

/// Blocks of rows of P^T in which `triple_product` computes P^T A P, cut by the rows of A
/// they reach: the rows of A P one block needs are held at a time (about an eighth of A P
/// where the whole was held, one of the products at the peak of a multilevel build), a row
/// kept while consecutive blocks need it. (Block on block n = 80, 2 ranks, a build's coarse
/// levels: 3.0 s holding A P whole; 3.5-3.7 s with 8 blocks and the first level split over
/// the ranks, 4.0-4.3 s with 16.)
pub const TRIPLE_BLOCKS: usize = 8;

/// P^T A P from P and its transpose `pt`: the same entries, bit for bit, as
/// `pt.matmul(&a.matmul(p))`, without holding A P. The rows of P^T are taken in `blocks`
/// blocks; for each, the rows of A P its entries need are computed (each exactly as the
/// whole product computes it), then the block's rows of P^T times them.
pub fn triple_product(pt: &Csr, a: &Csr, p: &Csr, blocks: usize) -> Csr {
    assert_eq!(
        (pt.cols, a.rows, a.cols),
        (a.rows, a.cols, p.rows),
        "triple_product: shapes"
    );
    let rows = &mut Offset { a, first: 0 };
    triple_product_part((pt, 0..pt.rows), rows, 0..a.rows, p, blocks, None)
}

/// The part of P^T A P that the rows `ks` of A contribute (`a`: the rows of A, asked only
/// for k in `ks`), continuing `seed`, the part of the rows of A before `ks`: each
/// entry's sum goes on from the seed's value over the terms of k in `ks`, in the order of
/// k, so the parts of consecutive ranges of rows, each seeded with the one before, end
/// with `triple_product`'s bits. An entry some term reached is kept (also when it sums to
/// zero), as the whole product keeps it. Only the rows `range` of the product are formed
/// (of P^T, `pt`; the seed holds those rows, numbered from 0): each row's sums are its
/// own, so the product's rows may be formed in groups.
pub fn triple_product_part(
    (pt, range): (&Csr, std::ops::Range<usize>),
    a: &mut impl Rows,
    ks: std::ops::Range<usize>,
    p: &impl RowsOf,
    blocks: usize,
    seed: Option<&Csr>,
) -> Csr {
    let cols = pt.rows;
    let mut inner = RowProduct::new(cols);
    let mut outer = RowProduct::new(cols);
    // slot[k - ks.start]: the row of `ap` that holds row k of A P (u32::MAX: none);
    // have[r]: the k of ap's row r; want[k - ks.start]: the last block that needs row k.
    let mut slot = vec![u32::MAX; ks.len()];
    let mut want = vec![usize::MAX; ks.len()];
    let mut have: Vec<u32> = Vec::new();
    let mut need: Vec<u32> = Vec::new();
    let mut ap = Csr::empty(cols);
    let mut out = Csr::empty(cols);
    out.ptr.reserve(range.len());
    // Row i of P^T restricted to `ks` (its columns are sorted).
    let part = |i: usize| {
        let (c, v) = pt.row(i);
        let lo = c.partition_point(|&k| (k as usize) < ks.start);
        let hi = c.partition_point(|&k| (k as usize) < ks.end);
        (&c[lo..hi], &v[lo..hi])
    };
    // A block of rows of P^T ends once its rows reach `per` rows of A (or more): only one
    // block's rows of A P are held, each formed once while consecutive blocks need it (a
    // row of A P is its own sum whichever block forms it), and the rows of P^T that reach
    // none of `ks` cost nothing.
    let per = ks.len().div_ceil(blocks.max(1)).max(1);
    let mut start = range.start;
    let mut block = 0usize;
    while start < range.end {
        let mut end = start;
        while end < range.end && need.len() < per {
            for &k in part(end).0 {
                let s = k as usize - ks.start;
                if want[s] != block {
                    want[s] = block;
                    need.push(k);
                }
            }
            end += 1;
        }
        // The rows the block needs again move to the front; the others go.
        let mut w = 0;
        for r in 0..ap.rows {
            let s = have[r] as usize - ks.start;
            if want[s] != block {
                slot[s] = u32::MAX;
                continue;
            }
            let (from, len) = (ap.ptr[r], ap.ptr[r + 1] - ap.ptr[r]);
            let to = ap.ptr[w];
            ap.idx.copy_within(from..from + len, to);
            ap.val.copy_within(from..from + len, to);
            ap.ptr[w + 1] = to + len;
            have[w] = have[r];
            slot[s] = w as u32;
            w += 1;
        }
        ap.rows = w;
        ap.ptr.truncate(w + 1);
        ap.idx.truncate(ap.ptr[w]);
        ap.val.truncate(ap.ptr[w]);
        have.truncate(w);
        need.sort_unstable();
        for &k in &need {
            let s = k as usize - ks.start;
            if slot[s] == u32::MAX {
                slot[s] = ap.rows as u32;
                have.push(k);
                inner.push_row(a.row(k as usize), |m| p.row_of(m), &mut ap);
            }
        }
        for i in start..end {
            if let Some(seed) = seed {
                outer.seed(seed.row(i - range.start));
            }
            let row = |k: usize| ap.row(slot[k - ks.start] as usize);
            outer.push_row(part(i), row, &mut out);
        }
        need.clear();
        start = end;
        block += 1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rounding(rows: usize, cols: usize, seed: u32) -> Csr {
        let mut t = Vec::new();
        for i in 0..rows as u32 {
            for j in 0..cols as u32 {
                if (i * 7 + j * 3 + seed) % 5 < 2 {
                    t.push((
                        i,
                        j,
                        0.1 * (i as f64 + 1.3) / (j as f64 + 2.7) - 0.041 * seed as f64,
                    ));
                }
            }
        }
        Csr::from_triplets(rows, cols, t)
    }

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    #[test]
    fn the_triple_product_by_blocks_is_the_whole_product_bit_for_bit() {
        let a = rounding(13, 13, 1).symmetric_part();
        let p = rounding(13, 5, 2);
        let pt = p.transpose();
        let whole = pt.matmul(&a.matmul(&p));
        for blocks in [1, 2, 3, 5, 16] {
            let t = triple_product(&pt, &a, &p, blocks);
            assert_eq!((t.rows, t.cols), (5, 5));
            assert_eq!(
                (&t.ptr, &t.idx),
                (&whole.ptr, &whole.idx),
                "{blocks} blocks"
            );
            assert_eq!(bits(&t.val), bits(&whole.val), "{blocks} blocks");
        }
        // Prolongation by the transpose's scattered product: P's row products' bits.
        let x: Vec<f64> = (0..5).map(|j| 0.3 / (j as f64 + 0.7) - 0.2).collect();
        let (mut y, mut z) = (vec![0.0; 13], vec![1.0; 13]);
        p.mul_into(&x, &mut y);
        pt.mul_transpose_into(&x, &mut z);
        assert_eq!(bits(&y), bits(&z));
    }

    #[test]
    fn the_product_in_turns_with_the_rows_of_p_it_reaches_is_the_whole_product() {
        // As the first level forms it: the rows of A split in consecutive ranges (the
        // ranks), each range's part seeded with the parts before, P given only by the rows
        // the range's rows of A reach (`Picked`), P^T only by its columns in the range;
        // the product's rows formed whole or in groups (`first::pipelined`), stacked.
        let a = rounding(13, 13, 1).symmetric_part();
        let p = rounding(13, 5, 2);
        let pt = p.transpose();
        let whole = pt.matmul(&a.matmul(&p));
        for cuts in [vec![0, 13], vec![0, 6, 13], vec![0, 4, 4, 9, 13]] {
            let ranges: Vec<_> = cuts.windows(2).map(|w| w[0]..w[1]).collect();
            let parts: Vec<_> = ranges.iter().map(|ks| in_range(&a, &p, ks)).collect();
            for groups in [vec![0, 5], vec![0, 2, 5], vec![0, 1, 1, 3, 5]] {
                for blocks in [1, 3, 8] {
                    let mut t = Csr::empty(5);
                    for g in groups.windows(2) {
                        let mut sums: Option<Csr> = None;
                        for (ks, (picked, pt_ks)) in ranges.iter().zip(&parts) {
                            let rows = &mut Offset { a: &a, first: 0 };
                            sums = Some(triple_product_part(
                                (pt_ks, g[0]..g[1]),
                                rows,
                                ks.clone(),
                                picked,
                                blocks,
                                sums.as_ref(),
                            ));
                        }
                        t.append(&sums.unwrap());
                    }
                    let what = format!("{cuts:?}, groups {groups:?}, {blocks} blocks");
                    assert_eq!((&t.ptr, &t.idx), (&whole.ptr, &whole.idx), "{what}");
                    assert_eq!(bits(&t.val), bits(&whole.val), "{what}");
                }
            }
        }
    }

    /// What a rank holding the rows `ks` of A has: the rows of P they reach, and P^T's
    /// columns in `ks`.
    fn in_range(a: &Csr, p: &Csr, ks: &std::ops::Range<usize>) -> (Picked, Csr) {
        let mut reached: Vec<u32> = ks.clone().flat_map(|k| a.row(k).0.to_vec()).collect();
        reached.sort_unstable();
        reached.dedup();
        let mut slot = vec![u32::MAX; p.rows];
        let mut held = Csr::empty(p.cols);
        for (s, &m) in reached.iter().enumerate() {
            slot[m as usize] = s as u32;
            let (c, v) = p.row(m as usize);
            held.idx.extend_from_slice(c);
            held.val.extend_from_slice(v);
            held.ptr.push(held.idx.len());
            held.rows += 1;
        }
        let range: Vec<_> = (0..p.rows)
            .flat_map(|m| {
                let (c, v) = p.row(m);
                c.iter().zip(v).map(move |(&j, &x)| (m as u32, j, x))
            })
            .filter(|&(m, _, _)| ks.contains(&(m as usize)))
            .collect();
        let pt_ks = Csr::from_triplets(p.rows, p.cols, range).transpose();
        (Picked::new(slot, held), pt_ks)
    }
}
