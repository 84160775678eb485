//! The composite tetrahedron's kernels: internal force, the nodal diagonal blocks of the
//! tangent, the element-average Cauchy stress, the history a converged step commits and
//! the mean equivalent plastic strain. Small kinematics use the linearised strain of the
//! projected gradient h̄; large kinematics are total Lagrangian with F̄ = I + h̄ (the
//! material's `stress` is Cauchy or first Piola-Kirchhoff accordingly, so one loop serves
//! both). The geometry and the projection are `composite.rs`.
//!
//! Stabilization. The projected gradient is linear over the element, so the twelve
//! sub-tetrahedra's gradients H_s differ from it by a field the stress never sees. In the
//! elastic range the four stress points control all 24 deformation modes, but Foulk et al.
//! (2021) report a soft mode of the unstabilized composite tetrahedron at large plastic
//! strain, where the deviatoric tangent collapses; Ostien et al. (2016) stabilize the
//! element for that reason. We could read only those papers' abstracts here, so the form
//! below is ours and we say so: an elastic energy on what the projection discards,
//! W_stab = (k/2) sum_s V_s |D_s|^2, D_s = H_s - H̄(centroid of s) = F_s - F̄(centroid),
//! with k = 2 `STABILIZATION` mu (mu the elastic shear modulus). It is
//! - zero for every linear displacement field (all H_s equal the projection), so the patch
//!   test and the exact constant stress are untouched;
//! - zero for a rigid rotation, and objective (|F_s - F̄| is unchanged by a superposed
//!   rotation), so it serves large kinematics as written;
//! - bounded by mu, never the bulk modulus, so it adds no volumetric locking;
//! - linear in the displacements with no history, so plastic elements keep their states
//!   per stress point only (`STRESS_POINTS`).

use super::composite::{point_lambda, shape_gradients, Geometry, MEAN_LAMBDA, SUB_TETS};
use crate::fem::element::add_tangent;
use crate::fem::{ElementFailure, Formulation};
use crate::material::{Material, PlasticState};
use crate::math::{det, Mat3, Vec3, ZERO33};

/// History states per plastic element: one per integration point.
pub const STRESS_POINTS: usize = 4;

/// The stabilization stiffness as a fraction of twice the shear modulus (see the module
/// comment): small enough not to stiffen bending measurably, large enough to hold the
/// modes the projection does not see once the material's tangent has gone soft.
pub const STABILIZATION: f64 = 0.01;

/// The gradients of one evaluation: each sub-tetrahedron's H_s, the projection's values
/// H̄_k at the parent's corners, and the projected gradient h at each integration point.
struct Gradients {
    sub: [Mat3; 12],
    corner: [Mat3; 4],
    point: [Mat3; 4],
}

#[inline(always)]
fn axpy(y: &mut Mat3, a: f64, x: &Mat3) {
    for i in 0..3 {
        for j in 0..3 {
            y[i][j] += a * x[i][j];
        }
    }
}

#[inline]
fn gradients(geo: &Geometry, u: &[Vec3; 10], form: Formulation) -> Gradients {
    let uc = {
        let mut c = [0.0; 3];
        for p in &u[4..] {
            for k in 0..3 {
                c[k] += p[k] / 6.0;
            }
        }
        c
    };
    let at = |v: usize| if v == 10 { uc } else { u[v] };
    let mut sub = [ZERO33; 12];
    for (s, t) in SUB_TETS.iter().enumerate() {
        let u0 = at(t[0]);
        let j = &geo.jinv[s];
        for v in 0..3 {
            let uv = at(t[v + 1]);
            for r in 0..3 {
                let du = uv[r] - u0[r];
                for c in 0..3 {
                    sub[s][r][c] += du * j[v][c];
                }
            }
        }
    }
    let mut corner = [ZERO33; 4];
    for (k, ck) in corner.iter_mut().enumerate() {
        for (s, hs) in sub.iter().enumerate() {
            axpy(ck, geo.c[k][s], hs);
        }
    }
    let mut point = [ZERO33; 4];
    for (q, hq) in point.iter_mut().enumerate() {
        for (k, ck) in corner.iter().enumerate() {
            axpy(hq, point_lambda(q, k), ck);
        }
    }
    if mean_dilatation(form) {
        // h_q + (theta_bar - tr h_q) / 3 I, theta_bar the weighted mean of tr h_q.
        let v: f64 = geo.w.iter().sum();
        let mean = (0..4).map(|q| geo.w[q] * trace(&point[q])).sum::<f64>() / v;
        for hq in point.iter_mut() {
            let d = (mean - trace(hq)) / 3.0;
            for (i, row) in hq.iter_mut().enumerate() {
                row[i] += d;
            }
        }
    }
    Gradients { sub, corner, point }
}

