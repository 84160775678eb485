//! Nodal block Jacobi: the inverse of each node's 3 x 3 diagonal block of the tangent
//! (the solver forms the blocks, with the constraints' projection, and projects the
//! inverses), and its application.

use crate::math::{inverse, matvec, Mat3, Vec3};

/// Replaces each block by its inverse; a block with no finite inverse by the inverse of
/// its mean diagonal times the identity, so that the preconditioner stays invertible.
pub fn invert_blocks(blocks: &mut [Mat3]) {
    for b in blocks {
        let m = *b;
        let (inv, det) = inverse(&m);
        *b = if det.is_finite() && det != 0.0 && inv.iter().flatten().all(|v| v.is_finite()) {
            inv
        } else {
            let s = 1.0 / (m[0][0] + m[1][1] + m[2][2]).abs().max(f64::MIN_POSITIVE);
            [[s, 0.0, 0.0], [0.0, s, 0.0], [0.0, 0.0, s]]
        };
    }
}

/// z = M^-1 r, node by node.
pub fn apply(minv: &[Mat3], r: &[Vec3], z: &mut [Vec3]) {
    for ((z, r), m) in z.iter_mut().zip(r).zip(minv) {
        *z = matvec(m, r);
    }
}
