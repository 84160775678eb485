//! J2 (von Mises) plasticity under small kinematics with linear isotropic and linear
//! kinematic hardening, integrated by the radial return (backward Euler), and its
//! consistent (algorithmic) tangent. Simo and Hughes, Computational Inelasticity (1998),
//! boxes 3.1 and 3.2:
//!
//!   f = |s - beta| - sqrt(2/3) (sigma_y + K alpha),
//!   eps_p' = gamma n, alpha' = sqrt(2/3) gamma, beta' = (2/3) H gamma n,
//!
//! with n = (s - beta) / |s - beta|, K the isotropic and H the kinematic modulus. Under
//! uniaxial stress the yield stress grows at the rate K + H per unit plastic strain.
//!
//! The model as the solver sees it under both kinematics (`PointModel`, dispatching to
//! `update_small` or `j2_large`'s `update_large`) and its scene keys (`J2Params`) are here
//! too.

use super::parameters::{check_elastic, ParamError, Parameters};
use super::point::{lame, PointModel, Update};
use super::state::PlasticState;
use super::tangent::{Moduli, PointTangent};
use crate::math::{Mat3, Vec3, ZERO33};
use serde::Deserialize;

/// Symmetric tensor from the order xx yy zz xy yz zx.
#[inline]
pub fn from_sym6(v: &[f64; 6]) -> Mat3 {
    [[v[0], v[3], v[5]], [v[3], v[1], v[4]], [v[5], v[4], v[2]]]
}

/// Parameters of the J2 model (both kinematics).
#[derive(serde::Serialize, serde::Deserialize, Clone, Copy, Debug, PartialEq)]
pub struct J2Plastic {
    pub lambda: f64,
    pub mu: f64,
    /// Initial yield stress in uniaxial tension, sigma_y.
    pub yield_stress: f64,
    /// Linear isotropic hardening modulus K.
    pub isotropic: f64,
    /// Linear kinematic hardening modulus H.
    pub kinematic: f64,
    /// Finite strain: the multiplicative split with logarithmic elastic strains
    /// (see `j2_large`); small strain otherwise.
    pub large: bool,
}

/// What the return mapping did at a point, enough for the consistent tangent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Return {
    /// Plastic multiplier increment (zero when elastic).
    pub gamma: f64,
    /// Flow direction n (unit deviatoric tensor); zero when elastic.
    pub n: Mat3,
    /// |s_trial - beta_old|.
    pub xi_norm: f64,
}

/// Result of the radial return on a trial elastic strain (deviatoric and volumetric parts
/// handled by the caller's kinematics).
pub struct Radial {
    /// Deviatoric stress s (or Kirchhoff deviator under large kinematics).
    pub s: Mat3,
    pub ret: Return,
    pub back: Mat3,
    pub eqps: f64,
}

impl Return {
    /// The return data of an elastic point.
    pub const ELASTIC: Return = Return {
        gamma: 0.0,
        n: ZERO33,
        xi_norm: 0.0,
    };
}

const SQRT_2_3: f64 = 0.816_496_580_927_726;

#[inline]
fn dev(m: &Mat3) -> (Mat3, f64) {
    let tr = m[0][0] + m[1][1] + m[2][2];
    let mut d = *m;
    for (i, row) in d.iter_mut().enumerate() {
        row[i] -= tr / 3.0;
    }
    (d, tr)
}

#[inline]
fn ddot(a: &Mat3, b: &Mat3) -> f64 {
    let mut s = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            s += a[i][j] * b[i][j];
        }
    }
    s
}

impl J2Plastic {
    pub fn new(
        e: f64,
        nu: f64,
        yield_stress: f64,
        isotropic: f64,
        kinematic: f64,
        large: bool,
    ) -> Self {
        let (lambda, mu) = lame(e, nu);
        J2Plastic {
            lambda,
            mu,
            yield_stress,
            isotropic,
            kinematic,
            large,
        }
    }

    /// Bulk modulus lambda + 2 mu / 3.
    #[inline]
    pub fn bulk(&self) -> f64 {
        self.lambda + 2.0 * self.mu / 3.0
    }

