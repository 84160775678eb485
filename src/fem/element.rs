//! Element kernels for the 8-node hexahedron: internal force, the nodal 3x3 diagonal
//! blocks of the tangent (for the block-Jacobi preconditioner) and the element-average
//! Cauchy stress. Small kinematics use the linearised strain; large kinematics are total
//! Lagrangian. Inputs are the reference coordinates and the displacements of the 8 nodes.

use super::hex8::{gradients, GAUSS, NODE_XI};
use crate::material::Material;
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

/// Reference-configuration data of one element at its Gauss points: computed once per
/// element and reused for every evaluation (see `Assembly`).
#[derive(Clone, Debug)]
pub struct Geometry {
    g: [[Vec3; 8]; 8],
    wdet: [f64; 8],
    volume: f64,
    /// Volume-averaged gradients (the uniform gradient of Flanagan and Belytschko).
    bbar: [Vec3; 8],
}

#[inline]
pub fn geometry(x: &[Vec3; 8]) -> Result<Geometry, ElementFailure> {
    let mut g = [[[0.0; 3]; 8]; 8];
    let mut wdet = [0.0; 8];
    let mut volume = 0.0;
    let mut bbar = [[0.0; 3]; 8];
    for q in 0..8 {
        let (gq, d) = gradients(x, &GAUSS[q]).ok_or(ElementFailure::InvertedReference)?;
        g[q] = gq;
        wdet[q] = d;
        volume += d;
        for a in 0..8 {
            for k in 0..3 {
                bbar[a][k] += d * gq[a][k];
            }
        }
    }
    for b in bbar.iter_mut() {
        for v in b.iter_mut() {
            *v /= volume;
        }
    }
    Ok(Geometry {
        g,
        wdet,
        volume,
        bbar,
    })
}

/// h_ij = sum_a u_a,i g_a,j
#[inline]
fn displacement_gradient(u: &[Vec3; 8], g: &[Vec3; 8]) -> Mat3 {
    let mut h = ZERO33;
    for a in 0..8 {
        for i in 0..3 {
            for j in 0..3 {
                h[i][j] += u[a][i] * g[a][j];
            }
        }
    }
    h
}

#[inline]
fn add_identity(h: &Mat3) -> Mat3 {
    let mut f = *h;
    for (i, row) in f.iter_mut().enumerate() {
        row[i] += 1.0;
    }
    f
}

#[inline]
fn sub_identity(f: &Mat3) -> Mat3 {
    let mut h = *f;
    for (i, row) in h.iter_mut().enumerate() {
        row[i] -= 1.0;
    }
    h
}

#[inline]
fn scaled(m: &Mat3, s: f64) -> Mat3 {
    let mut r = *m;
    for row in r.iter_mut() {
        for v in row.iter_mut() {
            *v *= s;
        }
    }
    r
}

/// F-bar deformation gradient at one Gauss point: (J0 / J)^(1/3) F.
struct FBar {
    f: Mat3,
    finv_t_g: [Vec3; 8],
    ratio: f64,
    fbar: Mat3,
}

#[inline]
fn fbar_at(h: &Mat3, g: &[Vec3; 8], j0: f64) -> Result<FBar, ElementFailure> {
    let f = add_identity(h);
    let (finv, j) = inverse(&f);
    if !(j > 0.0) {
        return Err(ElementFailure::InvertedCurrent);
    }
    let ratio = (j0 / j).cbrt();
    let mut finv_t_g = [[0.0; 3]; 8];
    for a in 0..8 {
        for i in 0..3 {
            finv_t_g[a][i] = finv[0][i] * g[a][0] + finv[1][i] * g[a][1] + finv[2][i] * g[a][2];
        }
    }
    Ok(FBar {
        f,
        finv_t_g,
        ratio,
        fbar: scaled(&f, ratio),
    })
}

/// Mean-dilatation data for F-bar: the volume-averaged Jacobian J_bar = (1/V0) int J dV0 and
/// its gradient with respect to each node's displacement divided by J_bar,
/// hbar_a = (1/(V0 J_bar)) int J F^-T g_a dV0. Using the average (not the centroid value)
/// keeps the element passing the patch test on distorted meshes.
#[inline]
fn mean_dilatation(u: &[Vec3; 8], geo: &Geometry) -> Result<(f64, [Vec3; 8]), ElementFailure> {
    let mut jsum = 0.0;
    let mut hbar = [[0.0; 3]; 8];
    for q in 0..8 {
        let f = add_identity(&displacement_gradient(u, &geo.g[q]));
        let (finv, j) = inverse(&f);
        if !(j > 0.0) {
            return Err(ElementFailure::InvertedCurrent);
        }
        let w = geo.wdet[q] * j;
        jsum += w;
        for a in 0..8 {
            let g = &geo.g[q][a];
            for i in 0..3 {
                hbar[a][i] += w * (finv[0][i] * g[0] + finv[1][i] * g[1] + finv[2][i] * g[2]);
            }
        }
    }
    for h in hbar.iter_mut() {
        for v in h.iter_mut() {
            *v /= jsum;
        }
    }
    Ok((jsum / geo.volume, hbar))
}

