//! The foundation's acceptance: exact bar, patch tests, neo-Hookean kernel checks,
//! volumetric locking, and the scene layer's error messages.

use crate::common;
use common::{problem, solve, Rng};
use solver::fem::element::{average_cauchy, diagonal_blocks, internal_force};
use solver::fem::{Formulation, Stabilization};
use solver::material::{LinearElastic, Material, NeoHookean};
use solver::math::Vec3;
use solver::problem::{Dirichlet, NodeSet};
use solver::scene::PiecewiseLinear;

#[test]
fn bar_under_end_displacement_is_exact() {
    let text = std::fs::read_to_string("run/examples/bar.toml").unwrap();
    let p = problem(&text);
    let (summary, state) = solve(&p);
    assert_eq!(summary.steps.len(), 4);
    // u_x = d x / L with d = 1e-3, L = 1; nu = 0 makes the 3-D field exactly 1-D, and the
    // trilinear element reproduces a linear field, so only solver round-off remains. The
    // residual tolerance 1e-12 bounds the displacement error far below 1e-10 of d.
    let d = 1e-3;
    let mut worst: f64 = 0.0;
    for (n, x) in p.mesh.coords.iter().enumerate() {
        let u = state.displacement[n];
        worst = worst
            .max((u[0] - d * x[0]).abs() / d)
            .max(u[1].abs() / d)
            .max(u[2].abs() / d);
    }
    println!("bar: max |u - exact| / d = {worst:.3e}");
    assert!(worst <= 1e-10, "bar displacement error {worst:e}");
    // Every element carries sigma_xx = E d / L.
    for s in &state.stress {
        assert!((s[0] - 1e7 * d).abs() <= 1e-10 * 1e7 * d, "stress {s:?}");
    }
}

const CUBE3: &str = r#"
kinematics = "KIN"
[[body]]
name = "cube"
box = { min = [0.0, 0.0, 0.0], max = [1.0, 1.0, 1.0] }
divisions = [3, 3, 3]
material = { model = "MODEL", E = 1000.0, nu = 0.3 }
integration = "INTEG"
volumetric = "VOL"
[time]
segments = [{ end = 1.0, steps = 1 }]
[solver]
tolerance = 1e-13
"#;

/// A 3x3x3 mesh with its interior nodes moved off the grid, every boundary node
/// prescribed to the linear field u = A X + c.
fn patch_problem(
    kin: &str,
    model: &str,
    integ: &str,
    vol: &str,
    a: [[f64; 3]; 3],
    c: Vec3,
) -> solver::problem::Problem {
    let text = CUBE3
        .replace("KIN", kin)
        .replace("MODEL", model)
        .replace("INTEG", integ)
        .replace("VOL", vol);
    let mut p = problem(&text);
    let mut rng = Rng::new(7);
    let h = 1.0 / 3.0;
    for x in p.mesh.coords.iter_mut() {
        let interior = x.iter().all(|&v| v > 1e-9 && v < 1.0 - 1e-9);
        if interior {
            for v in x.iter_mut() {
                *v += 0.2 * h * rng.next();
            }
        }
    }
    for (n, x) in p.mesh.coords.clone().iter().enumerate() {
        let boundary = x.iter().any(|&v| !(1e-9..=1.0 - 1e-9).contains(&v));
        if !boundary {
            continue;
        }
        p.node_sets.push(NodeSet {
            name: format!("n{n}"),
            nodes: vec![n as u32],
        });
        let set = p.node_sets.len() - 1;
        for i in 0..3 {
            let mut dir = [0.0; 3];
            dir[i] = 1.0;
            let value = c[i] + a[i][0] * x[0] + a[i][1] * x[1] + a[i][2] * x[2];
            p.dirichlet.push(Dirichlet {
                node_set: set,
                direction: dir,
                function: PiecewiseLinear::new(vec![(0.0, 0.0), (1.0, value)]),
            });
        }
    }
    p
}

