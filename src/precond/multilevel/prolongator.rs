//! Prolongators between coarse levels: the tentative one interpolates the near-nullspace
//! (the rigid-body modes) exactly, aggregate by aggregate (an orthonormal basis of the
//! modes restricted to the aggregate; the coarse modes are the coefficients), and one
//! damped Jacobi step smooths it, P = (I - omega D^-1 A) P_tent with omega = 4 / (3 lmax).

use super::blocks::BlockInverse;
use super::sparse::{merge_row, Csr, MergeRule, Offset, RowProduct, Rows};

/// Near-nullspace vectors per unknown.
pub const MODES: usize = 6;

/// A tentative prolongator, with its coarse unknowns grouped by aggregate.
pub struct Tentative {
    pub p: Csr,
    /// Coarse unknowns of each aggregate: node_ptr[k]..node_ptr[k + 1].
    pub node_ptr: Vec<usize>,
    /// The near-nullspace on the coarse level (one row per coarse unknown).
    pub b: Vec<[f64; MODES]>,
}

/// Builds the tentative prolongator: `agg` is the aggregate of every fine node (u32::MAX
/// for none), `node_ptr` the fine unknowns of every fine node, `b` the fine near-nullspace.
/// Modes that are (numerically) spanned by earlier ones on an aggregate are dropped. With
/// `rows`, only the rows of the fine unknowns it marks get their entries (the others are
/// left empty; the columns, the coarse near-nullspace and every kept entry are the same).
pub fn tentative(
    agg: &[u32],
    num_aggs: usize,
    node_ptr: &[usize],
    b: impl Fn(usize) -> [f64; MODES],
    rows: Option<&[bool]>,
) -> Tentative {
    let wanted = |row: usize| rows.is_none_or(|keep| keep[row]);
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); num_aggs];
    for (node, &k) in agg.iter().enumerate() {
        if k != u32::MAX {
            members[k as usize].extend(node_ptr[node]..node_ptr[node + 1]);
        }
    }
    let mut trip = Vec::new();
    let mut cptr = vec![0usize];
    let mut cb = Vec::new();
    let mut col = 0u32;
    for unknowns in &members {
        // Modified Gram-Schmidt on the columns of B restricted to the aggregate.
        let m = unknowns.len();
        let mut q: Vec<Vec<f64>> = Vec::with_capacity(MODES);
        let mut r = [[0.0; MODES]; MODES];
        for c in 0..MODES {
            let mut v: Vec<f64> = unknowns.iter().map(|&i| b(i)[c]).collect();
            let n0 = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            for (k, qk) in q.iter().enumerate() {
                let s: f64 = qk.iter().zip(&v).map(|(a, b)| a * b).sum();
                r[k][c] = s;
                for i in 0..m {
                    v[i] -= s * qk[i];
                }
            }
            let n1 = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            if n0 > 0.0 && n1 > 1e-8 * n0 {
                r[q.len()][c] = n1;
                v.iter_mut().for_each(|x| *x /= n1);
                q.push(v);
            }
        }
        for (k, qk) in q.iter().enumerate() {
            for (i, &row) in unknowns.iter().enumerate() {
                if qk[i] != 0.0 && wanted(row) {
                    trip.push((row as u32, col + k as u32, qk[i]));
                }
            }
            cb.push(r[k]);
        }
        col += q.len() as u32;
        cptr.push(col as usize);
    }
    Tentative {
        p: Csr::from_triplets(node_ptr[node_ptr.len() - 1], col as usize, trip),
        node_ptr: cptr,
        b: cb,
    }
}

/// P = (I - omega D^-1 A) P_tent, omega = 4 / (3 lmax(D^-1 A)), D the node-block diagonal;
/// rows of unknowns without stiffness (left out of D^-1) are left as they are. Each row
/// merges the two sorted rows: t - omega x where both have the column, exact zeros left
/// out. Computed node by node (the node's rows of A P_tent, then of D^-1 A P_tent, then
/// of P), the same bits as the whole products `dinv.left_multiply(&a.matmul(pt))` merged
/// with P_tent, without holding either product (each as large as P: two of the
/// products at the peak of a multilevel build).
pub fn smooth(a: &Csr, dinv: &BlockInverse, lmax: f64, pt: &Csr) -> Csr {
    let p = smooth_nodes(
        &mut Offset { a, first: 0 },
        dinv,
        lmax,
        pt,
        0..dinv.nodes(),
        (0, 0),
    );
    assert_eq!(p.rows, a.rows, "smooth: the nodes cover every unknown");
    p
}

