//! Internal force of one element, per formulation: fully integrated, B-bar (small
//! kinematics), F-bar (large kinematics) and one-point with hourglass control.

use super::geometry::{
    at, gauss_gradient, gauss_scatter, geometry, hourglass, mean_gradient, put, GaussGeometry,
    Geometry, HG_BASE, ZERO_Q,
};
use super::kinematics::{deformation, mean_dilatation, scaled, sub_identity};
use super::stabilization::Stiffness;
use super::{ElementFailure, Formulation, Stabilization};
use crate::material::{Material, PlasticState};
use crate::math::{Mat3, Vec3, ZERO33};

/// Internal force of one element into `f` (overwritten).
pub fn internal_force(
    x: &[Vec3; 8],
    u: &[Vec3; 8],
    mat: &Material,
    form: Formulation,
    f: &mut [Vec3; 8],
) -> Result<(), ElementFailure> {
    let (geo, gauss) = geometry(x)?;
    internal_force_with(&geo, Some(&gauss), u, mat, form, &[], f)
}

/// Stress at stress point `q`: from the committed state when the element has a history
/// (`hist` holds one state per stress point), history-free otherwise.
#[inline(always)]
fn point_stress(mat: &Material, h: &Mat3, hist: &[PlasticState], q: usize) -> Option<Mat3> {
    match hist.get(q) {
        Some(old) => mat.update(h, old).map(|r| r.stress),
        None => mat.stress(h),
    }
}

/// `internal_force` with the element's reference geometry already computed. `gauss` may
/// be `None` for `Formulation::Mean` only. `hist` is the committed history of a plastic
/// element (one state per stress point, see `history::points`), empty otherwise.
///
/// On a processor with AVX2 the same code runs compiled for it (the Gauss-point loops four
/// points to an instruction instead of two). Every operation is the same IEEE operation on
/// the same operands in the same order (no fused multiply-adds are enabled, and the lanes
/// are independent), so the force is bitwise the same either way.
pub fn internal_force_with(
    geo: &Geometry,
    gauss: Option<&GaussGeometry>,
    u: &[Vec3; 8],
    mat: &Material,
    form: Formulation,
    hist: &[PlasticState],
    f: &mut [Vec3; 8],
) -> Result<(), ElementFailure> {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the processor has AVX2, checked just above.
        return unsafe { internal_force_avx2(geo, gauss, u, mat, form, hist, f) };
    }
    internal_force_body(geo, gauss, u, mat, form, hist, f)
}

/// `internal_force_body` compiled for AVX2 (the caller checks the processor has it).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn internal_force_avx2(
    geo: &Geometry,
    gauss: Option<&GaussGeometry>,
    u: &[Vec3; 8],
    mat: &Material,
    form: Formulation,
    hist: &[PlasticState],
    f: &mut [Vec3; 8],
) -> Result<(), ElementFailure> {
    internal_force_body(geo, gauss, u, mat, form, hist, f)
}

#[inline(always)]
fn internal_force_body(
    geo: &Geometry,
    gauss: Option<&GaussGeometry>,
    u: &[Vec3; 8],
    mat: &Material,
    form: Formulation,
    hist: &[PlasticState],
    f: &mut [Vec3; 8],
) -> Result<(), ElementFailure> {
    *f = [[0.0; 3]; 8];
    let large = mat.is_large();
    let full = || gauss.expect("Gauss-point geometry of a fully integrated element");
    match form {
        Formulation::Full => force_full(full(), u, mat, hist, f)?,
        Formulation::FullBar if !large => force_bar_small(geo, full(), u, mat, hist, f)?,
        Formulation::FullBar => force_bar_large(geo, full(), u, mat, hist, f)?,
        Formulation::Mean { hourglass: control } => force_mean(geo, u, mat, hist, control, f)?,
    }
    for fa in f.iter() {
        if !crate::math::is_finite3(fa) {
            return Err(ElementFailure::NonFinite);
        }
    }
    Ok(())
}

