//! A sparse Cholesky factor computed and held by supernodes, with one of two pivot rules:
//! the full tangent's modified factor (a pivot below a fraction of its diagonal entry is
//! raised to that: the factor of a positive definite matrix near an indefinite or singular
//! one), or the coarse level's (a pivot lost to cancellation, or an unknown without
//! stiffness, drops out: its solution component is zero). Supernodes: runs of columns of L with
//! the same rows below them (a column whose parent in the elimination tree is the next
//! column and which has one more entry than it), each a dense block factored by dense
//! loops, left-looking: a supernode takes the updates of every earlier one whose rows reach
//! its columns, each as a dense product scattered once. The same order, the same rows and
//! the same pivot rules as `SparseCholesky::column_modified` and `SparseCholesky::new`
//! (their references), in a different order of additions. The solves run by the same blocks: within a supernode's columns a
//! dense triangular solve, below them one dense product whose result is scattered (forward)
//! or gathered (backward) once per supernode instead of once per column. A fixed sequence
//! of operations on data every rank holds alike: bitwise the same on every rank.

use super::elimination::{etree, reach};
use super::sparse::Csr;

/// One supernode: columns `first..first + width` of L, then the rows below them.
struct Supernode {
    first: usize,
    width: usize,
    /// Rows below the supernode's columns, increasing.
    rows: Vec<usize>,
    /// Column-major, `width + rows.len()` rows: the columns' own rows, then `rows`.
    block: Vec<f64>,
}

impl Supernode {
    fn height(&self) -> usize {
        self.width + self.rows.len()
    }

    /// The matrix row of local row `t`.
    fn row(&self, t: usize) -> usize {
        if t < self.width {
            self.first + t
        } else {
            self.rows[t - self.width]
        }
    }
}

/// What a pivot too small becomes.
#[derive(Clone, Copy)]
enum Pivot {
    /// Raised to this fraction of its diagonal entry of A.
    Floor(f64),
    /// Dropped (its column zero, its solution component zero) where it fell below 1e-10 of
    /// its diagonal entry of A (lost to cancellation: a mode the earlier columns span) or
    /// that entry is below 1e-14 of A's largest diagonal entry (no stiffness).
    Drop,
}

/// The factor of `a` in the order `perm` as its supernodes, with `counts` entries below the
/// diagonal in each column, small pivots by `rule`.
fn supernodes(a: &Csr, perm: &[usize], counts: &[usize], rule: Pivot) -> Vec<Supernode> {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the processor has AVX2, checked just above.
        return unsafe { supernodes_avx2(a, perm, counts, rule) };
    }
    supernodes_body(a, perm, counts, rule)
}

/// `supernodes_body` compiled for AVX2 (the caller checks the processor has it). Every
/// operation is the same IEEE operation on the same operands in the same order (no fused
/// multiply-adds, independent lanes): the factor is bitwise the same either way.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn supernodes_avx2(a: &Csr, perm: &[usize], counts: &[usize], rule: Pivot) -> Vec<Supernode> {
    supernodes_body(a, perm, counts, rule)
}

#[inline(always)]
fn supernodes_body(a: &Csr, perm: &[usize], counts: &[usize], rule: Pivot) -> Vec<Supernode> {
    let n = a.rows;
    let mut inv = vec![0usize; n];
    for (k, &i) in perm.iter().enumerate() {
        inv[i] = k;
    }
    let parent = etree(a, perm, &inv);
    let (mut supers, owner) = symbolic(a, perm, &inv, &parent, counts);
    let scale = a.diagonal().iter().fold(0.0f64, |m, d| m.max(d.abs()));
    let akk: Vec<f64> = {
        let d = a.diagonal();
        perm.iter().map(|&i| d[i]).collect()
    };
    // Descendants waiting for each supernode, and where each stands in its own rows.
    let mut waiting: Vec<Vec<usize>> = vec![Vec::new(); supers.len()];
    let mut next_row = vec![0usize; supers.len()];
    let mut relpos = vec![usize::MAX; n];
    let mut map = Vec::new();
    let mut update = Vec::new();
    for s in 0..supers.len() {
        let (done, rest) = supers.split_at_mut(s);
        let sn = &mut rest[0];
        let m = sn.height();
        for t in 0..m {
            relpos[sn.row(t)] = t;
        }
        load(a, perm, &inv, sn, &relpos);
        for d in std::mem::take(&mut waiting[s]) {
            let dn = &done[d];
            let p1 = next_row[d];
            let end = sn.first + sn.width;
            let p2 = (p1..dn.height())
                .find(|&t| dn.row(t) >= end)
                .unwrap_or(dn.height());
            map.clear();
            map.extend((p1..dn.height()).map(|t| relpos[dn.row(t)]));
            apply_update(dn, p1, p2, &map, sn, &mut update);
            next_row[d] = p2;
            if p2 < dn.height() {
                waiting[owner[dn.row(p2)]].push(d);
            }
        }
        factor_block(sn, &akk, rule, scale);
        next_row[s] = sn.width;
        if !sn.rows.is_empty() {
            waiting[owner[sn.rows[0]]].push(s);
        }
    }
    supers
}

