//! J2 plasticity under large kinematics: the multiplicative split F = F_e F_p with
//! logarithmic elastic strains (Hencky elasticity) and the exponential-map return
//! (Simo, CMAME 99, 1992; Simo and Hughes 1998, box 9.1). The trial elastic left
//! Cauchy-Green tensor b_e = F C_p^-1 F^T is diagonalised; in its principal frame the
//! logarithmic elastic strains eps_A = ln(lambda_A) take the small-strain radial return
//! unchanged (Kirchhoff stress tau = lambda tr(eps) I + 2 mu eps), and b_e is rebuilt
//! from the returned strains. Isotropic hardening only: `J2Params` refuses a kinematic
//! modulus with large kinematics.
//!
//! The state keeps C_p^-1 - I (zero in a virgin point) and the equivalent plastic strain.

use super::j2_small::{from_sym6, J2Plastic, Return};
use super::state::PlasticState;
use crate::math::{inverse, matmul, transpose, Mat3, ZERO33};

/// Eigenvalues and eigenvectors (columns of the second) of a symmetric 3x3 matrix, by
/// cyclic Jacobi rotations: deterministic and accurate to round-off in every eigenvalue,
/// repeated ones included.
pub fn sym_eigen(a: &Mat3) -> ([f64; 3], Mat3) {
    let mut m = *a;
    let mut q = crate::math::IDENTITY;
    for _sweep in 0..50 {
        let off = m[0][1] * m[0][1] + m[1][2] * m[1][2] + m[0][2] * m[0][2];
        let diag = m[0][0] * m[0][0] + m[1][1] * m[1][1] + m[2][2] * m[2][2];
        if !(off > 1e-36 * diag) {
            break;
        }
        for (p, r) in [(0usize, 1usize), (0, 2), (1, 2)] {
            let apq = m[p][r];
            if apq == 0.0 {
                continue;
            }
            let theta = (m[r][r] - m[p][p]) / (2.0 * apq);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // m <- J^T m J with the rotation J in the (p, r) plane.
            for k in 0..3 {
                let mkp = m[k][p];
                let mkr = m[k][r];
                m[k][p] = c * mkp - s * mkr;
                m[k][r] = s * mkp + c * mkr;
            }
            for k in 0..3 {
                let mpk = m[p][k];
                let mrk = m[r][k];
                m[p][k] = c * mpk - s * mrk;
                m[r][k] = s * mpk + c * mrk;
            }
            for row in q.iter_mut() {
                let qp = row[p];
                let qr = row[r];
                row[p] = c * qp - s * qr;
                row[r] = s * qp + c * qr;
            }
        }
    }
    ([m[0][0], m[1][1], m[2][2]], q)
}

/// Q diag(d) Q^T
fn spectral(q: &Mat3, d: &[f64; 3]) -> Mat3 {
    let mut m = ZERO33;
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = (0..3).map(|a| q[i][a] * d[a] * q[j][a]).sum();
        }
    }
    m
}

/// What the large-kinematics update returns: first Piola-Kirchhoff stress, Kirchhoff
/// stress, the state to commit and the return data (spatial flow direction).
pub struct LargeUpdate {
    pub pk1: Mat3,
    pub tau: Mat3,
    pub state: PlasticState,
    pub ret: Return,
    pub finv: Mat3,
    pub j: f64,
}

impl J2Plastic {
    /// The exponential-map return at F = I + h from the committed state; `None` when
    /// J <= 0.
    pub fn update_large(&self, h: &Mat3, old: &PlasticState) -> Option<LargeUpdate> {
        let mut f = *h;
        for (i, row) in f.iter_mut().enumerate() {
            row[i] += 1.0;
        }
        let (finv, j) = inverse(&f);
        if !(j > 0.0) {
            return None;
        }
        let mut cpinv = from_sym6(&old.strain);
        for (i, row) in cpinv.iter_mut().enumerate() {
            row[i] += 1.0;
        }
        let mut be = matmul(&matmul(&f, &cpinv), &transpose(&f));
        for i in 0..3 {
            for k in 0..i {
                let v = 0.5 * (be[i][k] + be[k][i]);
                be[i][k] = v;
                be[k][i] = v;
            }
        }
        let (l2, q) = sym_eigen(&be);
        if !l2.iter().all(|&v| v > 0.0) {
            return None;
        }
        let eps: [f64; 3] = std::array::from_fn(|a| 0.5 * l2[a].ln());
        let tr = eps[0] + eps[1] + eps[2];
        let mut s_trial = ZERO33;
        for a in 0..3 {
            s_trial[a][a] = 2.0 * self.mu * (eps[a] - tr / 3.0);
        }
        let r = self.radial_return(&s_trial, &ZERO33, old.eqps);
        let gamma = r.ret.gamma;
        let eps_e: [f64; 3] = std::array::from_fn(|a| eps[a] - gamma * r.ret.n[a][a]);
        let tau_p: [f64; 3] = std::array::from_fn(|a| r.s[a][a] + self.bulk() * tr);
        let tau = spectral(&q, &tau_p);
        let be_new = spectral(&q, &std::array::from_fn(|a| (2.0 * eps_e[a]).exp()));
        let mut cp_new = matmul(&matmul(&finv, &be_new), &transpose(&finv));
        for (i, row) in cp_new.iter_mut().enumerate() {
            row[i] -= 1.0;
        }
        let n_spatial = spectral(&q, &std::array::from_fn(|a| r.ret.n[a][a]));
        // P = tau F^-T
        let mut pk1 = ZERO33;
        for i in 0..3 {
            for k in 0..3 {
                pk1[i][k] = (0..3).map(|m| tau[i][m] * finv[k][m]).sum();
            }
        }
        Some(LargeUpdate {
            pk1,
            tau,
            state: PlasticState {
                strain: crate::math::to_sym6(&cp_new),
                back: [0.0; 6],
                eqps: r.eqps,
            },
            ret: Return {
                gamma,
                n: n_spatial,
                xi_norm: r.ret.xi_norm,
            },
            finv,
            j,
        })
    }
}