    /// The radial return from the trial deviatoric stress `s_trial` with the old back
    /// stress and equivalent plastic strain.
    #[inline(always)]
    pub fn radial_return(&self, s_trial: &Mat3, back_old: &Mat3, eqps_old: f64) -> Radial {
        let mut xi = ZERO33;
        for i in 0..3 {
            for j in 0..3 {
                xi[i][j] = s_trial[i][j] - back_old[i][j];
            }
        }
        let xi_norm = ddot(&xi, &xi).sqrt();
        let radius = SQRT_2_3 * (self.yield_stress + self.isotropic * eqps_old);
        let f = xi_norm - radius;
        if !(f > 0.0) {
            return Radial {
                s: *s_trial,
                ret: Return {
                    gamma: 0.0,
                    n: ZERO33,
                    xi_norm,
                },
                back: *back_old,
                eqps: eqps_old,
            };
        }
        let gamma = f / (2.0 * self.mu + 2.0 / 3.0 * (self.isotropic + self.kinematic));
        let mut n = ZERO33;
        let mut s = *s_trial;
        let mut back = *back_old;
        for i in 0..3 {
            for j in 0..3 {
                n[i][j] = xi[i][j] / xi_norm;
                s[i][j] -= 2.0 * self.mu * gamma * n[i][j];
                back[i][j] += 2.0 / 3.0 * self.kinematic * gamma * n[i][j];
            }
        }
        Radial {
            s,
            ret: Return { gamma, n, xi_norm },
            back,
            eqps: eqps_old + SQRT_2_3 * gamma,
        }
    }

    /// Small kinematics: the Cauchy stress at the displacement gradient `h` from the
    /// committed state `old`, the state the step would commit, and the return data.
    // Always inlined, as `radial_return`: behind `PointModel::update` the compiler left
    // them out of line, and punch_40 took 5-10% more CPU time (run/scenes/plasticity).
    #[inline(always)]
    pub fn update_small(&self, h: &Mat3, old: &PlasticState) -> (Mat3, PlasticState, Return) {
        let mut eps = ZERO33;
        for i in 0..3 {
            for j in 0..3 {
                eps[i][j] = 0.5 * (h[i][j] + h[j][i]);
            }
        }
        let (e, tr) = dev(&eps);
        let ep = from_sym6(&old.strain);
        let mut s_trial = ZERO33;
        for i in 0..3 {
            for j in 0..3 {
                s_trial[i][j] = 2.0 * self.mu * (e[i][j] - ep[i][j]);
            }
        }
        let r = self.radial_return(&s_trial, &from_sym6(&old.back), old.eqps);
        let mut sigma = r.s;
        let p = self.bulk() * tr;
        for (i, row) in sigma.iter_mut().enumerate() {
            row[i] += p;
        }
        let mut ep_new = ep;
        for i in 0..3 {
            for j in 0..3 {
                ep_new[i][j] += r.ret.gamma * r.ret.n[i][j];
            }
        }
        let state = PlasticState {
            strain: crate::math::to_sym6(&ep_new),
            back: crate::math::to_sym6(&r.back),
            eqps: r.eqps,
        };
        (sigma, state, r.ret)
    }

    /// The algorithmic moduli: C = kappa I(x)I + 2 mu theta I_dev - 2 mu theta_bar n(x)n,
    /// returned as (kappa, mu theta, 2 mu theta_bar).
    #[inline]
    pub fn moduli(&self, ret: &Return) -> (f64, f64, f64) {
        if ret.gamma == 0.0 {
            return (self.bulk(), self.mu, 0.0);
        }
        let theta = 1.0 - 2.0 * self.mu * ret.gamma / ret.xi_norm;
        let theta_bar =
            1.0 / (1.0 + (self.isotropic + self.kinematic) / (3.0 * self.mu)) - (1.0 - theta);
        (self.bulk(), self.mu * theta, 2.0 * self.mu * theta_bar)
    }

