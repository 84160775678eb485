//! The friction links of the coupled solve (`coupled`): a slipping node whose friction
//! follows its normal force, the coupling of its own rows, and the solve's vectors.

use crate::math::Vec3;
use crate::memory::try_filled;

/// A slipping node whose friction follows its normal force within the model problem.
#[derive(Clone, Debug)]
pub struct FrictionLink {
    /// The node's normal row (flat index), on the rank that owns the slave node.
    pub row: Option<usize>,
    /// The slave node's local index, where it is local.
    pub slave: Option<usize>,
    /// Local master nodes and their weights.
    pub masters: Vec<(usize, f64)>,
    pub mu: f64,
    /// Friction direction (unit, on the slave).
    pub dir: Vec3,
    /// The friction magnitude the fixed loads (`ModelProblem::extra`) hold.
    pub held: f64,
    /// The normal multiplier a unit force along `dir` at the slave node takes through the
    /// node's other rows (`self_coupling`), on the owner rank; 0 elsewhere.
    pub own: f64,
}

/// The normal row's multiplier of a unit force `d` on a node whose rows (kept, in order)
/// have directions `dirs`, the normal being row `normal`: minus the normal component of the
/// Gram split G^-1 (c_i . d), as `Constraints::reduce` splits a force. Zero when the rows
/// are orthogonal to `d` (a node tied along its normal only, d in the tangent plane); a
/// Dirichlet direction at the node that is not orthogonal to the normal passes part of the
/// friction force on to the normal row.
pub fn self_coupling(dirs: &[Vec3], normal: usize, d: &Vec3) -> f64 {
    let k = dirs.len().min(3);
    let mut g = crate::math::IDENTITY;
    let mut c = [0.0; 3];
    for a in 0..k {
        for b in 0..k {
            g[a][b] = crate::math::dot(&dirs[a], &dirs[b]);
        }
        c[a] = crate::math::dot(&dirs[a], d);
    }
    let (inv, _) = crate::math::inverse(&g);
    let x = crate::math::matvec(&inv, &c);
    if normal < k && x[normal].is_finite() {
        -x[normal]
    } else {
        0.0
    }
}

/// BiCGStab's vectors, allocated at the first coupled solve.
#[derive(Default)]
pub(super) struct Work {
    /// The residual (the CG's own `r` is the preconditioner's input).
    pub(super) res: Vec<Vec3>,
    pub(super) rhat: Vec<Vec3>,
    pub(super) p: Vec<Vec3>,
    pub(super) v: Vec<Vec3>,
    pub(super) s: Vec<Vec3>,
    pub(super) t: Vec<Vec3>,
    pub(super) ph: Vec<Vec3>,
    pub(super) sh: Vec<Vec3>,
    pub(super) mult: Vec<f64>,
    pub(super) normal: Vec<f64>,
    /// Nonlinear bodies: the point the operator is linearised at (the last true residual's)
    /// and that residual's norm.
    pub(super) base: Vec<Vec3>,
    pub(super) base_rnorm: f64,
    /// Nonlinear bodies: the elements elastic at `base` (`Assembly::mark_elastic`) and the
    /// internal force there of the others (`Assembly::kernel_force`); how many are marked
    /// on all ranks (none: the forward difference of the whole force, as for other
    /// bodies), None until the operator is first applied at `base`.
    pub(super) marks: Vec<bool>,
    pub(super) marked: Option<u64>,
    pub(super) base_force: Vec<Vec3>,
}

impl Work {
    pub(super) fn ensure(&mut self, n: usize) -> Result<(), crate::memory::AllocError> {
        if self.rhat.len() != n {
            let v = || try_filled([0.0; 3], n, "the coupled friction solver's vectors");
            self.res = v()?;
            self.rhat = v()?;
            self.p = v()?;
            self.v = v()?;
            self.s = v()?;
            self.t = v()?;
            self.ph = v()?;
            self.sh = v()?;
            self.base = v()?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn friction_in_the_tangent_plane_of_a_node_tied_along_its_normal_feeds_nothing() {
        // One row, the normal; the friction direction orthogonal to it: exactly zero.
        let m = self_coupling(&[[0.0, 1.0, 0.0]], 0, &[1.0, 0.0, 0.0]);
        assert_eq!(m, 0.0);
    }

    #[test]
    fn a_dirichlet_direction_beside_the_normal_passes_friction_to_it() {
        // Rows u_x (Dirichlet) and the normal n = (-sin t, cos t, 0) of a slope at t; the
        // friction direction down the slope d = (cos t, sin t, 0) splits as
        // d = a e_x + b n with b = tan t: the normal row's multiplier is -tan t. Tolerance:
        // a 2x2 Gram solve in double precision (a few ulps of tan t).
        for deg in [10.0f64, 20.0, 45.0] {
            let t = deg.to_radians();
            let n = [-t.sin(), t.cos(), 0.0];
            let d = [t.cos(), t.sin(), 0.0];
            let m = self_coupling(&[[1.0, 0.0, 0.0], n], 1, &d);
            assert!((m + t.tan()).abs() <= 1e-15 * (1.0 + t.tan()), "{deg}: {m}");
        }
    }
}
