//! The constant-strain patch test of the one-point (`mean`) element: the seven-element
//! patch of MacNeal and Harder (Finite Elements in Analysis and Design 1 (1985) 3), a unit
//! cube around a distorted inner hexahedron, under a linear displacement field u = A x + b.
//! The exact solution is that field with the constant stress C : sym(A): every element's
//! stress must be it, and the internal forces assembled at the eight inner nodes (which
//! carry no load) must vanish. Every hourglass control: the assumed-strain stabilisation
//! with the shear modulus only (the default of linear elastic bodies), with lambda, and
//! Flanagan-Belytschko; linear elastic and neo-Hookean (a homogeneous deformation), also
//! near incompressibility.

use solver::fem::element::{average_cauchy, internal_force};
use solver::fem::{Formulation, Stabilization};
use solver::material::{LinearElastic, Material, NeoHookean};
use solver::math::Vec3;

const XI: [[f64; 3]; 8] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
];

/// The inner nodes of MacNeal and Harder's patch, in the corner order of `XI`.
const INNER: [Vec3; 8] = [
    [0.249, 0.342, 0.192],
    [0.826, 0.288, 0.288],
    [0.850, 0.649, 0.263],
    [0.273, 0.750, 0.230],
    [0.320, 0.186, 0.643],
    [0.677, 0.305, 0.683],
    [0.788, 0.693, 0.644],
    [0.165, 0.745, 0.702],
];

/// Node c of the cube's corner order: outer nodes 0..8, inner 8..16.
fn corner(p: &[f64; 3]) -> usize {
    XI.iter().position(|q| q == p).expect("a corner")
}

/// The seven elements: the inner one, and for each face of the cube the one between the
/// inner and the outer face (its local axis k runs from the inner face to the outer on the
/// + side, from the outer to the inner on the - side, so that its Jacobian is positive).
fn elements() -> Vec<[usize; 8]> {
    let mut out = vec![std::array::from_fn(|a| 8 + a)];
    for k in 0..3 {
        for side in [-1.0, 1.0] {
            out.push(std::array::from_fn(|a| {
                let mut p = XI[a];
                let inner = p[k] != side;
                p[k] = side;
                corner(&p) + if inner { 8 } else { 0 }
            }));
        }
    }
    out
}

fn nodes() -> Vec<Vec3> {
    let mut x: Vec<Vec3> = XI
        .iter()
        .map(|p| std::array::from_fn(|i| 0.5 * (1.0 + p[i])))
        .collect();
    x.extend_from_slice(&INNER);
    x
}

#[test]
fn mean_elements_pass_the_constant_strain_patch_test() {
    let x = nodes();
    let a = [
        [1.0e-3, 2.0e-4, -3.0e-4],
        [-1.0e-4, -5.0e-4, 4.0e-4],
        [2.5e-4, 1.5e-4, 7.0e-4],
    ];
    let b = [0.01, -0.02, 0.005];
    let u: Vec<Vec3> = x
        .iter()
        .map(|p| std::array::from_fn(|i| b[i] + (0..3).map(|j| a[i][j] * p[j]).sum::<f64>()))
        .collect();
    let mats = [
        Material::LinearElastic(LinearElastic::new(1000.0, 0.3)),
        Material::LinearElastic(LinearElastic::new(1000.0, 0.4999)),
        Material::NeoHookean(NeoHookean::new(1000.0, 0.3)),
    ];
    let controls = [
        Stabilization::AssumedStrainMu,
        Stabilization::AssumedStrain,
        Stabilization::Coefficient(0.1),
    ];
    for mat in &mats {
        for &control in &controls {
            let form = Formulation::Mean { hourglass: control };
            let mut f = vec![[0.0; 3]; 16];
            let mut stresses = Vec::new();
            for e in elements() {
                let xe: [Vec3; 8] = std::array::from_fn(|k| x[e[k]]);
                let ue: [Vec3; 8] = std::array::from_fn(|k| u[e[k]]);
                let mut fe = [[0.0; 3]; 8];
                internal_force(&xe, &ue, mat, form, &mut fe).expect("a valid element");
                for k in 0..8 {
                    for i in 0..3 {
                        f[e[k]][i] += fe[k][i];
                    }
                }
                stresses.push(average_cauchy(&xe, &ue, mat, form).expect("a valid element"));
            }
            let fscale = f.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            let inner = f[8..].iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            let s0 = stresses[0];
            let sscale = s0.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let spread = stresses
                .iter()
                .flat_map(|s| (0..6).map(move |k| (s[k] - s0[k]).abs()))
                .fold(0.0f64, f64::max);
            println!(
                "{control:?} {mat:?}: max inner-node force / max force {:.1e}, stress spread / max stress {:.1e}",
                inner / fscale,
                spread / sscale
            );
            // Exact to rounding: the forces are sums of a few dozen terms of the size of
            // the largest nodal force (1e-13 of it), the stresses the same constant in every
            // element (near incompressibility lambda tr(eps) dominates and its rounding is
            // 1e-16 lambda / mu = 1e-13 of the stress).
            assert!(
                inner <= 1e-12 * fscale,
                "{control:?} {mat:?}: {inner} of {fscale}"
            );
            assert!(
                spread <= 1e-12 * sscale,
                "{control:?} {mat:?}: {spread} of {sscale}"
            );
            if let Material::LinearElastic(m) = mat {
                // xx yy zz xy yz zx
                let pairs = [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0)];
                let tr = a[0][0] + a[1][1] + a[2][2];
                for (k, &(i, j)) in pairs.iter().enumerate() {
                    let diag = if i == j { m.lambda * tr } else { 0.0 };
                    let exact = m.mu * (a[i][j] + a[j][i]) + diag;
                    assert!(
                        (s0[k] - exact).abs() <= 1e-12 * sscale,
                        "{k}: {} vs {exact}",
                        s0[k]
                    );
                }
            }
        }
    }
}
