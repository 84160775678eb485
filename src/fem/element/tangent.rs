//! The nodal 3x3 diagonal blocks of the element tangent (for the block-Jacobi
//! preconditioner), per formulation, and the material tangent at one point.

use super::geometry::{
    at, g_at, gauss_gradient, geometry, hourglass, mean_gradient, GaussGeometry, Geometry, HG_BASE,
    ZERO_Q,
};
use super::kinematics::{deformation, mean_dilatation, point_gradients};
use super::stabilization::Stiffness;
use super::{ElementFailure, Formulation, Stabilization};
use crate::material::{Material, PlasticState, PointTangent};
use crate::math::{Mat3, Vec3, ZERO33};

/// The eight 3x3 diagonal blocks K_aa of the element tangent, into `d` (overwritten).
/// Exact for `Full`, for `Mean` and for `FullBar` under small kinematics; under large
/// kinematics `FullBar` gets a consistent-in-the-limit approximation (it only preconditions).
pub fn diagonal_blocks(
    x: &[Vec3; 8],
    u: &[Vec3; 8],
    mat: &Material,
    form: Formulation,
    d: &mut [Mat3; 8],
) -> Result<(), ElementFailure> {
    let (geo, gauss) = geometry(x)?;
    diagonal_blocks_with(&geo, Some(&gauss), u, mat, form, &[], d)
}

/// F^-T g: v_i = sum_L Finv_Li g_L
#[inline(always)]
pub(in crate::fem) fn finv_t(finv: &Mat3, g: &Vec3) -> Vec3 {
    [
        finv[0][0] * g[0] + finv[1][0] * g[1] + finv[2][0] * g[2],
        finv[0][1] * g[0] + finv[1][1] * g[1] + finv[2][1] * g[2],
        finv[0][2] * g[0] + finv[1][2] * g[1] + finv[2][2] * g[2],
    ]
}

/// d += w (c v v^T + mu |g|^2 I - cn (n v)(n v)^T), the point's tangent (`PointTangent`)
/// contracted with `g`.
#[inline(always)]
pub(in crate::fem) fn add_tangent(d: &mut Mat3, pt: &PointTangent, g: &Vec3, w: f64) {
    let v = match &pt.finv {
        Some(finv) => finv_t(finv, g),
        None => *g,
    };
    let gg = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
    let nv = crate::math::matvec(&pt.n, &v);
    for i in 0..3 {
        for k in 0..3 {
            d[i][k] += w * (pt.c * v[i] * v[k] - pt.cn * nv[i] * nv[k]);
        }
        d[i][i] += w * (pt.mu * gg);
    }
}

/// `diagonal_blocks` with the element's reference geometry already computed. `gauss` may
/// be `None` for `Formulation::Mean` only; `hist` as in `internal_force_with`.
pub fn diagonal_blocks_with(
    geo: &Geometry,
    gauss: Option<&GaussGeometry>,
    u: &[Vec3; 8],
    mat: &Material,
    form: Formulation,
    hist: &[PlasticState],
    d: &mut [Mat3; 8],
) -> Result<(), ElementFailure> {
    *d = [ZERO33; 8];
    if mat.is_plastic() && matches!(form, Formulation::FullBar) {
        return diagonal_blocks_bar(geo, gauss, u, mat, hist, d);
    }
    let full = || gauss.expect("Gauss-point geometry of a fully integrated element");
    match form {
        Formulation::Full => diagonal_full(full(), u, mat, hist, d),
        Formulation::FullBar => diagonal_bar(geo, full(), u, mat, d)?,
        Formulation::Mean { hourglass: control } => diagonal_mean(geo, u, mat, hist, control, d),
    }
    Ok(())
}