/// The supernodes of L (with their rows below) and the supernode of every column.
fn symbolic(
    a: &Csr,
    perm: &[usize],
    inv: &[usize],
    parent: &[usize],
    counts: &[usize],
) -> (Vec<Supernode>, Vec<usize>) {
    let n = a.rows;
    let mut owner = vec![0usize; n];
    let mut supers: Vec<Supernode> = Vec::new();
    for j in 0..n {
        let joins = j > 0 && parent[j - 1] == j && counts[j - 1] == counts[j] + 1;
        if joins {
            supers
                .last_mut()
                .expect("a supernode before column j")
                .width += 1;
        } else {
            supers.push(Supernode {
                first: j,
                width: 1,
                rows: Vec::with_capacity(counts[j]),
                block: Vec::new(),
            });
        }
        owner[j] = supers.len() - 1;
    }
    // The rows of each supernode's first column below the supernode, from the row patterns
    // of L (row k holds column j when j is reached from A's row k through the tree).
    let (mut flag, mut stack, mut pattern) = (vec![usize::MAX; n], Vec::new(), Vec::new());
    for k in 0..n {
        reach(a, perm, inv, parent, k, &mut flag, &mut stack, &mut pattern);
        for &j in &pattern {
            let sn = &mut supers[owner[j]];
            if sn.first == j && k >= sn.first + sn.width {
                sn.rows.push(k);
            }
        }
    }
    (supers, owner)
}

/// The supernode's block set to the lower part of A in its columns (`relpos`: local row of
/// every row of the supernode).
#[inline(always)]
fn load(a: &Csr, perm: &[usize], inv: &[usize], sn: &mut Supernode, relpos: &[usize]) {
    let m = sn.height();
    sn.block = vec![0.0; m * sn.width];
    for c in 0..sn.width {
        let j = sn.first + c;
        let (cols, vals) = a.row(perm[j]);
        for (&q, &v) in cols.iter().zip(vals) {
            let i = inv[q as usize];
            if i >= j {
                sn.block[relpos[i] + c * m] += v;
            }
        }
    }
}

/// Subtracts from `sn` the update of the finished supernode `dn`: L_d[p1.., :] times
/// L_d[p1..p2, :]^T (rows p1..p2 of `dn` are in `sn`'s columns), formed densely in
/// `update` and scattered through `map` (the local row in `sn` of each row p1.. of `dn`).
#[inline(always)]
fn apply_update(
    dn: &Supernode,
    p1: usize,
    p2: usize,
    map: &[usize],
    sn: &mut Supernode,
    update: &mut Vec<f64>,
) {
    let (md, h) = (dn.height(), dn.height() - p1);
    let w = p2 - p1;
    update.clear();
    update.resize(h * w, 0.0);
    for k in 0..dn.width {
        let col = &dn.block[k * md + p1..(k + 1) * md];
        for j in 0..w {
            let ljk = col[j];
            if ljk == 0.0 {
                continue;
            }
            let out = &mut update[j * h..(j + 1) * h];
            for i in j..h {
                out[i] += col[i] * ljk;
            }
        }
    }
    let m = sn.height();
    let first = sn.first;
    for j in 0..w {
        let c = map[j];
        debug_assert!(c < sn.width && sn.row(c) >= first);
        let dst = &mut sn.block[c * m..(c + 1) * m];
        for i in j..h {
            dst[map[i]] -= update[j * h + i];
        }
    }
}

