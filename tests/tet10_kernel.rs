//! The composite 10-node tetrahedron's kernels (`fem::tet10`) against exact answers: the
//! patch test on a distorted mesh of tetrahedra for every material (a linear displacement
//! field gives the material's stress at that gradient in every element and zero force at
//! the interior nodes), zero stress under a finite rigid rotation, the diagonal tangent
//! blocks against central differences of the force, the nodal volumes against their closed
//! form, and a flipped element refused.

use crate::common;
use common::tets::{boundary, distorted_cube};
use solver::fem::tet10;
use solver::fem::{ElementFailure, Formulation};
use solver::material::{J2Plastic, LinearElastic, Material, NeoHookean, PlasticState};
use solver::math::{Mat3, Vec3};

const E: f64 = 1000.0;

fn materials() -> Vec<(&'static str, Material)> {
    vec![
        (
            "linear",
            Material::LinearElastic(LinearElastic::new(E, 0.3)),
        ),
        (
            "neo-Hookean",
            Material::NeoHookean(NeoHookean::new(E, 0.45)),
        ),
        // Yield stress low enough that the patch's strain (about 1e-2) flows plastically.
        (
            "J2 small",
            Material::J2Plastic(J2Plastic::new(E, 0.3, 2.0, 5.0, 3.0, false)),
        ),
        (
            "J2 large",
            Material::J2Plastic(J2Plastic::new(E, 0.3, 2.0, 5.0, 0.0, true)),
        ),
    ]
}

fn gather<const N: usize>(v: &[Vec3], el: &[usize; N]) -> [Vec3; N] {
    el.map(|a| v[a])
}

fn max_abs(m: &Mat3) -> f64 {
    m.iter().flatten().fold(0.0f64, |a, &b| a.max(b.abs()))
}

/// The patch test: u = G X + c on every node; every element's stress is the material's at G
/// (through `average_cauchy` and through the points' gradients), and the assembled force
/// vanishes at the interior nodes, relative to the force at the boundary.
#[test]
fn a_linear_field_gives_the_exact_stress_and_no_force_inside_a_distorted_mesh() {
    let mesh = distorted_cube(2);
    let on = boundary(&mesh);
    let interior = on.iter().filter(|&&b| !b).count();
    // Inside: the centre vertex, the midside nodes of its 14 edges, of the 6 small cubes'
    // diagonals that miss it and of the 6 diagonals of the inner faces that miss it.
    assert_eq!(interior, 27, "interior nodes");
    let g: Mat3 = [
        [0.011, -0.004, 0.006],
        [0.003, -0.009, 0.002],
        [-0.005, 0.007, 0.013],
    ];
    let u: Vec<Vec3> = mesh
        .x
        .iter()
        .map(|p| {
            std::array::from_fn(|i| {
                0.01 * (i as f64 + 1.0) + (0..3).map(|j| g[i][j] * p[j]).sum::<f64>()
            })
        })
        .collect();
    // Both volumetric treatments: a linear field has the same dilatation at every point, so
    // the mean dilatation changes nothing (small kinematics only in a scene; the kernel's
    // patch test holds for every material).
    let forms = [Formulation::Full, Formulation::FullBar];
    for ((name, mat), form) in materials().into_iter().flat_map(|m| forms.map(|f| (m, f))) {
        let mut f = vec![[0.0; 3]; mesh.x.len()];
        let virgin = vec![PlasticState::default(); tet10::STRESS_POINTS];
        let hist: &[PlasticState] = if mat.is_plastic() { &virgin } else { &[] };
        let expected = mat.cauchy(&g, &PlasticState::default()).unwrap();
        let scale = max_abs(&expected);
        let mut worst_stress: f64 = 0.0;
        for el in &mesh.elements {
            let geo = tet10::geometry(&gather(&mesh.x, el)).expect("a valid element");
            let ue = gather(&u, el);
            for h in tet10::point_gradients(&geo, &ue, form) {
                for i in 0..3 {
                    for j in 0..3 {
                        worst_stress = worst_stress.max((h[i][j] - g[i][j]).abs() / 0.013);
                    }
                }
            }
            let s = tet10::average_cauchy(&geo, &ue, &mat, form, hist).unwrap();
            let want = solver::math::to_sym6(&expected);
            for c in 0..6 {
                worst_stress = worst_stress.max((s[c] - want[c]).abs() / scale);
            }
            let mut fe = [[0.0; 3]; 10];
            tet10::internal_force(&geo, &ue, &mat, form, hist, &mut fe).unwrap();
            for (a, &n) in el.iter().enumerate() {
                for i in 0..3 {
                    f[n][i] += fe[a][i];
                }
            }
        }
        let name = format!("{name} {form:?}");
        let fmax = f.iter().flatten().fold(0.0f64, |a, &b| a.max(b.abs()));
        let inside = f
            .iter()
            .zip(&on)
            .filter(|(_, &b)| !b)
            .flat_map(|(fa, _)| fa.iter())
            .fold(0.0f64, |a, &b| a.max(b.abs()));
        println!(
            "{name}: stress error {worst_stress:.2e}, interior force {:.2e} of {fmax:.3e}",
            inside / fmax
        );
        // Round-off of sums over 12 sub-tetrahedra and 4x4 solves on values of order one:
        // 1e-10 relative is five orders above it and far below any discretisation error
        // (a wrong weight or projection is off by percents).
        assert!(
            worst_stress < 1e-10,
            "{name}: stress error {worst_stress:e}"
        );
        assert!(
            inside < 1e-10 * fmax,
            "{name}: interior force {inside:e} of {fmax:e}"
        );
        assert!(fmax > 1e-3 * scale, "{name}: the boundary carries the load");
    }
}

