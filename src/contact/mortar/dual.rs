//! The dual (biorthogonal) basis of a bilinear slave face: Phi_a = sum_b A_ab N_b with
//! A = D M^-1, M_ab = int N_a N_b, D = diag(int N_a), so that int Phi_a N_b = delta_ab
//! int N_a. A slave node's multiplier then couples to no other slave node, and its
//! constraint is one kinematic row: the node tied to master nodes with weights. On a
//! linear triangle (a sub-triangle of a tet10's face) the same condition gives the
//! closed form Phi_a = 3 L_a - L_b - L_c (the fourth, repeated corner has none).

use super::plane::{jacobian, P2};
use crate::fem::face::shape;

const G3: [(f64, f64); 3] = [
    (-0.774_596_669_241_483_4, 5.0 / 9.0),
    (0.0, 8.0 / 9.0),
    (0.774_596_669_241_483_4, 5.0 / 9.0),
];

/// The coefficients A of the dual basis on the face with in-plane corners `c`, and the
/// integrals of the standard basis (int N_a, the nodes' areas). None for a degenerate face.
pub fn coefficients(c: &[P2; 4]) -> Option<([[f64; 4]; 4], [f64; 4])> {
    // N_a N_b J is of degree 3 in each local coordinate: the 3 x 3 Gauss rule is exact.
    let mut m = nalgebra::Matrix4::<f64>::zeros();
    let mut d = [0.0; 4];
    for (s, ws) in G3 {
        for (t, wt) in G3 {
            let w = ws * wt * jacobian(c, &[s, t]);
            let n = shape(s, t);
            for a in 0..4 {
                d[a] += w * n[a];
                for b in 0..4 {
                    m[(a, b)] += w * n[a] * n[b];
                }
            }
        }
    }
    if d.iter().any(|&x| !(x > 0.0)) {
        return None;
    }
    let inv = m.try_inverse()?;
    let mut a = [[0.0; 4]; 4];
    for (i, row) in a.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = d[i] * inv[(i, j)];
        }
    }
    Some((a, d))
}

/// The dual basis of the linear triangle with in-plane corners `c` (the first three; a
/// triangle's fourth repeats its third) and the nodes' areas (a third of the area each).
/// None for a degenerate triangle.
pub fn triangle_coefficients(c: &[P2; 4]) -> Option<([[f64; 4]; 4], [f64; 4])> {
    let area = 0.5 * super::plane::orient(&c[0], &c[1], &c[2]).abs();
    if !(area > 0.0) {
        return None;
    }
    let a = [
        [3.0, -1.0, -1.0, 0.0],
        [-1.0, 3.0, -1.0, 0.0],
        [-1.0, -1.0, 3.0, 0.0],
        [0.0; 4],
    ];
    Some((a, [area / 3.0, area / 3.0, area / 3.0, 0.0]))
}

/// The dual shape functions at local coordinates `s` of a quadrilateral or, when
/// `triangle`, a triangle (`contact::facet`).
pub fn dual_shape(a: &[[f64; 4]; 4], triangle: bool, s: &P2) -> [f64; 4] {
    let n = if triangle {
        crate::contact::facet::shape(true, s)
    } else {
        shape(s[0], s[1])
    };
    std::array::from_fn(|i| (0..4).map(|j| a[i][j] * n[j]).sum())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn biorthogonality(c: &[P2; 4]) -> f64 {
        let (a, d) = coefficients(c).unwrap();
        let mut worst: f64 = 0.0;
        for i in 0..4 {
            for j in 0..4 {
                let mut q = 0.0;
                for (s, ws) in G3 {
                    for (t, wt) in G3 {
                        let phi = dual_shape(&a, false, &[s, t]);
                        q += ws * wt * jacobian(c, &[s, t]) * phi[i] * shape(s, t)[j];
                    }
                }
                let exact = if i == j { d[i] } else { 0.0 };
                worst = worst.max((q - exact).abs() / d[i]);
            }
        }
        worst
    }

    #[test]
    fn dual_basis_is_biorthogonal() {
        // A square: the textbook coefficients 4, -2, 1, -2.
        let sq = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let (a, _) = coefficients(&sq).unwrap();
        for (j, want) in [4.0, -2.0, 1.0, -2.0].iter().enumerate() {
            assert!((a[0][j] - want).abs() < 1e-13, "{:?}", a[0]);
        }
        // A distorted quadrilateral: biorthogonal to round-off.
        let q = [[0.0, 0.0], [2.0, 0.1], [2.3, 1.7], [-0.2, 1.2]];
        assert!(biorthogonality(&sq) < 1e-14);
        assert!(biorthogonality(&q) < 1e-13);
    }

    #[test]
    fn triangle_dual_basis_is_biorthogonal() {
        // int Phi_a L_b over a triangle by the degree-5 rule (exact for these quadratics):
        // delta_ab times int L_a = area / 3.
        let c = [[0.1, 0.0], [1.3, 0.2], [0.4, 0.9], [0.4, 0.9]];
        let (a, d) = triangle_coefficients(&c).unwrap();
        let area = 0.5 * super::super::plane::orient(&c[0], &c[1], &c[2]);
        for i in 0..3 {
            for j in 0..3 {
                let mut q = 0.0;
                for (l, w) in super::super::plane::TRIANGLE_RULE {
                    let s = [l[1], l[2]];
                    let phi = dual_shape(&a, true, &s);
                    q += w * area * phi[i] * crate::contact::facet::shape(true, &s)[j];
                }
                let exact = if i == j { d[i] } else { 0.0 };
                // Round-off of a few sums of order 1.
                assert!((q - exact).abs() < 1e-15, "{i} {j} {q}");
            }
        }
    }
}
