//! The composite 10-node tetrahedron's reference geometry: its twelve linear
//! sub-tetrahedra, the L2 projection of their constant displacement gradients onto a field
//! linear over the element, and the weights of its four integration points.
//!
//! The element (Thoutireddy, Molinari, Repetto and Ortiz, IJNME 55, 2002; the "composite
//! tet10" of Sierra/SM in the form of Ostien, Foulk, Mota and Veilleux, IJNME 107, 2016):
//!
//! - The ten nodes and an auxiliary eleventh at the mean of the six midside nodes (its
//!   displacement is their mean, so it adds no unknowns) span twelve linear tetrahedra:
//!   one at each corner and eight filling the inner octahedron around the auxiliary node.
//!   The displacement is linear on each, so each has a constant gradient H_s. The nodal
//!   shape functions are these piecewise-linear hats: non-negative, so lumped masses,
//!   nodal volumes and contact tractions are positive.
//! - The assumed gradient H̄ is linear over the element, H̄(X) = sum_k lambda_k H̄_k with
//!   lambda_k the parent tetrahedron's barycentric coordinates (linear on each
//!   sub-tetrahedron through its affine map), and is the L2 projection of the H_s:
//!   int lambda_k (H̄ - H_s) dV = 0 for k = 0..3, i.e. sum_l M_kl H̄_l = sum_s V_s
//!   m_sk H_s with M_kl = int lambda_k lambda_l dV (exact on each sub-tetrahedron) and
//!   m_sk the mean of lambda_k over sub-tetrahedron s. Hence H̄_k = sum_s c_ks H_s with
//!   c_ks = V_s sum_l (M^-1)_kl m_sl, and sum_s c_ks = 1: a linear displacement field
//!   (every H_s the same) is reproduced exactly, on any shape.
//! - Stress is evaluated at the four points of the parent's 4-point rule. Their weights are
//!   the ones that integrate every linear function of the parent coordinates exactly over
//!   the element's reference volume (w_q = int phi_q dV, phi_q the linear function that is 1
//!   at point q and 0 at the others), so that sum_q w_q grad_bar N_a(q) = int grad N_a dV:
//!   a constant stress gives the exact nodal forces (the patch test) also when the
//!   midside nodes are off the edges' midpoints. On a straight-sided element every weight
//!   is V/4.

use super::reference::{A, B};
use crate::fem::ElementFailure;
use crate::math::{det, inverse, Mat3, Vec3};

/// The twelve sub-tetrahedra as local node lists (node 10 is the auxiliary node), each
/// ordered so that its volume is positive in a valid element: the four corner ones, then
/// the eight around the auxiliary node, one on each face of the inner octahedron.
pub const SUB_TETS: [[usize; 4]; 12] = [
    [0, 4, 6, 7],
    [1, 5, 4, 8],
    [2, 6, 5, 9],
    [3, 8, 7, 9],
    [4, 6, 7, 10],
    [4, 8, 5, 10],
    [5, 9, 6, 10],
    [7, 9, 8, 10],
    [4, 7, 8, 10],
    [5, 8, 9, 10],
    [7, 6, 9, 10],
    [6, 4, 5, 10],
];

/// The parent's barycentric coordinates at the eleven nodes: a corner's are a unit vector,
/// a midside node's are halves at its edge's corners, the auxiliary node's are quarters.
pub(super) const LAMBDA: [[f64; 4]; 11] = lambda_at_nodes();

const fn lambda_at_nodes() -> [[f64; 4]; 11] {
    let mut l = [[0.0; 4]; 11];
    let mut a = 0;
    while a < 4 {
        l[a][a] = 1.0;
        l[10][a] = 0.25;
        a += 1;
    }
    let mut m = 0;
    while m < 6 {
        let (i, j) = super::MIDSIDE[m];
        l[4 + m][i] = 0.5;
        l[4 + m][j] = 0.5;
        m += 1;
    }
    l
}