/// Internal force of a fully integrated element (eight Gauss points), added to `f`.
#[inline(always)]
fn force_full(
    gauss: &GaussGeometry,
    u: &[Vec3; 8],
    mat: &Material,
    hist: &[PlasticState],
    f: &mut [Vec3; 8],
) -> Result<(), ElementFailure> {
    let h = gauss_gradient(u, gauss);
    let mut t = ZERO_Q;
    match mat.linear() {
        Some((lambda, mu)) => {
            // s = mu (h + h^T) + lambda tr(h) I, weighted, all Gauss points at once.
            let w = &gauss.wdet;
            let mut tr = [0.0; 8];
            for q in 0..8 {
                tr[q] = h[0][0][q] + h[1][1][q] + h[2][2][q];
            }
            for i in 0..3 {
                for j in 0..3 {
                    for q in 0..8 {
                        let mut s = mu * (h[i][j][q] + h[j][i][q]);
                        if i == j {
                            s += lambda * tr[q];
                        }
                        t[i][j][q] = w[q] * s;
                    }
                }
            }
        }
        None => {
            for q in 0..8 {
                let s = point_stress(mat, &at(&h, q), hist, q)
                    .ok_or(ElementFailure::InvertedCurrent)?;
                put(&mut t, q, &s, gauss.wdet[q]);
            }
        }
    }
    gauss_scatter(&t, gauss, f);
    Ok(())
}

/// Internal force of the B-bar element under small kinematics, added to `f`:
/// f_a = sum_q w_q [(s_q - p_q I) g_a(q) + p_q bbar_a] with p_q = tr(s_q)/3.
#[inline(always)]
fn force_bar_small(
    geo: &Geometry,
    gauss: &GaussGeometry,
    u: &[Vec3; 8],
    mat: &Material,
    hist: &[PlasticState],
    f: &mut [Vec3; 8],
) -> Result<(), ElementFailure> {
    let theta_bar: f64 = (0..8)
        .map(|a| crate::math::dot(&u[a], &geo.bbar_at(a)))
        .sum();
    let h = gauss_gradient(u, gauss);
    let mut t = ZERO_Q;
    let mut pw = 0.0;
    for q in 0..8 {
        let mut hq = at(&h, q);
        let shift = (theta_bar - (hq[0][0] + hq[1][1] + hq[2][2])) / 3.0;
        for (i, row) in hq.iter_mut().enumerate() {
            row[i] += shift;
        }
        let mut s = point_stress(mat, &hq, hist, q).ok_or(ElementFailure::InvertedCurrent)?;
        let p3 = (s[0][0] + s[1][1] + s[2][2]) / 3.0;
        for (i, row) in s.iter_mut().enumerate() {
            row[i] -= p3;
        }
        put(&mut t, q, &s, gauss.wdet[q]);
        pw += gauss.wdet[q] * p3;
    }
    gauss_scatter(&t, gauss, f);
    for (a, fa) in f.iter_mut().enumerate() {
        for i in 0..3 {
            fa[i] += pw * geo.bbar[i][a];
        }
    }
    Ok(())
}

/// Internal force of the F-bar element under large kinematics, added to `f`:
/// f_a = sum_q w_q [(P - (P:F)/3 F^-T) g_a(q) + (P:F)/3 h0_a], w_q = det_q ratio_q.
#[inline(always)]
fn force_bar_large(
    geo: &Geometry,
    gauss: &GaussGeometry,
    u: &[Vec3; 8],
    mat: &Material,
    hist: &[PlasticState],
    f: &mut [Vec3; 8],
) -> Result<(), ElementFailure> {
    let h = gauss_gradient(u, gauss);
    let (fq, finv, jq) = deformation(&h)?;
    let (j0, h0) = mean_dilatation(geo, gauss, &finv, &jq);
    let mut t = ZERO_Q;
    let mut cw = 0.0;
    for q in 0..8 {
        let ratio = (j0 / jq[q]).cbrt();
        let p = point_stress(mat, &sub_identity(&scaled(&fq[q], ratio)), hist, q)
            .ok_or(ElementFailure::InvertedCurrent)?;
        let mut pf = 0.0;
        for i in 0..3 {
            for k in 0..3 {
                pf += p[i][k] * fq[q][i][k];
            }
        }
        let w = gauss.wdet[q] * ratio;
        let c = pf / 3.0;
        for i in 0..3 {
            for k in 0..3 {
                t[i][k][q] = w * (p[i][k] - c * finv[q][k][i]);
            }
        }
        cw += w * c;
    }
    gauss_scatter(&t, gauss, f);
    for (fa, ha) in f.iter_mut().zip(h0.iter()) {
        for i in 0..3 {
            fa[i] += cw * ha[i];
        }
    }
    Ok(())
}

