//! Hourglass control of the one-point element in a plastic body: the hourglass forces are
//! accumulated step by step with the stiffness scaled by the centre point's effective shear
//! modulus over the step, so that they stop growing where the material flows.
//!
//! An elastic body's hourglass force is the total form f = k q (Flanagan and Belytschko
//! 1981), k proportional to the shear modulus. In a yielded region that stiffness is a
//! spring the plastic mechanism has to stretch: the limit load of a flat punch rises
//! without bound (issue 47). Here the generalised hourglass forces Q_alpha (k q_alpha of the
//! elastic element) are incremental,
//!
//!   Q = Q_old + k r (q - q_old),   r = (ds : de) / (2 mu de : de), clamped to [R_MIN, 1],
//!
//! with de and ds the increments since the last converged step of the deviatoric strain and
//! stress at the element's centre: r is the ratio of the effective shear modulus of the
//! step to the elastic one (the "effective moduli" the hourglass control and time step of
//! explicit codes use for inelastic materials: Flanagan and Belytschko 1981, sec. 4;
//! Belytschko and Bindeman 1993, sec. 5), 1 while the centre is elastic and near 0 while
//! it flows without hardening. Q_old, q_old and the centre's deviatoric strain and stress
//! of the last converged step are committed with the element's history (`SLOTS` extra
//! states after the centre's), so a restart continues bit for bit.

use super::geometry::Geometry;
use super::stabilization::Stiffness;
use crate::material::{Material, PlasticState, STATE_LEN};
use crate::math::{Mat3, Vec3};

/// The smallest stiffness ratio: a step whose centre flows keeps this fraction of the
/// elastic hourglass stiffness, so the hourglass modes never lose their stiffness entirely
/// (the one-point element's kernel would be singular there).
pub const R_MIN: f64 = 0.01;

/// History states one plastic `mean` element keeps for its hourglass control after its
/// centre's state: 12 + 12 + 6 + 6 = 36 values in 3 x 13.
pub const SLOTS: usize = 3;

/// The committed hourglass state of one element.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Hourglass {
    /// Generalised hourglass forces Q_alpha (already times the stiffness).
    pub force: [Vec3; 4],
    /// Hourglass displacement sums q_alpha = sum_a gamma_alpha,a u_a.
    pub q: [Vec3; 4],
    /// Deviatoric strain of the centre (xx yy zz xy yz zx).
    pub strain: [f64; 6],
    /// Deviatoric stress of the centre, same order.
    pub stress: [f64; 6],
}

impl Hourglass {
    fn flat(&self) -> [f64; SLOTS * STATE_LEN] {
        let mut a = [0.0; SLOTS * STATE_LEN];
        for alpha in 0..4 {
            for i in 0..3 {
                a[3 * alpha + i] = self.force[alpha][i];
                a[12 + 3 * alpha + i] = self.q[alpha][i];
            }
        }
        a[24..30].copy_from_slice(&self.strain);
        a[30..36].copy_from_slice(&self.stress);
        a
    }

    /// Read from the `SLOTS` states that follow the centre's (all zero: a virgin element).
    pub fn read(states: &[PlasticState]) -> Self {
        let mut a = [0.0; SLOTS * STATE_LEN];
        for (s, chunk) in states.iter().zip(a.chunks_mut(STATE_LEN)) {
            chunk.copy_from_slice(&s.to_array());
        }
        Hourglass {
            force: std::array::from_fn(|alpha| std::array::from_fn(|i| a[3 * alpha + i])),
            q: std::array::from_fn(|alpha| std::array::from_fn(|i| a[12 + 3 * alpha + i])),
            strain: std::array::from_fn(|i| a[24 + i]),
            stress: std::array::from_fn(|i| a[30 + i]),
        }
    }

    /// Write into the `SLOTS` states that follow the centre's.
    pub fn write(&self, states: &mut [PlasticState]) {
        let a = self.flat();
        for (s, chunk) in states.iter_mut().zip(a.chunks(STATE_LEN)) {
            *s = PlasticState::from_slice(chunk);
        }
    }
}

