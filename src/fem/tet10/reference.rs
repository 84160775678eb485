//! The 10-node tetrahedron's reference element: nodes, faces, edges, quadrature and the
//! quadratic isoparametric map (what `fem::kind` asks of the kind; no kernel here).

use crate::math::{det, Mat3, Vec3};

pub const NODE_XI: [[f64; 3]; 10] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [0.5, 0.0, 0.0],
    [0.5, 0.5, 0.0],
    [0.0, 0.5, 0.0],
    [0.0, 0.0, 0.5],
    [0.5, 0.0, 0.5],
    [0.0, 0.5, 0.5],
];

/// The corner pair of each midside node 4..9.
pub const MIDSIDE: [(usize, usize); 6] = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)];

/// Faces: 0 (y = 0), 1 (the slanted face), 2 (x = 0), 3 (z = 0).
pub const FACES: [[usize; 6]; 4] = [
    [0, 1, 3, 4, 8, 7],
    [1, 2, 3, 5, 9, 8],
    [0, 3, 2, 7, 9, 6],
    [0, 2, 1, 6, 5, 4],
];

/// The edges of the node graph: each edge's two halves (corner to midside node) and the
/// segments between midside nodes of one face and across the element (the edges of the
/// composite element's linear sub-tetrahedra), so that every node is linked to the nodes
/// it shares a sub-tetrahedron with.
pub const EDGES: [(usize, usize); 27] = [
    (0, 4),
    (4, 1),
    (1, 5),
    (5, 2),
    (2, 6),
    (6, 0),
    (0, 7),
    (7, 3),
    (1, 8),
    (8, 3),
    (2, 9),
    (9, 3),
    (4, 8),
    (8, 7),
    (7, 4),
    (5, 9),
    (9, 8),
    (8, 5),
    (7, 9),
    (9, 6),
    (6, 7),
    (6, 5),
    (5, 4),
    (4, 6),
    (4, 9),
    (5, 7),
    (6, 8),
];

pub(super) const A: f64 = 0.585_410_196_624_968_5; // (5 + 3 sqrt 5) / 20
pub(super) const B: f64 = 0.138_196_601_125_010_5; // (5 - sqrt 5) / 20

/// The 4-point rule, exact for quadratic integrands (weights 1/24: the reference volume
/// is 1/6).
pub const QUADRATURE: [[f64; 3]; 4] = [[B, B, B], [A, B, B], [B, A, B], [B, B, A]];

/// The weights of `QUADRATURE`.
pub const WEIGHTS: [f64; 4] = [1.0 / 24.0; 4];

/// Shape functions of the quadratic tetrahedron at a reference point.
#[inline]
pub fn shape(xi: &[f64; 3]) -> [f64; 10] {
    let l = barycentric(xi);
    let mut n = [0.0; 10];
    for a in 0..4 {
        n[a] = l[a] * (2.0 * l[a] - 1.0);
    }
    for (m, &(i, j)) in MIDSIDE.iter().enumerate() {
        n[4 + m] = 4.0 * l[i] * l[j];
    }
    n
}

/// Derivatives of the quadratic shape functions with respect to the reference
/// coordinates.
#[inline]
pub fn shape_derivatives(xi: &[f64; 3]) -> [Vec3; 10] {
    let l = barycentric(xi);
    // dL_a / dxi: L0 = 1 - xi - eta - zeta, L1 = xi, L2 = eta, L3 = zeta.
    const DL: [Vec3; 4] = [
        [-1.0, -1.0, -1.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let mut d = [[0.0; 3]; 10];
    for a in 0..4 {
        for k in 0..3 {
            d[a][k] = (4.0 * l[a] - 1.0) * DL[a][k];
        }
    }
    for (m, &(i, j)) in MIDSIDE.iter().enumerate() {
        for k in 0..3 {
            d[4 + m][k] = 4.0 * (DL[i][k] * l[j] + l[i] * DL[j][k]);
        }
    }
    d
}

#[inline]
fn barycentric(xi: &[f64; 3]) -> [f64; 4] {
    [1.0 - xi[0] - xi[1] - xi[2], xi[0], xi[1], xi[2]]
}

/// Jacobian J_ij = dX_i / dxi_j of the quadratic map.
#[inline]
pub fn jacobian(x: &[Vec3; 10], dn: &[Vec3; 10]) -> Mat3 {
    let mut j = [[0.0; 3]; 3];
    for a in 0..10 {
        for i in 0..3 {
            for k in 0..3 {
                j[i][k] += x[a][i] * dn[a][k];
            }
        }
    }
    j
}

/// Smallest Jacobian determinant of the quadratic map over the nodes and the quadrature
/// points, relative to their mean; non-positive means inverted or degenerate.
pub fn min_jacobian_ratio(x: &[Vec3; 10]) -> f64 {
    let mut min = f64::INFINITY;
    let mut sum = 0.0;
    for xi in NODE_XI.iter().chain(QUADRATURE.iter()) {
        let d = det(&jacobian(x, &shape_derivatives(xi)));
        min = min.min(d);
        sum += d;
    }
    min / (sum / 14.0).abs().max(f64::MIN_POSITIVE)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shape_functions_interpolate_the_nodes_and_sum_to_one() {
        for (a, xi) in NODE_XI.iter().enumerate() {
            let n = shape(xi);
            for (b, &nb) in n.iter().enumerate() {
                // Exact small integers and halves: any error is a wrong formula.
                assert!((nb - if a == b { 1.0 } else { 0.0 }).abs() < 1e-15);
            }
        }
        let d = shape_derivatives(&[0.2, 0.3, 0.1]);
        for k in 0..3 {
            // Partition of unity: the derivatives sum to zero up to rounding (~1e-15).
            assert!(d.iter().map(|v| v[k]).sum::<f64>().abs() < 1e-14);
        }
    }

    #[test]
    fn midside_nodes_sit_halfway_and_faces_point_outwards() {
        for (m, &(i, j)) in MIDSIDE.iter().enumerate() {
            for k in 0..3 {
                assert_eq!(NODE_XI[4 + m][k], 0.5 * (NODE_XI[i][k] + NODE_XI[j][k]));
            }
        }
        let centre = [0.25; 3];
        for f in FACES {
            let p = |a: usize| NODE_XI[f[a]];
            let n = crate::math::cross(
                &crate::math::sub(&p(1), &p(0)),
                &crate::math::sub(&p(2), &p(0)),
            );
            assert!(crate::math::dot(&n, &crate::math::sub(&p(0), &centre)) > 0.0);
            for (m, (a, b)) in [(0, 1), (1, 2), (2, 0)].into_iter().enumerate() {
                let mid = f[3 + m] - 4;
                let pair = MIDSIDE[mid];
                assert!(pair == (f[a], f[b]) || pair == (f[b], f[a]));
            }
        }
    }

    #[test]
    fn the_reference_element_is_regular_and_a_flipped_one_is_not() {
        let x = NODE_XI;
        assert!((min_jacobian_ratio(&x) - 1.0).abs() < 1e-14);
        let mut y = x;
        y.swap(1, 2);
        y.swap(4, 6);
        y.swap(8, 9);
        assert!(min_jacobian_ratio(&y) < 0.0);
    }
}