/// The dense factor of the supernode's block: its diagonal block by Cholesky with the
/// pivot rule `rule` (`akk`: the diagonal of A in the factor's order), the rows below by
/// the triangular solve, column by column. A dropped pivot leaves its column zero.
#[inline(always)]
fn factor_block(sn: &mut Supernode, akk: &[f64], rule: Pivot, scale: f64) {
    let m = sn.height();
    let b = &mut sn.block;
    for c in 0..sn.width {
        let j = sn.first + c;
        let d = b[c + c * m];
        let pivot = match rule {
            Pivot::Floor(floor) => d.max(floor * akk[j].abs().max(1e-14 * scale)).sqrt(),
            Pivot::Drop if d > 1e-10 * akk[j] && akk[j] > 1e-14 * scale => d.sqrt(),
            Pivot::Drop => {
                b[c * m + c..(c + 1) * m].fill(0.0);
                continue;
            }
        };
        b[c + c * m] = pivot;
        for i in c + 1..m {
            b[i + c * m] /= pivot;
        }
        for c2 in c + 1..sn.width {
            let l = b[c2 + c * m];
            if l == 0.0 {
                continue;
            }
            let (head, tail) = b.split_at_mut(c2 * m);
            let src = &head[c * m..(c + 1) * m];
            let dst = &mut tail[..m];
            for i in c2..m {
                dst[i] -= src[i] * l;
            }
        }
    }
}

/// The factor by supernodes (see the module), with its work vectors.
pub struct Factor {
    /// `perm[k]` is the unknown eliminated k-th.
    perm: Vec<usize>,
    supers: Vec<Supernode>,
    nnz: usize,
    work: Vec<f64>,
    /// One supernode's rows below its columns.
    below: Vec<f64>,
}

impl Factor {
    /// Factors `a` in the order `perm` (from `SparseCholesky::analyse`, with its column
    /// counts), every pivot at least `floor` times its diagonal entry of `a`.
    pub fn new(a: &Csr, perm: Vec<usize>, counts: &[usize], floor: f64) -> Self {
        Self::with(a, perm, counts, Pivot::Floor(floor))
    }

    /// Factors `a` in the order `perm` (from `SparseCholesky::analyse`, with its column
    /// counts), dropping the pivots `SparseCholesky::new` drops: the unknowns left out
    /// solve to zero.
    pub fn dropping(a: &Csr, perm: Vec<usize>, counts: &[usize]) -> Self {
        Self::with(a, perm, counts, Pivot::Drop)
    }

    fn with(a: &Csr, perm: Vec<usize>, counts: &[usize], rule: Pivot) -> Self {
        let supers = supernodes(a, &perm, counts, rule);
        let nnz = supers
            .iter()
            .map(|s| s.width * (s.width - 1) / 2 + s.width * s.rows.len())
            .sum();
        let tallest = supers.iter().map(|s| s.rows.len()).max().unwrap_or(0);
        Factor {
            work: vec![0.0; perm.len()],
            below: vec![0.0; tallest],
            perm,
            supers,
            nnz,
        }
    }

    /// Entries of L below the diagonal.
    pub fn nnz(&self) -> usize {
        self.nnz
    }

    /// x <- A^-1 x for the modified A: L y = P x forward, L^T z = y backward, x = P^T z.
    /// On a processor with AVX2 compiled for it, bitwise the same (see `supernodes_avx2`).
    pub fn solve(&mut self, x: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor has AVX2, checked just above.
            return unsafe { self.solve_avx2(x) };
        }
        self.solve_body(x)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn solve_avx2(&mut self, x: &mut [f64]) {
        self.solve_body(x)
    }

    #[inline(always)]
    fn solve_body(&mut self, x: &mut [f64]) {
        let y = &mut self.work;
        for (k, &i) in self.perm.iter().enumerate() {
            y[k] = x[i];
        }
        for sn in &self.supers {
            forward(sn, y, &mut self.below);
        }
        for sn in self.supers.iter().rev() {
            backward(sn, y, &mut self.below);
        }
        for (k, &i) in self.perm.iter().enumerate() {
            x[i] = y[k];
        }
    }
}