/// Deviatoric part of the symmetric part of `m`, as xx yy zz xy yz zx.
#[inline]
pub fn dev_sym(m: &Mat3) -> [f64; 6] {
    let tr = (m[0][0] + m[1][1] + m[2][2]) / 3.0;
    [
        m[0][0] - tr,
        m[1][1] - tr,
        m[2][2] - tr,
        0.5 * (m[0][1] + m[1][0]),
        0.5 * (m[1][2] + m[2][1]),
        0.5 * (m[2][0] + m[0][2]),
    ]
}

/// a : b of two symmetric tensors stored as xx yy zz xy yz zx.
#[inline]
fn ddot6(a: &[f64; 6], b: &[f64; 6]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + 2.0 * (a[3] * b[3] + a[4] * b[4] + a[5] * b[5])
}

/// The stiffness ratio r of the step (module comment) from the centre's deviatoric strain
/// `e` and stress `s` now, whether its return was plastic, and the committed state.
#[inline]
pub fn ratio(mu: f64, e: &[f64; 6], s: &[f64; 6], plastic: bool, old: &Hourglass) -> f64 {
    if !plastic {
        return 1.0;
    }
    let de: [f64; 6] = std::array::from_fn(|i| e[i] - old.strain[i]);
    let ds: [f64; 6] = std::array::from_fn(|i| s[i] - old.stress[i]);
    let ee = ddot6(&de, &de);
    if !(ee > 0.0) {
        return 1.0;
    }
    (ddot6(&ds, &de) / (2.0 * mu * ee)).clamp(R_MIN, 1.0)
}

/// The centre's stress at `h` from the committed state `hist[0]` and the state the step
/// would commit, the hourglass state `hist[1..]` holds, the stiffness ratio of the step
/// and the centre's yield radius sqrt(2/3) (sigma_y + K alpha) after the step. `None`
/// when the deformation is inadmissible.
#[inline]
pub fn centre(mat: &Material, h: &Mat3, hist: &[PlasticState]) -> Option<Centre> {
    let up = mat.update(h, &hist[0])?;
    let old = Hourglass::read(&hist[1..]);
    let (_, mu) = mat.lambda_mu();
    let r = ratio(mu, &dev_sym(h), &dev_sym(&up.stress), up.yielded, &old);
    let radius = mat.yield_radius(&up.state);
    Some(Centre {
        stress: up.stress,
        state: up.state,
        old,
        r,
        radius,
    })
}

/// What `centre` finds.
pub struct Centre {
    pub stress: Mat3,
    /// The centre's state the step would commit.
    pub state: PlasticState,
    pub old: Hourglass,
    pub r: f64,
    pub radius: f64,
}