/// Rotation matrix about the unit axis `n` by `t` radians (Rodrigues).
fn rotation(n: Vec3, t: f64) -> Mat3 {
    let (s, c) = t.sin_cos();
    std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            let k = [[0.0, -n[2], n[1]], [n[2], 0.0, -n[0]], [-n[1], n[0], 0.0]];
            let kk: f64 = (0..3).map(|m| k[i][m] * k[m][j]).sum();
            (if i == j { 1.0 } else { 0.0 }) + s * k[i][j] + (1.0 - c) * kk
        })
    })
}

/// A finite rigid rotation (50 degrees) of every element gives zero force and zero stress
/// under large kinematics.
#[test]
fn a_rigid_rotation_gives_no_stress_under_large_kinematics() {
    let mesh = distorted_cube(2);
    let n = 1.0 / 14f64.sqrt();
    let r = rotation([n, 2.0 * n, 3.0 * n], 50f64.to_radians());
    let u: Vec<Vec3> = mesh
        .x
        .iter()
        .map(|p| std::array::from_fn(|i| (0..3).map(|j| r[i][j] * p[j]).sum::<f64>() - p[i]))
        .collect();
    for (name, mat) in materials().into_iter().filter(|(_, m)| m.is_large()) {
        let virgin = vec![PlasticState::default(); tet10::STRESS_POINTS];
        let hist: &[PlasticState] = if mat.is_plastic() { &virgin } else { &[] };
        let mut worst: f64 = 0.0;
        for el in &mesh.elements {
            let geo = tet10::geometry(&gather(&mesh.x, el)).unwrap();
            let ue = gather(&u, el);
            let s = tet10::average_cauchy(&geo, &ue, &mat, Formulation::Full, hist).unwrap();
            let mut fe = [[0.0; 3]; 10];
            tet10::internal_force(&geo, &ue, &mat, Formulation::Full, hist, &mut fe).unwrap();
            let fscale = E * tet10::volume(&geo).powf(2.0 / 3.0);
            worst = worst.max(s.iter().fold(0.0f64, |a, &b| a.max(b.abs())) / E);
            worst = worst.max(fe.iter().flatten().fold(0.0f64, |a, &b| a.max(b.abs())) / fscale);
        }
        println!("{name}: rigid rotation stress and force {worst:.2e} of E");
        // Stress of F = R is zero exactly; what is left is round-off of F^T F - I on values
        // of order one (~1e-15): 1e-10 of E leaves room and catches any spurious term.
        assert!(worst < 1e-10, "{name}: {worst:e}");
    }
}

/// One curved, distorted element: corners of a skewed tetrahedron, midside nodes moved off
/// the edges' midpoints.
fn curved_element() -> [Vec3; 10] {
    let c = [
        [0.0, 0.0, 0.0],
        [1.1, 0.1, -0.05],
        [0.2, 0.9, 0.1],
        [0.15, 0.2, 1.2],
    ];
    std::array::from_fn(|a| {
        if a < 4 {
            c[a]
        } else {
            let (i, j) = tet10::MIDSIDE[a - 4];
            let w = |k: usize| 0.03 * ((7 * a + 3 * k) as f64).sin();
            std::array::from_fn(|k| 0.5 * (c[i][k] + c[j][k]) + w(k))
        }
    })
}

