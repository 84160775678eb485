use super::*;

/// `a`'s rows split as over 1 to 5 ranks (at rows within blocks too): each rank's
/// product and rows are the sparse ones bit for bit; `more` checks each rank's rows
/// further (ranks, rank, its rows, them as sparse rows).
fn split_rows_give_the_sparse_bits(a: &Csr, mut more: impl FnMut(usize, usize, &BlockRows, &Csr)) {
    let n = a.rows;
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let x: Vec<f64> = (0..n).map(|j| (j as f64 * 0.37).sin()).collect();
    let mut whole = vec![0.0; n];
    a.mul_into(&x, &mut whole);
    for ranks in 1..=5usize {
        let l = n.div_ceil(ranks);
        for r in 0..ranks {
            let rows = BlockRows::new(a, r * l, l).expect("grouped in blocks");
            let mut y = vec![f64::NAN; l];
            rows.mul_rows_into(&x, r * l, &mut y);
            for (k, &v) in y.iter().enumerate() {
                let want = whole.get(r * l + k).copied().unwrap_or(0.0);
                assert_eq!(
                    v.to_bits(),
                    want.to_bits(),
                    "ranks {ranks} rank {r} row {k}"
                );
            }
            // The sparse rows come back: the same entries (an explicit zero
            // included) and bits.
            let back = rows.to_csr();
            assert_eq!(
                (back.rows, back.cols),
                ((n.min((r + 1) * l)).saturating_sub(r * l), n)
            );
            for k in 0..back.rows {
                let ((c, v), (wc, wv)) = (back.row(k), a.row(r * l + k));
                assert_eq!(c, wc, "ranks {ranks} rank {r} row {k}");
                assert_eq!(bits(v), bits(wv));
            }
            more(ranks, r, &rows, &back);
        }
    }
}

/// Rows of blocks give the bits of the sparse product, whole or split at rows that do
/// not fall on block boundaries, with entries whose sums round and zeros the sparse
/// rows leave out.
#[test]
fn block_rows_give_the_sparse_product_bit_for_bit() {
    let n = 4 * B;
    let mut t = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let h = (i * 31 + j * 17) % 7;
            if h < 3 && (i / B + j / B) % 3 != 2 {
                t.push((i as u32, j as u32, 1.0 / (h as f64 + 3.0) - 0.1 * j as f64));
            }
        }
    }
    t.push((1, 2, 0.0));
    split_rows_give_the_sparse_bits(&Csr::from_triplets(n, n, t), |_, _, _, _| {});
    assert!(BlockRows::new(&Csr::from_triplets(7, 7, vec![]), 0, 7).is_none());
}

/// A symmetric operator: the blocks below the diagonal whose transposes are held are
/// not stored again, and the product and the rows are the sparse ones bit for bit,
/// whole and split (at rows within blocks too). One entry breaks the symmetry of its
/// block pair, which is then stored twice.
#[test]
fn symmetric_rows_store_a_mirrored_block_once_and_give_the_same_bits() {
    let n = 6 * B;
    let mut t = Vec::new();
    for i in 0..n {
        for j in 0..=i {
            let h = (i * 31 + j * 17 + i * j) % 7;
            if h < 4 && (i / B + j / B) % 3 != 2 {
                let v = 1.0 / (h as f64 + 3.0) - 0.1 * (i + j) as f64;
                t.push((i as u32, j as u32, v));
                if i != j {
                    t.push((j as u32, i as u32, v));
                }
            }
        }
    }
    // Not symmetric: row 4 * B, column B (block (4, 1)) against block (1, 4).
    t.push((4 * B as u32, B as u32 + 1, 0.25));
    let a = Csr::from_triplets(n, n, t);
    let mut mirrored_somewhere = false;
    split_rows_give_the_sparse_bits(&a, |ranks, _, rows, back| {
        let stored = rows.stored_blocks();
        let mirrored = rows.slot.iter().filter(|&&s| s & MIRROR != 0).count();
        assert_eq!(stored + mirrored, rows.col.len());
        mirrored_somewhere |= mirrored > 0;
        if ranks == 1 {
            assert_eq!(rows.nnz(), back.idx.len());
            // Every block below the diagonal but the broken pair's is mirrored.
            let below = (0..n / B)
                .map(|i| {
                    let cols = &rows.col[rows.ptr[i]..rows.ptr[i + 1]];
                    cols.iter().filter(|&&j| (j as usize) < i).count()
                })
                .sum::<usize>();
            assert_eq!(mirrored, below - 1);
        }
    });
    assert!(mirrored_somewhere);
}

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