/// The supernode's part of L y = b in place: its columns by the dense triangle, then the
/// rows below less the block's product, scattered once.
#[inline(always)]
fn forward(sn: &Supernode, y: &mut [f64], below: &mut [f64]) {
    let (m, w, f) = (sn.height(), sn.width, sn.first);
    let b = &sn.block;
    for c in 0..w {
        let col = &b[c * m..(c + 1) * m];
        // A dropped pivot: its component zero (its column is zero below it too).
        let yc = if col[c] == 0.0 {
            0.0
        } else {
            y[f + c] / col[c]
        };
        y[f + c] = yc;
        for i in c + 1..w {
            y[f + i] -= col[i] * yc;
        }
    }
    let h = m - w;
    let out = &mut below[..h];
    out.iter_mut().for_each(|v| *v = 0.0);
    for c in 0..w {
        let yc = y[f + c];
        let col = &b[c * m + w..(c + 1) * m];
        for t in 0..h {
            out[t] += col[t] * yc;
        }
    }
    for (&r, &v) in sn.rows.iter().zip(out.iter()) {
        y[r] -= v;
    }
}

/// The supernode's part of L^T z = y in place: the rows below gathered once, then each
/// column backwards less its products with them and with the later columns.
#[inline(always)]
fn backward(sn: &Supernode, y: &mut [f64], below: &mut [f64]) {
    let (m, w, f) = (sn.height(), sn.width, sn.first);
    let b = &sn.block;
    let h = m - w;
    let g = &mut below[..h];
    for (v, &r) in g.iter_mut().zip(&sn.rows) {
        *v = y[r];
    }
    for c in (0..w).rev() {
        let col = &b[c * m..(c + 1) * m];
        if col[c] == 0.0 {
            y[f + c] = 0.0;
            continue;
        }
        let s = y[f + c] - dot4(&col[w..], g) - dot4(&col[c + 1..w], &y[f + c + 1..f + w]);
        y[f + c] = s / col[c];
    }
}

/// a . b in four interleaved partial sums (a single running sum waits on each addition).
#[inline(always)]
fn dot4(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0; 4];
    let (ac, bc) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ar, br) = (ac.remainder(), bc.remainder());
    for (a4, b4) in ac.zip(bc) {
        for k in 0..4 {
            acc[k] += a4[k] * b4[k];
        }
    }
    for (x, v) in ar.iter().zip(br) {
        acc[0] += x * v;
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3])
}

#[cfg(test)]
mod tests {
    use super::super::sparse_cholesky::SparseCholesky;
    use super::*;
    use crate::precond::multilevel::smoother::hash_value;

    /// A 3-D 7-point operator on an m^3 grid, 3 unknowns per node coupled within the node
    /// (positive definite: its smallest eigenvalue is above 6.5 - 6 - 0.2), shifted by
    /// `shift` times the identity (indefinite for a shift below -0.3).
    fn grid(m: usize, shift: f64) -> (Csr, Vec<usize>) {
        let id = |i: usize, j: usize, k: usize| i + m * (j + m * k);
        let mut t = Vec::new();
        for k in 0..m {
            for j in 0..m {
                for i in 0..m {
                    for c in 0..3u32 {
                        let a = 3 * id(i, j, k) as u32 + c;
                        t.push((a, a, 6.5 + shift + 0.1 * c as f64));
                        let d = 3 * id(i, j, k) as u32 + (c + 1) % 3;
                        t.push((a, d, 0.2));
                        t.push((d, a, 0.2));
                        for (x, y, z) in [(i + 1, j, k), (i, j + 1, k), (i, j, k + 1)] {
                            if x < m && y < m && z < m {
                                let b = 3 * id(x, y, z) as u32 + c;
                                t.push((a, b, -1.0));
                                t.push((b, a, -1.0));
                            }
                        }
                    }
                }
            }
        }
        let n = 3 * m * m * m;
        let node_ptr = (0..=m * m * m).map(|i| 3 * i).collect();
        (Csr::from_triplets(n, n, t), node_ptr)
    }

    /// The 3-D 7-point Laplacian on an m^3 grid without boundary conditions (singular: the
    /// constant is its null space), 2 unknowns per node, the second one of node 5 without
    /// any stiffness.
    fn floating(m: usize) -> (Csr, Vec<usize>) {
        let id = |i: usize, j: usize, k: usize| i + m * (j + m * k);
        let dead = |node: usize, c: u32| node == 5 && c == 1;
        let mut t = Vec::new();
        for k in 0..m {
            for j in 0..m {
                for i in 0..m {
                    for (x, y, z) in [(i + 1, j, k), (i, j + 1, k), (i, j, k + 1)] {
                        if x >= m || y >= m || z >= m {
                            continue;
                        }
                        for c in 0..2u32 {
                            let (p, q) = (id(i, j, k), id(x, y, z));
                            if dead(p, c) || dead(q, c) {
                                continue;
                            }
                            let (a, b) = (2 * p as u32 + c, 2 * q as u32 + c);
                            t.extend([(a, a, 1.0), (b, b, 1.0), (a, b, -1.0), (b, a, -1.0)]);
                        }
                    }
                }
            }
        }
        let n = 2 * m * m * m;
        t.push((11, 11, 0.0));
        let node_ptr = (0..=m * m * m).map(|i| 2 * i).collect();
        (Csr::from_triplets(n, n, t), node_ptr)
    }