fn check_patch(kin: &str, model: &str, integ: &str, vol: &str, a: [[f64; 3]; 3]) {
    let c = [0.01, -0.02, 0.005];
    let p = patch_problem(kin, model, integ, vol, a, c);
    let (_, state) = solve(&p);
    // Interior nodes reproduce the linear field.
    for (n, x) in p.mesh.coords.iter().enumerate() {
        for i in 0..3 {
            let exact = c[i] + a[i][0] * x[0] + a[i][1] * x[1] + a[i][2] * x[2];
            assert!(
                (state.displacement[n][i] - exact).abs() <= 1e-9 * 0.01,
                "{integ}/{vol}: node {n} u{i}"
            );
        }
    }
    let s0 = state.stress[0];
    let scale = s0.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut worst: f64 = 0.0;
    for s in &state.stress {
        for k in 0..6 {
            worst = worst.max((s[k] - s0[k]).abs() / scale);
        }
    }
    println!("patch {kin} {model} {integ} {vol}: stress non-uniformity {worst:.3e}");
    // A linear field is in the element space, so any non-uniformity is solver round-off
    // (tolerance 1e-13) amplified by the distorted mesh: 1e-9 relative is the acceptance.
    assert!(
        worst <= 1e-9,
        "{integ}/{vol}: stress not uniform: {worst:e}"
    );
    if kin == "small" {
        // sigma = lambda tr(eps) I + 2 mu eps, with E = 1000, nu = 0.3.
        let (lambda, mu) = solver::material::lame(1000.0, 0.3);
        let eps = |i: usize, j: usize| 0.5 * (a[i][j] + a[j][i]);
        let tr = eps(0, 0) + eps(1, 1) + eps(2, 2);
        let exact = [
            lambda * tr + 2.0 * mu * eps(0, 0),
            lambda * tr + 2.0 * mu * eps(1, 1),
            lambda * tr + 2.0 * mu * eps(2, 2),
            2.0 * mu * eps(0, 1),
            2.0 * mu * eps(1, 2),
            2.0 * mu * eps(2, 0),
        ];
        for k in 0..6 {
            assert!(
                (s0[k] - exact[k]).abs() <= 1e-9 * scale,
                "{integ}/{vol}: sigma[{k}] {} vs {}",
                s0[k],
                exact[k]
            );
        }
    }
}

const A: [[f64; 3]; 3] = [
    [1e-3, 2e-4, -3e-4],
    [5e-4, -2e-3, 1e-4],
    [-1e-4, 3e-4, 7e-4],
];

#[test]
fn patch_test_full_integration() {
    check_patch("small", "linear_elastic", "full", "standard", A);
}

#[test]
fn patch_test_mean_dilatation() {
    check_patch("small", "linear_elastic", "full", "mean_dilatation", A);
}

#[test]
fn patch_test_mean_integration() {
    check_patch("small", "linear_elastic", "mean", "standard", A);
}

#[test]
fn patch_test_neo_hookean_large_strain() {
    // A homogeneous finite deformation (about 10% strains) is also in the element space.
    let a = A.map(|r| r.map(|v| v * 100.0));
    check_patch("large", "neo_hookean", "full", "standard", a);
    check_patch("large", "neo_hookean", "full", "mean_dilatation", a);
    check_patch("large", "neo_hookean", "mean", "standard", a);
}

fn distorted_element() -> [Vec3; 8] {
    let mut x = solver::mesh::block::box_corners(&[0.0, 0.0, 0.0], &[1.0, 0.8, 1.2]);
    let mut rng = Rng::new(3);
    for p in x.iter_mut() {
        for v in p.iter_mut() {
            *v += 0.1 * rng.next();
        }
    }
    x
}