/// Whether the element takes the mean dilatation: `FullBar` (the scene's
/// `volumetric = "mean_dilatation"`, small kinematics only: see the module comment).
#[inline(always)]
fn mean_dilatation(form: Formulation) -> bool {
    matches!(form, Formulation::FullBar)
}

#[inline(always)]
fn trace(m: &Mat3) -> f64 {
    m[0][0] + m[1][1] + m[2][2]
}

/// Stress at point `q`: from the committed state when the element has a history (`hist`
/// holds one state per point), history-free otherwise.
#[inline]
fn point_stress(mat: &Material, h: &Mat3, hist: &[PlasticState], q: usize) -> Option<Mat3> {
    match hist.get(q) {
        Some(old) => mat.update(h, old).map(|r| r.stress),
        None => mat.stress(h),
    }
}

/// The stabilization stiffness k of `mat`.
#[inline]
pub(super) fn stiffness(mat: &Material) -> f64 {
    2.0 * STABILIZATION * mat.lambda_mu().1
}

/// Internal force of one element into `f` (overwritten). `hist` is the committed history of
/// a plastic element (`STRESS_POINTS` states), empty otherwise.
pub fn internal_force(
    geo: &Geometry,
    u: &[Vec3; 10],
    mat: &Material,
    form: Formulation,
    hist: &[PlasticState],
    f: &mut [Vec3; 10],
) -> Result<(), ElementFailure> {
    let g = gradients(geo, u, form);
    let mut p = [ZERO33; 4];
    for (q, pq) in p.iter_mut().enumerate() {
        *pq = point_stress(mat, &g.point[q], hist, q).ok_or(ElementFailure::InvertedCurrent)?;
    }
    if mean_dilatation(form) {
        // The variation of the mean dilatation hands every point the element's mean
        // pressure: P_q - tr P_q / 3 I + p_bar I, p_bar = sum_r w_r tr P_r / (3 V).
        let v: f64 = geo.w.iter().sum();
        let mean = (0..4).map(|q| geo.w[q] * trace(&p[q])).sum::<f64>() / (3.0 * v);
        for pq in p.iter_mut() {
            let d = mean - trace(pq) / 3.0;
            for (i, row) in pq.iter_mut().enumerate() {
                row[i] += d;
            }
        }
    }
    // The stresses carried back to the parent's corners: R_k = sum_q lambda_k(q) w_q P_q.
    let mut r = [ZERO33; 4];
    for (q, pq) in p.iter().enumerate() {
        for (k, rk) in r.iter_mut().enumerate() {
            axpy(rk, point_lambda(q, k) * geo.w[q], pq);
        }
    }
    // Stabilization: T_s += k V_s D_s and R_k -= sum_s k V_s m_sk D_s (the projection's
    // share of D_s's variation).
    let k = stiffness(mat);
    let mut t = [ZERO33; 12];
    for s in 0..12 {
        let d = discarded(&g, s);
        let kv = k * geo.vol[s];
        axpy(&mut t[s], kv, &d);
        for (kk, rk) in r.iter_mut().enumerate() {
            axpy(rk, -kv * MEAN_LAMBDA[s][kk], &d);
        }
    }
    for (s, ts) in t.iter_mut().enumerate() {
        for (kk, rk) in r.iter().enumerate() {
            axpy(ts, geo.c[kk][s], rk);
        }
    }
    scatter(geo, &t, f);
    if f.iter().all(crate::math::is_finite3) {
        Ok(())
    } else {
        Err(ElementFailure::NonFinite)
    }
}

/// D_s = H_s - H̄(centroid of s), what the projection discards in sub-tetrahedron s.
#[inline(always)]
fn discarded(g: &Gradients, s: usize) -> Mat3 {
    let mut d = g.sub[s];
    for (kk, ck) in g.corner.iter().enumerate() {
        axpy(&mut d, -MEAN_LAMBDA[s][kk], ck);
    }
    d
}

/// The projected gradient at each point and the stabilization's D_s of a displacement,
/// both linear in it (the assembled tangent, `tangent.rs`).
pub(super) fn linear_parts(
    geo: &Geometry,
    u: &[Vec3; 10],
    form: Formulation,
) -> ([Mat3; 4], [Mat3; 12]) {
    let g = gradients(geo, u, form);
    (g.point, std::array::from_fn(|s| discarded(&g, s)))
}

/// f_a = sum_s T_s grad N_a|_s, the auxiliary node's share handed to the midside nodes.
#[inline]
fn scatter(geo: &Geometry, t: &[Mat3; 12], f: &mut [Vec3; 10]) {
    let mut f11 = [[0.0; 3]; 11];
    for (s, nodes) in SUB_TETS.iter().enumerate() {
        let j = &geo.jinv[s];
        let ts = &t[s];
        let mut f0 = [0.0; 3];
        for v in 0..3 {
            let fv = crate::math::matvec(ts, &j[v]);
            for r in 0..3 {
                f11[nodes[v + 1]][r] += fv[r];
                f0[r] += fv[r];
            }
        }
        for r in 0..3 {
            f11[nodes[0]][r] -= f0[r];
        }
    }
    f.copy_from_slice(&f11[..10]);
    for fa in f[4..].iter_mut() {
        for r in 0..3 {
            fa[r] += f11[10][r] / 6.0;
        }
    }
}

