//! Directions along which a slave node and its master point are both held: a displacement
//! component prescribed zero for all time (a symmetry plane, a plane-strain face) at the
//! slave node and at a node of its master point. Coulomb's law acts across such a
//! direction, not along it.
//!
//! Why. The slave node's stick row along the direction is in the span of its Dirichlet
//! row and is dropped (`constraints`), so a sticking node carries no friction force along
//! it. Its master point, a weighted sum of master nodes, some of them off the plane, moves
//! a little along it all the same: the quarter model of a sphere pressed on a block, its
//! slave nodes on the two symmetry planes, measured that motion as slip and set friction
//! forces along it, which the node's Dirichlet reaction took while the master nodes moved
//! along the force; the node moved along its own friction force, stuck again, slipped again,
//! and the step never settled (200 contact updates, with identical materials, whose exact
//! answer has no friction force at all). In the continuum the two surfaces do not move
//! relative to each other along a direction both hold at zero: what the master point shows
//! there is the discretisation's. A direction driven by prescribed motion (a function not
//! zero throughout), or held at the slave alone while its master moves along it, keeps
//! Coulomb's law along it as before (`slip::driven_slip`).

use crate::math::{dot, norm, scale, sub, Vec3};
use crate::problem::Problem;
use std::collections::HashMap;

/// Two directions closer than this (1 - |cos|) are the same held direction.
const SAME: f64 = 1e-9;

/// The directions held at zero for all time, orthonormal, of every node of a friction
/// pair's surfaces (slave nodes and master face nodes) that has any.
#[derive(Clone, Debug, Default)]
pub struct HeldDirections {
    held: HashMap<u32, Vec<Vec3>>,
}

impl HeldDirections {
    pub fn of(problem: &Problem) -> HeldDirections {
        let mut wanted: Vec<u32> = Vec::new();
        for p in problem.contacts.iter().filter(|p| p.mu > 0.0) {
            wanted.extend(p.slave_nodes.iter());
            wanted.extend(p.face_nodes.iter().flatten());
        }
        wanted.sort_unstable();
        wanted.dedup();
        let mut held: HashMap<u32, Vec<Vec3>> = HashMap::new();
        if wanted.is_empty() {
            return HeldDirections { held };
        }
        // In the scene's order of the conditions, so the basis is the same on every rank.
        for bc in problem
            .dirichlet
            .iter()
            .filter(|bc| bc.function.max_abs() == 0.0)
        {
            for &n in &problem.node_sets[bc.node_set].nodes {
                if wanted.binary_search(&n).is_ok() {
                    let basis = held.entry(n).or_default();
                    if let Some(e) = orthogonal(basis, &bc.direction) {
                        basis.push(e);
                    }
                }
            }
        }
        HeldDirections { held }
    }

    /// Whether `node` holds any direction at zero.
    pub fn holds(&self, node: u32) -> bool {
        self.held.contains_key(&node)
    }

    /// The directions held at `slave` that a master node of `masters` (with a weight not
    /// zero) holds too; empty for most nodes.
    pub fn common(&self, slave: u32, masters: &[(u32, f64)]) -> Vec<Vec3> {
        let Some(own) = self.held.get(&slave) else {
            return Vec::new();
        };
        own.iter()
            .copied()
            .filter(|d| {
                masters.iter().any(|(m, w)| {
                    *w != 0.0
                        && self
                            .held
                            .get(m)
                            .is_some_and(|b| b.iter().any(|e| 1.0 - dot(d, e).abs() <= SAME))
                })
            })
            .collect()
    }
}

/// `v` without its parts along the orthonormal `dirs`.
pub fn across(dirs: &[Vec3], v: &Vec3) -> Vec3 {
    dirs.iter().fold(*v, |w, e| sub(&w, &scale(e, dot(&w, e))))
}

/// The unit part of `d` orthogonal to the orthonormal `basis`; None when `d` lies in its
/// span.
fn orthogonal(basis: &[Vec3], d: &Vec3) -> Option<Vec3> {
    let l = norm(d);
    if !(l > 0.0) {
        return None;
    }
    let r = across(basis, &scale(d, 1.0 / l));
    let n = norm(&r);
    (n > SAME.sqrt()).then(|| scale(&r, 1.0 / n))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_direction_held_at_both_sides_is_common() {
        let mut h = HeldDirections::default();
        h.held.insert(1, vec![[0.0, 0.0, 1.0]]);
        h.held.insert(2, vec![[0.0, 0.0, -1.0], [1.0, 0.0, 0.0]]);
        h.held.insert(3, vec![[1.0, 0.0, 0.0]]);
        // Node 2 holds z (either sign): common.
        assert_eq!(h.common(1, &[(2, 0.5), (4, 0.5)]), vec![[0.0, 0.0, 1.0]]);
        // A master node with weight zero, or one holding another direction, does not count.
        assert!(h.common(1, &[(2, 0.0), (3, 1.0)]).is_empty());
        // A slave node holding nothing.
        assert!(h.common(4, &[(2, 1.0)]).is_empty());
    }

    #[test]
    fn across_removes_the_held_parts() {
        let dirs = [[0.0, 0.0, 1.0]];
        assert_eq!(across(&dirs, &[0.3, 0.0, -0.9]), [0.3, 0.0, 0.0]);
        // A vector with no part along them is returned bit for bit.
        let v = [0.1 + 0.2, -1e-17, 0.0];
        assert_eq!(across(&dirs, &v), v);
        let b = [[1.0, 0.0, 0.0]];
        let e = orthogonal(&b, &[1.0, 1.0, 0.0]).unwrap();
        assert!((e[1] - 1.0).abs() < 1e-15 && e[0].abs() < 1e-15);
        assert!(orthogonal(&b, &[-2.0, 0.0, 0.0]).is_none());
    }
}