    /// The consistent tangent applied to a displacement-gradient increment: C : sym(dh).
    pub fn tangent_apply(&self, ret: &Return, dh: &Mat3) -> Mat3 {
        let (kappa, mu_t, c_n) = self.moduli(ret);
        let mut de = ZERO33;
        for i in 0..3 {
            for j in 0..3 {
                de[i][j] = 0.5 * (dh[i][j] + dh[j][i]);
            }
        }
        let (d, tr) = dev(&de);
        let nd = ddot(&ret.n, &de);
        let mut out = ZERO33;
        for i in 0..3 {
            for j in 0..3 {
                out[i][j] = 2.0 * mu_t * d[i][j] - c_n * nd * ret.n[i][j];
            }
            out[i][i] += kappa * tr;
        }
        out
    }

    /// `sum_jl g_j C_ijkl g_l` for the consistent tangent:
    /// (kappa + mu_t / 3) g g^T + mu_t |g|^2 I - c_n (n g)(n g)^T.
    #[inline]
    pub fn tangent_gg(&self, ret: &Return, g: &Vec3) -> Mat3 {
        let (kappa, mu_t, c_n) = self.moduli(ret);
        let ng = crate::math::matvec(&ret.n, g);
        let gg = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
        let mut k = ZERO33;
        for i in 0..3 {
            for m in 0..3 {
                k[i][m] = (kappa + mu_t / 3.0) * g[i] * g[m] - c_n * ng[i] * ng[m];
            }
            k[i][i] += mu_t * gg;
        }
        k
    }

    /// The consistent moduli at `h` from the committed state `old` (small kinematics) for
    /// an assembled tangent: elastic inside the yield surface, the return map's algorithmic
    /// moduli (`moduli`) outside it, and at a point on the surface, where the return map
    /// has a kink (|f| <= `ON_SURFACE` of its radius: a point the last step returned to
    /// the surface and this state has not moved), the mean of its elastic and its loading
    /// branch, which is what a central difference of the forces about the state measures
    /// there. The mean keeps the point's tangent symmetric and positive semi-definite,
    /// and it does not take the loading branch's softness along n for a point that the
    /// next step may unload.
    pub fn surface_moduli(&self, h: &Mat3, old: &PlasticState) -> Moduli {
        let elastic = Moduli {
            kappa: self.bulk(),
            mu_t: self.mu,
            cn: 0.0,
            n: ZERO33,
        };
        let (_, _, ret) = self.update_small(h, old);
        let radius = SQRT_2_3 * (self.yield_stress + self.isotropic * old.eqps);
        let f = ret.xi_norm - radius;
        if f.abs() > ON_SURFACE * radius || ret.xi_norm == 0.0 {
            let (kappa, mu_t, cn) = self.moduli(&ret);
            return Moduli {
                kappa,
                mu_t,
                cn,
                n: ret.n,
            };
        }
        // On the surface: n from the trial state (the return data holds it only when it
        // loads), the loading branch's moduli at gamma = 0 (theta = 1).
        let mut eps = ZERO33;
        for i in 0..3 {
            for j in 0..3 {
                eps[i][j] = 0.5 * (h[i][j] + h[j][i]);
            }
        }
        let (e, _) = dev(&eps);
        let (ep, back) = (from_sym6(&old.strain), from_sym6(&old.back));
        let mut n = ZERO33;
        for i in 0..3 {
            for j in 0..3 {
                n[i][j] = (2.0 * self.mu * (e[i][j] - ep[i][j]) - back[i][j]) / ret.xi_norm;
            }
        }
        let theta_bar = 1.0 / (1.0 + (self.isotropic + self.kinematic) / (3.0 * self.mu));
        Moduli {
            cn: self.mu * theta_bar,
            n,
            ..elastic
        }
    }
}

/// How close to its yield surface, relative to the surface's radius, a point counts as on
/// it (`J2Plastic::surface_moduli`): a return lands on the surface to rounding (1e-16 of
/// the radius), and a point a step has moved is off it by the step's strain, orders above.
pub const ON_SURFACE: f64 = 1e-9;