/// The ten 3x3 diagonal blocks K_aa of the element tangent, into `d` (overwritten): the
/// material tangent at each point (`Material::tangent`, exact for linear elasticity,
/// neo-Hookean and small-strain J2; an approximation that only preconditions for J2 under
/// large kinematics) with the projected gradients, plus the stabilization's.
pub fn diagonal_blocks(
    geo: &Geometry,
    u: &[Vec3; 10],
    mat: &Material,
    form: Formulation,
    hist: &[PlasticState],
    d: &mut [Mat3; 10],
) -> Result<(), ElementFailure> {
    let g = gradients(geo, u, form);
    let gs = shape_gradients(geo);
    // grad_bar N_a at the parent's corners: sum_s c_ks grad N_a|_s.
    let mut bk = [[[0.0; 3]; 10]; 4];
    for (k, bka) in bk.iter_mut().enumerate() {
        for (s, gsa) in gs.iter().enumerate() {
            for a in 0..10 {
                for i in 0..3 {
                    bka[a][i] += geo.c[k][s] * gsa[a][i];
                }
            }
        }
    }
    *d = [ZERO33; 10];
    for q in 0..4 {
        let pt = mat.tangent(&g.point[q], hist.get(q));
        for (a, da) in d.iter_mut().enumerate() {
            let b: Vec3 =
                std::array::from_fn(|i| (0..4).map(|k| point_lambda(q, k) * bk[k][a][i]).sum());
            add_tangent(da, &pt, &b, geo.w[q]);
        }
    }
    let k = stiffness(mat);
    for (a, da) in d.iter_mut().enumerate() {
        let mut sum = 0.0;
        for s in 0..12 {
            let mut sa = gs[s][a];
            for kk in 0..4 {
                for i in 0..3 {
                    sa[i] -= MEAN_LAMBDA[s][kk] * bk[kk][a][i];
                }
            }
            sum += geo.vol[s] * crate::math::dot(&sa, &sa);
        }
        for i in 0..3 {
            da[i][i] += k * sum;
        }
    }
    if d.iter().flatten().flatten().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(ElementFailure::NonFinite)
    }
}

/// Element-average Cauchy stress (current-volume weighted), order xx yy zz xy yz zx.
pub fn average_cauchy(
    geo: &Geometry,
    u: &[Vec3; 10],
    mat: &Material,
    form: Formulation,
    hist: &[PlasticState],
) -> Result<[f64; 6], ElementFailure> {
    let g = gradients(geo, u, form);
    let virgin = PlasticState::default();
    let mut sum = ZERO33;
    let mut vol = 0.0;
    for q in 0..4 {
        let h = &g.point[q];
        let s = mat
            .cauchy(h, hist.get(q).unwrap_or(&virgin))
            .ok_or(ElementFailure::InvertedCurrent)?;
        let jw = if mat.is_large() {
            let mut f = *h;
            for (i, row) in f.iter_mut().enumerate() {
                row[i] += 1.0;
            }
            geo.w[q] * det(&f)
        } else {
            geo.w[q]
        };
        axpy(&mut sum, jw, &s);
        vol += jw;
    }
    let mut s = sum;
    for row in s.iter_mut() {
        for v in row.iter_mut() {
            *v /= vol;
        }
    }
    let out = crate::math::to_sym6(&s);
    if out.iter().all(|v| v.is_finite()) {
        Ok(out)
    } else {
        Err(ElementFailure::NonFinite)
    }
}

/// The states a converged step commits: `new[q]` from `old[q]` at the displacements `u`
/// (`STRESS_POINTS` of each).
pub fn update_history(
    geo: &Geometry,
    u: &[Vec3; 10],
    mat: &Material,
    form: Formulation,
    old: &[PlasticState],
    new: &mut [PlasticState],
) -> Result<(), ElementFailure> {
    let g = gradients(geo, u, form);
    for q in 0..STRESS_POINTS {
        new[q] = mat
            .update(&g.point[q], &old[q])
            .ok_or(ElementFailure::InvertedCurrent)?
            .state;
    }
    Ok(())
}

/// Reference-volume average of the equivalent plastic strain over the element's points.
pub fn mean_eqps(geo: &Geometry, hist: &[PlasticState]) -> f64 {
    let s: f64 = (0..STRESS_POINTS).map(|q| geo.w[q] * hist[q].eqps).sum();
    s / geo.volume
}

/// The projected displacement gradient at each integration point (for tests and output).
pub fn point_gradients(geo: &Geometry, u: &[Vec3; 10], form: Formulation) -> [Mat3; 4] {
    gradients(geo, u, form).point
}