#[test]
fn neo_hookean_tangent_diagonal_matches_finite_differences() {
    let x = distorted_element();
    let mut rng = Rng::new(11);
    let u: [Vec3; 8] =
        std::array::from_fn(|_| [0.05 * rng.next(), 0.05 * rng.next(), 0.05 * rng.next()]);
    let mat = Material::NeoHookean(NeoHookean::new(1000.0, 0.3));
    let small = Material::LinearElastic(LinearElastic::new(1000.0, 0.3));
    // Exact diagonals: full and mean for neo-Hookean, and B-bar for linear elasticity.
    for (m, form) in [
        (mat, Formulation::Full),
        (
            mat,
            Formulation::Mean {
                hourglass: Stabilization::Coefficient(0.5),
            },
        ),
        (small, Formulation::FullBar),
        (
            small,
            Formulation::Mean {
                hourglass: Stabilization::Coefficient(0.5),
            },
        ),
        (
            mat,
            Formulation::Mean {
                hourglass: Stabilization::AssumedStrain,
            },
        ),
        (
            small,
            Formulation::Mean {
                hourglass: Stabilization::AssumedStrain,
            },
        ),
    ] {
        let mut d = [[[0.0; 3]; 3]; 8];
        diagonal_blocks(&x, &u, &m, form, &mut d).unwrap();
        let mut worst: f64 = 0.0;
        let scale = d.iter().map(|b| b[0][0].abs()).fold(0.0, f64::max);
        for a in 0..8 {
            for k in 0..3 {
                // Central differences with step 1e-6: truncation O(1e-12), round-off about
                // 1e-16 * |f| / 1e-6 = O(1e-10) relative to the stiffness scale.
                let eps = 1e-6;
                let (mut up, mut um) = (u, u);
                up[a][k] += eps;
                um[a][k] -= eps;
                let (mut fp, mut fm) = ([[0.0; 3]; 8], [[0.0; 3]; 8]);
                internal_force(&x, &up, &m, form, &mut fp).unwrap();
                internal_force(&x, &um, &m, form, &mut fm).unwrap();
                for i in 0..3 {
                    let fd = (fp[a][i] - fm[a][i]) / (2.0 * eps);
                    worst = worst.max((fd - d[a][i][k]).abs() / scale);
                }
            }
        }
        println!(
            "{form:?} {}: max |K_aa - FD| / max K = {worst:.2e}",
            if m.is_large() {
                "neo-Hookean"
            } else {
                "linear"
            }
        );
        assert!(
            worst <= 1e-6,
            "{form:?}: tangent diagonal differs from finite differences by {worst:e}"
        );
    }
}

#[test]
fn rigid_rotation_by_90_degrees_gives_zero_stress() {
    let x = distorted_element();
    let mat = Material::NeoHookean(NeoHookean::new(1000.0, 0.3));
    // Rotation by 90 degrees about the axis (1, 1, 1)/sqrt(3), plus a translation.
    let n = [1.0 / 3f64.sqrt(); 3];
    let r = |p: &Vec3| -> Vec3 {
        // Rodrigues with cos = 0, sin = 1: R p = (n . p) n + n x p
        let np = n[0] * p[0] + n[1] * p[1] + n[2] * p[2];
        let c = solver::math::cross(&n, p);
        [np * n[0] + c[0], np * n[1] + c[1], np * n[2] + c[2]]
    };
    let u: [Vec3; 8] = std::array::from_fn(|a| {
        let rx = r(&x[a]);
        [
            rx[0] - x[a][0] + 0.3,
            rx[1] - x[a][1] - 0.1,
            rx[2] - x[a][2] + 0.2,
        ]
    });
    for form in [
        Formulation::Full,
        Formulation::FullBar,
        Formulation::Mean {
            hourglass: Stabilization::Coefficient(0.5),
        },
        Formulation::Mean {
            hourglass: Stabilization::AssumedStrain,
        },
    ] {
        let s = average_cauchy(&x, &u, &mat, form).unwrap();
        let mut f = [[0.0; 3]; 8];
        internal_force(&x, &u, &mat, form, &mut f).unwrap();
        let smax = s.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let fmax = f.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        println!(
            "{form:?}: max |sigma| / E = {:.2e}, max |f| / E = {:.2e}",
            smax / 1000.0,
            fmax / 1000.0
        );
        // Round-off of F^T F - I with |F| ~ 1: about 1e-16 times a few; 1e-10 of E is the
        // acceptance and leaves room for the trigonometric constants.
        assert!(
            smax <= 1e-10 * 1000.0,
            "{form:?}: stress under rigid rotation {s:?}"
        );
        assert!(
            fmax <= 1e-10 * 1000.0,
            "{form:?}: force under rigid rotation {f:?}"
        );
    }
}

