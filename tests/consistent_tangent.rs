//! The assembled consistent tangent of small-kinematics J2 elements (`fem::consistent`:
//! hex8 fully integrated and B-bar, the composite tet10 plain and with the mean
//! dilatation) against central differences of the elements' own forces, at states that
//! load plastically, at states on the yield surface (where the return map has a kink and
//! the tangent is the mean of its two branches) and at elastic states; and symmetric,
//! positive semi-definite.

use solver::fem::{element, hex8, tet10, Formulation};
use solver::material::{J2Plastic, Material, PlasticState};
use solver::math::{Mat3, Vec3};

/// A pseudo-random number in [-0.5, 0.5).
struct Rnd(u64);
impl Rnd {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    }
}

/// E = 1000, nu = 0.3, sigma_y = 1: yield strain 1e-3. Perfectly plastic, and with both
/// hardenings (the moduli's theta_bar and the back stress in the flow direction).
fn materials() -> Vec<(&'static str, Material)> {
    vec![
        (
            "perfect",
            Material::J2Plastic(J2Plastic::new(1000.0, 0.3, 1.0, 0.0, 0.0, false)),
        ),
        (
            "hardening",
            Material::J2Plastic(J2Plastic::new(1000.0, 0.3, 1.0, 40.0, 25.0, false)),
        ),
    ]
}

/// An element kind under test, reduced to what the comparison needs.
trait Element {
    const DOF: usize;
    fn gradients(&self, u: &[f64]) -> Vec<Mat3>;
    fn force(&self, u: &[f64], hist: &[PlasticState]) -> Vec<f64>;
    fn tangent(&self, u: &[f64], hist: &[PlasticState]) -> Vec<f64>;
}

struct Hex {
    geo: element::Geometry,
    gauss: element::GaussGeometry,
    mat: Material,
    form: Formulation,
}

fn nodes<const N: usize>(u: &[f64]) -> [Vec3; N] {
    std::array::from_fn(|a| std::array::from_fn(|i| u[3 * a + i]))
}

impl Element for Hex {
    const DOF: usize = 24;
    fn gradients(&self, u: &[f64]) -> Vec<Mat3> {
        let (h, _, n) =
            element::point_gradients(&self.geo, Some(&self.gauss), &nodes(u), false, self.form)
                .unwrap();
        h[..n].to_vec()
    }
    fn force(&self, u: &[f64], hist: &[PlasticState]) -> Vec<f64> {
        let mut f = [[0.0; 3]; 8];
        element::internal_force_with(
            &self.geo,
            Some(&self.gauss),
            &nodes(u),
            &self.mat,
            self.form,
            hist,
            &mut f,
        )
        .unwrap();
        f.as_flattened().to_vec()
    }
    fn tangent(&self, u: &[f64], hist: &[PlasticState]) -> Vec<f64> {
        element::consistent_matrix(
            &self.geo,
            Some(&self.gauss),
            &nodes(u),
            &self.mat,
            self.form,
            hist,
        )
        .unwrap()
        .to_vec()
    }
}

struct Tet {
    geo: tet10::Geometry,
    mat: Material,
    form: Formulation,
}

impl Element for Tet {
    const DOF: usize = 30;
    fn gradients(&self, u: &[f64]) -> Vec<Mat3> {
        tet10::point_gradients(&self.geo, &nodes(u), self.form).to_vec()
    }
    fn force(&self, u: &[f64], hist: &[PlasticState]) -> Vec<f64> {
        let mut f = [[0.0; 3]; 10];
        tet10::internal_force(&self.geo, &nodes(u), &self.mat, self.form, hist, &mut f).unwrap();
        f.as_flattened().to_vec()
    }
    fn tangent(&self, u: &[f64], hist: &[PlasticState]) -> Vec<f64> {
        let mut k = vec![0.0; 900];
        assert!(tet10::consistent_matrix(
            &self.geo,
            &nodes(u),
            &self.mat,
            self.form,
            hist,
            &mut k
        ));
        k
    }
}

/// The points' committed states after one step from a virgin element to `u`.
fn committed<E: Element>(e: &E, mat: &Material, u: &[f64]) -> Vec<PlasticState> {
    e.gradients(u)
        .iter()
        .map(|h| mat.update(h, &PlasticState::default()).unwrap().state)
        .collect()
}

/// The largest |K d - (f(u + h d) - f(u - h d)) / 2h| over random directions d, relative
/// to the largest entry of the difference; and K's symmetry and x^T K x over random x.
fn compare<E: Element>(e: &E, u: &[f64], hist: &[PlasticState], h: f64, rnd: &mut Rnd) -> f64 {
    let n = E::DOF;
    let k = e.tangent(u, hist);
    for j in 0..n {
        for i in 0..n {
            assert_eq!(k[j * n + i].to_bits(), k[i * n + j].to_bits(), "symmetric");
        }
    }
    let diag = (0..n).map(|i| k[i * n + i]).fold(0.0, f64::max);
    let mut worst: f64 = 0.0;
    for _ in 0..6 {
        let d: Vec<f64> = (0..n).map(|_| rnd.next()).collect();
        let shifted = |s: f64| -> Vec<f64> { u.iter().zip(&d).map(|(a, b)| a + s * b).collect() };
        let (fp, fm) = (e.force(&shifted(h), hist), e.force(&shifted(-h), hist));
        let fd: Vec<f64> = fp
            .iter()
            .zip(&fm)
            .map(|(p, m)| (p - m) / (2.0 * h))
            .collect();
        let kd: Vec<f64> = (0..n)
            .map(|i| (0..n).map(|j| k[j * n + i] * d[j]).sum())
            .collect();
        let scale = fd.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (a, b) in fd.iter().zip(&kd) {
            worst = worst.max((a - b).abs() / scale);
        }
        // Positive semi-definite: every point's moduli are (the loading branch has a zero
        // along n only), up to the rounding of sums of n^2 terms of K's size.
        let xkx: f64 = (0..n).map(|i| d[i] * kd[i]).sum();
        let dd: f64 = d.iter().map(|v| v * v).sum();
        assert!(xkx >= -1e-12 * diag * dd, "x^T K x = {xkx:e}");
    }
    worst
}

