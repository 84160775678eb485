//! Element-average Cauchy stress, weighted by the current volume.

use super::geometry::{geometry, GaussGeometry, Geometry};
use super::kinematics::{add_identity, point_gradients, scaled};
use super::{ElementFailure, Formulation};
use crate::material::{Material, PlasticState};
use crate::math::{det, Mat3, Vec3, ZERO33};

#[inline]
fn add_scaled(d: &mut Mat3, m: &Mat3, w: f64) {
    for i in 0..3 {
        for k in 0..3 {
            d[i][k] += w * m[i][k];
        }
    }
}

/// Element-average Cauchy stress (current-volume weighted), order xx yy zz xy yz zx.
pub fn average_cauchy(
    x: &[Vec3; 8],
    u: &[Vec3; 8],
    mat: &Material,
    form: Formulation,
) -> Result<[f64; 6], ElementFailure> {
    let (geo, gauss) = geometry(x)?;
    average_cauchy_with(&geo, Some(&gauss), u, mat, form, &[])
}

/// `average_cauchy` with the element's reference geometry already computed. `gauss` may
/// be `None` for `Formulation::Mean` only; `hist` as in `internal_force_with`.
pub fn average_cauchy_with(
    geo: &Geometry,
    gauss: Option<&GaussGeometry>,
    u: &[Vec3; 8],
    mat: &Material,
    form: Formulation,
    hist: &[PlasticState],
) -> Result<[f64; 6], ElementFailure> {
    let mut sum = ZERO33;
    let mut vol = 0.0;
    let (h, w, n) = point_gradients(geo, gauss, u, mat.is_large(), form)?;
    let virgin = PlasticState::default();
    for q in 0..n {
        let s = mat
            .cauchy(&h[q], hist.get(q).unwrap_or(&virgin))
            .ok_or(ElementFailure::InvertedCurrent)?;
        let jw = if mat.is_large() {
            w[q] * det(&add_identity(&h[q]))
        } else {
            w[q]
        };
        add_scaled(&mut sum, &s, jw);
        vol += jw;
    }
    let s = scaled(&sum, 1.0 / vol);
    let out = crate::math::to_sym6(&s);
    if out.iter().all(|v| v.is_finite()) {
        Ok(out)
    } else {
        Err(ElementFailure::NonFinite)
    }
}