/// The diagonal blocks against central differences of the force, for the materials whose
/// point tangent is exact (linear, neo-Hookean, J2 small from a plastic state).
#[test]
fn the_diagonal_blocks_match_central_differences_of_the_force() {
    let x = curved_element();
    let geo = tet10::geometry(&x).unwrap();
    let u: [Vec3; 10] = std::array::from_fn(|a| {
        std::array::from_fn(|i| 0.02 * ((3 * a + 5 * i) as f64 * 0.77).sin())
    });
    for (name, mat) in materials().into_iter().filter(|(n, _)| *n != "J2 large") {
        // A plastic element's committed state from a step to u/2, so that u flows on.
        let mut hist = vec![PlasticState::default(); tet10::STRESS_POINTS];
        if mat.is_plastic() {
            let half = u.map(|v| v.map(|c| 0.5 * c));
            let old = hist.clone();
            tet10::update_history(&geo, &half, &mat, Formulation::Full, &old, &mut hist).unwrap();
            assert!(hist.iter().all(|s| s.eqps > 0.0), "the points flowed");
        } else {
            hist.clear();
        }
        let mut d = [[[0.0; 3]; 3]; 10];
        tet10::diagonal_blocks(&geo, &u, &mat, Formulation::Full, &hist, &mut d).unwrap();
        let scale = d.iter().map(max_abs).fold(0.0, f64::max);
        let eps = 1e-6;
        let mut worst: f64 = 0.0;
        for a in 0..10 {
            for k in 0..3 {
                let force = |s: f64| {
                    let mut up = u;
                    up[a][k] += s;
                    let mut f = [[0.0; 3]; 10];
                    tet10::internal_force(&geo, &up, &mat, Formulation::Full, &hist, &mut f)
                        .unwrap();
                    f[a]
                };
                let (fp, fm) = (force(eps), force(-eps));
                for i in 0..3 {
                    let fd = (fp[i] - fm[i]) / (2.0 * eps);
                    worst = worst.max((fd - d[a][i][k]).abs() / scale);
                }
            }
        }
        println!("{name}: diagonal blocks vs central differences {worst:.2e}");
        // Central differences with step 1e-6 on displacements of 2e-2: truncation
        // O(eps^2 |f'''|) ~ 1e-10 and cancellation ~1e-16/1e-6 = 1e-10 of the scale; 1e-6
        // leaves room, while a wrong term is off by percents.
        assert!(worst < 1e-6, "{name}: {worst:e}");
    }
}

/// The nodal volumes of a straight-sided element are V/32 at the corners and 7V/48 at the
/// midside nodes (the composite hats' integrals: a corner's hat lives on its corner
/// sub-tetrahedron of volume V/8; a midside node's on two corner ones, four of the eight
/// V/16 octahedron ones, and a sixth of the auxiliary node's); on a curved element they
/// stay positive and sum to its volume.
#[test]
fn nodal_volumes_are_positive_and_sum_to_the_volume() {
    let c = [
        [0.0, 0.0, 0.0],
        [1.1, 0.1, -0.05],
        [0.2, 0.9, 0.1],
        [0.15, 0.2, 1.2],
    ];
    let straight: [Vec3; 10] = std::array::from_fn(|a| {
        if a < 4 {
            c[a]
        } else {
            let (i, j) = tet10::MIDSIDE[a - 4];
            std::array::from_fn(|k| 0.5 * (c[i][k] + c[j][k]))
        }
    });
    let geo = tet10::geometry(&straight).unwrap();
    let v = tet10::volume(&geo);
    let exact = solver::math::det(&std::array::from_fn(|i| {
        std::array::from_fn(|k| c[i + 1][k] - c[0][k])
    })) / 6.0;
    // Sums of twelve positive terms: rounding ~1e-16 relative.
    assert!((v - exact).abs() < 1e-14 * exact);
    let n = tet10::nodal_volumes(&geo);
    for (a, &na) in n.iter().enumerate() {
        let want = if a < 4 { v / 32.0 } else { 7.0 * v / 48.0 };
        assert!((na - want).abs() < 1e-14 * v, "node {a}: {na} vs {want}");
    }
    let geo = tet10::geometry(&curved_element()).unwrap();
    let n = tet10::nodal_volumes(&geo);
    let v = tet10::volume(&geo);
    assert!(n.iter().all(|&na| na > 0.0));
    assert!((n.iter().sum::<f64>() - v).abs() < 1e-14 * v);
    println!("curved element: volume {v:.6}, nodal volumes {n:.5?}");
}

/// An element with two corners swapped (and its midside nodes with them) is inside out:
/// refused.
#[test]
fn a_flipped_element_is_refused() {
    let mut y = curved_element();
    assert!(tet10::geometry(&y).is_ok());
    y.swap(1, 2);
    y.swap(4, 6);
    y.swap(8, 9);
    assert_eq!(
        tet10::geometry(&y).err(),
        Some(ElementFailure::InvertedReference)
    );
}