/// Hourglass base vectors orthogonalised against linear fields (Flanagan-Belytschko), and
/// the stiffness k: f_a = k sum_alpha gamma_alpha,a q_alpha, q_alpha = sum_a gamma_alpha,a u_a.
#[inline]
fn hourglass(x: &[Vec3; 8], geo: &Geometry, coefficient: f64, mu: f64) -> ([[f64; 8]; 4], f64) {
    let mut gamma = [[0.0; 8]; 4];
    for (alpha, ga) in gamma.iter_mut().enumerate() {
        let mut base = [0.0; 8];
        for (a, b) in base.iter_mut().enumerate() {
            let p = NODE_XI[a];
            *b = match alpha {
                0 => p[1] * p[2],
                1 => p[2] * p[0],
                2 => p[0] * p[1],
                _ => p[0] * p[1] * p[2],
            };
        }
        let mut hx = [0.0; 3];
        for a in 0..8 {
            for i in 0..3 {
                hx[i] += base[a] * x[a][i];
            }
        }
        for a in 0..8 {
            ga[a] = base[a]
                - (geo.bbar[a][0] * hx[0] + geo.bbar[a][1] * hx[1] + geo.bbar[a][2] * hx[2]);
        }
    }
    let bb: f64 = geo
        .bbar
        .iter()
        .map(|b| b[0] * b[0] + b[1] * b[1] + b[2] * b[2])
        .sum();
    // Scaled so that coefficient 1 matches the shear part of the fully integrated
    // element's hourglass-mode stiffness on a cube. Shear modulus only: the modes are
    // volume-preserving on average, and lambda would lock near incompressibility.
    (gamma, coefficient * mu * geo.volume * bb / 24.0)
}

/// Internal force of one element into `f` (overwritten).
pub fn internal_force(
    x: &[Vec3; 8],
    u: &[Vec3; 8],
    mat: &Material,
    form: Formulation,
    f: &mut [Vec3; 8],
) -> Result<(), ElementFailure> {
    internal_force_with(&geometry(x)?, x, u, mat, form, f)
}

/// `internal_force` with the element's reference geometry already computed.
pub fn internal_force_with(
    geo: &Geometry,
    x: &[Vec3; 8],
    u: &[Vec3; 8],
    mat: &Material,
    form: Formulation,
    f: &mut [Vec3; 8],
) -> Result<(), ElementFailure> {
    *f = [[0.0; 3]; 8];
    let large = mat.is_large();
    match form {
        Formulation::Full => {
            for q in 0..8 {
                let h = displacement_gradient(u, &geo.g[q]);
                let s = mat.stress(&h).ok_or(ElementFailure::InvertedCurrent)?;
                accumulate(f, &s, &geo.g[q], geo.wdet[q]);
            }
        }
        Formulation::FullBar if !large => {
            let theta_bar: f64 = (0..8).map(|a| crate::math::dot(&u[a], &geo.bbar[a])).sum();
            for q in 0..8 {
                let mut h = displacement_gradient(u, &geo.g[q]);
                let shift = (theta_bar - (h[0][0] + h[1][1] + h[2][2])) / 3.0;
                for (i, row) in h.iter_mut().enumerate() {
                    row[i] += shift;
                }
                let s = mat.stress(&h).ok_or(ElementFailure::InvertedCurrent)?;
                let p3 = (s[0][0] + s[1][1] + s[2][2]) / 3.0;
                accumulate(f, &s, &geo.g[q], geo.wdet[q]);
                for a in 0..8 {
                    for i in 0..3 {
                        f[a][i] += geo.wdet[q] * p3 * (geo.bbar[a][i] - geo.g[q][a][i]);
                    }
                }
            }
        }
        Formulation::FullBar => {
            let (j0, h0) = mean_dilatation(u, geo)?;
            for q in 0..8 {
                let h = displacement_gradient(u, &geo.g[q]);
                let fb = fbar_at(&h, &geo.g[q], j0)?;
                let p = mat
                    .stress(&sub_identity(&fb.fbar))
                    .ok_or(ElementFailure::InvertedCurrent)?;
                let mut pf = 0.0;
                for i in 0..3 {
                    for k in 0..3 {
                        pf += p[i][k] * fb.f[i][k];
                    }
                }
                let w = geo.wdet[q] * fb.ratio;
                accumulate(f, &p, &geo.g[q], w);
                for a in 0..8 {
                    for i in 0..3 {
                        f[a][i] += w * pf / 3.0 * (h0[a][i] - fb.finv_t_g[a][i]);
                    }
                }
            }
        }
        Formulation::Mean {
            hourglass: coefficient,
        } => {
            let h = displacement_gradient(u, &geo.bbar);
            let s = mat.stress(&h).ok_or(ElementFailure::InvertedCurrent)?;
            accumulate(f, &s, &geo.bbar, geo.volume);
            let (_, mu) = mat.lambda_mu();
            let (gamma, k) = hourglass(x, geo, coefficient, mu);
            for ga in gamma.iter() {
                let mut qv = [0.0; 3];
                for a in 0..8 {
                    for i in 0..3 {
                        qv[i] += ga[a] * u[a][i];
                    }
                }
                for a in 0..8 {
                    for i in 0..3 {
                        f[a][i] += k * ga[a] * qv[i];
                    }
                }
            }
        }
    }
    for fa in f.iter() {
        if !crate::math::is_finite3(fa) {
            return Err(ElementFailure::NonFinite);
        }
    }
    Ok(())
}

