//! The stiffness matrix of a linear element (small kinematics, an elastic material), for
//! elements whose shape many others share: one 24 x 24 product per element evaluation
//! instead of the Gauss-point kernel (`solver::shapes` keeps one matrix per shape).

use super::force::internal_force_with;
use super::kinematics::point_gradients;
use super::{ElementFailure, Formulation, GaussGeometry, Geometry};
use crate::fem::consistent::{add_products, point_moduli, small_j2};
use crate::material::{Material, PlasticState};
use crate::math::Vec3;

/// A 24 x 24 element matrix, column by column: entry (i, j) at `j * 24 + i`, the degrees
/// of freedom node by node (3 a + k).
pub type ElementMatrix = [f64; 576];

/// The element's stiffness K, column j the internal force of the unit displacement of
/// degree of freedom j (the kernel is linear in u for a linear body, so K u is its force
/// up to rounding), made exactly symmetric: (K + K^T) / 2.
pub fn element_matrix(
    geo: &Geometry,
    gauss: Option<&GaussGeometry>,
    mat: &Material,
    form: Formulation,
) -> Result<Box<ElementMatrix>, ElementFailure> {
    let mut k = Box::new([0.0; 576]);
    for j in 0..24 {
        let mut u = [[0.0; 3]; 8];
        u[j / 3][j % 3] = 1.0;
        let mut f = [[0.0; 3]; 8];
        internal_force_with(geo, gauss, &u, mat, form, &[], &mut f)?;
        k[j * 24..(j + 1) * 24].copy_from_slice(f.as_flattened());
    }
    for j in 0..24 {
        for i in 0..j {
            let m = 0.5 * k[j * 24 + i] + 0.5 * k[i * 24 + j];
            k[j * 24 + i] = m;
            k[i * 24 + j] = m;
        }
    }
    Ok(k)
}

/// Whether the element's force is linear in u with the material's elastic moduli wherever
/// no stress point yields: a plastic material under small kinematics, integrated at its
/// Gauss points (the one-point element's hourglass stiffness follows the plastic state).
fn elastic_part_is_linear(mat: &Material, form: Formulation) -> bool {
    mat.is_plastic() && !mat.is_large() && !matches!(form, Formulation::Mean { .. })
}

/// The stiffness of an element of a small-kinematics plastic body at a state where every
/// stress point responds elastically (`responds_elastically`): there the return map is the
/// identity and the stress 2 mu (e - e_p) + kappa tr(eps) I is linear in u with the
/// material's elastic moduli, so its derivative is the linear elastic element's matrix
/// with the same Lame constants, whatever the plastic strain. None for other materials and
/// for the one-point formulation (its hourglass stiffness follows the plastic state).
pub fn elastic_matrix(
    geo: &Geometry,
    gauss: Option<&GaussGeometry>,
    mat: &Material,
    form: Formulation,
) -> Option<Box<ElementMatrix>> {
    if !elastic_part_is_linear(mat, form) {
        return None;
    }
    let (lambda, mu) = mat.lambda_mu();
    let elastic = Material::LinearElastic(crate::material::LinearElastic { lambda, mu });
    element_matrix(geo, gauss, &elastic, form).ok()
}

/// Whether no stress point of the element yields at `u` from its committed history `hist`
/// (one state per point): the state at which `elastic_matrix` is the element's tangent.
/// False for what `elastic_matrix` does not cover and where a point's update fails.
pub fn responds_elastically(
    geo: &Geometry,
    gauss: Option<&GaussGeometry>,
    u: &[Vec3; 8],
    mat: &Material,
    form: Formulation,
    hist: &[PlasticState],
) -> bool {
    if !elastic_part_is_linear(mat, form) {
        return false;
    }
    let Ok((h, _, points)) = point_gradients(geo, gauss, u, false, form) else {
        return false;
    };
    hist.len() >= points
        && (0..points).all(|q| mat.update(&h[q], &hist[q]).is_some_and(|r| !r.yielded))
}

/// The consistent tangent of an element of a small-kinematics J2 body at `u` from its
/// committed history `hist` (`fem::consistent`), fully integrated or B-bar; None for other
/// materials and for the one-point element (its hourglass stiffness follows the plastic
/// state).
pub fn consistent_matrix(
    geo: &Geometry,
    gauss: Option<&GaussGeometry>,
    u: &[Vec3; 8],
    mat: &Material,
    form: Formulation,
    hist: &[PlasticState],
) -> Option<Box<ElementMatrix>> {
    let m = small_j2(mat)?;
    if matches!(form, Formulation::Mean { .. }) {
        return None;
    }
    let (h, w, points) = point_gradients(geo, gauss, u, false, form).ok()?;
    if hist.len() < points {
        return None;
    }
    let moduli = point_moduli(m, &h[..points], &hist[..points]);
    let mut dh = Vec::with_capacity(24 * points);
    for j in 0..24 {
        let mut e = [[0.0; 3]; 8];
        e[j / 3][j % 3] = 1.0;
        let (g, _, _) = point_gradients(geo, gauss, &e, false, form).ok()?;
        dh.extend_from_slice(&g[..points]);
    }
    let mut k = Box::new([0.0; 576]);
    add_products(&dh, &w[..points], |q, d| moduli[q].apply(d), &mut k[..]);
    Some(k)
}

