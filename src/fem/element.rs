//! Element kernels for the 8-node hexahedron: internal force, the nodal 3x3 diagonal
//! blocks of the tangent (for the block-Jacobi preconditioner) and the element-average
//! Cauchy stress. Small kinematics use the linearised strain; large kinematics are total
//! Lagrangian. Inputs are the reference coordinates and the displacements of the 8 nodes.

use super::hex8::{gradients, GAUSS, NODE_XI};
use crate::material::{Material, PlasticState};
use crate::math::{det, inverse, Mat3, Vec3, ZERO33};

/// How an element is integrated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Formulation {
    /// 2x2x2 Gauss.
    Full,
    /// 2x2x2 Gauss with the volumetric part taken from the element mean: B-bar (mean
    /// dilatation) under small kinematics, F-bar with the volume-averaged J under large.
    FullBar,
    /// One-point uniform-gradient integration with Flanagan-Belytschko hourglass stiffness
    /// of the given coefficient.
    Mean { hourglass: f64 },
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ElementFailure {
    /// The reference element has a non-positive Jacobian determinant.
    InvertedReference,
    /// The deformed element has J <= 0 somewhere it is sampled.
    InvertedCurrent,
    /// A non-finite value appeared.
    NonFinite,
}

impl std::fmt::Display for ElementFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ElementFailure::InvertedReference => write!(
                f,
                "inverted or degenerate element (reference Jacobian <= 0)"
            ),
            ElementFailure::InvertedCurrent => {
                write!(f, "inverted element (J <= 0 in the deformed configuration)")
            }
            ElementFailure::NonFinite => write!(f, "non-finite value in the element"),
        }
    }
}

/// Reference-configuration data of one element that every formulation uses: computed once
/// per element and reused for every evaluation (see `Assembly`). 304 bytes.
#[derive(Clone, Debug)]
pub struct Geometry {
    /// Volume-averaged gradients (the uniform gradient of Flanagan and Belytschko),
    /// component-major: `bbar[k][a]` = d N_a / d X_k averaged over the element.
    pub(super) bbar: [[f64; 8]; 3],
    pub(super) volume: f64,
    /// volume * sum_a |bbar_a|^2, the scale of the hourglass stiffness.
    vbb: f64,
    /// Hourglass sums of the reference coordinates, hx_alpha = sum_a base_alpha,a x_a
    /// (kept so the one-point kernel need not gather the coordinates).
    hx: [Vec3; 4],
}

/// The gradients at the eight Gauss points, Gauss-point index innermost (`g[a][k][q]`)
/// so that loops over the Gauss points vectorise, and det J at each. 1600 bytes; needed
/// only by the fully integrated formulations.
#[derive(Clone, Debug, Default)]
pub struct GaussGeometry {
    g: [[[f64; 8]; 3]; 8],
    pub(super) wdet: [f64; 8],
}

/// A 3x3 matrix at each of the eight Gauss points: `m[i][j][q]`.
pub(super) type QMat = [[[f64; 8]; 3]; 3];
const ZERO_Q: QMat = [[[0.0; 8]; 3]; 3];

/// The hourglass base vectors (xi eta, eta zeta, zeta xi, xi eta zeta at the nodes):
/// `HG_BASE[alpha][a]`, entries +-1.
const HG_BASE: [[f64; 8]; 4] = hg_base();

const fn hg_base() -> [[f64; 8]; 4] {
    let mut b = [[0.0; 8]; 4];
    let mut a = 0;
    while a < 8 {
        let p = NODE_XI[a];
        b[0][a] = p[1] * p[2];
        b[1][a] = p[2] * p[0];
        b[2][a] = p[0] * p[1];
        b[3][a] = p[0] * p[1] * p[2];
        a += 1;
    }
    b
}

#[inline]
pub fn geometry(x: &[Vec3; 8]) -> Result<(Geometry, GaussGeometry), ElementFailure> {
    let mut gauss = GaussGeometry::default();
    let mut volume = 0.0;
    let mut bbar = [[0.0; 8]; 3];
    for q in 0..8 {
        let (gq, d) = gradients(x, &GAUSS[q]).ok_or(ElementFailure::InvertedReference)?;
        gauss.wdet[q] = d;
        volume += d;
        for a in 0..8 {
            for k in 0..3 {
                gauss.g[a][k][q] = gq[a][k];
                bbar[k][a] += d * gq[a][k];
            }
        }
    }
    let mut bb = 0.0;
    for row in bbar.iter_mut() {
        for v in row.iter_mut() {
            *v /= volume;
            bb += *v * *v;
        }
    }
    let mut hx = [[0.0; 3]; 4];
    for (alpha, h) in hx.iter_mut().enumerate() {
        for a in 0..8 {
            for i in 0..3 {
                h[i] += HG_BASE[alpha][a] * x[a][i];
            }
        }
    }
    Ok((
        Geometry {
            bbar,
            volume,
            vbb: volume * bb,
            hx,
        },
        gauss,
    ))
}