/// Rank of a square matrix by Gaussian elimination with full pivoting, counting pivots
/// above `tol` times the largest entry.
fn rank(mut m: Vec<Vec<f64>>, tol: f64) -> usize {
    let n = m.len();
    let big = m.iter().flatten().fold(0.0f64, |a, &b| a.max(b.abs()));
    for r in 0..n {
        let (mut pi, mut pj, mut pv) = (r, r, 0.0);
        for (i, row) in m.iter().enumerate().skip(r) {
            for (j, &v) in row.iter().enumerate().skip(r) {
                if v.abs() > pv {
                    (pi, pj, pv) = (i, j, v.abs());
                }
            }
        }
        if pv <= tol * big {
            return r;
        }
        m.swap(r, pi);
        for row in m.iter_mut() {
            row.swap(r, pj);
        }
        for i in r + 1..n {
            let f = m[i][r] / m[r][r];
            for j in r..n {
                m[i][j] -= f * m[r][j];
            }
        }
    }
    n
}

/// The stiffness of one curved element (linear elasticity: the force is linear in u, so
/// its columns are the forces of unit displacements) has rank 24: the six rigid motions
/// are its only zero-energy modes.
#[test]
fn the_element_has_no_zero_energy_mode_besides_the_rigid_ones() {
    let geo = tet10::geometry(&curved_element()).unwrap();
    let mat = Material::LinearElastic(LinearElastic::new(E, 0.3));
    let mut k = vec![vec![0.0; 30]; 30];
    for col in 0..30 {
        let mut u = [[0.0; 3]; 10];
        u[col / 3][col % 3] = 1.0;
        let mut f = [[0.0; 3]; 10];
        tet10::internal_force(&geo, &u, &mat, Formulation::Full, &[], &mut f).unwrap();
        for row in 0..30 {
            k[row][col] = f[row / 3][row % 3];
        }
    }
    // Rigid modes give pivots at round-off (~1e-13 of the largest); the softest deformation
    // mode is well above 1e-8 of it (the stabilization alone is 1e-2 mu).
    assert_eq!(rank(k, 1e-8), 24);
}

/// The stiffness of one element of a linear material, column by column (the force is
/// linear in u).
fn element_stiffness(geo: &tet10::Geometry, mat: &Material, form: Formulation) -> Vec<Vec<f64>> {
    let mut k = vec![vec![0.0; 30]; 30];
    for col in 0..30 {
        let mut u = [[0.0; 3]; 10];
        u[col / 3][col % 3] = 1.0;
        let mut f = [[0.0; 3]; 10];
        tet10::internal_force(geo, &u, mat, form, &[], &mut f).unwrap();
        for row in 0..30 {
            k[row][col] = f[row / 3][row % 3];
        }
    }
    k
}

/// Volumetric constraints per element near incompressibility: the composite element's
/// dilatation is linear over it (four constraints, as a discontinuous linear pressure:
/// too many against a quadratic tetrahedron's unknowns, it locks), the mean dilatation
/// one (a constant pressure per element). Counted as the eigenvalues of the element's
/// stiffness at nu = 0.4999 (lambda = 5000 mu) above 50 times the largest at lambda = 0
/// (the same mu): the volumetric ones are about lambda / mu = 5000 times the shear scale,
/// the shear ones at most 1 times it, so the gap is wide on either side of 50. Both
/// stiffnesses are symmetric.
#[test]
fn the_mean_dilatation_leaves_one_volumetric_constraint() {
    let geo = tet10::geometry(&curved_element()).unwrap();
    let mu = E / (2.0 * 1.4999);
    let shear = Material::LinearElastic(LinearElastic { lambda: 0.0, mu });
    let nearly = Material::LinearElastic(LinearElastic::new(E, 0.4999));
    let eig = |k: Vec<Vec<f64>>| -> Vec<f64> {
        let m = nalgebra::DMatrix::from_fn(30, 30, |i, j| 0.5 * (k[i][j] + k[j][i]));
        m.symmetric_eigenvalues().iter().copied().collect()
    };
    for (form, constraints) in [(Formulation::Full, 4), (Formulation::FullBar, 1)] {
        // The force is the gradient of an energy in either form (the mean dilatation's
        // pressure handed back through its own variation): a symmetric stiffness, to
        // round-off of sums of order-one products (1e-12 of the largest entry).
        let k = element_stiffness(&geo, &nearly, form);
        let big = k.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        for i in 0..30 {
            for j in 0..i {
                assert!((k[i][j] - k[j][i]).abs() < 1e-12 * big, "{form:?} {i} {j}");
            }
        }
        let top = eig(element_stiffness(&geo, &shear, form))
            .into_iter()
            .fold(0.0f64, f64::max);
        let stiff = eig(element_stiffness(&geo, &nearly, form))
            .into_iter()
            .filter(|&e| e > 50.0 * top)
            .count();
        assert_eq!(stiff, constraints, "{form:?}");
    }
}
