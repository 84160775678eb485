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
    let mut min = f64::INFINITY;
    let mut sum = 0.0;
    for xi in NODE_XI.iter().chain(GAUSS.iter()) {
        let dn = shape_derivatives(xi);
        let d = crate::math::det(&jacobian(x, &dn));
        min = min.min(d);
        sum += d;
    }
    min / (sum / 16.0).abs().max(f64::MIN_POSITIVE)
}