/// f = K (u - u_1): K annihilates the element's translations, so the first node's
/// displacement is taken out first, and the product's rounding scales with the element's
/// deformation, not with its rigid motion (a stiff body carried on a soft one moves far
/// more than it deforms: contrast_stiff_on_soft stalled at a residual 25 times higher with
/// K u). Each entry is the sum over the columns in order (on a processor with AVX2 the
/// same operations, four entries to an instruction: bitwise the same force).
#[inline]
pub fn matrix_force(k: &ElementMatrix, u: &[Vec3; 8], f: &mut [Vec3; 8]) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the processor has AVX2, checked just above.
        return unsafe { matrix_force_avx2(k, u, f) };
    }
    matrix_force_body(k, u, f)
}

/// `matrix_force_body` compiled for AVX2 (the caller checks the processor has it).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn matrix_force_avx2(k: &ElementMatrix, u: &[Vec3; 8], f: &mut [Vec3; 8]) {
    matrix_force_body(k, u, f)
}

#[inline(always)]
fn matrix_force_body(k: &ElementMatrix, u: &[Vec3; 8], f: &mut [Vec3; 8]) {
    let mut d = [0.0; 24];
    for (a, ua) in u.iter().enumerate() {
        for i in 0..3 {
            d[3 * a + i] = ua[i] - u[0][i];
        }
    }
    // The first node's three columns meet d = u_1 - u_1 = 0: they would add c 0 = +-0 to
    // sums that start at +0 (the sum stays +0), so they are left out, bitwise alike.
    let mut acc = [0.0; 24];
    for (j, &uj) in d.iter().enumerate().skip(3) {
        let col = &k[j * 24..(j + 1) * 24];
        for (a, &c) in acc.iter_mut().zip(col) {
            *a += c * uj;
        }
    }
    f.as_flattened_mut().copy_from_slice(&acc);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::element::geometry;

    /// K u against the kernel's force for random displacements of distorted elements in
    /// each formulation: the same linear map (to rounding: 1e-13 of the force's scale,
    /// a few units in the last place of the sums of 24 and of 8 Gauss points), K exactly
    /// symmetric; and the dispatched product bitwise the portable one.
    #[test]
    fn the_matrix_gives_the_kernel_force_and_is_symmetric() {
        let mat = Material::LinearElastic(crate::material::LinearElastic::new(1000.0, 0.3));
        let mut seed = 7u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for form in [
            Formulation::Full,
            Formulation::FullBar,
            Formulation::Mean {
                hourglass: crate::fem::Stabilization::Coefficient(0.05),
            },
            Formulation::Mean {
                hourglass: crate::fem::Stabilization::AssumedStrain,
            },
        ] {
            for _ in 0..5 {
                let mut x = [[0.0; 3]; 8];
                for (a, p) in crate::fem::hex8::NODE_XI.iter().enumerate() {
                    for i in 0..3 {
                        x[a][i] = 0.5 * (p[i] + 1.0) + 0.15 * rnd();
                    }
                }
                let (geo, gauss) = geometry(&x).unwrap();
                let k = element_matrix(&geo, Some(&gauss), &mat, form).unwrap();
                for j in 0..24 {
                    for i in 0..24 {
                        assert_eq!(k[j * 24 + i].to_bits(), k[i * 24 + j].to_bits());
                    }
                }
                let mut u = [[0.0; 3]; 8];
                u.as_flattened_mut().iter_mut().for_each(|v| *v = rnd());
                let (mut want, mut got, mut portable) =
                    ([[0.0; 3]; 8], [[0.0; 3]; 8], [[0.0; 3]; 8]);
                internal_force_with(&geo, Some(&gauss), &u, &mat, form, &[], &mut want).unwrap();
                matrix_force(&k, &u, &mut got);
                matrix_force_body(&k, &u, &mut portable);
                let scale = want
                    .as_flattened()
                    .iter()
                    .fold(0.0f64, |m, v| m.max(v.abs()));
                for (a, b) in want.as_flattened().iter().zip(got.as_flattened()) {
                    assert!((a - b).abs() <= 1e-13 * scale, "{form:?}: {a} {b}");
                }
                assert_eq!(format!("{got:?}"), format!("{portable:?}"));
            }
        }
    }

    /// A J2 element (small kinematics) with a plastic strain in its history, at a state
    /// where no point yields: `responds_elastically` holds, and `elastic_matrix` K gives
    /// the central difference of its force at that state along random directions, in both
    /// stress-point formulations. Tolerance 1e-7 of the difference's scale: the force is
    /// affine there, so the difference is K x up to rounding (1e-16 of the force over the
    /// step's 1e-6 relative size: about 1e-10), while a wrong modulus or a missed B-bar
    /// term would be off by percents. At twenty times the displacement the points yield
    /// and the test fails.
    #[test]
    fn the_elastic_matrix_is_the_derivative_of_a_plastic_element_that_does_not_yield() {
        use crate::material::{J2Plastic, PlasticState};
        let j2 = Material::J2Plastic(J2Plastic::new(1000.0, 0.3, 1.0, 10.0, 5.0, false));
        let mut seed = 11u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let hist = vec![
            PlasticState {
                strain: [4e-4, -3e-4, -1e-4, 2e-4, 0.0, -1e-4],
                back: [0.0; 6],
                eqps: 5e-4,
            };
            8
        ];
        for form in [Formulation::Full, Formulation::FullBar] {
            let mut x = [[0.0; 3]; 8];
            for (a, p) in crate::fem::hex8::NODE_XI.iter().enumerate() {
                for i in 0..3 {
                    x[a][i] = 0.5 * (p[i] + 1.0) + 0.15 * rnd();
                }
            }
            let (geo, gauss) = geometry(&x).unwrap();
            let k = elastic_matrix(&geo, Some(&gauss), &j2, form).unwrap();
            let mut u = [[0.0; 3]; 8];
            u.as_flattened_mut()
                .iter_mut()
                .for_each(|v| *v = 1e-4 * rnd());
            assert!(responds_elastically(
                &geo,
                Some(&gauss),
                &u,
                &j2,
                form,
                &hist
            ));
            let far: [Vec3; 8] = std::array::from_fn(|a| std::array::from_fn(|i| 20.0 * u[a][i]));
            assert!(!responds_elastically(
                &geo,
                Some(&gauss),
                &far,
                &j2,
                form,
                &hist
            ));
            for _ in 0..3 {
                let mut d = [[0.0; 3]; 8];
                d.as_flattened_mut().iter_mut().for_each(|v| *v = rnd());
                let h = 1e-6;
                let (mut fp, mut fm, mut kd) = ([[0.0; 3]; 8], [[0.0; 3]; 8], [[0.0; 3]; 8]);
                let shift = |s: f64| -> [Vec3; 8] {
                    std::array::from_fn(|a| std::array::from_fn(|i| u[a][i] + s * d[a][i]))
                };
                internal_force_with(&geo, Some(&gauss), &shift(h), &j2, form, &hist, &mut fp)
                    .unwrap();
                internal_force_with(&geo, Some(&gauss), &shift(-h), &j2, form, &hist, &mut fm)
                    .unwrap();
                matrix_force(&k, &d, &mut kd);
                let want: Vec<f64> = fp
                    .as_flattened()
                    .iter()
                    .zip(fm.as_flattened())
                    .map(|(p, m)| (p - m) / (2.0 * h))
                    .collect();
                let scale = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                for (w, g) in want.iter().zip(kd.as_flattened()) {
                    assert!((w - g).abs() <= 1e-7 * scale, "{form:?}: {w} {g}");
                }
            }
        }
    }

    /// Neither a material without a plastic history nor the one-point element nor large
    /// kinematics has an elastic matrix: their tangent is not the linear elastic one.
    #[test]
    fn only_small_strain_plastic_stress_point_elements_have_an_elastic_matrix() {
        use crate::material::J2Plastic;
        let x: [Vec3; 8] = std::array::from_fn(|a| {
            std::array::from_fn(|i| 0.5 * (crate::fem::hex8::NODE_XI[a][i] + 1.0))
        });
        let (geo, gauss) = geometry(&x).unwrap();
        let elastic = Material::LinearElastic(crate::material::LinearElastic::new(1000.0, 0.3));
        let small = Material::J2Plastic(J2Plastic::new(1000.0, 0.3, 1.0, 0.0, 0.0, false));
        let large = Material::J2Plastic(J2Plastic::new(1000.0, 0.3, 1.0, 0.0, 0.0, true));
        let mean = Formulation::Mean {
            hourglass: crate::fem::Stabilization::AssumedStrain,
        };
        assert!(elastic_matrix(&geo, Some(&gauss), &elastic, Formulation::Full).is_none());
        assert!(elastic_matrix(&geo, Some(&gauss), &large, Formulation::Full).is_none());
        assert!(elastic_matrix(&geo, Some(&gauss), &small, mean).is_none());
        assert!(elastic_matrix(&geo, Some(&gauss), &small, Formulation::Full).is_some());
    }
}