impl PointModel for J2Plastic {
    fn name(&self) -> &'static str {
        "j2_plastic"
    }

    #[inline]
    fn lambda_mu(&self) -> (f64, f64) {
        (self.lambda, self.mu)
    }

    #[inline]
    fn is_large(&self) -> bool {
        self.large
    }

    #[inline]
    fn is_plastic(&self) -> bool {
        true
    }

    #[inline]
    fn stress(&self, h: &Mat3) -> Option<Mat3> {
        Some(self.update(h, &PlasticState::default())?.stress)
    }

    /// The radial return (`update_small`) or the exponential-map return (`update_large`).
    #[inline]
    fn update(&self, h: &Mat3, old: &PlasticState) -> Option<Update> {
        if self.large {
            let r = self.update_large(h, old)?;
            Some(Update {
                stress: r.pk1,
                state: r.state,
                yielded: r.ret.gamma > 0.0,
            })
        } else {
            let (stress, state, ret) = self.update_small(h, old);
            Some(Update {
                stress,
                state,
                yielded: ret.gamma > 0.0,
            })
        }
    }

    #[inline]
    fn cauchy(&self, h: &Mat3, old: &PlasticState) -> Option<Mat3> {
        if self.large {
            let r = self.update_large(h, old)?;
            let s = 1.0 / r.j;
            Some(std::array::from_fn(|i| {
                std::array::from_fn(|j| r.tau[i][j] * s)
            }))
        } else {
            Some(self.update_small(h, old).0)
        }
    }

    /// The consistent tangent (`tangent_gg`) at the return from `old`; under large
    /// kinematics the same moduli with the spatial flow direction and v = F^-T g (an
    /// approximation that only preconditions).
    #[inline]
    fn tangent(&self, h: &Mat3, old: Option<&PlasticState>) -> PointTangent {
        let virgin = PlasticState::default();
        let old = old.unwrap_or(&virgin);
        let (ret, finv) = if self.large {
            match self.update_large(h, old) {
                Some(r) => (r.ret, Some(r.finv)),
                None => (Return::ELASTIC, Some(crate::math::IDENTITY)),
            }
        } else {
            (self.update_small(h, old).2, None)
        };
        let (kappa, mu_t, cn) = self.moduli(&ret);
        PointTangent {
            finv,
            c: kappa + mu_t / 3.0,
            mu: mu_t,
            n: ret.n,
            cn,
        }
    }

    /// sqrt(2/3) (sigma_y + K alpha).
    #[inline]
    fn yield_radius(&self, state: &PlasticState) -> f64 {
        SQRT_2_3 * (self.yield_stress + self.isotropic * state.eqps)
    }
}

/// The scene keys of `j2_plastic`.
#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct J2Params {
    #[serde(rename = "E")]
    pub e: f64,
    pub nu: f64,
    pub yield_stress: f64,
    #[serde(default)]
    pub isotropic_hardening: f64,
    #[serde(default)]
    pub kinematic_hardening: f64,
    #[serde(default)]
    pub density: f64,
}

impl<M: From<J2Plastic>> Parameters<M> for J2Params {
    fn young_poisson(&self) -> (f64, f64) {
        (self.e, self.nu)
    }

    fn density(&self) -> f64 {
        self.density
    }

    fn is_plastic(&self) -> bool {
        true
    }

    fn is_linear(&self) -> bool {
        false
    }

    fn build(&self, large: bool) -> Result<M, ParamError> {
        check_elastic(self.e, self.nu, self.density)?;
        let yield_stress = self.yield_stress;
        if !(yield_stress.is_finite() && yield_stress > 0.0) {
            return Err(ParamError::new(
                "yield_stress",
                format!("expected a yield stress > 0, got {yield_stress}"),
            ));
        }
        // Softening (a negative modulus) makes the load step's energy non-convex: the
        // minimisation the solver performs has no unique answer and the mesh decides it.
        for (key, v) in [
            ("isotropic_hardening", self.isotropic_hardening),
            ("kinematic_hardening", self.kinematic_hardening),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(ParamError::new(
                    key,
                    format!("expected a hardening modulus >= 0 (softening is not supported: the load step would have no unique solution), got {v}"),
                ));
            }
        }
        if large && self.kinematic_hardening != 0.0 {
            return Err(ParamError::new(
                "kinematic_hardening",
                "kinematic hardening is available with kinematics = \"small\" only; under kinematics = \"large\" j2_plastic hardens isotropically (use isotropic_hardening)",
            ));
        }
        Ok(M::from(J2Plastic::new(
            self.e,
            self.nu,
            yield_stress,
            self.isotropic_hardening,
            self.kinematic_hardening,
            large,
        )))
    }
}