/// Diagonal blocks of a fully integrated element, added to `d`.
#[inline(always)]
fn diagonal_full(
    gauss: &GaussGeometry,
    u: &[Vec3; 8],
    mat: &Material,
    hist: &[PlasticState],
    d: &mut [Mat3; 8],
) {
    // The linear elastic tangent does not depend on u.
    let h = if mat.linear().is_some() {
        ZERO_Q
    } else {
        gauss_gradient(u, gauss)
    };
    for q in 0..8 {
        let pt = mat.tangent(&at(&h, q), hist.get(q));
        for (a, da) in d.iter_mut().enumerate() {
            add_tangent(da, &pt, &g_at(gauss, a, q), gauss.wdet[q]);
        }
    }
}

/// Diagonal blocks of the B-bar / F-bar element (not plastic), added to `d`.
#[inline(always)]
fn diagonal_bar(
    geo: &Geometry,
    gauss: &GaussGeometry,
    u: &[Vec3; 8],
    mat: &Material,
    d: &mut [Mat3; 8],
) -> Result<(), ElementFailure> {
    let (lambda, mu) = mat.lambda_mu();
    let (hbar, finv) = if mat.is_large() {
        let h = gauss_gradient(u, gauss);
        let (_, finv, j) = deformation(&h)?;
        (mean_dilatation(geo, gauss, &finv, &j).1, Some(finv))
    } else {
        (std::array::from_fn(|a| geo.bbar_at(a)), None)
    };
    for q in 0..8 {
        let w = gauss.wdet[q];
        for (a, da) in d.iter_mut().enumerate() {
            let g = g_at(gauss, a, q);
            let gg = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
            let hv = match &finv {
                Some(fi) => finv_t(&fi[q], &g),
                None => g,
            };
            for i in 0..3 {
                for k in 0..3 {
                    da[i][k] += w * (mu / 3.0) * hv[i] * hv[k];
                }
                da[i][i] += w * mu * gg;
            }
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

/// Diagonal blocks of the one-point element with hourglass control, added to `d`: the
/// centre's tangent with the mean gradients and sum_alpha,beta gamma_alpha,a
/// gamma_beta,a K_alpha,beta, K the hourglass stiffness (`stabilization`) of the step.
#[inline(always)]
fn diagonal_mean(
    geo: &Geometry,
    u: &[Vec3; 8],
    mat: &Material,
    hist: &[PlasticState],
    control: Stabilization,
    d: &mut [Mat3; 8],
) {
    let h = mean_gradient(u, geo);
    let pt = mat.tangent(&h, hist.first());
    let hx = hourglass(geo);
    let stiff = Stiffness::new(geo, control, mat);
    // A plastic element's hourglass stiffness of the step (see `hourglass`).
    let r = if hist.len() > 1 {
        super::hourglass::centre(mat, &h, hist).map_or(1.0, |c| c.r)
    } else {
        1.0
    };
    for (a, da) in d.iter_mut().enumerate() {
        let b = geo.bbar_at(a);
        add_tangent(da, &pt, &b, geo.volume);
        let gamma: [f64; 4] =
            std::array::from_fn(|alpha| HG_BASE[alpha][a] - crate::math::dot(&b, &hx[alpha]));
        match stiff {
            Stiffness::Scalar(mut k) => {
                k *= r;
                let mut s = 0.0;
                for g in gamma {
                    s += g * g;
                }
                for i in 0..3 {
                    da[i][i] += k * s;
                }
            }
            Stiffness::AssumedStrain { .. } => {
                for j in 0..3 {
                    let q: [Vec3; 4] = std::array::from_fn(|alpha| {
                        std::array::from_fn(|i| if i == j { gamma[alpha] } else { 0.0 })
                    });
                    let f = stiff.apply(r, &q);
                    for i in 0..3 {
                        for alpha in 0..4 {
                            da[i][j] += gamma[alpha] * f[alpha][i];
                        }
                    }
                }
            }
        }
    }
}

/// Diagonal blocks of a plastic `FullBar` element: the deviatoric part of the consistent
/// tangent with each Gauss point's gradients and the bulk part with the mean ones (exact
/// under small kinematics, where the pressure is kappa times the mean dilatation; an
/// approximation under large kinematics that only preconditions).
fn diagonal_blocks_bar(
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