impl Geometry {
    #[inline]
    pub(super) fn bbar_at(&self, a: usize) -> Vec3 {
        [self.bbar[0][a], self.bbar[1][a], self.bbar[2][a]]
    }
}

/// h_ij = sum_a u_a,i bbar_a,j (the element-mean displacement gradient)
#[inline]
pub(super) fn mean_gradient(u: &[Vec3; 8], geo: &Geometry) -> Mat3 {
    let mut h = ZERO33;
    for a in 0..8 {
        for i in 0..3 {
            for j in 0..3 {
                h[i][j] += u[a][i] * geo.bbar[j][a];
            }
        }
    }
    h
}

/// h_ij(q) = sum_a u_a,i g_a,j(q) at every Gauss point.
#[inline(always)]
pub(super) fn gauss_gradient(u: &[Vec3; 8], gauss: &GaussGeometry) -> QMat {
    let mut h = ZERO_Q;
    for j in 0..3 {
        let mut acc = [[0.0; 8]; 3];
        for a in 0..8 {
            let ga = &gauss.g[a][j];
            for i in 0..3 {
                let ua = u[a][i];
                for q in 0..8 {
                    acc[i][q] += ua * ga[q];
                }
            }
        }
        for i in 0..3 {
            h[i][j] = acc[i];
        }
    }
    h
}

/// f_a,i += sum_q sum_j t_ij(q) g_a,j(q)  (t already carries the quadrature weights).
#[inline(always)]
fn gauss_scatter(t: &QMat, gauss: &GaussGeometry, f: &mut [Vec3; 8]) {
    for a in 0..8 {
        let ga = &gauss.g[a];
        for i in 0..3 {
            let mut acc = [0.0; 8];
            for j in 0..3 {
                for q in 0..8 {
                    acc[q] += t[i][j][q] * ga[j][q];
                }
            }
            f[a][i] += hsum(&acc);
        }
    }
}

/// Sum of eight values in a fixed order.
#[inline(always)]
fn hsum(v: &[f64; 8]) -> f64 {
    let s = [v[0] + v[4], v[1] + v[5], v[2] + v[6], v[3] + v[7]];
    (s[0] + s[2]) + (s[1] + s[3])
}

#[inline(always)]
pub(super) fn at(m: &QMat, q: usize) -> Mat3 {
    std::array::from_fn(|i| std::array::from_fn(|j| m[i][j][q]))
}

/// t(q) = w m
#[inline(always)]
fn put(t: &mut QMat, q: usize, m: &Mat3, w: f64) {
    for i in 0..3 {
        for j in 0..3 {
            t[i][j][q] = w * m[i][j];
        }
    }
}

#[inline]
pub(super) fn add_identity(h: &Mat3) -> Mat3 {
    let mut f = *h;
    for (i, row) in f.iter_mut().enumerate() {
        row[i] += 1.0;
    }
    f
}

#[inline]
pub(super) fn sub_identity(f: &Mat3) -> Mat3 {
    let mut h = *f;
    for (i, row) in h.iter_mut().enumerate() {
        row[i] -= 1.0;
    }
    h
}

#[inline]
pub(super) fn scaled(m: &Mat3, s: f64) -> Mat3 {
    let mut r = *m;
    for row in r.iter_mut() {
        for v in row.iter_mut() {
            *v *= s;
        }
    }
    r
}

/// F, F^-1 and J at each of the eight Gauss points.
pub(super) type Deformation = ([Mat3; 8], [Mat3; 8], [f64; 8]);

