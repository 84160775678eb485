//! The consistent tangent matrix of an element of a small-kinematics J2 body, assembled
//! from its stress points instead of probed: the element's force is
//! f_i = sum_q w_q sigma_q : dH_q/du_i with the point gradients H_q linear in u (hex8
//! fully integrated or B-bar, the composite tet10 in either form), so its derivative is
//! K_ij = sum_q w_q dH_q(e_i) : C_q : dH_q(e_j), C_q the point's algorithmic moduli
//! (`J2Plastic::surface_moduli`), plus whatever the element adds that is linear in u (the
//! composite tetrahedron's stabilization). Symmetric by construction (C_q has the major
//! symmetry; the upper triangle is computed and mirrored).

use crate::material::{J2Plastic, Material, Moduli, PlasticState};
use crate::math::Mat3;

/// The J2 model of a small-kinematics plastic material, the only one whose element
/// tangent is assembled here.
pub fn small_j2(mat: &Material) -> Option<&J2Plastic> {
    match mat {
        Material::J2Plastic(m) if !m.large => Some(m),
        _ => None,
    }
}

/// Every point's moduli at its gradient `h[q]` from its committed state `hist[q]`.
pub fn point_moduli(m: &J2Plastic, h: &[Mat3], hist: &[PlasticState]) -> Vec<Moduli> {
    h.iter()
        .zip(hist)
        .map(|(hq, old)| m.surface_moduli(hq, old))
        .collect()
}

/// k += sum_q w_q dh(e_i)_q : stress_q(dh(e_j)_q), where `dh[j * points + q]` is point q's
/// gradient of the unit displacement of degree of freedom j and `stress(q, d)` is linear
/// and symmetric in the pairing (k is n x n, column j at `j * n`, n = dh.len() / points).
pub fn add_products(dh: &[Mat3], w: &[f64], stress: impl Fn(usize, &Mat3) -> Mat3, k: &mut [f64]) {
    let points = w.len();
    let n = dh.len() / points;
    let s: Vec<Mat3> = dh
        .iter()
        .enumerate()
        .map(|(i, d)| stress(i % points, d))
        .collect();
    for j in 0..n {
        for i in 0..=j {
            let mut sum = 0.0;
            for q in 0..points {
                let (a, b) = (&dh[i * points + q], &s[j * points + q]);
                let mut c = 0.0;
                for r in 0..3 {
                    for t in 0..3 {
                        c += a[r][t] * b[r][t];
                    }
                }
                sum += w[q] * c;
            }
            k[j * n + i] += sum;
            if i != j {
                k[i * n + j] += sum;
            }
        }
    }
}