/// The mean of each barycentric coordinate over each sub-tetrahedron (the mean of its
/// vertices' values): `MEAN_LAMBDA[s][k]`.
pub(super) const MEAN_LAMBDA: [[f64; 4]; 12] = mean_lambda();

const fn mean_lambda() -> [[f64; 4]; 12] {
    let mut m = [[0.0; 4]; 12];
    let mut s = 0;
    while s < 12 {
        let mut v = 0;
        while v < 4 {
            let mut k = 0;
            while k < 4 {
                m[s][k] += 0.25 * LAMBDA[SUB_TETS[s][v]][k];
                k += 1;
            }
            v += 1;
        }
        s += 1;
    }
    m
}

/// The barycentric coordinates of the integration points (`tet10::QUADRATURE`): point q
/// has A at corner q and B at the others.
#[inline(always)]
pub(super) fn point_lambda(q: usize, k: usize) -> f64 {
    if q == k {
        A
    } else {
        B
    }
}

/// Reference-configuration data of one composite tetrahedron, computed once (`geometry`)
/// and reused for every evaluation. 1384 bytes.
#[derive(Clone, Debug)]
pub struct Geometry {
    /// Per sub-tetrahedron, the inverse of its edge matrix [X_1 - X_0, X_2 - X_0, X_3 - X_0]
    /// (vertices in `SUB_TETS` order): row i is the gradient of vertex i+1's hat function.
    pub(super) jinv: [Mat3; 12],
    /// Reference volume of each sub-tetrahedron.
    pub(super) vol: [f64; 12],
    /// The projection: H̄_k = sum_s c[k][s] H_s at the parent's corners k.
    pub(super) c: [[f64; 12]; 4],
    /// Weights of the four integration points (reference volume).
    pub(super) w: [f64; 4],
    /// Reference volume of the element.
    pub(super) volume: f64,
}

/// The element's reference geometry from its ten node positions. Fails with
/// `InvertedReference` if a sub-tetrahedron has a non-positive volume or an integration
/// weight is non-positive (an element too curved to integrate).
pub fn geometry(x: &[Vec3; 10]) -> Result<Geometry, ElementFailure> {
    let xc = auxiliary(x);
    let at = |v: usize| if v == 10 { xc } else { x[v] };
    let mut jinv = [[[0.0; 3]; 3]; 12];
    let mut vol = [0.0; 12];
    for (s, t) in SUB_TETS.iter().enumerate() {
        let p0 = at(t[0]);
        let mut e = [[0.0; 3]; 3];
        for i in 0..3 {
            let p = at(t[i + 1]);
            for k in 0..3 {
                e[k][i] = p[k] - p0[k];
            }
        }
        let d = det(&e);
        if !(d > 0.0) || !d.is_finite() {
            return Err(ElementFailure::InvertedReference);
        }
        jinv[s] = inverse(&e).0;
        vol[s] = d / 6.0;
    }
    let volume: f64 = vol.iter().sum();
    let (c, integral) = projection(&vol)?;
    // w = L^-1 I with L_qk = A on the diagonal and B off it: L^-1 = (Id - B 1 1^T)/(A - B)
    // since A + 3 B = 1.
    let w: [f64; 4] = std::array::from_fn(|q| (integral[q] - B * volume) / (A - B));
    if w.iter().any(|&wq| !(wq > 0.0)) {
        return Err(ElementFailure::InvertedReference);
    }
    Ok(Geometry {
        jinv,
        vol,
        c,
        w,
        volume,
    })
}

/// The auxiliary node: the mean of the six midside nodes.
#[inline]
fn auxiliary(x: &[Vec3; 10]) -> Vec3 {
    let mut c = [0.0; 3];
    for p in &x[4..] {
        for k in 0..3 {
            c[k] += p[k] / 6.0;
        }
    }
    c
}