/// F = I + h, F^-1 and J at every Gauss point; fails if J <= 0 at one.
#[inline]
pub(super) fn deformation(h: &QMat) -> Result<Deformation, ElementFailure> {
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
pub(super) fn mean_dilatation(
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

/// Hourglass sums of the reference coordinates, hx_alpha = sum_a base_alpha,a x_a (from
/// the geometry), and the stiffness k (Flanagan-Belytschko): the hourglass vectors
/// orthogonalised against linear fields are gamma_alpha,a = base_alpha,a - bbar_a .
/// hx_alpha, and f_a = k sum_alpha gamma_alpha,a q_alpha with q_alpha = sum_a
/// gamma_alpha,a u_a.
#[inline]
fn hourglass(geo: &Geometry, coefficient: f64, mu: f64) -> ([Vec3; 4], f64) {
    let hx = geo.hx;
    // Scaled so that coefficient 1 matches the shear part of the fully integrated
    // element's hourglass-mode stiffness on a cube. Shear modulus only: the modes are
    // volume-preserving on average, and lambda would lock near incompressibility.
    (hx, coefficient * mu * geo.vbb / 24.0)
}

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
        Some(old) => mat.update(h, old).map(|r| r.0),
        None => mat.stress(h),
    }
}

/// `internal_force` with the element's reference geometry already computed. `gauss` may
/// be `None` for `Formulation::Mean` only. `hist` is the committed history of a plastic
/// element (one state per stress point, see `history::points`), empty otherwise.
pub fn internal_force_with(
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
        Formulation::Mean {
            hourglass: coefficient,
        } => force_mean(geo, u, mat, hist, coefficient, f)?,
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
    match mat {
        Material::LinearElastic(m) => {
            // s = mu (h + h^T) + lambda tr(h) I, weighted, all Gauss points at once.
            let w = &gauss.wdet;
            let mut tr = [0.0; 8];
            for q in 0..8 {
                tr[q] = h[0][0][q] + h[1][1][q] + h[2][2][q];
            }
            for i in 0..3 {
                for j in 0..3 {
                    for q in 0..8 {
                        let mut s = m.mu * (h[i][j][q] + h[j][i][q]);
                        if i == j {
                            s += m.lambda * tr[q];
                        }
                        t[i][j][q] = w[q] * s;
                    }
                }
            }
        }
        _ => {
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

/// Internal force of the one-point element with hourglass control, into `f`.
#[inline(always)]
fn force_mean(
    geo: &Geometry,
    u: &[Vec3; 8],
    mat: &Material,
    hist: &[PlasticState],
    coefficient: f64,
    f: &mut [Vec3; 8],
) -> Result<(), ElementFailure> {
    let h = mean_gradient(u, geo);
    let s = point_stress(mat, &h, hist, 0).ok_or(ElementFailure::InvertedCurrent)?;
    let (_, mu) = mat.lambda_mu();
    let (hx, k) = hourglass(geo, coefficient, mu);
    // q_alpha = sum_a gamma_alpha,a u_a = sum_a base_alpha,a u_a - h hx_alpha, since
    // sum_a u_a bbar_a^T = h; scaled by k.
    let mut qk = [[0.0; 3]; 4];
    for alpha in 0..4 {
        let mut bu = [0.0; 3];
        for a in 0..8 {
            for i in 0..3 {
                bu[i] += HG_BASE[alpha][a] * u[a][i];
            }
        }
        for i in 0..3 {
            let hh = h[i][0] * hx[alpha][0] + h[i][1] * hx[alpha][1] + h[i][2] * hx[alpha][2];
            qk[alpha][i] = k * (bu[i] - hh);
        }
    }
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

/// The material tangent at one point, ready to be contracted with gradients:
/// `sum_JL g_J A_iJkL g_L = c v v^T + mu |g|^2 I` with v = g (linear elasticity,
/// c = lambda + mu) or v = F^-T g (neo-Hookean, c = mu + lambda - lambda ln J); the same
/// expressions as `Material::tangent_gg`, with F^-1 and ln J computed once per point.
/// For J2 plasticity (consistent tangent, see `J2Plastic::tangent_gg`) c = kappa + mu_t/3,
/// mu = mu_t and the extra term - cn (n v)(n v)^T; under large kinematics the same form
/// with v = F^-T g, an approximation that only preconditions.
pub(super) struct PointTangent {
    finv: Option<Mat3>,
    pub(super) c: f64,
    mu: f64,
    n: Mat3,
    cn: f64,
}

#[inline]
pub(super) fn point_tangent(mat: &Material, h: &Mat3, old: Option<&PlasticState>) -> PointTangent {
    match mat {
        Material::LinearElastic(m) => PointTangent {
            finv: None,
            c: m.lambda + m.mu,
            mu: m.mu,
            n: ZERO33,
            cn: 0.0,
        },
        Material::J2Plastic(m) => {
            let virgin = PlasticState::default();
            let old = old.unwrap_or(&virgin);
            let (ret, finv) = if m.large {
                match m.update_large(h, old) {
                    Some(r) => (r.ret, Some(r.finv)),
                    None => (
                        crate::material::Return::ELASTIC,
                        Some(crate::math::IDENTITY),
                    ),
                }
            } else {
                (m.update(h, old).2, None)
            };
            let (kappa, mu_t, cn) = m.moduli(&ret);
            PointTangent {
                finv,
                c: kappa + mu_t / 3.0,
                mu: mu_t,
                n: ret.n,
                cn,
            }
        }
        Material::NeoHookean(m) => {
            let (finv, j) = inverse(&add_identity(h));
            let lnj = if j > 0.0 { j.ln() } else { 0.0 };
            PointTangent {
                finv: Some(finv),
                c: m.mu + m.lambda - m.lambda * lnj,
                mu: m.mu,
                n: ZERO33,
                cn: 0.0,
            }
        }
    }
}

/// F^-T g: v_i = sum_L Finv_Li g_L
#[inline(always)]
pub(super) fn finv_t(finv: &Mat3, g: &Vec3) -> Vec3 {
    [
        finv[0][0] * g[0] + finv[1][0] * g[1] + finv[2][0] * g[2],
        finv[0][1] * g[0] + finv[1][1] * g[1] + finv[2][1] * g[2],
        finv[0][2] * g[0] + finv[1][2] * g[1] + finv[2][2] * g[2],
    ]
}

/// d += w (c v v^T + mu |g|^2 I)
#[inline(always)]
pub(super) fn add_tangent(d: &mut Mat3, pt: &PointTangent, g: &Vec3, w: f64) {
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

#[inline(always)]
pub(super) fn g_at(gauss: &GaussGeometry, a: usize, q: usize) -> Vec3 {
    [gauss.g[a][0][q], gauss.g[a][1][q], gauss.g[a][2][q]]
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
        return super::history::diagonal_blocks_bar(geo, gauss, u, mat, hist, d);
    }
    let full = || gauss.expect("Gauss-point geometry of a fully integrated element");
    match form {
        Formulation::Full => diagonal_full(full(), u, mat, hist, d),
        Formulation::FullBar => diagonal_bar(geo, full(), u, mat, d)?,
        Formulation::Mean {
            hourglass: coefficient,
        } => diagonal_mean(geo, u, mat, hist, coefficient, d),
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
    let h = if mat.is_large() || mat.is_plastic() {
        gauss_gradient(u, gauss)
    } else {
        ZERO_Q
    };
    for q in 0..8 {
        let pt = point_tangent(mat, &at(&h, q), hist.get(q));
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

/// Diagonal blocks of the one-point element with hourglass control, added to `d`.
#[inline(always)]
fn diagonal_mean(
    geo: &Geometry,
    u: &[Vec3; 8],
    mat: &Material,
    hist: &[PlasticState],
    coefficient: f64,
    d: &mut [Mat3; 8],
) {
    let (_, mu) = mat.lambda_mu();
    let h = mean_gradient(u, geo);
    let pt = point_tangent(mat, &h, hist.first());
    let (hx, k) = hourglass(geo, coefficient, mu);
    for (a, da) in d.iter_mut().enumerate() {
        let b = geo.bbar_at(a);
        add_tangent(da, &pt, &b, geo.volume);
        let mut s = 0.0;
        for alpha in 0..4 {
            let g = HG_BASE[alpha][a] - crate::math::dot(&b, &hx[alpha]);
            s += g * g;
        }
        for i in 0..3 {
            da[i][i] += k * s;
        }
    }
}

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
    let (h, w, n) = super::history::point_gradients(geo, gauss, u, mat.is_large(), form)?;
    let virgin = PlasticState::default();
    for q in 0..n {
        let s = mat
            .cauchy_from(&h[q], hist.get(q).unwrap_or(&virgin))
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

/// Reference volume of the element.
pub fn volume(x: &[Vec3; 8]) -> Result<f64, ElementFailure> {
    Ok(geometry(x)?.0.volume)
}
