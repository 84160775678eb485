//! The hourglass stiffness of the one-point element: the linear map from the hourglass
//! displacement sums q_alpha to the generalised hourglass forces Q_alpha (f_a = sum_alpha
//! gamma_alpha,a Q_alpha, see `force::force_mean`).
//!
//! The assumed-strain physical stabilisation (Belytschko and Bindeman, CMAME 105 (1993)
//! 225; Puso, IJNME 49 (2000) 1029): the stiffness comes from the material's moduli and
//! the element's geometry, with no coefficient. The hourglass part of the trilinear field
//! is u = (1/8) sum_alpha q_alpha h_alpha(xi), h = (eta zeta, zeta xi, xi eta, xi eta
//! zeta), and its gradient, with n_k the element's mean gradient of xi_k, splits by the
//! monomial it multiplies:
//!
//! - xi_k (k = 1, 2, 3): G_k = (q_j2 (x) n_j1 + q_j1 (x) n_j2) / 8, (j1, j2) the other two
//!   axes. The shear across n_k that G_k holds is the parasitic shear of a bending mode;
//!   it and the normal strain along n_k are relaxed by the incompatible mode (1 - xi_k^2)
//!   c (Wilson, Taylor): c is chosen to minimise the energy, which leaves the stress
//!   traction-free across n_k (plane stress in the element's layer). Integrated over a
//!   parallelepiped with weight xi_k^2 (V / 3), this is the incompatible-mode element's
//!   hourglass energy exactly: pure bending of a rectangular element is exact for every
//!   nu, and a bending mode does not lock as nu -> 1/2 (the plane-stress modulus stays
//!   below 4 mu).
//! - xi_j xi_l (the trilinear mode, weight V / 9): G = q_4 (x) n_k / 8, its deviatoric
//!   energy only (its volume change averages to zero over the element; with lambda it
//!   would lock near incompressibility, as Belytschko and Bindeman's ASMD also drops it).
//!
//! The energy is a minimum over c, so its derivative is the stress of the relaxed strain
//! (the envelope theorem): Q_j2 += (V / 24) sigma n_j1 and Q_j1 += (V / 24) sigma n_j2.
//! For a distorted element the n_k are the volume means of grad xi_k; the constant-strain
//! patch test holds for any stiffness, since the gamma vectors annihilate linear fields.
//!
//! `AssumedStrainMu`, the default of linear elastic bodies, is the same energy with lambda = 0:
//! the layer's stress 2 mu P e P, the hourglass modes' normal modulus 2 mu for every nu
//! (E at nu = 0, where pure bending stays exact), as Flanagan-Belytschko and Belytschko
//! and Bindeman's ASMD take the shear modulus only. With lambda the plane-strain layer's
//! modulus doubles to 4 mu as nu -> 1/2, and a coarse near-incompressible mesh is stiffer
//! (docs/elements.md: the bonded block of `tests/foundation.rs`).
//!
//! The older Flanagan-Belytschko control (IJNME 17 (1981) 679), Q = k q with k proportional
//! to a user coefficient, remains for scenes that set `hourglass = <coefficient>` and is the
//! default of plastic (`hourglass`) and neo-Hookean bodies.

use super::geometry::Geometry;
use super::Stabilization;
use crate::fem::hex8::NODE_XI;
use crate::material::Material;
use crate::math::{Mat3, Vec3};

/// The elastic hourglass stiffness of one element.
#[derive(Clone, Copy, Debug)]
pub enum Stiffness {
    /// Flanagan-Belytschko: Q = k q.
    Scalar(f64),
    /// The assumed-strain stabilisation (module comment) of moduli lambda, mu, with the
    /// element's mean dual basis n and volume.
    AssumedStrain {
        n: [Vec3; 3],
        volume: f64,
        lambda: f64,
        mu: f64,
    },
}