/// f_a += w * s g_a
#[inline]
fn accumulate(f: &mut [Vec3; 8], s: &Mat3, g: &[Vec3; 8], w: f64) {
    for a in 0..8 {
        for i in 0..3 {
            f[a][i] += w * (s[i][0] * g[a][0] + s[i][1] * g[a][1] + s[i][2] * g[a][2]);
        }
    }
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
    diagonal_blocks_with(&geometry(x)?, x, u, mat, form, d)
}

/// `diagonal_blocks` with the element's reference geometry already computed.
pub fn diagonal_blocks_with(
    geo: &Geometry,
    x: &[Vec3; 8],
    u: &[Vec3; 8],
    mat: &Material,
    form: Formulation,
    d: &mut [Mat3; 8],
) -> Result<(), ElementFailure> {
    *d = [ZERO33; 8];
    let (lambda, mu) = mat.lambda_mu();
    match form {
        Formulation::Full => {
            for q in 0..8 {
                let h = displacement_gradient(u, &geo.g[q]);
                for a in 0..8 {
                    add_scaled(&mut d[a], &mat.tangent_gg(&h, &geo.g[q][a]), geo.wdet[q]);
                }
            }
        }
        Formulation::FullBar => {
            let large = mat.is_large();
            let hbar = if large {
                mean_dilatation(u, geo)?.1
            } else {
                geo.bbar
            };
            for q in 0..8 {
                let hvec: [Vec3; 8] = if large {
                    let h = displacement_gradient(u, &geo.g[q]);
                    fbar_at(&h, &geo.g[q], 1.0)?.finv_t_g
                } else {
                    geo.g[q]
                };
                for a in 0..8 {
                    let g = &geo.g[q][a];
                    let gg = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
                    let hv = &hvec[a];
                    for i in 0..3 {
                        for k in 0..3 {
                            d[a][i][k] += geo.wdet[q] * (mu / 3.0) * hv[i] * hv[k];
                        }
                        d[a][i][i] += geo.wdet[q] * mu * gg;
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
        }
        Formulation::Mean {
            hourglass: coefficient,
        } => {
            let h = displacement_gradient(u, &geo.bbar);
            for a in 0..8 {
                add_scaled(&mut d[a], &mat.tangent_gg(&h, &geo.bbar[a]), geo.volume);
            }
            let (gamma, k) = hourglass(x, geo, coefficient, mu);
            for a in 0..8 {
                let s: f64 = gamma.iter().map(|ga| ga[a] * ga[a]).sum();
                for i in 0..3 {
                    d[a][i][i] += k * s;
                }
            }
        }
    }
    Ok(())
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
    let geo = geometry(x)?;
    average_cauchy_with(&geo, u, mat, form)
}

/// `average_cauchy` with the element's reference geometry already computed.
pub fn average_cauchy_with(
    geo: &Geometry,
    u: &[Vec3; 8],
    mat: &Material,
    form: Formulation,
) -> Result<[f64; 6], ElementFailure> {
    let mut sum = ZERO33;
    let mut vol = 0.0;
    let mut add = |h: &Mat3, w: f64| -> Result<(), ElementFailure> {
        let s = mat.cauchy(h).ok_or(ElementFailure::InvertedCurrent)?;
        let jw = if mat.is_large() {
            w * det(&add_identity(h))
        } else {
            w
        };
        add_scaled(&mut sum, &s, jw);
        vol += jw;
        Ok(())
    };
    match form {
        Formulation::Full => {
            for q in 0..8 {
                add(&displacement_gradient(u, &geo.g[q]), geo.wdet[q])?;
            }
        }
        Formulation::FullBar if !mat.is_large() => {
            let theta_bar: f64 = (0..8).map(|a| crate::math::dot(&u[a], &geo.bbar[a])).sum();
            for q in 0..8 {
                let mut h = displacement_gradient(u, &geo.g[q]);
                let shift = (theta_bar - (h[0][0] + h[1][1] + h[2][2])) / 3.0;
                for (i, row) in h.iter_mut().enumerate() {
                    row[i] += shift;
                }
                add(&h, geo.wdet[q])?;
            }
        }
        Formulation::FullBar => {
            let (j0, _) = mean_dilatation(u, geo)?;
            for q in 0..8 {
                let h = displacement_gradient(u, &geo.g[q]);
                let fb = fbar_at(&h, &geo.g[q], j0)?;
                add(&sub_identity(&fb.fbar), geo.wdet[q])?;
            }
        }
        Formulation::Mean { .. } => {
            add(&displacement_gradient(u, &geo.bbar), geo.volume)?;
        }
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
    Ok(geometry(x)?.volume)
}
