//! Tangential springs of slipping contact nodes in the model problem. A slipping node's
//! friction force is a load of fixed magnitude along a direction the contact update turns;
//! alone it gives the node no tangential stiffness, and a body held only by slipping nodes
//! would be a mechanism within the model problem. Each slipping node therefore carries a
//! spring across its friction direction (the direction's derivative with respect to the
//! slip), anchored where the node stood when the model problem began: it holds the node
//! while the model problem is solved and is unstretched once the contact loop has settled
//! (the last model problem moves nothing), so it leaves the converged state unchanged.
//! With linear bodies, slipping nodes beyond their stick range carry a spring of Coulomb's
//! tangent instead (`contact::slip::coulomb_tangent`), anchored the same way.

use crate::math::{matvec, Mat3, Vec3};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spring {
    /// Local index of the (owned) slave node.
    pub node: usize,
    /// Symmetric positive semi-definite stiffness (force per displacement).
    pub k: Mat3,
    /// Displacement of the node at which the spring is unstretched.
    pub anchor: Vec3,
}

/// f += K (u - anchor) at each spring's node: the springs' part of the internal force.
pub fn add_forces(springs: &[Spring], u: &[Vec3], f: &mut [Vec3]) {
    for s in springs {
        let d = crate::math::sub(&u[s.node], &s.anchor);
        f[s.node] = crate::math::add(&f[s.node], &matvec(&s.k, &d));
    }
}

/// q += K p at each spring's node: the springs' part of the stiffness times a direction.
pub fn add_action(springs: &[Spring], p: &[Vec3], q: &mut [Vec3]) {
    for s in springs {
        q[s.node] = crate::math::add(&q[s.node], &matvec(&s.k, &p[s.node]));
    }
}

/// The springs' part of the nodal diagonal blocks.
pub fn add_diagonal(springs: &[Spring], d: &mut [Mat3]) {
    for s in springs {
        for i in 0..3 {
            for j in 0..3 {
                d[s.node][i][j] += s.k[i][j];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn forces_are_the_action_on_the_stretch() {
        // K = k e e^T with e = (0.6, 0.8, 0): the force of a stretch d is K d, the same as the
        // action on d; a stretch along (0.8, -0.6, 0) (normal to e) carries no force.
        let e = [0.6, 0.8, 0.0];
        let k: Mat3 = std::array::from_fn(|i| std::array::from_fn(|j| 2.0 * e[i] * e[j]));
        let s = [Spring {
            node: 1,
            k,
            anchor: [1.0, 1.0, 1.0],
        }];
        let u = vec![[0.0; 3], [1.5, 2.0, 3.0]];
        let mut f = vec![[0.0; 3]; 2];
        add_forces(&s, &u, &mut f);
        let mut q = vec![[0.0; 3]; 2];
        add_action(&s, &[[0.0; 3], [0.5, 1.0, 2.0]], &mut q);
        assert_eq!(f, q);
        // K d = 2 (e . d) e with e . d = 0.3 + 0.8 = 1.1.
        for i in 0..3 {
            assert!((f[1][i] - 2.2 * e[i]).abs() < 1e-15);
        }
        let mut g = vec![[0.0; 3]; 2];
        add_forces(&s, &[[0.0; 3], [1.8, 0.4, 1.0]], &mut g);
        assert!(g[1].iter().all(|x| x.abs() < 1e-15), "{g:?}");
    }
}