/// Internal force of the one-point element with hourglass control, into `f`. A plastic
/// element (`hist` holds its centre's state and its hourglass state, see `hourglass`)
/// accumulates its hourglass forces with the stiffness of the step; any other takes the
/// total form K q (`stabilization`).
#[inline(always)]
fn force_mean(
    geo: &Geometry,
    u: &[Vec3; 8],
    mat: &Material,
    hist: &[PlasticState],
    control: Stabilization,
    f: &mut [Vec3; 8],
) -> Result<(), ElementFailure> {
    let h = mean_gradient(u, geo);
    let (_, mu) = mat.lambda_mu();
    let hx = hourglass(geo);
    let k = Stiffness::new(geo, control, mat);
    let q = modes(u, &h, &hx);
    let (s, qk) = if hist.len() > 1 {
        let c = super::hourglass::centre(mat, &h, hist).ok_or(ElementFailure::InvertedCurrent)?;
        let qk = super::hourglass::forces(&q, &k, mu, geo, &c);
        (c.stress, qk)
    } else {
        let s = point_stress(mat, &h, hist, 0).ok_or(ElementFailure::InvertedCurrent)?;
        (s, k.apply(1.0, &q))
    };
    // f_a = V s bbar_a + sum_alpha gamma_alpha,a qk_alpha
    //     = (V s - M) bbar_a + sum_alpha base_alpha,a qk_alpha,
    // with M_ij = sum_alpha qk_alpha,i hx_alpha,j.
    let mut t = ZERO33;
    for i in 0..3 {
        for j in 0..3 {
            let mut m = 0.0;
            for alpha in 0..4 {
                m += qk[alpha][i] * hx[alpha][j];
            }
            t[i][j] = geo.volume * s[i][j] - m;
        }
    }
    for (a, fa) in f.iter_mut().enumerate() {
        for i in 0..3 {
            let mut v =
                t[i][0] * geo.bbar[0][a] + t[i][1] * geo.bbar[1][a] + t[i][2] * geo.bbar[2][a];
            for alpha in 0..4 {
                v += HG_BASE[alpha][a] * qk[alpha][i];
            }
            fa[i] = v;
        }
    }
    Ok(())
}

/// The hourglass displacement sums q_alpha = sum_a gamma_alpha,a u_a = sum_a base_alpha,a
/// u_a - h hx_alpha (since sum_a u_a bbar_a^T = h).
#[inline(always)]
pub(in crate::fem) fn modes(u: &[Vec3; 8], h: &Mat3, hx: &[Vec3; 4]) -> [Vec3; 4] {
    let mut q = [[0.0; 3]; 4];
    for alpha in 0..4 {
        let mut bu = [0.0; 3];
        for a in 0..8 {
            for i in 0..3 {
                bu[i] += HG_BASE[alpha][a] * u[a][i];
            }
        }
        for i in 0..3 {
            let hh = h[i][0] * hx[alpha][0] + h[i][1] * hx[alpha][1] + h[i][2] * hx[alpha][2];
            q[alpha][i] = bu[i] - hh;
        }
    }
    q
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::{LinearElastic, NeoHookean};

    /// The kernel as dispatched (AVX2 where the processor has it) gives the bits of the
    /// kernel compiled for any x86-64, on distorted elements, every formulation, linear and
    /// large-kinematics materials. (On a processor without AVX2 both are the same code.)
    #[test]
    fn the_dispatched_kernel_gives_the_bits_of_the_portable_one() {
        let mats = [
            Material::LinearElastic(LinearElastic::new(1000.0, 0.3)),
            Material::NeoHookean(NeoHookean::new(1000.0, 0.45)),
        ];
        let forms = [
            Formulation::Full,
            Formulation::FullBar,
            Formulation::Mean {
                hourglass: Stabilization::Coefficient(0.05),
            },
            Formulation::Mean {
                hourglass: Stabilization::AssumedStrain,
            },
        ];
        let wobble = |k: usize| 0.1 * ((k as f64) * 0.731).sin();
        for e in 0..20 {
            let x: [Vec3; 8] = std::array::from_fn(|a| {
                let p = crate::fem::hex8::NODE_XI[a];
                std::array::from_fn(|i| 0.5 * (1.0 + p[i]) + wobble(100 * e + 3 * a + i))
            });
            let u: [Vec3; 8] = std::array::from_fn(|a| {
                std::array::from_fn(|i| 0.01 * wobble(7 * e + 5 * a + i + 1))
            });
            let (geo, gauss) = super::super::geometry::geometry(&x).expect("a valid element");
            for mat in &mats {
                for &form in &forms {
                    let (mut f1, mut f2) = ([[0.0; 3]; 8], [[0.0; 3]; 8]);
                    let r1 = internal_force_with(&geo, Some(&gauss), &u, mat, form, &[], &mut f1);
                    let r2 = internal_force_body(&geo, Some(&gauss), &u, mat, form, &[], &mut f2);
                    assert_eq!(r1, r2);
                    for a in 0..8 {
                        for i in 0..3 {
                            assert_eq!(f1[a][i].to_bits(), f2[a][i].to_bits(), "{e} {form:?}");
                        }
                    }
                }
            }
        }
    }
}