/// At `u`, from a step to `u / 2` (every point loads on: f well above zero), from a step to
/// `u` itself (every yielded point on its surface) and from a step to `2 u` (elastic
/// unloading back to u): the tangent against central differences.
fn check<E: Element>(name: &str, e: &E, mat: &Material, u: &[f64], rnd: &mut Rnd) {
    let half: Vec<f64> = u.iter().map(|v| 0.5 * v).collect();
    let double: Vec<f64> = u.iter().map(|v| 2.0 * v).collect();
    let loading = committed(e, mat, &half);
    assert!(
        loading.iter().all(|s| s.eqps > 0.0),
        "{name}: the points flowed"
    );
    // Smooth branches: truncation O(h^2 |f'''|) with h = 1e-7 on displacements of 1e-2
    // (1e-10 relative) and cancellation 1e-16 / 1e-7 relative; 1e-6 leaves room, while a
    // wrong modulus or a missed B-bar or stabilization term is off by percents.
    let w = compare(e, u, &loading, 1e-7, rnd);
    println!("{name} loading: {w:.2e}");
    assert!(w < 1e-6, "{name} loading: {w:e}");
    let unloading = committed(e, mat, &double);
    let w = compare(e, u, &unloading, 1e-7, rnd);
    println!("{name} unloading: {w:.2e}");
    assert!(w < 1e-6, "{name} unloading: {w:e}");
    // On the surface each point's central difference is exactly the mean of its elastic
    // and loading branches to first order; the loading side's flow direction turns by
    // O(h |B d| / |xi|), a second-order error of relative size h |d| / |u|: measured
    // 1e-6 to 5e-6 at h = 1e-8, so 1e-9 here (cancellation 1e-16 |f| / (h |K d|), about
    // 1e-9 relative); bound 1e-5. The plain loading branch would be off by a third (the
    // deviatoric stiffness along n halved).
    let surface = committed(e, mat, u);
    let w = compare(e, u, &surface, 1e-9, rnd);
    println!("{name} on the surface: {w:.2e}");
    assert!(w < 1e-5, "{name} on the surface: {w:e}");
}

#[test]
fn hex8_consistent_tangent_is_the_derivative_of_its_force() {
    let mut rnd = Rnd(5);
    for (mname, mat) in materials() {
        for form in [Formulation::Full, Formulation::FullBar] {
            let x: [Vec3; 8] = std::array::from_fn(|a| {
                std::array::from_fn(|i| 0.5 * (hex8::NODE_XI[a][i] + 1.0) + 0.15 * rnd.next())
            });
            let (geo, gauss) = element::geometry(&x).unwrap();
            let u: Vec<f64> = (0..24).map(|_| 0.02 * rnd.next()).collect();
            let e = Hex {
                geo,
                gauss,
                mat,
                form,
            };
            check(&format!("hex8 {form:?} {mname}"), &e, &mat, &u, &mut rnd);
        }
    }
}

#[test]
fn tet10_consistent_tangent_is_the_derivative_of_its_force() {
    let mut rnd = Rnd(9);
    let c = [
        [0.0, 0.0, 0.0],
        [1.1, 0.1, -0.05],
        [0.2, 0.9, 0.1],
        [0.15, 0.2, 1.2],
    ];
    let x: [Vec3; 10] = std::array::from_fn(|a| {
        if a < 4 {
            c[a]
        } else {
            let (i, j) = tet10::MIDSIDE[a - 4];
            std::array::from_fn(|k| 0.5 * (c[i][k] + c[j][k]) + 0.03 * rnd.next())
        }
    });
    for (mname, mat) in materials() {
        for form in [Formulation::Full, Formulation::FullBar] {
            let geo = tet10::geometry(&x).unwrap();
            let u: Vec<f64> = (0..30).map(|_| 0.02 * rnd.next()).collect();
            let e = Tet { geo, mat, form };
            check(&format!("tet10 {form:?} {mname}"), &e, &mat, &u, &mut rnd);
        }
    }
}

/// Materials and formulations the assembled tangent does not cover say so (the probed
/// difference serves them).
#[test]
fn only_small_strain_j2_stress_point_elements_are_assembled() {
    let x: [Vec3; 8] =
        std::array::from_fn(|a| std::array::from_fn(|i| 0.5 * (hex8::NODE_XI[a][i] + 1.0)));
    let (geo, gauss) = element::geometry(&x).unwrap();
    let hist = vec![PlasticState::default(); 8];
    let u = [[0.0; 3]; 8];
    let large = Material::J2Plastic(J2Plastic::new(1000.0, 0.3, 1.0, 0.0, 0.0, true));
    let small = Material::J2Plastic(J2Plastic::new(1000.0, 0.3, 1.0, 0.0, 0.0, false));
    let mean = Formulation::Mean {
        hourglass: solver::fem::Stabilization::AssumedStrain,
    };
    let k = |m: &Material, f: Formulation| {
        element::consistent_matrix(&geo, Some(&gauss), &u, m, f, &hist).is_some()
    };
    assert!(!k(&large, Formulation::Full));
    assert!(!k(&small, mean));
    assert!(k(&small, Formulation::Full));
}
