//! A level's values rounded to f32 with its diagonal raised (`BlockRows::round_dominant`):
//! never less than the measured operator, so positive definite wherever it is, and stored
//! in the order the product reads them.

use super::{BlockRows, Values, B};

/// By how much at least `BlockRows::round_dominant` raises each held row's diagonal entry
/// (None: a row without one, and nothing off its diagonal to make up for).
pub struct Rounding(Vec<Option<f64>>);

impl BlockRows {
    /// How `round_dominant` would change the values (`diag` the whole operator's
    /// diagonal, row by row): for each held row i, at least how much its diagonal entry
    /// must rise, the sum over the row's entries off the diagonal of |e_ij| sqrt(d_i /
    /// d_j), e_ij an entry's change, summed in the order of the row's entries. None where
    /// the values cannot be so rounded: one not finite or beyond f32's range, a held row
    /// with values off the diagonal and no diagonal entry, or a change in a row or column
    /// whose diagonal is not positive.
    pub fn rounding(&self, diag: &[f64]) -> Option<Rounding> {
        let Values::Wide(val) = &self.val else {
            return Some(Rounding(Vec::new()));
        };
        if val
            .iter()
            .any(|v| !v.is_finite() || v.abs() > 0.5 * f64::from(f32::MAX))
        {
            return None;
        }
        let mut raise = Vec::with_capacity(self.len);
        for r in self.first..self.first + self.len {
            let i = r / B - self.block_first;
            let (mut diagonal, mut sum) = (None, 0.0f64);
            for b in self.ptr[i]..self.ptr[i + 1] {
                for c in 0..B {
                    let at = self.at(b, r % B, c);
                    if self.present[at / 64] & (1 << (at % 64)) == 0 {
                        continue;
                    }
                    let j = B * self.col[b] as usize + c;
                    let change = (val[at] - f64::from(val[at] as f32)).abs();
                    if j == r {
                        diagonal = Some(at);
                    } else if change > 0.0 {
                        let (di, dj) = (diag[r], diag[j]);
                        if !(di > 0.0 && dj > 0.0) {
                            return None;
                        }
                        sum += change * (di / dj).sqrt();
                    }
                }
            }
            match diagonal {
                Some(_) => raise.push(Some(sum)),
                None if sum > 0.0 => return None,
                None => raise.push(None),
            }
        }
        Some(Rounding(raise))
    }

    /// Stores the values in f32, every block its own and column-major in the order of the
    /// blocks (`Values::Columns`; `rounding` the change, of these rows): every value off
    /// the diagonal rounded to the nearest f32, and every diagonal entry of a held row
    /// raised to an f32 at or above d_i + sum_j |e_ij| sqrt(d_i / d_j). The change
    /// E = A' - A, scaled as D^-1/2 E D^-1/2, is then diagonally dominant with a non-negative
    /// diagonal, so E is positive semi-definite (Gershgorin's theorem; the operator is
    /// symmetric, its values mirrored bit for bit, and a value rounds alike wherever it
    /// stands) and A' is at least A: positive definite where A is, however nearly
    /// singular A is (a body held only by contact). Scaled so, each diagonal rises by at
    /// most 2^-24 times the row's entries in relative terms (|a_ij| <= sqrt(d_i d_j)), a
    /// few parts in 10^6 of it, however different the rows' scales (a row's own sum of
    /// changes can exceed a small diagonal by far). Each row's change is a function of
    /// that row's values and the diagonal alone, so every split of the rows over the ranks
    /// gives the same bits.
    pub fn round_dominant(&mut self, rounding: Rounding) {
        const BB: usize = B * B;
        if self.is_rounded() {
            return;
        }
        // A diagonal entry d raised to an f32 at or above d + sum (the sum's own rounding,
        // a few ulps of each term over a row's entries, covered by a margin of 2^-40 of
        // it): the nearest f32 to d + need, then the next ones up until it is above (one
        // or two steps).
        let raise = |d: f64, sum: f64| {
            let need = sum * (1.0 + f64::from(1u32 << 12) * f64::EPSILON);
            let mut t = (d + need) as f32;
            for _ in 0..8 {
                if f64::from(t) >= d + need && f64::from(t) - d >= need {
                    break;
                }
                t = t.next_up();
            }
            t
        };
        let blocks = self.col.len();
        let mut columns = vec![0.0f32; BB * blocks];
        let mut present = vec![0u64; (BB * blocks).div_ceil(64)];
        for i in 0..self.ptr.len() - 1 {
            for b in self.ptr[i]..self.ptr[i + 1] {
                for r in 0..B {
                    let row = B * (self.block_first + i) + r;
                    let held = (self.first..self.first + self.len).contains(&row);
                    for c in 0..B {
                        let at = self.at(b, r, c);
                        let to = BB * b + B * c + r;
                        let v = self.val.get(at);
                        let on = self.present[at / 64] & (1 << (at % 64)) != 0;
                        columns[to] = match rounding.0.get(row.wrapping_sub(self.first)) {
                            Some(&Some(sum))
                                if held && on && B * self.col[b] as usize + c == row =>
                            {
                                raise(v, sum)
                            }
                            _ => v as f32,
                        };
                        if on {
                            present[to / 64] |= 1 << (to % 64);
                        }
                    }
                }
            }
        }
        self.val = Values::Columns(columns);
        self.present = present;
        self.slot = Vec::new();
    }

