//! The J2 kernels against closed forms: uniaxial stress loading past yield, unloading,
//! yielding in reverse and reloading, for linear isotropic, linear kinematic, mixed and zero
//! hardening, in tension first and compression first; the consistent tangent against
//! central differences of the stress update; the large-kinematics model in uniaxial stretch
//! to 50 % against its closed form.

use solver::material::{from_sym6, J2Plastic, PlasticState};
use solver::math::Mat3;

const E: f64 = 200e3;
const NU: f64 = 0.3;
const SY: f64 = 250.0;

/// The uniaxial closed form of the model: yield surface |sigma - H eps_p| = sigma_y + K
/// alpha. In a segment of monotone strain in direction s, starting from (eps_p0, alpha0),
/// the plastic increment is
/// d = max(0, (s (E (eps - eps_p0) - H eps_p0) - sigma_y - K alpha0) / (E + H + K)),
/// exact because every quantity is linear in d. Returns (sigma, eps_p, alpha).
fn closed_form(k: f64, h: f64, start: (f64, f64), eps: f64, s: f64) -> (f64, f64, f64) {
    let (ep0, a0) = start;
    let d = ((s * (E * (eps - ep0) - h * ep0) - SY - k * a0) / (E + h + k)).max(0.0);
    let ep = ep0 + s * d;
    (E * (eps - ep), ep, a0 + d)
}

fn diag(a: f64, b: f64) -> Mat3 {
    [[a, 0.0, 0.0], [0.0, b, 0.0], [0.0, 0.0, b]]
}

/// Drives the kernel along the strain path through `turns` in `n` increments per segment,
/// prescribing the closed form's full strain (lateral strain -nu sigma/E - eps_p/2), and
/// compares stress, plastic strain, back stress and equivalent plastic strain at every
/// increment.
fn uniaxial_path(k: f64, h: f64, turns: &[f64]) -> usize {
    let m = J2Plastic::new(E, NU, SY, k, h, false);
    let mut state = PlasticState::default();
    let mut seg_start = (0.0, 0.0);
    let mut eps_prev = 0.0;
    let mut plastic_points = 0;
    for &target in turns {
        let s = (target - eps_prev).signum();
        let n = 37; // not a divisor of anything special: yield falls inside an increment
        for i in 1..=n {
            let eps = eps_prev + (target - eps_prev) * i as f64 / n as f64;
            let (sig, ep, alpha) = closed_form(k, h, seg_start, eps, s);
            let lateral = -NU * sig / E - ep / 2.0;
            let (stress, new, ret) = m.update_small(&diag(eps, lateral), &state);
            if ret.gamma > 0.0 {
                plastic_points += 1;
            }
            // Tolerances: the kernel and the closed form differ only by round-off of
            // O(10) flops on values of size sigma_y (stress) and 5 eps_y (strain);
            // 1e-10 relative is five orders above that and far below any modelling error.
            let ts = 1e-10 * SY;
            let te = 1e-10 * SY / E;
            assert!(
                (stress[0][0] - sig).abs() < ts,
                "sigma_xx {} vs {sig}",
                stress[0][0]
            );
            assert!(stress[1][1].abs() < ts && stress[2][2].abs() < ts);
            assert!(stress[0][1].abs() < ts && stress[1][2].abs() < ts);
            let epn = from_sym6(&new.strain);
            assert!((epn[0][0] - ep).abs() < te, "eps_p {} vs {ep}", epn[0][0]);
            assert!((epn[1][1] + ep / 2.0).abs() < te);
            assert!(
                (new.eqps - alpha).abs() < te,
                "eqps {} vs {alpha}",
                new.eqps
            );
            // Uniaxial back stress: beta_xx = (2/3) H eps_p.
            assert!((new.back[0] - 2.0 / 3.0 * h * ep).abs() < ts);
            state = new;
        }
        let (_, ep, alpha) = closed_form(k, h, seg_start, target, s);
        seg_start = (ep, alpha);
        eps_prev = target;
    }
    plastic_points
}

const EY: f64 = SY / E;

#[test]
fn uniaxial_isotropic_tension_compression_reload() {
    let n = uniaxial_path(10e3, 0.0, &[5.0 * EY, -5.0 * EY, 6.0 * EY]);
    assert!(
        n > 60,
        "the path must yield in all three segments ({n} plastic points)"
    );
    uniaxial_path(10e3, 0.0, &[-5.0 * EY, 5.0 * EY, -6.0 * EY]);
}