/// Plane-strain block of width 1 and height 2 (modelled as its half, x in [0, 0.5], with a
/// symmetry plane at x = 0), nu = 0.4999, bonded to rigid plates at top and bottom and
/// compressed by 0.01: returns the total vertical reaction on the top plate. A tall block
/// keeps the bonded corners' singular stresses from dominating the coarse meshes.
fn bonded_block_reaction(nx: usize, integ: &str, vol: &str) -> (f64, u64) {
    let ny = 4 * nx;
    let text = format!(
        r#"
[[body]]
name = "block"
box = {{ min = [0.0, 0.0, 0.0], max = [0.5, 2.0, 0.1] }}
divisions = [{nx}, {ny}, 1]
material = {{ model = "linear_elastic", E = 1000.0, nu = 0.4999 }}
integration = "{integ}"
volumetric = "{vol}"
[[node_set]]
name = "bottom"
plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}
[[node_set]]
name = "top"
plane = {{ point = [0.0, 2.0, 0.0], normal = [0.0, 1.0, 0.0] }}
[[node_set]]
name = "symmetry"
plane = {{ point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}
[[node_set]]
name = "all"
box = {{ min = [0.0, 0.0, 0.0], max = [0.5, 2.0, 0.1] }}
[[displacement]]
node_set = "all"
components = ["z"]
value = 0.0
[[displacement]]
node_set = "symmetry"
components = ["x"]
value = 0.0
[[displacement]]
node_set = "bottom"
components = ["x", "y"]
value = 0.0
[[displacement]]
node_set = "top"
components = ["x"]
value = 0.0
[[displacement]]
node_set = "top"
components = ["y"]
function = [[0.0, 0.0], [1.0, -0.01]]
[time]
segments = [{{ end = 1.0, steps = 1 }}]
[solver]
tolerance = 1e-9
max_iterations = 200000
"#
    );
    let p = problem(&text);
    let (summary, state) = solve(&p);
    let top = &p.node_set("top").unwrap().nodes;
    let fy: f64 = top.iter().map(|&n| state.reaction[n as usize][1]).sum();
    (fy, summary.steps[0].cg_iterations)
}

#[test]
fn near_incompressible_block_does_not_lock_with_bbar_or_mean() {
    // Mesh h: 2 x 8 elements; h/4: 8 x 32.
    let (reference, it_ref) = bonded_block_reaction(8, "full", "mean_dilatation");
    let (bbar, it_b) = bonded_block_reaction(2, "full", "mean_dilatation");
    let (mean, it_m) = bonded_block_reaction(2, "mean", "standard");
    let (full, it_f) = bonded_block_reaction(2, "full", "standard");
    let rel = |v: f64| (v - reference) / reference;
    println!("bonded block, nu = 0.4999, reaction on the top plate:");
    println!("  B-bar  h/4: {reference:.6e} (reference, {it_ref} CG iterations)");
    println!(
        "  B-bar  h  : {bbar:.6e} ({:+.2}%, {it_b} CG)",
        100.0 * rel(bbar)
    );
    println!(
        "  mean   h  : {mean:.6e} ({:+.2}%, {it_m} CG)",
        100.0 * rel(mean)
    );
    println!(
        "  full   h  : {full:.6e} ({:+.2}%, {it_f} CG)  <- plain full integration locks",
        100.0 * rel(full)
    );
    // The issue's acceptance: within 2% of the locking-free value at h/4. Measured: B-bar
    // +1.81%, `mean` (its elastic default, the assumed strain with the shear modulus only)
    // +1.54% (with lambda +2.98%; Flanagan-Belytschko at 0.1 +0.44%). Every control
    // converges from above to about 0.5% below the reference (B-bar at h/8 -0.26%; the
    // bonded corners are singular): docs/elements.md.
    assert!(
        rel(bbar).abs() <= 0.02,
        "B-bar at h is {:.2}% off",
        100.0 * rel(bbar)
    );
    assert!(
        rel(mean).abs() <= 0.02,
        "mean at h is {:.2}% off",
        100.0 * rel(mean)
    );
    // Plain full integration locks: far stiffer (reported above, checked only as stiffer).
    assert!(
        rel(full) > 0.5,
        "plain full integration was expected to lock"
    );
}