/// The generalised hourglass forces of the step: Q = Q_old + r K (q - q_old), K the
/// element's elastic hourglass stiffness (`stabilization`), each Q_alpha then held to the
/// length `Stiffness::cap` at which the mode yields, as the stress of a fully integrated
/// element's hourglass mode is held by its Gauss points' yield surfaces. Without the bound
/// a body past its limit load finds equilibrium on the hourglass springs (Hill's sphere at
/// 1.02 of its limit pressure did, at 2000 times the displacement just below it).
#[inline]
pub fn forces(q: &[Vec3; 4], k: &Stiffness, mu: f64, geo: &Geometry, c: &Centre) -> [Vec3; 4] {
    let cap = k.cap(c.radius, mu, geo.rms_gradient(), geo.volume);
    let dq: [Vec3; 4] =
        std::array::from_fn(|alpha| std::array::from_fn(|i| q[alpha][i] - c.old.q[alpha][i]));
    let df = k.apply(c.r, &dq);
    std::array::from_fn(|alpha| {
        let mut f: Vec3 = std::array::from_fn(|i| c.old.force[alpha][i] + df[alpha][i]);
        let norm = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
        if norm > cap {
            for v in f.iter_mut() {
                *v *= cap / norm;
            }
        }
        f
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn some(seed: f64) -> Hourglass {
        let v = |k: usize| (seed + k as f64 * 0.37).sin();
        Hourglass {
            force: std::array::from_fn(|a| std::array::from_fn(|i| v(3 * a + i))),
            q: std::array::from_fn(|a| std::array::from_fn(|i| v(12 + 3 * a + i))),
            strain: std::array::from_fn(|i| v(24 + i)),
            stress: std::array::from_fn(|i| v(30 + i)),
        }
    }

    #[test]
    fn the_state_is_kept_bit_for_bit_in_its_history_slots() {
        let h = some(0.3);
        let mut slots = [PlasticState::default(); SLOTS];
        h.write(&mut slots);
        assert_eq!(Hourglass::read(&slots), h);
        assert_eq!(
            Hourglass::read(&[PlasticState::default(); SLOTS]),
            Hourglass::default()
        );
    }

    #[test]
    fn the_ratio_is_one_when_elastic_and_the_floor_when_flowing_freely() {
        let old = some(1.1);
        let mu = 50.0;
        let e: [f64; 6] = std::array::from_fn(|i| old.strain[i] + 1e-3 * (i as f64 - 2.0));
        // Elastic: ds = 2 mu de gives 1 (to rounding), and a non-plastic return 1 exactly.
        let s: [f64; 6] =
            std::array::from_fn(|i| old.stress[i] + 2.0 * mu * (e[i] - old.strain[i]));
        assert!((ratio(mu, &e, &s, true, &old) - 1.0).abs() < 1e-12);
        assert_eq!(ratio(mu, &e, &s, false, &old), 1.0);
        // Perfectly plastic flow, the stress unchanged: the floor.
        assert_eq!(ratio(mu, &e, &old.stress, true, &old), R_MIN);
        // Half the elastic stress increment: 1/2.
        let half: [f64; 6] = std::array::from_fn(|i| old.stress[i] + mu * (e[i] - old.strain[i]));
        assert!((ratio(mu, &e, &half, true, &old) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn a_virgin_elastic_step_gives_the_total_force_and_the_bound_holds_each_mode() {
        let q: [Vec3; 4] = std::array::from_fn(|a| std::array::from_fn(|i| 1e-3 * (a + i) as f64));
        // A cube of side 2: volume 8, mean gradients (+-1/8, +-1/8, +-1/8), g = sqrt(3)/8.
        let x: [Vec3; 8] = crate::fem::hex8::NODE_XI;
        let (geo, _) = super::super::geometry::geometry(&x).expect("a valid element");
        let g = 3f64.sqrt() / 8.0;
        assert!((geo.rms_gradient() - g).abs() < 1e-15);
        let mu = 50.0;
        let c = |radius| Centre {
            stress: [[0.0; 3]; 3],
            state: PlasticState::default(),
            old: Hourglass::default(),
            r: 1.0,
            radius,
        };
        let mat = Material::LinearElastic(crate::material::LinearElastic::new(130.0, 0.3));
        for k in [
            Stiffness::Scalar(7.0),
            Stiffness::new(&geo, super::super::Stabilization::AssumedStrain, &mat),
        ] {
            let f = forces(&q, &k, mu, &geo, &c(f64::INFINITY));
            let total = k.apply(1.0, &q);
            for a in 0..4 {
                for i in 0..3 {
                    assert_eq!(f[a][i].to_bits(), total[a][i].to_bits());
                }
            }
            // The bound: k radius / (2 mu g) for a scalar k, (V / 3) g radius otherwise.
            let cap = match k {
                Stiffness::Scalar(k) => k * 0.1 / (2.0 * mu * g),
                _ => 8.0 / 3.0 * g * 0.1,
            };
            for fa in forces(&q, &k, mu, &geo, &c(0.1)) {
                let norm = (fa[0] * fa[0] + fa[1] * fa[1] + fa[2] * fa[2]).sqrt();
                assert!(norm <= cap * (1.0 + 1e-15), "{norm} {cap}");
            }
        }
    }
}