#[test]
fn uniaxial_kinematic_tension_compression_reload() {
    let n = uniaxial_path(0.0, 20e3, &[5.0 * EY, -5.0 * EY, 6.0 * EY]);
    assert!(n > 60);
    uniaxial_path(0.0, 20e3, &[-5.0 * EY, 5.0 * EY, -6.0 * EY]);
}

#[test]
fn uniaxial_mixed_and_perfect() {
    uniaxial_path(7e3, 13e3, &[5.0 * EY, -5.0 * EY, 6.0 * EY]);
    uniaxial_path(0.0, 0.0, &[5.0 * EY, -5.0 * EY, 6.0 * EY]);
}

/// A deterministic pseudo-random matrix with entries in (-1, 1).
fn pseudo_random(seed: u64) -> Mat3 {
    let mut x = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    std::array::from_fn(|_| {
        std::array::from_fn(|_| {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((x >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        })
    })
}

fn check_tangent(m: &J2Plastic, h: &Mat3, old: &PlasticState, plastic: bool) {
    let (_, _, ret) = m.update_small(h, old);
    assert_eq!(ret.gamma > 0.0, plastic, "regime of the test point");
    let delta = 1e-6 * EY;
    for seed in 0..6 {
        let dh = pseudo_random(100 + seed);
        let plus: Mat3 =
            std::array::from_fn(|i| std::array::from_fn(|j| h[i][j] + delta * dh[i][j]));
        let minus: Mat3 =
            std::array::from_fn(|i| std::array::from_fn(|j| h[i][j] - delta * dh[i][j]));
        let sp = m.update_small(&plus, old).0;
        let sm = m.update_small(&minus, old).0;
        let c = m.tangent_apply(&ret, &dh);
        for i in 0..3 {
            for j in 0..3 {
                let fd = (sp[i][j] - sm[i][j]) / (2.0 * delta);
                // Central differences: truncation O(delta^2 |C'''|) and round-off
                // O(eps |sigma| / delta) ~ 1e-16 * 1e3 / 1e-9 = 1e-4 of E = 2e5, so
                // 1e-7 E bounds both with margin; a wrong term in C is O(mu) = 8e4.
                assert!(
                    (fd - c[i][j]).abs() < 1e-7 * E,
                    "C:dh [{i}][{j}] {} vs fd {fd}",
                    c[i][j]
                );
            }
        }
        // The contraction the preconditioner uses: sum_jl g_j C_ijkl g_l, i.e. column k
        // is C : (e_k (x) g) applied to g.
        let g = [dh[0][0], dh[1][1], dh[2][2]];
        let kgg = m.tangent_gg(&ret, &g);
        for k in 0..3 {
            let mut dk = [[0.0; 3]; 3];
            dk[k] = g;
            let col = m.tangent_apply(&ret, &dk);
            for i in 0..3 {
                let v: f64 = (0..3).map(|j| col[i][j] * g[j]).sum();
                assert!((v - kgg[i][k]).abs() < 1e-10 * E, "gg [{i}][{k}]");
            }
        }
    }
}

#[test]
fn consistent_tangent_against_finite_differences() {
    for (k, h) in [(10e3, 0.0), (0.0, 20e3), (7e3, 13e3), (0.0, 0.0)] {
        let m = J2Plastic::new(E, NU, SY, k, h, false);
        // A committed state with plastic strain, back stress and hardening.
        let (_, old, _) = m.update_small(
            &scaled(&pseudo_random(7), 4.0 * EY),
            &PlasticState::default(),
        );
        assert!(old.eqps > 0.0);
        // Elastic: a small strain change from the committed point's strain.
        let base = scaled(&pseudo_random(7), 4.0 * EY);
        let elastic = add(&base, &scaled(&pseudo_random(9), 0.05 * EY));
        let (_, _, r) = m.update_small(&elastic, &old);
        let elastic = if r.gamma > 0.0 {
            add(&base, &scaled(&pseudo_random(9), -0.05 * EY))
        } else {
            elastic
        };
        check_tangent(&m, &elastic, &old, false);
        // Plastic: well beyond the surface.
        let plastic = add(&base, &scaled(&pseudo_random(11), 3.0 * EY));
        check_tangent(&m, &plastic, &old, true);
        check_tangent(
            &m,
            &scaled(&pseudo_random(3), 6.0 * EY),
            &PlasticState::default(),
            true,
        );
    }
}

fn scaled(m: &Mat3, s: f64) -> Mat3 {
    std::array::from_fn(|i| std::array::from_fn(|j| m[i][j] * s))
}

fn add(a: &Mat3, b: &Mat3) -> Mat3 {
    std::array::from_fn(|i| std::array::from_fn(|j| a[i][j] + b[i][j]))
}

/// Large kinematics, uniaxial stress stretch to lambda = 1.5 with linear isotropic
/// hardening. In the principal frame the model is the small-strain one in logarithmic
/// strains and Kirchhoff stress: tau = E (eps - eps_p), eps_p = (E eps - sigma_y)/(E + K)
/// past yield, the lateral logarithmic strain -nu tau/E - eps_p/2, P_xx = tau / lambda.
#[test]
fn large_uniaxial_stretch_to_half_against_closed_form() {
    let k = 2e3;
    let m = J2Plastic::new(E, NU, SY, k, 0.0, true);
    let mut state = PlasticState::default();
    let n = 200;
    let mut plastic = 0;
    for i in 1..=n {
        let lam = 1.0 + 0.5 * i as f64 / n as f64;
        let eps = lam.ln();
        let ep = ((E * eps - SY) / (E + k)).max(0.0);
        let tau = E * (eps - ep);
        let lateral = (-NU * tau / E - ep / 2.0).exp();
        let h = diag(lam - 1.0, lateral - 1.0);
        let r = m.update_large(&h, &state).expect("admissible");
        if r.ret.gamma > 0.0 {
            plastic += 1;
        }
        // 1e-8 relative: the logarithm, exponential and Jacobi eigen-decomposition are
        // accurate to a few ulp; the closed form is exact; 1e-8 leaves six orders.
        assert!(
            (r.pk1[0][0] - tau / lam).abs() < 1e-8 * tau.abs(),
            "P_xx at {lam}"
        );
        assert!(r.pk1[1][1].abs() < 1e-8 * tau.abs() && r.pk1[2][2].abs() < 1e-8 * tau.abs());
        assert!((r.tau[0][0] - tau).abs() < 1e-8 * tau.abs());
        assert!(
            (r.state.eqps - ep).abs() <= 1e-8 * ep.max(EY),
            "eqps {} vs {ep}",
            r.state.eqps
        );
        // C_p^-1 = diag(exp(-2 eps_p), exp(eps_p), exp(eps_p)) (incompressible flow).
        assert!((r.state.strain[0] - ((-2.0 * ep).exp() - 1.0)).abs() < 1e-8 * ep.max(EY));
        assert!((r.state.strain[1] - (ep.exp() - 1.0)).abs() < 1e-8 * ep.max(EY));
        state = r.state;
    }
    assert!(plastic > n / 2);
    assert!(state.eqps > 0.3, "stretched well into the plastic range");
}

/// Objectivity of the large model: a rigid rotation of the stretched state rotates P.
#[test]
fn large_model_is_frame_indifferent() {
    let m = J2Plastic::new(E, NU, SY, 2e3, 0.0, true);
    let h = diag(0.2, -0.08);
    let r0 = m.update_large(&h, &PlasticState::default()).unwrap();
    let (c, s) = (0.6f64, 0.8f64);
    let rot = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
    let f = add(&h, &solver::math::IDENTITY);
    let rf = solver::math::matmul(&rot, &f);
    let hr = add(&rf, &scaled(&solver::math::IDENTITY, -1.0));
    let r1 = m.update_large(&hr, &PlasticState::default()).unwrap();
    let rp = solver::math::matmul(&rot, &r0.pk1);
    for i in 0..3 {
        for j in 0..3 {
            // Round-off of the eigen-decomposition on stresses of size 1e3.
            assert!((rp[i][j] - r1.pk1[i][j]).abs() < 1e-9 * SY, "[{i}][{j}]");
        }
    }
    assert!((r0.state.eqps - r1.state.eqps).abs() < 1e-14);
    assert!(r0.state.eqps > 0.0);
}