    /// The first row held.
    pub fn first(&self) -> usize {
        self.first
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::split_rows_give_the_sparse_bits;
    use super::*;
    use crate::precond::multilevel::sparse::Csr;

    /// A chain of `nodes` node blocks coupled by springs, free at both ends (rigid
    /// translations cost nothing), of values that are not floats: symmetric, positive
    /// semi-definite.
    fn spring_chain(nodes: usize) -> Csr {
        let n = nodes * B;
        let mut t = Vec::new();
        for k in 0..nodes - 1 {
            for r in 0..B {
                // A spring between node k and k + 1 in each unknown, with a coupling
                // between unknowns r and r + 1 of the same pair (still a sum of squares).
                let w = 1.0 + 0.1 * ((k * B + r) as f64).sqrt();
                let c = 0.3 * w / 3.0;
                let (i, j) = ((k * B + r) as u32, ((k + 1) * B + r) as u32);
                for (a, b, v) in [(i, i, w), (j, j, w), (i, j, -w), (j, i, -w)] {
                    t.push((a, b, v));
                }
                if r + 1 < B {
                    let (i2, j2) = (i + 1, j + 1);
                    for (a, b, v) in [
                        (i, i2, c),
                        (i2, i, c),
                        (j, j2, c),
                        (j2, j, c),
                        (i, j2, -c),
                        (j2, i, -c),
                        (i2, j, -c),
                        (j, i2, -c),
                    ] {
                        t.push((a, b, v));
                    }
                }
            }
        }
        Csr::from_triplets(n, n, t)
    }

    /// The diagonal of `a`, row by row.
    fn diagonal(a: &Csr) -> Vec<f64> {
        (0..a.rows)
            .map(|r| {
                let (c, v) = a.row(r);
                c.binary_search(&(r as u32)).map_or(0.0, |k| v[k])
            })
            .collect()
    }

    /// `a` rounded (whole): every value a float's, those off the diagonal the nearest
    /// ones, and each diagonal raised by at least sum_j |e_ij| sqrt(d_i / d_j) (the
    /// premise of E = A' - A positive semi-definite) and by at most `most` of itself; every
    /// split of the rows over 1 to 5 ranks rounds to the same bits, and products and rows
    /// stay the sparse ones'. Returns the rounded operator.
    fn rounds_alike_on_any_split(a: &Csr, most: f64) -> Csr {
        let n = a.rows;
        let d = diagonal(a);
        let mut whole = BlockRows::new(a, 0, n).unwrap();
        let rounding = whole.rounding(&d).expect("finite, with diagonals");
        whole.round_dominant(rounding);
        let rounded = whole.to_csr();
        for r in 0..n {
            let ((c, v), (c0, v0)) = (rounded.row(r), a.row(r));
            assert_eq!(c, c0);
            let mut off = 0.0;
            for ((&j, &x), &x0) in c.iter().zip(v).zip(v0) {
                assert_eq!(f64::from(x as f32), x, "a float's value");
                if j as usize != r {
                    assert_eq!(x, f64::from(x0 as f32), "the nearest float");
                    off += (x - x0).abs() * (d[r] / d[j as usize]).sqrt();
                }
            }
            let k = c.binary_search(&(r as u32)).unwrap();
            assert!(v[k] - v0[k] >= off, "row {r}: the diagonal raised enough");
            assert!(
                v[k] - v0[k] <= most * v0[k],
                "row {r}: raised by at most {most}"
            );
        }
        split_rows_give_the_sparse_bits(&rounded, |_, _, _, _| {});
        for ranks in 1..=5usize {
            let l = n.div_ceil(ranks);
            for r in 0..ranks {
                let mut rows = BlockRows::new(a, r * l, l).unwrap();
                let rounding = rows.rounding(&d).unwrap();
                rows.round_dominant(rounding);
                let (back, first) = (rows.to_csr(), r * l);
                for k in 0..back.rows {
                    let ((c, v), (wc, wv)) = (back.row(k), rounded.row(first + k));
                    assert_eq!(c, wc);
                    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                    assert_eq!(bits(v), bits(wv), "ranks {ranks} rank {r} row {k}");
                }
                let x: Vec<f64> = (0..n).map(|j| (j as f64 * 0.37).cos()).collect();
                let (mut y, mut want) = (vec![0.0; l], vec![0.0; n]);
                rows.mul_rows_into(&x, first, &mut y);
                rounded.mul_into(&x, &mut want);
                for (k, &v) in y.iter().enumerate() {
                    let w = want.get(first + k).copied().unwrap_or(0.0);
                    assert_eq!(v.to_bits(), w.to_bits());
                }
            }
        }
        rounded
    }

    /// A symmetric positive semi-definite operator with a null space (a chain of node
    /// blocks coupled by springs, free at both ends: rigid translations cost nothing) of
    /// values that are not floats: rounded (`rounds_alike_on_any_split`), no direction,
    /// the null space's included, loses energy, while rounding to the nearest alone would
    /// make the operator indefinite. The same chain with its nodes scaled by 1 and 10^6 in
    /// turn (diagonals 1 and 10^12 side by side: a row's own sum of changes is then 6% of
    /// its diagonal, which the scaled bound takes as 6e-8) rounds with every diagonal
    /// raised by at most 10^-5 of itself (2^-24 times the 11 to 31 entries of a row).
    #[test]
    fn rounded_rows_are_floats_and_never_less_than_the_operator() {
        let nodes = 7;
        let n = nodes * B;
        let a = spring_chain(nodes);
        let mut scaled = a.clone();
        let s = |i: usize| if (i / B).is_multiple_of(2) { 1.0 } else { 1e6 };
        for r in 0..n {
            for k in scaled.ptr[r]..scaled.ptr[r + 1] {
                scaled.val[k] *= s(r) * s(scaled.idx[k] as usize);
            }
        }
        rounds_alike_on_any_split(&scaled, 1e-5);
        let rounded = rounds_alike_on_any_split(&a, 1e-5);
        let quadratic = |m: &Csr, x: &[f64]| {
            let mut y = vec![0.0; n];
            m.mul_into(x, &mut y);
            x.iter().zip(&y).map(|(a, b)| a * b).sum::<f64>()
        };
        // Translations along one unknown: a null vector of the operator.
        let null: Vec<f64> = (0..n).map(|i| if i % B == 2 { 1.0 } else { 0.0 }).collect();
        assert!(quadratic(&a, &null).abs() < 1e-12);
        // The change E = A' - A: x^T E x >= 0 for the null vector and others.
        let mut e = rounded.clone();
        for (x, x0) in e.val.iter_mut().zip(&a.val) {
            *x -= x0;
        }
        for x in [
            null.clone(),
            (0..n).map(|i| (i as f64 * 0.71).sin()).collect(),
        ] {
            assert!(quadratic(&e, &x) >= 0.0, "x^T E x");
        }
        // Rounding to the nearest alone loses energy in some direction: the null vector
        // or one of the node-to-node differences.
        let mut nearest = a.clone();
        nearest
            .val
            .iter_mut()
            .for_each(|x| *x = f64::from(*x as f32));
        let lost = (0..B).any(|u| {
            let x: Vec<f64> = (0..n).map(|i| if i % B == u { 1.0 } else { 0.0 }).collect();
            quadratic(&nearest, &x) < 0.0
        });
        assert!(
            lost,
            "the test's operator shows what the raised diagonal is for"
        );
    }
}