    #[test]
    fn dropped_pivots_are_the_column_factors() {
        // A singular operator: each component's constant mode is lost to cancellation at its
        // last pivot (left at round-off, about 1e-15 of its diagonal entry, against the
        // rule's 1e-10) and the dead unknown has no stiffness. The supernodal factor drops
        // the same pivots as the column one: the same unknowns solve to exactly zero, and
        // on a right-hand side in the range both solve A x = b (to round-off times the
        // condition number of the rest, about 1e2 here: 1e-11 of the largest entry of b)
        // and the solutions agree to 1e-9 of the largest component.
        let (a, node_ptr) = floating(8);
        let n = a.rows;
        let (perm, counts) = SparseCholesky::analyse(&a, &node_ptr, usize::MAX).unwrap();
        let mut col = SparseCholesky::new(&a, perm.clone(), &counts);
        let mut sup = Factor::dropping(&a, perm, &counts);
        assert_eq!(col.nnz(), sup.nnz());
        let x_true: Vec<f64> = (0..n)
            .map(|i| if i == 11 { 0.0 } else { hash_value(i as u64) })
            .collect();
        let mut b = vec![0.0; n];
        a.mul_into(&x_true, &mut b);
        let (mut x, mut y) = (b.clone(), b.clone());
        col.solve(&mut x);
        sup.solve(&mut y);
        let zeros = |v: &[f64]| (0..n).filter(|&i| v[i] == 0.0).collect::<Vec<_>>();
        // Three unknowns drop out: the dead one and one per component's constant mode.
        assert_eq!(zeros(&x).len(), 3, "{:?}", zeros(&x));
        assert_eq!(zeros(&x), zeros(&y));
        let norm = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for i in 0..n {
            assert!(
                (x[i] - y[i]).abs() < 1e-9 * norm,
                "{i}: {} vs {}",
                x[i],
                y[i]
            );
        }
        let mut r = vec![0.0; n];
        a.mul_into(&y, &mut r);
        let bn = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for i in 0..n {
            assert!(
                (r[i] - b[i]).abs() < 1e-11 * bn,
                "{i}: {} vs {}",
                r[i],
                b[i]
            );
        }
    }

    #[test]
    fn supernodes_give_the_column_factor() {
        // Positive definite (shift 0) and indefinite (shift -0.4: the floor raises pivots):
        // the supernodal factor is the column-by-column one up to the order of additions
        // (in the factor and in the solves by blocks), so their solves agree to a few round-offs times the condition number (at most
        // about 1e3 here: 1e-9 relative).
        for shift in [0.0, -0.4] {
            let (a, node_ptr) = grid(9, shift);
            let (perm, counts) = SparseCholesky::analyse(&a, &node_ptr, usize::MAX).unwrap();
            let mut col = SparseCholesky::column_modified(&a, perm.clone(), &counts, 1e-2);
            let mut sup = Factor::new(&a, perm, &counts, 1e-2);
            assert_eq!(col.nnz(), sup.nnz());
            let n = a.rows;
            let b: Vec<f64> = (0..n).map(|i| hash_value(i as u64)).collect();
            let (mut x, mut y) = (b.clone(), b);
            col.solve(&mut x);
            sup.solve(&mut y);
            let norm = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for i in 0..n {
                assert!(
                    (x[i] - y[i]).abs() < 1e-9 * norm,
                    "{shift} {i}: {} vs {}",
                    x[i],
                    y[i]
                );
            }
            if shift == 0.0 {
                // Positive definite: the factor solves A x = b (to round-off times the
                // condition number, below 100 here).
                let mut r = vec![0.0; n];
                a.mul_into(&y, &mut r);
                for (i, ri) in r.iter().enumerate() {
                    assert!((ri - hash_value(i as u64)).abs() < 1e-11, "{i}");
                }
            }
        }
    }
}