/// The rows of P (`smooth`) of the unknowns of `nodes`; `a` gives the rows of A (asked
/// only for those unknowns). `dinv` holds the inverses of the nodes from `base` on,
/// numbered from 0 (`BlockInverse::of_nodes`; (0, 0) for every node), the first of whose
/// unknowns is the level's unknown `first`.
pub fn smooth_nodes(
    a: &mut impl Rows,
    dinv: &BlockInverse,
    lmax: f64,
    pt: &Csr,
    nodes: std::ops::Range<usize>,
    (base, first): (usize, usize),
) -> Csr {
    let omega = 4.0 / (3.0 * lmax);
    let mut prod = RowProduct::new(pt.cols);
    let mut ws = RowProduct::new(pt.cols);
    let (mut apt, mut dapt) = (Csr::empty(pt.cols), Csr::empty(pt.cols));
    let mut out = Csr::empty(pt.cols);
    let rule: MergeRule = (&|t, x| t + -omega * x, &|t| t, &|x| -omega * x);
    for i in nodes {
        let local = dinv.unknowns(i - base);
        let rows = first + local.start..first + local.end;
        apt.clear_rows();
        for r in rows.clone() {
            prod.push_row(a.row(r), |k| pt.row(k), &mut apt);
        }
        dapt.clear_rows();
        dinv.left_multiply_node(i - base, |q| apt.row(q), &mut ws, &mut dapt);
        for (q, r) in rows.enumerate() {
            merge_row(pt.row(r), dapt.row(q), rule, true, &mut out);
        }
    }
    out.idx.shrink_to_fit();
    out.val.shrink_to_fit();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tentative_interpolates_the_modes_and_is_orthonormal() {
        // Eight fine nodes with one unknown each, two aggregates; the near-nullspace has a
        // constant, a linear and (dependent) twice-constant columns, the rest zero.
        let agg = [0, 0, 0, 0, 1, 1, 1, u32::MAX];
        let node_ptr: Vec<usize> = (0..=8).collect();
        let b: Vec<[f64; MODES]> = (0..8)
            .map(|i| [1.0, i as f64, 2.0, 0.0, 0.0, 0.0])
            .collect();
        let t = tentative(&agg, 2, &node_ptr, |i| b[i], None);
        // Two independent columns per aggregate.
        assert_eq!(t.node_ptr, vec![0, 2, 4]);
        let pd = t.p.to_dense();
        // P_tent B_c = B on the aggregated nodes (to round-off of O(10) values: 1e-13),
        // zero on the unaggregated one; P^T P = I.
        for i in 0..8 {
            for c in 0..MODES {
                let s: f64 = (0..4).map(|j| pd[i * 4 + j] * t.b[j][c]).sum();
                let want = if agg[i] == u32::MAX { 0.0 } else { b[i][c] };
                assert!((s - want).abs() < 1e-13, "{i} {c}: {s} vs {want}");
            }
        }
        for j in 0..4 {
            for k in 0..4 {
                let s: f64 = (0..8).map(|i| pd[i * 4 + j] * pd[i * 4 + k]).sum();
                assert!((s - if j == k { 1.0 } else { 0.0 }).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn smoothing_keeps_a_nullspace_vector_in_the_range() {
        // A: the 1D Laplacian with free ends (constants in its kernel). Smoothing P_tent
        // leaves P * 1 = 1 exactly where A 1 = 0: the smoothed prolongator still
        // interpolates the kernel.
        let n = 9;
        let mut trip = Vec::new();
        for i in 0..n {
            let deg = if i == 0 || i == n - 1 { 1.0 } else { 2.0 };
            trip.push((i as u32, i as u32, deg));
            if i + 1 < n {
                trip.push((i as u32, i as u32 + 1, -1.0));
                trip.push((i as u32 + 1, i as u32, -1.0));
            }
        }
        let a = Csr::from_triplets(n, n, trip);
        let dinv = BlockInverse::new(&a, &(0..=n).collect::<Vec<_>>());
        let agg = [0, 0, 0, 1, 1, 1, 2, 2, 2];
        let node_ptr: Vec<usize> = (0..=n).collect();
        let b: Vec<[f64; MODES]> = (0..n).map(|_| [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]).collect();
        let t = tentative(&agg, 3, &node_ptr, |i| b[i], None);
        let p = smooth(&a, &dinv, 2.0, &t.p);
        let coarse_one: Vec<f64> = t.b.iter().map(|r| r[0]).collect();
        let mut y = vec![0.0; n];
        p.mul_into(&coarse_one, &mut y);
        // Sums of three terms of size 1/sqrt(3): round-off below 1e-15.
        for v in y {
            assert!((v - 1.0).abs() < 1e-15, "{v}");
        }
        // Node by node, the same bits as the whole products merged.
        let whole = t.p.merge(
            &dinv.left_multiply(&a.matmul(&t.p)),
            |t, x| t + -(4.0 / 6.0) * x,
            |t| t,
            |x| -(4.0 / 6.0) * x,
            true,
        );
        assert_eq!((&p.ptr, &p.idx), (&whole.ptr, &whole.idx));
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&p.val), bits(&whole.val));
    }

    #[test]
    fn smoothing_node_by_node_is_the_whole_products_bit_for_bit() {
        // Nodes of three unknowns, a diagonally dominant operator and a prolongator whose
        // entries round: the node-by-node rows must be those of the whole products.
        let n = 12;
        let mut trip = Vec::new();
        for i in 0..n as u32 {
            trip.push((i, i, 10.0 + 0.37 * i as f64));
            for j in 0..n as u32 {
                if i != j && (i * 5 + j * 3) % 4 == 0 {
                    trip.push((i, j, 0.1 / (1.3 + (i + j) as f64)));
                    trip.push((j, i, 0.1 / (1.3 + (i + j) as f64)));
                }
            }
        }
        let a = Csr::from_triplets(n, n, trip);
        let node_ptr = [0usize, 3, 6, 9, 12];
        let dinv = BlockInverse::new(&a, &node_ptr);
        let mut t = Vec::new();
        for i in 0..n as u32 {
            for j in 0..4u32 {
                if (i + 2 * j) % 3 != 1 {
                    t.push((i, j, 0.7 / (i as f64 + 1.9) + 0.11 * j as f64));
                }
            }
        }
        let pt = Csr::from_triplets(n, 4, t);
        let lmax = 1.7;
        let omega = 4.0 / (3.0 * lmax);
        let p = smooth(&a, &dinv, lmax, &pt);
        let whole = pt.merge(
            &dinv.left_multiply(&a.matmul(&pt)),
            |t, x| t + -omega * x,
            |t| t,
            |x| -omega * x,
            true,
        );
        assert_eq!(
            (p.rows, &p.ptr, &p.idx),
            (whole.rows, &whole.ptr, &whole.idx)
        );
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&p.val), bits(&whole.val));
    }
}
