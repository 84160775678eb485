//! A constant traction on element faces as the nodal forces ccx's own element would take
//! from it (`*CLOAD`): f_a = t * integral of N_a over the face, with N_a the face's shape
//! functions in ccx's element (bilinear on a C3D8's 4-node face, quadratic on a C3D10's
//! 6-node face). ccx's `*DLOAD` has pressures only; a shear traction (Cook's membrane) goes
//! in as these forces. On a flat C3D10 face with straight edges they are 0 at the corners
//! and a third of the face's force at each midside node, the load ccx itself would
//! apply (its manual: "zero (C3D10)" at the vertex nodes).

use crate::api::{norm, Vec3};

/// Gauss points of a 4-node face on [-1, 1]^2 (2 x 2, weight 1 each): exact for the
/// bilinear shape functions times the Jacobian of a flat parallelogram, and of degree 3
/// in each direction on a warped face.
const QUAD_POINTS: [(f64, f64); 4] = {
    const G: f64 = 0.577_350_269_189_625_8; // 1 / sqrt(3)
    [(-G, -G), (G, -G), (G, G), (-G, G)]
};

/// The 6-point rule of degree 4 on the triangle (Strang and Fix): (L2, L3, weight), the
/// weights summing to 1 (times the reference area 1/2). The shape functions are of degree
/// 2 and the Jacobian of a straight-sided face constant: exact there, and of degree 4
/// accuracy on a curved one.
const TRI_POINTS: [(f64, f64, f64); 6] = {
    const A: f64 = 0.445_948_490_915_965;
    const B: f64 = 0.108_103_018_168_070;
    const WA: f64 = 0.223_381_589_678_011;
    const C: f64 = 0.091_576_213_509_771;
    const D: f64 = 0.816_847_572_980_459;
    const WC: f64 = 0.109_951_743_655_322;
    [
        (A, A, WA),
        (B, A, WA),
        (A, B, WA),
        (C, C, WC),
        (D, C, WC),
        (C, D, WC),
    ]
};

/// The integral of each shape function over the face with corner and midside nodes `x`
/// (4: a bilinear quadrilateral in its node order; 6: a quadratic triangle, corners then
/// the midside nodes of edges 1-2, 2-3, 3-1), or `None` for another node count.
pub fn shape_integrals(x: &[Vec3]) -> Option<Vec<f64>> {
    let mut out = vec![0.0; x.len()];
    let mut add = |n: &[f64], dxi: &[f64], deta: &[f64], w: f64| {
        let mut a = [0.0; 3];
        let mut b = [0.0; 3];
        for k in 0..x.len() {
            for i in 0..3 {
                a[i] += dxi[k] * x[k][i];
                b[i] += deta[k] * x[k][i];
            }
        }
        let da = norm(&[
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]);
        for (o, n) in out.iter_mut().zip(n) {
            *o += w * da * n;
        }
    };
    match x.len() {
        4 => {
            let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
            for &(xi, eta) in &QUAD_POINTS {
                let n: Vec<f64> = corners
                    .iter()
                    .map(|(a, b)| 0.25 * (1.0 + a * xi) * (1.0 + b * eta))
                    .collect();
                let dxi: Vec<f64> = corners
                    .iter()
                    .map(|(a, b)| 0.25 * a * (1.0 + b * eta))
                    .collect();
                let deta: Vec<f64> = corners
                    .iter()
                    .map(|(a, b)| 0.25 * b * (1.0 + a * xi))
                    .collect();
                add(&n, &dxi, &deta, 1.0);
            }
        }
        6 => {
            for &(l2, l3, w) in &TRI_POINTS {
                let l1 = 1.0 - l2 - l3;
                let n = [
                    l1 * (2.0 * l1 - 1.0),
                    l2 * (2.0 * l2 - 1.0),
                    l3 * (2.0 * l3 - 1.0),
                    4.0 * l1 * l2,
                    4.0 * l2 * l3,
                    4.0 * l3 * l1,
                ];
                // d/dL2 and d/dL3 with L1 = 1 - L2 - L3.
                let dxi = [
                    1.0 - 4.0 * l1,
                    4.0 * l2 - 1.0,
                    0.0,
                    4.0 * (l1 - l2),
                    4.0 * l3,
                    -4.0 * l3,
                ];
                let deta = [
                    1.0 - 4.0 * l1,
                    0.0,
                    4.0 * l3 - 1.0,
                    -4.0 * l2,
                    4.0 * l2,
                    4.0 * (l1 - l3),
                ];
                add(&n, &dxi, &deta, 0.5 * w);
            }
        }
        _ => return None,
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat quadratic triangle of straight edges: corners 0, midside nodes a third of
    /// the area each (to the rule's rounding, 1e-14 of the area).
    #[test]
    fn a_flat_triangle_loads_its_midside_nodes_only() {
        let c = [[0.0, 0.0, 0.0], [3.0, 0.5, 0.0], [1.0, 2.0, 1.0]];
        let mid = |a: usize, b: usize| -> Vec3 {
            [
                0.5 * (c[a][0] + c[b][0]),
                0.5 * (c[a][1] + c[b][1]),
                0.5 * (c[a][2] + c[b][2]),
            ]
        };
        let x = [c[0], c[1], c[2], mid(0, 1), mid(1, 2), mid(2, 0)];
        let e1 = [3.0, 0.5, 0.0];
        let e2 = [1.0, 2.0, 1.0];
        let area = 0.5
            * norm(&[
                e1[1] * e2[2] - e1[2] * e2[1],
                e1[2] * e2[0] - e1[0] * e2[2],
                e1[0] * e2[1] - e1[1] * e2[0],
            ]);
        let f = shape_integrals(&x).unwrap();
        for (k, fk) in f.iter().enumerate() {
            let expected = if k < 3 { 0.0 } else { area / 3.0 };
            assert!(
                (fk - expected).abs() < 1e-14 * area,
                "{k}: {fk} vs {expected}"
            );
        }
    }

    /// A flat parallelogram: a quarter of its area at each corner; a trapezoid's shares
    /// differ but add up to its area (1e-14: roundings of four products).
    #[test]
    fn quadrilaterals() {
        let x = [
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [3.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
        ];
        for fk in shape_integrals(&x).unwrap() {
            assert!((fk - 0.5).abs() < 1e-14, "{fk}");
        }
        let trapezoid = [
            [0.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [3.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
        ];
        let f = shape_integrals(&trapezoid).unwrap();
        assert!((f.iter().sum::<f64>() - 3.0).abs() < 1e-14, "{f:?}");
        // The longer edge's nodes carry more: (2 * 4 + 2) / 6 = 5/6 each, the shorter
        // edge's (4 + 2 * 2) / 6 = 2/3 (the 1-D consistent loads of a linear width).
        assert!((f[0] - 5.0 / 6.0).abs() < 1e-14 && (f[2] - 2.0 / 3.0).abs() < 1e-14);
        assert!(shape_integrals(&x[..3]).is_none());
    }
}
