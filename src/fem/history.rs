//! Integration-point history of plastic elements: where the stress points are, the
//! displacement gradient each sees (with the B-bar / F-bar modification), the update of the
//! state a converged step commits, the element-mean equivalent plastic strain, and the
//! diagonal tangent blocks of a plastic B-bar / F-bar element.

use super::element::{
    add_tangent, at, centre, deformation, forces, g_at, gauss_gradient, hourglass_sums,
    mean_dilatation, mean_gradient, modes, scaled, sub_identity, ElementFailure, Formulation,
    GaussGeometry, Geometry, Hourglass, Stabilization, Stiffness, SLOTS,
};
use crate::material::{Material, PlasticState};
use crate::math::{Mat3, Vec3, ZERO33};

/// History states of a plastic element: one per Gauss point, or the mean point's followed
/// by the `SLOTS` that hold its hourglass state (`element::hourglass`).
#[inline]
pub fn points(form: Formulation) -> usize {
    match form {
        Formulation::Mean { .. } => 1 + SLOTS,
        _ => 8,
    }
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

/// The states a converged step commits: `new[q]` from `old[q]` at the displacements `u`.
pub fn update_with(
    geo: &Geometry,
    gauss: Option<&GaussGeometry>,
    u: &[Vec3; 8],
    mat: &Material,
    form: Formulation,
    old: &[PlasticState],
    new: &mut [PlasticState],
) -> Result<(), ElementFailure> {
    if let Formulation::Mean { hourglass } = form {
        return update_mean(geo, u, mat, hourglass, old, new);
    }
    let (h, _, n) = point_gradients(geo, gauss, u, mat.is_large(), form)?;
    for q in 0..n {
        new[q] = mat
            .update(&h[q], &old[q])
            .ok_or(ElementFailure::InvertedCurrent)?
            .state;
    }
    Ok(())
}

/// The states a converged step commits in a plastic one-point element: the centre's and
/// the hourglass state (the forces of the step, the displacement sums, and the centre's
/// deviatoric strain and stress), the same values `internal_force_with` used.
fn update_mean(
    geo: &Geometry,
    u: &[Vec3; 8],
    mat: &Material,
    control: Stabilization,
    old: &[PlasticState],
    new: &mut [PlasticState],
) -> Result<(), ElementFailure> {
    let h = mean_gradient(u, geo);
    let c = centre(mat, &h, old).ok_or(ElementFailure::InvertedCurrent)?;
    let (_, mu) = mat.lambda_mu();
    let hx = hourglass_sums(geo);
    let k = Stiffness::new(geo, control, mat);
    let q = modes(u, &h, &hx);
    new[0] = c.state;
    Hourglass {
        force: forces(&q, &k, mu, geo, &c),
        q,
        strain: super::element::dev_sym(&h),
        stress: super::element::dev_sym(&c.stress),
    }
    .write(&mut new[1..]);
    Ok(())
}

/// Reference-volume average of the equivalent plastic strain over the element's points.
pub fn mean_eqps(
    geo: &Geometry,
    gauss: Option<&GaussGeometry>,
    form: Formulation,
    hist: &[PlasticState],
) -> f64 {
    match form {
        Formulation::Mean { .. } => hist[0].eqps,
        _ => {
            let w = &gauss.expect("Gauss-point geometry").wdet;
            let s: f64 = (0..8).map(|q| w[q] * hist[q].eqps).sum();
            s / geo.volume
        }
    }
}

/// Diagonal blocks of a plastic `FullBar` element: the deviatoric part of the consistent
/// tangent with each Gauss point's gradients and the bulk part with the mean ones (exact
/// under small kinematics, where the pressure is kappa times the mean dilatation; an
/// approximation under large kinematics that only preconditions).
pub(super) fn diagonal_blocks_bar(
    geo: &Geometry,
    gauss: Option<&GaussGeometry>,
    u: &[Vec3; 8],
    mat: &Material,
    hist: &[PlasticState],
    d: &mut [Mat3; 8],
) -> Result<(), ElementFailure> {
    let gauss = gauss.expect("Gauss-point geometry of a fully integrated element");
    let large = mat.is_large();
    let (h, _, _) = point_gradients(geo, Some(gauss), u, large, Formulation::FullBar)?;
    let hbar: [Vec3; 8] = if large {
        let (_, finv, j) = deformation(&gauss_gradient(u, gauss))?;
        mean_dilatation(geo, gauss, &finv, &j).1
    } else {
        std::array::from_fn(|a| geo.bbar_at(a))
    };
    let (lambda, mu) = mat.lambda_mu();
    for q in 0..8 {
        let mut pt = mat.tangent(&h[q], hist.get(q));
        // Keep the deviatoric part only: c = kappa + mu_t / 3 minus kappa.
        pt.c -= lambda + 2.0 * mu / 3.0;
        let w = gauss.wdet[q];
        for (a, da) in d.iter_mut().enumerate() {
            add_tangent(da, &pt, &g_at(gauss, a, q), w);
        }
    }
    let bulk = lambda + 2.0 * mu / 3.0;
    for a in 0..8 {
        for i in 0..3 {
            for k in 0..3 {
                d[a][i][k] += geo.volume * bulk * hbar[a][i] * hbar[a][k];
            }
        }
    }
    Ok(())
}
