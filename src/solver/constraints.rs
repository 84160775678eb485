//! Prescribed displacements, skew ones included, as node-local projections.
//!
//! A node may carry several conditions whose directions are not orthogonal. They are
//! enforced together: the constrained part of the node's displacement lies in the span of
//! the directions and is found from the Gram system G l = v, G_ij = d_i . d_j, so the node
//! lands on the intersection of all its conditions at once. A direction that adds nothing
//! to the span of earlier ones on the same node (a node in two fixed faces, say) is dropped.

use crate::math::{dot, Mat3, Vec3, IDENTITY};
use crate::mesh::local::LocalMesh;
use crate::problem::Problem;
use crate::scene::PiecewiseLinear;

struct Row {
    direction: Vec3,
    function: usize,
}

pub struct Dirichlet {
    /// Local indices of nodes with conditions, ascending.
    nodes: Vec<usize>,
    rows: Vec<Vec<Row>>,
    /// P = I - Q Q^T per constrained node.
    projectors: Vec<Mat3>,
    functions: Vec<PiecewiseLinear>,
    /// Index into `nodes` by local node, usize::MAX when free.
    slot: Vec<usize>,
}

impl Dirichlet {
    pub fn new(problem: &Problem, mesh: &LocalMesh) -> Self {
        let mut slot = vec![usize::MAX; mesh.num_nodes()];
        let mut nodes = Vec::new();
        let mut rows: Vec<Vec<Row>> = Vec::new();
        let mut bases: Vec<Vec<Vec3>> = Vec::new();
        let functions: Vec<PiecewiseLinear> = problem
            .dirichlet
            .iter()
            .map(|d| d.function.clone())
            .collect();
        for (fi, bc) in problem.dirichlet.iter().enumerate() {
            for &g in &problem.node_sets[bc.node_set].nodes {
                let Some(l) = mesh.local_node(g) else {
                    continue;
                };
                if slot[l] == usize::MAX {
                    slot[l] = nodes.len();
                    nodes.push(l);
                    rows.push(Vec::new());
                    bases.push(Vec::new());
                }
                let s = slot[l];
                // Gram-Schmidt against the directions already kept on this node.
                let mut r = bc.direction;
                for q in &bases[s] {
                    let c = dot(&r, q);
                    for i in 0..3 {
                        r[i] -= c * q[i];
                    }
                }
                let n = dot(&r, &r).sqrt();
                if n > 1e-8 {
                    bases[s].push([r[0] / n, r[1] / n, r[2] / n]);
                    rows[s].push(Row {
                        direction: bc.direction,
                        function: fi,
                    });
                }
            }
        }
        // Keep the constrained nodes in ascending local order so loops are deterministic.
        let mut order: Vec<usize> = (0..nodes.len()).collect();
        order.sort_by_key(|&k| nodes[k]);
        let mut rows_sorted = Vec::with_capacity(order.len());
        let mut projectors = Vec::with_capacity(order.len());
        let mut rows_opt: Vec<Option<Vec<Row>>> = rows.into_iter().map(Some).collect();
        let mut nodes_sorted = Vec::with_capacity(order.len());
        for &k in &order {
            let mut p = IDENTITY;
            for q in &bases[k] {
                for i in 0..3 {
                    for j in 0..3 {
                        p[i][j] -= q[i] * q[j];
                    }
                }
            }
            projectors.push(p);
            rows_sorted.push(rows_opt[k].take().expect("each row list is taken once"));
            nodes_sorted.push(nodes[k]);
        }
        for (s, &l) in nodes_sorted.iter().enumerate() {
            slot[l] = s;
        }
        Dirichlet {
            nodes: nodes_sorted,
            rows: rows_sorted,
            projectors,
            functions,
            slot,
        }
    }

    pub fn is_constrained(&self, local: usize) -> bool {
        self.slot[local] != usize::MAX
    }

    /// The projector of a constrained node, or None for a free one.
    pub fn projector(&self, local: usize) -> Option<&Mat3> {
        let s = self.slot[local];
        (s != usize::MAX).then(|| &self.projectors[s])
    }

    /// v <- P v: removes the constrained components.
    pub fn project(&self, v: &mut [Vec3]) {
        for (s, &n) in self.nodes.iter().enumerate() {
            v[n] = crate::math::matvec(&self.projectors[s], &v[n]);
        }
    }

    /// The constrained part of the displacement of every constrained node at time t.
    pub fn constrained_values(&self, t: f64) -> Vec<Vec3> {
        self.rows
            .iter()
            .map(|rows| {
                let k = rows.len();
                let mut g = [[0.0; 3]; 3];
                let mut b = [0.0; 3];
                for i in 0..k {
                    for j in 0..k {
                        g[i][j] = dot(&rows[i].direction, &rows[j].direction);
                    }
                    b[i] = self.functions[rows[i].function].eval(t);
                }
                let l = solve_small(&g, &b, k);
                let mut uc = [0.0; 3];
                for i in 0..k {
                    for d in 0..3 {
                        uc[d] += l[i] * rows[i].direction[d];
                    }
                }
                uc
            })
            .collect()
    }

    /// u <- P u + u_c: puts every constrained node on all of its conditions at once.
    pub fn impose(&self, u: &mut [Vec3], values: &[Vec3]) {
        for (s, &n) in self.nodes.iter().enumerate() {
            let free = crate::math::matvec(&self.projectors[s], &u[n]);
            u[n] = crate::math::add(&free, &values[s]);
        }
    }
}

/// Solves the leading k x k block of a symmetric positive definite system (k <= 3) by
/// Gaussian elimination.
fn solve_small(g: &Mat3, b: &[f64; 3], k: usize) -> [f64; 3] {
    let mut a = *g;
    let mut x = *b;
    for c in 0..k {
        let piv = a[c][c];
        for r in c + 1..k {
            let f = a[r][c] / piv;
            for j in c..k {
                a[r][j] -= f * a[c][j];
            }
            x[r] -= f * x[c];
        }
    }
    for c in (0..k).rev() {
        let mut s = x[c];
        for j in c + 1..k {
            s -= a[c][j] * x[j];
        }
        x[c] = s / a[c][c];
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn skew_and_component_conditions_meet_at_their_intersection() {
        // u_x = 0 and u . n = -0.1 with n at 20 degrees from y: the node must satisfy both.
        let phi = 20f64.to_radians();
        let n = [-phi.sin(), phi.cos(), 0.0];
        let g = [
            [1.0, dot(&[1.0, 0.0, 0.0], &n), 0.0],
            [dot(&n, &[1.0, 0.0, 0.0]), 1.0, 0.0],
            [0.0; 3],
        ];
        let l = solve_small(&g, &[0.0, -0.1, 0.0], 2);
        let u = [l[0] + l[1] * n[0], l[1] * n[1], 0.0];
        assert!(u[0].abs() < 1e-15);
        assert!((dot(&u, &n) + 0.1).abs() < 1e-15);
    }
}
