//! Kinematics at the Gauss points: F = I + h, F^-1 and J, the F-bar mean dilatation, and
//! the small 3x3 helpers (add or remove the identity, scale).

use super::formulation::{ElementFailure, Formulation};
use super::geometry::{
    at, gauss_gradient, gauss_scatter, mean_gradient, GaussGeometry, Geometry, QMat, ZERO_Q,
};
use crate::math::{inverse, Mat3, Vec3, ZERO33};

#[inline]
pub(in crate::fem) fn add_identity(h: &Mat3) -> Mat3 {
    let mut f = *h;
    for (i, row) in f.iter_mut().enumerate() {
        row[i] += 1.0;
    }
    f
}

#[inline]
pub(in crate::fem) fn sub_identity(f: &Mat3) -> Mat3 {
    let mut h = *f;
    for (i, row) in h.iter_mut().enumerate() {
        row[i] -= 1.0;
    }
    h
}

#[inline]
pub(in crate::fem) fn scaled(m: &Mat3, s: f64) -> Mat3 {
    let mut r = *m;
    for row in r.iter_mut() {
        for v in row.iter_mut() {
            *v *= s;
        }
    }
    r
}

/// F, F^-1 and J at each of the eight Gauss points.
pub(in crate::fem) type Deformation = ([Mat3; 8], [Mat3; 8], [f64; 8]);

/// F = I + h, F^-1 and J at every Gauss point; fails if J <= 0 at one.
#[inline]
pub(in crate::fem) fn deformation(h: &QMat) -> Result<Deformation, ElementFailure> {
    let mut f = [ZERO33; 8];
    let mut finv = [ZERO33; 8];
    let mut j = [0.0; 8];
    for q in 0..8 {
        f[q] = add_identity(&at(h, q));
        let (fi, jq) = inverse(&f[q]);
        if !(jq > 0.0) {
            return Err(ElementFailure::InvertedCurrent);
        }
        finv[q] = fi;
        j[q] = jq;
    }
    Ok((f, finv, j))
}

/// Mean-dilatation data for F-bar: the volume-averaged Jacobian J_bar = (1/V0) int J dV0 and
/// its gradient with respect to each node's displacement divided by J_bar,
/// hbar_a = (1/(V0 J_bar)) int J F^-T g_a dV0. Using the average (not the centroid value)
/// keeps the element passing the patch test on distorted meshes.
#[inline]
pub(in crate::fem) fn mean_dilatation(
    geo: &Geometry,
    gauss: &GaussGeometry,
    finv: &[Mat3; 8],
    j: &[f64; 8],
) -> (f64, [Vec3; 8]) {
    let mut jsum = 0.0;
    let mut t = ZERO_Q;
    for q in 0..8 {
        let w = gauss.wdet[q] * j[q];
        jsum += w;
        for i in 0..3 {
            for k in 0..3 {
                // F^-T_ik = Finv_ki
                t[i][k][q] = w * finv[q][k][i];
            }
        }
    }
    let mut hbar = [[0.0; 3]; 8];
    gauss_scatter(&t, gauss, &mut hbar);
    for h in hbar.iter_mut() {
        for v in h.iter_mut() {
            *v /= jsum;
        }
    }
    (jsum / geo.volume, hbar)
}

/// The displacement gradient at each stress point as the constitutive model sees it (the
/// volumetric part replaced by the element mean under `FullBar`), the reference volume
/// weight of each point, and how many points there are.
pub fn point_gradients(
    geo: &Geometry,
    gauss: Option<&GaussGeometry>,
    u: &[Vec3; 8],
    large: bool,
    form: Formulation,
) -> Result<([Mat3; 8], [f64; 8], usize), ElementFailure> {
    let expect = "Gauss-point geometry of a fully integrated element";
    let mut out = [ZERO33; 8];
    match form {
        Formulation::Full => {
            let gauss = gauss.expect(expect);
            let h = gauss_gradient(u, gauss);
            for (q, o) in out.iter_mut().enumerate() {
                *o = at(&h, q);
            }
            Ok((out, gauss.wdet, 8))
        }
        Formulation::FullBar if !large => {
            let gauss = gauss.expect(expect);
            let theta_bar: f64 = (0..8)
                .map(|a| crate::math::dot(&u[a], &geo.bbar_at(a)))
                .sum();
            let h = gauss_gradient(u, gauss);
            for (q, o) in out.iter_mut().enumerate() {
                let mut hq = at(&h, q);
                let shift = (theta_bar - (hq[0][0] + hq[1][1] + hq[2][2])) / 3.0;
                for (i, row) in hq.iter_mut().enumerate() {
                    row[i] += shift;
                }
                *o = hq;
            }
            Ok((out, gauss.wdet, 8))
        }
        Formulation::FullBar => {
            let gauss = gauss.expect(expect);
            let h = gauss_gradient(u, gauss);
            let (fq, finv, jq) = deformation(&h)?;
            let (j0, _) = mean_dilatation(geo, gauss, &finv, &jq);
            for (q, o) in out.iter_mut().enumerate() {
                let ratio = (j0 / jq[q]).cbrt();
                *o = sub_identity(&scaled(&fq[q], ratio));
            }
            Ok((out, gauss.wdet, 8))
        }
        Formulation::Mean { .. } => {
            out[0] = mean_gradient(u, geo);
            let mut w = [0.0; 8];
            w[0] = geo.volume;
            Ok((out, w, 1))
        }
    }
}