/// The projection coefficients c[k][s] and the integrals of the barycentric coordinates,
/// from the sub-tetrahedra's volumes.
fn projection(vol: &[f64; 12]) -> Result<([[f64; 12]; 4], [f64; 4]), ElementFailure> {
    // int_s f g dV = V_s / 20 (sum_v f_v g_v + (sum_v f_v)(sum_v g_v)) for f, g linear on
    // a tetrahedron, with sum_v f_v = 4 m_s.
    let mut m = [[0.0; 4]; 4];
    let mut integral = [0.0; 4];
    for (s, t) in SUB_TETS.iter().enumerate() {
        let ml = &MEAN_LAMBDA[s];
        for k in 0..4 {
            integral[k] += vol[s] * ml[k];
            for l in 0..4 {
                let mut vv = 0.0;
                for &v in t {
                    vv += LAMBDA[v][k] * LAMBDA[v][l];
                }
                m[k][l] += vol[s] / 20.0 * (vv + 16.0 * ml[k] * ml[l]);
            }
        }
    }
    let minv = inverse4(&m).ok_or(ElementFailure::InvertedReference)?;
    let mut c = [[0.0; 12]; 4];
    for k in 0..4 {
        for s in 0..12 {
            let mut v = 0.0;
            for l in 0..4 {
                v += minv[k][l] * MEAN_LAMBDA[s][l];
            }
            c[k][s] = vol[s] * v;
        }
    }
    Ok((c, integral))
}

/// Inverse of a 4x4 matrix by Gauss-Jordan elimination with partial pivoting (`None` if
/// singular).
fn inverse4(m: &[[f64; 4]; 4]) -> Option<[[f64; 4]; 4]> {
    let mut a = *m;
    let mut inv = [[0.0; 4]; 4];
    for (i, row) in inv.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for col in 0..4 {
        let p = (col..4).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if !(a[p][col].abs() > 0.0) {
            return None;
        }
        a.swap(col, p);
        inv.swap(col, p);
        let d = 1.0 / a[col][col];
        for j in 0..4 {
            a[col][j] *= d;
            inv[col][j] *= d;
        }
        for r in 0..4 {
            if r != col {
                let f = a[r][col];
                for j in 0..4 {
                    a[r][j] -= f * a[col][j];
                    inv[r][j] -= f * inv[col][j];
                }
            }
        }
    }
    Some(inv)
}

/// The gradient of each node's composite shape function on each sub-tetrahedron
/// (`g[s][a]`), the auxiliary node's share handed to the midside nodes.
pub(super) fn shape_gradients(geo: &Geometry) -> [[Vec3; 10]; 12] {
    let mut g = [[[0.0; 3]; 10]; 12];
    for (s, t) in SUB_TETS.iter().enumerate() {
        let j = &geo.jinv[s];
        let g0 = [
            -(j[0][0] + j[1][0] + j[2][0]),
            -(j[0][1] + j[1][1] + j[2][1]),
            -(j[0][2] + j[1][2] + j[2][2]),
        ];
        for (v, &node) in t.iter().enumerate() {
            let gv = if v == 0 { g0 } else { j[v - 1] };
            if node == 10 {
                for ga in g[s][4..].iter_mut() {
                    for k in 0..3 {
                        ga[k] += gv[k] / 6.0;
                    }
                }
            } else {
                for k in 0..3 {
                    g[s][node][k] += gv[k];
                }
            }
        }
    }
    g
}

/// The integral of each node's composite (piecewise-linear) shape function over the
/// reference element: every one positive, summing to the element's volume. Body forces
/// and lumped quantities use it.
pub fn nodal_volumes(geo: &Geometry) -> [f64; 10] {
    let mut n = [0.0; 10];
    for (s, t) in SUB_TETS.iter().enumerate() {
        let q = geo.vol[s] / 4.0;
        for &node in t {
            if node == 10 {
                for na in n[4..].iter_mut() {
                    *na += q / 6.0;
                }
            } else {
                n[node] += q;
            }
        }
    }
    n
}

/// The element's reference volume.
pub fn volume(geo: &Geometry) -> f64 {
    geo.volume
}