impl Stiffness {
    /// The stiffness of an element of geometry `geo` and material `mat` under `control`.
    #[inline]
    pub fn new(geo: &Geometry, control: Stabilization, mat: &Material) -> Self {
        let (lambda, mu) = mat.lambda_mu();
        match control {
            // Scaled so that coefficient 1 matches the shear part of the fully integrated
            // element's hourglass-mode stiffness on a cube. Shear modulus only: the modes
            // are volume-preserving on average, and lambda would lock near
            // incompressibility.
            Stabilization::Coefficient(c) => Stiffness::Scalar(c * mu * geo.vbb() / 24.0),
            Stabilization::AssumedStrain => Stiffness::AssumedStrain {
                n: dual_basis(geo),
                volume: geo.volume,
                lambda,
                mu,
            },
            Stabilization::AssumedStrainMu => Stiffness::AssumedStrain {
                n: dual_basis(geo),
                volume: geo.volume,
                lambda: 0.0,
                mu,
            },
        }
    }

    /// r K q: the generalised forces of `q` with the stiffness scaled by `r`.
    #[inline]
    pub fn apply(&self, r: f64, q: &[Vec3; 4]) -> [Vec3; 4] {
        match *self {
            Stiffness::Scalar(k) => {
                let kr = k * r;
                std::array::from_fn(|alpha| std::array::from_fn(|i| kr * q[alpha][i]))
            }
            Stiffness::AssumedStrain {
                n,
                volume,
                lambda,
                mu,
            } => {
                let f = assumed_strain(&n, volume, lambda, mu, q);
                if r == 1.0 {
                    return f;
                }
                std::array::from_fn(|alpha| std::array::from_fn(|i| r * f[alpha][i]))
            }
        }
    }

    /// The largest length of one mode's generalised force in a plastic element whose
    /// centre's yield radius is `radius`; `mu` the elastic shear modulus, `g` the rms of
    /// the nodes' mean gradients and `volume` the element's. Flanagan-Belytschko: k q_y,
    /// q_y = radius / (2 mu g) the displacement sum whose strain q g reaches the radius.
    /// Assumed strain: (V / 3) g radius, the force of a bending mode whose stress
    /// amplitude (the stress at xi_k = 1) is sqrt(3) radius on a cube, i.e. whose stress at
    /// the fully integrated element's Gauss points xi_k = +-1/sqrt(3) reaches the radius.
    #[inline]
    pub fn cap(&self, radius: f64, mu: f64, g: f64, volume: f64) -> f64 {
        match *self {
            Stiffness::Scalar(k) => k * radius / (2.0 * mu * g),
            Stiffness::AssumedStrain { .. } => volume / 3.0 * g * radius,
        }
    }
}

/// The element's mean dual basis: n_k = volume mean of grad xi_k = sum_a xi_a,k bbar_a
/// (the trilinear interpolation reproduces xi_k).
#[inline]
pub fn dual_basis(geo: &Geometry) -> [Vec3; 3] {
    std::array::from_fn(|k| {
        let mut n = [0.0; 3];
        for (a, p) in NODE_XI.iter().enumerate() {
            let b = geo.bbar_at(a);
            for i in 0..3 {
                n[i] += p[k] * b[i];
            }
        }
        n
    })
}

/// sym(a (x) b + c (x) d) / 8
#[inline(always)]
fn sym_outer(a: &Vec3, b: &Vec3, c: &Vec3, d: &Vec3) -> Mat3 {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| (a[i] * b[j] + a[j] * b[i] + c[i] * d[j] + c[j] * d[i]) / 16.0)
    })
}

/// The stress of the strain `e` relaxed by the incompatible mode c (1 - xi_k^2): the mode
/// adds sym(c (x) n) and c minimises the energy, so the traction across n vanishes and
/// sigma = 2 mu P e P + lambda* tr(P e P) P, P = I - m m^T (m = n / |n|), lambda* = 2 mu
/// lambda / (lambda + 2 mu). Written in this closed form rather than by solving for c:
/// that subtracts terms of size lambda tr(e), whose rounding near incompressibility
/// (lambda / mu = 5000 at nu = 0.4999) was noise the CG could not get below (the
/// extreme scene incompressible_mean stalled at 1e-10 of its load against 1e-12 asked).
#[inline(always)]
fn plane_stress(e: &Mat3, n: &Vec3, lambda: f64, mu: f64) -> Mat3 {
    let len = dot(n, n).sqrt();
    let m: Vec3 = std::array::from_fn(|i| n[i] / len);
    let em = crate::math::matvec(e, &m);
    let emm = dot(&em, &m);
    let p: Mat3 = std::array::from_fn(|i| {
        std::array::from_fn(|j| if i == j { 1.0 } else { 0.0 } - m[i] * m[j])
    });
    let pep: Mat3 = std::array::from_fn(|i| {
        std::array::from_fn(|j| e[i][j] - m[i] * em[j] - em[i] * m[j] + emm * m[i] * m[j])
    });
    let tr = pep[0][0] + pep[1][1] + pep[2][2];
    let ls = 2.0 * mu * lambda / (lambda + 2.0 * mu);
    std::array::from_fn(|i| std::array::from_fn(|j| 2.0 * mu * pep[i][j] + ls * tr * p[i][j]))
}

