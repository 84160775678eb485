//! The composite tetrahedron's consistent tangent matrix for a small-kinematics J2 body
//! (`fem::consistent`): the stress points' part from the projected gradients and the
//! stabilization's, which is linear in u: (k/2) sum_s V_s |D_s|^2 differentiates twice to
//! k sum_s V_s D_s(e_i) : D_s(e_j).

use super::composite::Geometry;
use super::kernel::{linear_parts, point_gradients, stiffness, STRESS_POINTS};
use crate::fem::consistent::{add_products, point_moduli, small_j2};
use crate::fem::Formulation;
use crate::material::{Material, PlasticState};
use crate::math::Vec3;

/// The 30 x 30 tangent (column j at `30 j`, the degrees of freedom node by node) at `u`
/// from the committed history `hist`, into `k` (overwritten); false (k untouched) for
/// other materials or a missing history.
pub fn consistent_matrix(
    geo: &Geometry,
    u: &[Vec3; 10],
    mat: &Material,
    form: Formulation,
    hist: &[PlasticState],
    k: &mut [f64],
) -> bool {
    let Some(m) = small_j2(mat) else {
        return false;
    };
    if hist.len() < STRESS_POINTS || k.len() != 900 {
        return false;
    }
    let moduli = point_moduli(m, &point_gradients(geo, u, form), &hist[..STRESS_POINTS]);
    let (mut dh, mut ds) = (Vec::with_capacity(120), Vec::with_capacity(360));
    for j in 0..30 {
        let mut e = [[0.0; 3]; 10];
        e[j / 3][j % 3] = 1.0;
        let (p, d) = linear_parts(geo, &e, form);
        dh.extend_from_slice(&p);
        ds.extend_from_slice(&d);
    }
    k.iter_mut().for_each(|v| *v = 0.0);
    add_products(&dh, &geo.w, |q, d| moduli[q].apply(d), k);
    let ks = stiffness(mat);
    let vol: Vec<f64> = geo.vol.iter().map(|v| ks * v).collect();
    add_products(&ds, &vol, |_, d| *d, k);
    true
}
