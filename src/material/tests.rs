//! Every model through `Material`: the point tangent against central differences of the
//! stress, and the scene parameters building the model or naming the bad key.

use super::*;
use crate::math::{matvec, Vec3, ZERO33};

/// `c v v^T + mu |g|^2 I - cn (n v)(n v)^T` (`PointTangent`'s contraction with `g`).
fn contract(pt: &PointTangent, g: &Vec3) -> Mat3 {
    let v: Vec3 = match &pt.finv {
        Some(fi) => std::array::from_fn(|i| (0..3).map(|l| fi[l][i] * g[l]).sum()),
        None => *g,
    };
    let gg = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
    let nv = matvec(&pt.n, &v);
    let mut k = ZERO33;
    for i in 0..3 {
        for m in 0..3 {
            k[i][m] = pt.c * v[i] * v[m] - pt.cn * nv[i] * nv[m];
        }
        k[i][i] += pt.mu * gg;
    }
    k
}

/// `sum_JL g_J dP_iJ/dH_kL g_L` by central differences of the stress from `old`.
fn finite_difference(mat: &Material, h: &Mat3, old: &PlasticState, g: &Vec3) -> Mat3 {
    let eps = 1e-7;
    let mut k = ZERO33;
    for m in 0..3 {
        let (mut hp, mut hm) = (*h, *h);
        for l in 0..3 {
            hp[m][l] += eps * g[l];
            hm[m][l] -= eps * g[l];
        }
        let sp = mat.update(&hp, old).expect("admissible").stress;
        let sm = mat.update(&hm, old).expect("admissible").stress;
        for i in 0..3 {
            k[i][m] = (0..3).map(|j| (sp[i][j] - sm[i][j]) * g[j]).sum::<f64>() / (2.0 * eps);
        }
    }
    k
}

#[test]
fn every_exact_tangent_matches_central_differences_of_the_stress() {
    let h = [
        [0.004, -0.002, 0.001],
        [0.003, -0.001, 0.002],
        [-0.001, 0.0015, 0.002],
    ];
    let big: Mat3 = std::array::from_fn(|i| std::array::from_fn(|j| 20.0 * h[i][j]));
    let g = [0.3, -0.7, 0.5];
    let virgin = PlasticState::default();
    let j2 = Material::J2Plastic(J2Plastic::new(1000.0, 0.3, 1.0, 10.0, 5.0, false));
    // At `big` the J2 point flows: the consistent tangent's flow term is tested.
    assert!(j2.update(&big, &virgin).unwrap().yielded);
    let cases = [
        (
            Material::LinearElastic(LinearElastic::new(1000.0, 0.3)),
            h,
            virgin,
        ),
        (
            Material::NeoHookean(NeoHookean::new(1000.0, 0.3)),
            big,
            virgin,
        ),
        (j2, h, virgin),
        (j2, big, virgin),
    ];
    for (mat, h, old) in cases {
        let exact = contract(&mat.tangent(&h, Some(&old)), &g);
        let fd = finite_difference(&mat, &h, &old, &g);
        let scale = exact.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
        for i in 0..3 {
            for k in 0..3 {
                let err = (exact[i][k] - fd[i][k]).abs() / scale;
                assert!(
                    err < 1e-6,
                    "{}: [{i}][{k}] {} vs {}",
                    mat.name(),
                    exact[i][k],
                    fd[i][k]
                );
            }
        }
    }
}

/// The material `p` builds (the scene reads parameters as `dyn Parameters<Material>`).
fn build(p: &dyn Parameters<Material>, large: bool) -> Result<Material, ParamError> {
    p.build(large)
}

#[test]
fn parameters_build_their_model_or_name_the_bad_key() {
    let elastic = LinearElasticParams {
        e: 1000.0,
        nu: 0.3,
        density: 0.0,
    };
    assert_eq!(
        build(&elastic, false),
        Ok(Material::LinearElastic(LinearElastic::new(1000.0, 0.3)))
    );
    assert_eq!(build(&elastic, true).unwrap_err().key, "model");
    let neo = NeoHookeanParams {
        e: 1000.0,
        nu: 0.6,
        density: 0.0,
    };
    assert_eq!(build(&neo, true).unwrap_err().key, "nu");
    let j2 = J2Params {
        e: 1000.0,
        nu: 0.3,
        yield_stress: 1.0,
        isotropic_hardening: 0.0,
        kinematic_hardening: 5.0,
        density: 0.0,
    };
    assert!(build(&j2, false).unwrap().is_plastic());
    assert_eq!(build(&j2, true).unwrap_err().key, "kinematic_hardening");
}
