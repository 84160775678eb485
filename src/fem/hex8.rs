//! The trilinear 8-node hexahedron on the reference cube [-1, 1]^3.
//!
//! Node order: (-1,-1,-1), (1,-1,-1), (1,1,-1), (-1,1,-1), then the same four at zeta = +1.
//! Local faces follow the Exodus side order (0-based), each listed so that its normal
//! (by the right-hand rule) points out of the element.

use crate::math::{inverse, Mat3, Vec3};

pub const NODE_XI: [[f64; 3]; 8] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
];

/// Faces: 0 (-y), 1 (+x), 2 (+y), 3 (-x), 4 (-z), 5 (+z).
pub const FACES: [[usize; 4]; 6] = [
    [0, 1, 5, 4],
    [1, 2, 6, 5],
    [2, 3, 7, 6],
    [0, 4, 7, 3],
    [0, 3, 2, 1],
    [4, 5, 6, 7],
];

/// The edges, as local node pairs.
pub const EDGES: [(usize, usize); 12] = [
    (0, 1),
    (1, 2),
    (2, 3),
    (3, 0),
    (4, 5),
    (5, 6),
    (6, 7),
    (7, 4),
    (0, 4),
    (1, 5),
    (2, 6),
    (3, 7),
];

const G: f64 = 0.577_350_269_189_625_8; // 1/sqrt(3)

/// The 2x2x2 Gauss points (all weights are 1).
pub const GAUSS: [[f64; 3]; 8] = [
    [-G, -G, -G],
    [G, -G, -G],
    [G, G, -G],
    [-G, G, -G],
    [-G, -G, G],
    [G, -G, G],
    [G, G, G],
    [-G, G, G],
];

/// Shape functions at a reference point.
#[inline]
pub fn shape(xi: &[f64; 3]) -> [f64; 8] {
    let mut n = [0.0; 8];
    for (a, na) in n.iter_mut().enumerate() {
        let p = NODE_XI[a];
        *na = 0.125 * (1.0 + xi[0] * p[0]) * (1.0 + xi[1] * p[1]) * (1.0 + xi[2] * p[2]);
    }
    n
}

/// Derivatives of the shape functions with respect to the reference coordinates.
#[inline]
pub fn shape_derivatives(xi: &[f64; 3]) -> [Vec3; 8] {
    let mut d = [[0.0; 3]; 8];
    for (a, da) in d.iter_mut().enumerate() {
        let p = NODE_XI[a];
        let fx = 1.0 + xi[0] * p[0];
        let fy = 1.0 + xi[1] * p[1];
        let fz = 1.0 + xi[2] * p[2];
        *da = [
            0.125 * p[0] * fy * fz,
            0.125 * p[1] * fx * fz,
            0.125 * p[2] * fx * fy,
        ];
    }
    d
}

/// Jacobian J_ij = dX_i / dxi_j.
#[inline]
pub fn jacobian(x: &[Vec3; 8], dn: &[Vec3; 8]) -> Mat3 {
    let mut j = [[0.0; 3]; 3];
    for a in 0..8 {
        for i in 0..3 {
            for k in 0..3 {
                j[i][k] += x[a][i] * dn[a][k];
            }
        }
    }
    j
}

/// Physical gradients of the shape functions at `xi` and det J; `None` if det J <= 0.
#[inline]
pub fn gradients(x: &[Vec3; 8], xi: &[f64; 3]) -> Option<([Vec3; 8], f64)> {
    let dn = shape_derivatives(xi);
    let j = jacobian(x, &dn);
    let (jinv, det) = inverse(&j);
    if !(det > 0.0) || !det.is_finite() {
        return None;
    }
    let mut g = [[0.0; 3]; 8];
    for a in 0..8 {
        for k in 0..3 {
            // dN/dX_k = sum_m dN/dxi_m dxi_m/dX_k = sum_m dn[a][m] jinv[m][k]
            g[a][k] = dn[a][0] * jinv[0][k] + dn[a][1] * jinv[1][k] + dn[a][2] * jinv[2][k];
        }
    }
    Some((g, det))
}

/// Smallest Jacobian determinant over the corners and Gauss points, relative to the
/// element's mean; non-positive means inverted or degenerate.
pub fn min_jacobian_ratio(x: &[Vec3; 8]) -> f64 {
    // The map in monomials, x = c0 + c1 xi + c2 eta + c3 zeta + c4 xi eta + c5 eta zeta
    // + c6 zeta xi + c7 xi eta zeta (c_m = 1/8 sum_a s_m(a) x_a with s_m the monomial at
    // node a), so each Jacobian column is a few terms: a pass over every element of a
    // mesh at set-up (a quarter of the work of `jacobian` at 16 points).
    let mut c = [[0.0; 3]; 8];
    for (a, xa) in x.iter().enumerate() {
        let p = NODE_XI[a];
        let s = [
            1.0,
            p[0],
            p[1],
            p[2],
            p[0] * p[1],
            p[1] * p[2],
            p[2] * p[0],
            p[0] * p[1] * p[2],
        ];
        for (cm, sm) in c.iter_mut().zip(s) {
            for i in 0..3 {
                cm[i] += 0.125 * sm * xa[i];
            }
        }
    }
    let mut min = f64::INFINITY;
    let mut sum = 0.0;
    for &[u, v, w] in NODE_XI.iter().chain(GAUSS.iter()) {
        let j: Mat3 = std::array::from_fn(|i| {
            [
                c[1][i] + c[4][i] * v + c[6][i] * w + c[7][i] * v * w,
                c[2][i] + c[4][i] * u + c[5][i] * w + c[7][i] * u * w,
                c[3][i] + c[5][i] * v + c[6][i] * u + c[7][i] * u * v,
            ]
        });
        let d = crate::math::det(&j);
        min = min.min(d);
        sum += d;
    }
    min / (sum / 16.0).abs().max(f64::MIN_POSITIVE)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The ratio from `jacobian` at the 16 points, as the definition reads.
    fn by_definition(x: &[Vec3; 8]) -> f64 {
        let d: Vec<f64> = NODE_XI
            .iter()
            .chain(GAUSS.iter())
            .map(|xi| crate::math::det(&jacobian(x, &shape_derivatives(xi))))
            .collect();
        let min = d.iter().copied().fold(f64::INFINITY, f64::min);
        min / (d.iter().sum::<f64>() / 16.0).abs()
    }

    #[test]
    fn min_jacobian_ratio_is_the_definition_in_monomials() {
        // A distorted element, a sheared one and an inverted one (two nodes swapped): the
        // same ratio to round-off (1e-13 of the ratio: a few operations in another order).
        let mut x: [Vec3; 8] = std::array::from_fn(|a| NODE_XI[a].map(|p| 1.7 * (1.0 + p)));
        for (a, v) in x.iter_mut().enumerate() {
            v[0] += 0.4 * ((a * 7 % 5) as f64 / 5.0 - 0.4);
            v[1] += 0.9 * v[2] - 0.3 * ((a * 3 % 4) as f64 / 4.0);
        }
        let mut y = x;
        y.swap(0, 6);
        for e in [x, y] {
            let (r, d) = (min_jacobian_ratio(&e), by_definition(&e));
            assert!((r - d).abs() <= 1e-13 * d.abs().max(1.0), "{r} against {d}");
        }
        assert!(min_jacobian_ratio(&x) > 0.0 && min_jacobian_ratio(&y) < 0.0);
        let cube: [Vec3; 8] = std::array::from_fn(|a| NODE_XI[a]);
        assert!((min_jacobian_ratio(&cube) - 1.0).abs() < 1e-15);
    }
}