#[inline(always)]
fn dot(a: &Vec3, b: &Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Q = K q of the assumed-strain stabilisation (module comment): n the element's mean dual
/// basis, `volume` its volume, lambda and mu the moduli.
#[inline]
pub fn assumed_strain(
    n: &[Vec3; 3],
    volume: f64,
    lambda: f64,
    mu: f64,
    q: &[Vec3; 4],
) -> [Vec3; 4] {
    let mut out = [[0.0; 3]; 4];
    for k in 0..3 {
        let (j1, j2) = ((k + 1) % 3, (k + 2) % 3);
        let e = sym_outer(&q[j2], &n[j1], &q[j1], &n[j2]);
        let s = plane_stress(&e, &n[k], lambda, mu);
        let w = volume / 24.0;
        let (s1, s2) = (
            crate::math::matvec(&s, &n[j1]),
            crate::math::matvec(&s, &n[j2]),
        );
        for i in 0..3 {
            out[j2][i] += w * s1[i];
            out[j1][i] += w * s2[i];
        }
    }
    for nk in n {
        // The trilinear mode's gradient q_4 (x) n_k / 8 on the monomial of the other two
        // axes: deviatoric stress only.
        let mut e: Mat3 = std::array::from_fn(|i| {
            std::array::from_fn(|j| (q[3][i] * nk[j] + q[3][j] * nk[i]) / 16.0)
        });
        let tr = (e[0][0] + e[1][1] + e[2][2]) / 3.0;
        for (i, row) in e.iter_mut().enumerate() {
            row[i] -= tr;
        }
        let s = crate::math::matvec(&e, nk);
        let w = volume / 72.0 * 2.0 * mu;
        for i in 0..3 {
            out[3][i] += w * s[i];
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::element::{geometry, internal_force, Formulation};
    use crate::material::LinearElastic;

    /// A rectangular element 2a x 2b x 2c rotated by `rot`, at an offset.
    fn element(half: Vec3, rot: &Mat3) -> [Vec3; 8] {
        std::array::from_fn(|a| {
            let p: Vec3 = std::array::from_fn(|i| half[i] * NODE_XI[a][i]);
            let rp = crate::math::matvec(rot, &p);
            [rp[0] + 0.3, rp[1] - 0.2, rp[2] + 0.7]
        })
    }

    fn rotation() -> Mat3 {
        // Rotation by 0.7 rad about (1, 2, 2)/3 (Rodrigues).
        let n = [1.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0];
        let (s, c) = 0.7f64.sin_cos();
        std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let k = [[0.0, -n[2], n[1]], [n[2], 0.0, -n[0]], [-n[1], n[0], 0.0]];
                let id = if i == j { 1.0 } else { 0.0 };
                id * c + (1.0 - c) * n[i] * n[j] + s * k[i][j]
            })
        })
    }

    /// Pure bending of one rectangular element, the exact field u_1 = kappa x y, u_2 =
    /// -kappa (x^2 + nu (y^2 - z^2)) / 2, u_3 = -nu kappa y z at the nodes (element axes;
    /// rotated with the element): the element's energy u . f / 2 is the beam's
    /// E kappa^2 I L / 2 for every nu, to rounding (the incompatible-mode element is exact
    /// here), also near incompressibility. The Flanagan-Belytschko element at 0.1 is not.
    #[test]
    fn pure_bending_of_a_rectangular_element_is_exact() {
        let half = [0.25, 0.125, 0.5];
        let kappa = 1e-3;
        for rot in [crate::math::IDENTITY, rotation()] {
            let x = element(half, &rot);
            for nu in [0.0, 0.3, 0.4999] {
                let e = 1000.0;
                let mat = Material::LinearElastic(LinearElastic::new(e, nu));
                let u: [Vec3; 8] = std::array::from_fn(|a| {
                    let p: Vec3 = std::array::from_fn(|i| half[i] * NODE_XI[a][i]);
                    let v = [
                        kappa * p[0] * p[1],
                        -kappa * (p[0] * p[0] + nu * (p[1] * p[1] - p[2] * p[2])) / 2.0,
                        -nu * kappa * p[1] * p[2],
                    ];
                    crate::math::matvec(&rot, &v)
                });
                let energy = |form| {
                    let mut f = [[0.0; 3]; 8];
                    internal_force(&x, &u, &mat, form, &mut f).unwrap();
                    (0..8).map(|a| dot(&u[a], &f[a])).sum::<f64>() / 2.0
                };
                let inertia = (2.0 * half[2]) * (2.0 * half[1]).powi(3) / 12.0;
                let exact = e * kappa * kappa * inertia * (2.0 * half[0]) / 2.0;
                let ours = energy(Formulation::Mean {
                    hourglass: Stabilization::AssumedStrain,
                });
                let fb = energy(Formulation::Mean {
                    hourglass: Stabilization::Coefficient(0.1),
                });
                // Rounding: sums of a few dozen terms of one sign, and lambda / mu = 5000
                // at nu = 0.4999 cancelled in the plane-stress relaxation: 1e-9.
                assert!((ours / exact - 1.0).abs() < 1e-9, "{nu}: {ours} vs {exact}");
                // The elastic default (lambda = 0 in the hourglass energy) is exact at nu = 0.
                if nu == 0.0 {
                    let mu_only = energy(Formulation::Mean {
                        hourglass: Stabilization::AssumedStrainMu,
                    });
                    assert!((mu_only / exact - 1.0).abs() < 1e-9, "{mu_only} vs {exact}");
                }
                assert!((fb / exact - 1.0).abs() > 0.1, "{nu}: {fb} vs {exact}");
            }
        }
    }

    /// K is symmetric and positive definite on the 12 hourglass displacement sums of a
    /// distorted element (its energy q . K q > 0 for random q), and linear: K (a q) = a K q.
    #[test]
    fn the_stiffness_is_symmetric_and_positive() {
        let x: [Vec3; 8] = std::array::from_fn(|a| {
            std::array::from_fn(|i| {
                0.5 * (1.0 + NODE_XI[a][i]) + 0.1 * ((3 * a + i) as f64 * 0.731).sin()
            })
        });
        let (geo, _) = geometry(&x).unwrap();
        let mat = Material::LinearElastic(LinearElastic::new(1000.0, 0.3));
        let k = Stiffness::new(&geo, Stabilization::AssumedStrain, &mat);
        let unit = |m: usize| -> [Vec3; 4] {
            let mut q = [[0.0; 3]; 4];
            q[m / 3][m % 3] = 1.0;
            q
        };
        let mut diag_min = f64::INFINITY;
        let mut scale: f64 = 0.0;
        let mut kk = [[0.0; 12]; 12];
        for m in 0..12 {
            let f = k.apply(1.0, &unit(m));
            for l in 0..12 {
                kk[l][m] = f[l / 3][l % 3];
                scale = scale.max(kk[l][m].abs());
            }
            diag_min = diag_min.min(kk[m][m]);
        }
        for l in 0..12 {
            for m in 0..12 {
                // Sums of a few dozen products: 1e-13 of the largest entry.
                assert!((kk[l][m] - kk[m][l]).abs() < 1e-13 * scale, "{l} {m}");
            }
        }
        assert!(diag_min > 0.0);
        for s in 0..50 {
            let q: [Vec3; 4] = std::array::from_fn(|a| {
                std::array::from_fn(|i| ((s * 12 + 3 * a + i) as f64 * 1.37).sin())
            });
            let f = k.apply(1.0, &q);
            let f2 = k.apply(2.5, &q);
            let w: f64 = (0..4).map(|a| dot(&q[a], &f[a])).sum();
            assert!(w > 0.0, "{s}: {w}");
            for a in 0..4 {
                for i in 0..3 {
                    assert!((f2[a][i] - 2.5 * f[a][i]).abs() <= 1e-15 * scale * 10.0);
                }
            }
        }
    }
}
