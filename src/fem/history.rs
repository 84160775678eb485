//! Integration-point history of plastic elements: how many stress points there are, the
//! update of the state a converged step commits, and the element-mean equivalent plastic
//! strain. The displacement gradient each point sees (with the B-bar / F-bar modification)
//! is `element::point_gradients` (kinematics.rs), the diagonal tangent blocks of a plastic
//! B-bar / F-bar element `diagonal_blocks_bar` (tangent.rs).

pub use super::element::point_gradients;
use super::element::{
    centre, forces, hourglass_sums, mean_gradient, modes, ElementFailure, Formulation,
    GaussGeometry, Geometry, Hourglass, Stabilization, Stiffness, SLOTS,
};
use crate::material::{Material, PlasticState};
use crate::math::Vec3;

/// History states of a plastic element: one per Gauss point, or the mean point's followed
/// by the `SLOTS` that hold its hourglass state (`element::hourglass`).
#[inline]
pub fn points(form: Formulation) -> usize {
    match form {
        Formulation::Mean { .. } => MEAN_POINTS,
        _ => 8,
    }
}

/// History states of a plastic hexahedron of the mean formulation (`points`).
pub const MEAN_POINTS: usize = 1 + SLOTS;

/// History states of a plastic element of `kind`: `points` for a hexahedron, one per
/// stress point of a composite tetrahedron.
#[inline]
pub fn points_of(kind: crate::fem::ElementKind, form: Formulation) -> usize {
    match kind {
        crate::fem::ElementKind::Hex8 => points(form),
        crate::fem::ElementKind::Tet10 => crate::fem::tet10::STRESS_POINTS,
    }
}

/// The states a converged step commits: `new[q]` from `old[q]` at the displacements `u`.
pub fn update_with(
    geo: &Geometry,
    gauss: Option<&GaussGeometry>,
    u: &[Vec3; 8],
    mat: &Material,
    form: Formulation,
    old: &[PlasticState],
    new: &mut [PlasticState],
) -> Result<(), ElementFailure> {
    if let Formulation::Mean { hourglass } = form {
        return update_mean(geo, u, mat, hourglass, old, new);
    }
    let (h, _, n) = point_gradients(geo, gauss, u, mat.is_large(), form)?;
    for q in 0..n {
        new[q] = mat
            .update(&h[q], &old[q])
            .ok_or(ElementFailure::InvertedCurrent)?
            .state;
    }
    Ok(())
}

/// The states a converged step commits in a plastic one-point element: the centre's and
/// the hourglass state (the forces of the step, the displacement sums, and the centre's
/// deviatoric strain and stress), the same values `internal_force_with` used.
fn update_mean(
    geo: &Geometry,
    u: &[Vec3; 8],
    mat: &Material,
    control: Stabilization,
    old: &[PlasticState],
    new: &mut [PlasticState],
) -> Result<(), ElementFailure> {
    let h = mean_gradient(u, geo);
    let c = centre(mat, &h, old).ok_or(ElementFailure::InvertedCurrent)?;
    let (_, mu) = mat.lambda_mu();
    let hx = hourglass_sums(geo);
    let k = Stiffness::new(geo, control, mat);
    let q = modes(u, &h, &hx);
    new[0] = c.state;
    Hourglass {
        force: forces(&q, &k, mu, geo, &c),
        q,
        strain: super::element::dev_sym(&h),
        stress: super::element::dev_sym(&c.stress),
    }
    .write(&mut new[1..]);
    Ok(())
}

/// Reference-volume average of the equivalent plastic strain over the element's points.
pub fn mean_eqps(
    geo: &Geometry,
    gauss: Option<&GaussGeometry>,
    form: Formulation,
    hist: &[PlasticState],
) -> f64 {
    match form {
        Formulation::Mean { .. } => hist[0].eqps,
        _ => {
            let w = &gauss.expect("Gauss-point geometry").wdet;
            let s: f64 = (0..8).map(|q| w[q] * hist[q].eqps).sum();
            s / geo.volume
        }
    }
}
