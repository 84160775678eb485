//! Node-local constraint rows: prescribed displacements (any direction) and contact ties,
//! enforced together as a change of variables u = T v + g.
//!
//! A constrained node s carries rows c_i . (u_s - sum_j w_ij u_mj) = b_i: a Dirichlet row
//! has no master terms; a contact row ties the node to a point of a master face (weights
//! w_ij = face shape functions at the contact point). Rows on one node need not be
//! orthogonal (a skew Dirichlet condition and a contact normal at 20 degrees, or three
//! master faces meeting at a corner): they are enforced at once through the Gram system
//! G l = (b + B u_m), G_ij = c_i . c_j, so the node lands on the intersection of all of
//! them, and a residual splits into the row forces G^-1 C r plus a free part P r. A row that
//! adds nothing to the span of the node's earlier rows is dropped (Dirichlet rows come
//! first, so a node fixed in every direction by Dirichlet conditions carries no contact
//! force and cannot slip).
//!
//! Nodes are processed in order of dependency depth (a master node that is itself a slave
//! elsewhere is resolved first), so T is a product of node-local maps and T^T applies their
//! transposes in reverse order.

use crate::math::{dot, matvec, Mat3, Vec3, IDENTITY};

/// What a row stands for, so forces can be reported per constraint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RowKind {
    /// A prescribed displacement; the index is the scene's Dirichlet entry.
    Dirichlet(usize),
    /// A contact tie; `constraint` indexes the contact state's active list, `component`
    /// is 0 for the normal and 1, 2 for the tangents of a sticking node.
    Contact { constraint: usize, component: u8 },
}

#[derive(Clone, Debug)]
pub struct Row {
    pub dir: Vec3,
    /// Fixed part of the right-hand side.
    pub value: f64,
    /// Master nodes (local indices) and weights.
    pub masters: Vec<(usize, f64)>,
    pub kind: RowKind,
}

/// A row as given, before the independent subset is chosen.
pub struct RowSpec {
    pub node: usize,
    pub row: Row,
}

struct NodeRows {
    node: usize,
    rows: Vec<Row>,
    /// Inverse of the Gram matrix of the kept rows (leading k x k block).
    ginv: Mat3,
    proj: Mat3,
    /// Index of the node's first row in the flat multiplier array.
    first: usize,
}

pub struct Constraints {
    /// In dependency order (depth, then local node index).
    nodes: Vec<NodeRows>,
    /// Position in `nodes` by local node, usize::MAX when free.
    slot: Vec<usize>,
    num_rows: usize,
    /// Rows dropped as redundant with earlier rows on their node.
    pub dropped: Vec<(usize, RowKind)>,
}

/// A circular master/slave dependency between constrained nodes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CircularDependency(pub usize);

impl Constraints {
    /// Builds the constraint set; rows are taken per node in the order given.
    pub fn new(num_nodes: usize, specs: Vec<RowSpec>) -> Result<Self, CircularDependency> {
        let mut slot = vec![usize::MAX; num_nodes];
        let mut nodes: Vec<NodeRows> = Vec::new();
        let mut bases: Vec<Vec<Vec3>> = Vec::new();
        let mut dropped = Vec::new();
        for spec in specs {
            let l = spec.node;
            if slot[l] == usize::MAX {
                slot[l] = nodes.len();
                nodes.push(NodeRows {
                    node: l,
                    rows: Vec::new(),
                    ginv: [[0.0; 3]; 3],
                    proj: IDENTITY,
                    first: 0,
                });
                bases.push(Vec::new());
            }
            let s = slot[l];
            let mut r = spec.row.dir;
            let n0 = dot(&r, &r).sqrt();
            for q in &bases[s] {
                let c = dot(&r, q);
                for i in 0..3 {
                    r[i] -= c * q[i];
                }
            }
            let n = dot(&r, &r).sqrt();
            if n > 1e-8 * n0 && bases[s].len() < 3 {
                bases[s].push([r[0] / n, r[1] / n, r[2] / n]);
                nodes[s].rows.push(spec.row);
            } else {
                dropped.push((l, spec.row.kind));
            }
        }
        for (s, nr) in nodes.iter_mut().enumerate() {
            let mut p = IDENTITY;
            for q in &bases[s] {
                for i in 0..3 {
                    for j in 0..3 {
                        p[i][j] -= q[i] * q[j];
                    }
                }
            }
            nr.proj = p;
            let k = nr.rows.len();
            let mut g = [[0.0; 3]; 3];
            for i in 0..k {
                for j in 0..k {
                    g[i][j] = dot(&nr.rows[i].dir, &nr.rows[j].dir);
                }
            }
            nr.ginv = invert_small(&g, k);
        }
        // Dependency depth: a node tied to masters that are themselves constrained by
        // contact comes after them.
        let mut depth = vec![0usize; nodes.len()];
        let limit = nodes.len() + 1;
        for _ in 0..limit {
            let mut changed = false;
            for s in 0..nodes.len() {
                let mut d = 0;
                for row in &nodes[s].rows {
                    for &(m, _) in &row.masters {
                        let ms = slot[m];
                        // Any constrained master is resolved first: its value is imposed
                        // before the slave reads it, and its residual projected after the
                        // slave has passed its force on.
                        if ms != usize::MAX && ms != s {
                            d = d.max(depth[ms] + 1);
                        }
                    }
                }
                if d != depth[s] {
                    if d > limit {
                        return Err(CircularDependency(nodes[s].node));
                    }
                    depth[s] = d;
                    changed = true;
                }
            }
            if !changed {
                break;
            }
        }
        if depth.iter().any(|&d| d >= limit) {
            let s = depth.iter().position(|&d| d >= limit).unwrap_or(0);
            return Err(CircularDependency(nodes[s].node));
        }
        let mut order: Vec<usize> = (0..nodes.len()).collect();
        order.sort_by_key(|&s| (depth[s], nodes[s].node));
        let mut taken: Vec<Option<NodeRows>> = nodes.into_iter().map(Some).collect();
        let mut sorted = Vec::with_capacity(order.len());
        let mut first = 0;
        for &s in &order {
            let mut nr = taken[s].take().expect("each node once");
            nr.first = first;
            first += nr.rows.len();
            slot[nr.node] = sorted.len();
            sorted.push(nr);
        }
        Ok(Constraints {
            nodes: sorted,
            slot,
            num_rows: first,
            dropped,
        })
    }

    pub fn num_rows(&self) -> usize {
        self.num_rows
    }

    pub fn is_constrained(&self, local: usize) -> bool {
        self.slot[local] != usize::MAX
    }

    /// Projector onto the free directions of a constrained node.
    pub fn projector(&self, local: usize) -> Option<&Mat3> {
        let s = self.slot[local];
        (s != usize::MAX).then(|| &self.nodes[s].proj)
    }

    /// Rows of a node with their flat indices.
    pub fn rows(&self, local: usize) -> impl Iterator<Item = (usize, &Row)> {
        let s = self.slot[local];
        let nr = (s != usize::MAX).then(|| &self.nodes[s]);
        nr.into_iter().flat_map(|nr| {
            nr.rows
                .iter()
                .enumerate()
                .map(move |(i, r)| (nr.first + i, r))
        })
    }

    /// u <- T u + g: every constrained node put on all of its rows (gap removal included).
    pub fn impose(&self, u: &mut [Vec3]) {
        self.apply(u, true);
    }

    /// p <- T p: the homogeneous map, for search directions.
    pub fn expand(&self, p: &mut [Vec3]) {
        self.apply(p, false);
    }

    fn apply(&self, u: &mut [Vec3], with_values: bool) {
        for nr in &self.nodes {
            let k = nr.rows.len();
            let mut b = [0.0; 3];
            for (i, row) in nr.rows.iter().enumerate() {
                let mut v = if with_values { row.value } else { 0.0 };
                for &(m, w) in &row.masters {
                    v += w * dot(&row.dir, &u[m]);
                }
                b[i] = v;
            }
            let l = matvec(&nr.ginv, &b);
            let mut x = matvec(&nr.proj, &u[nr.node]);
            for i in 0..k {
                for d in 0..3 {
                    x[d] += l[i] * nr.rows[i].dir[d];
                }
            }
            u[nr.node] = x;
        }
    }

    /// r <- T^T r. When `multipliers` is given, row i's force coefficient is written to it:
    /// the force the constraint exerts on its node is sum_i m_i c_i (positive along c_i).
    pub fn reduce(&self, r: &mut [Vec3], mut multipliers: Option<&mut [f64]>) {
        for nr in self.nodes.iter().rev() {
            let k = nr.rows.len();
            let rs = r[nr.node];
            let mut c = [0.0; 3];
            for i in 0..k {
                c[i] = dot(&nr.rows[i].dir, &rs);
            }
            let mu = matvec(&nr.ginv, &c);
            for (i, row) in nr.rows.iter().enumerate() {
                for &(m, w) in &row.masters {
                    for d in 0..3 {
                        r[m][d] += w * mu[i] * row.dir[d];
                    }
                }
            }
            if let Some(out) = multipliers.as_deref_mut() {
                for i in 0..k {
                    out[nr.first + i] = -mu[i];
                }
            }
            r[nr.node] = matvec(&nr.proj, &rs);
        }
    }

    /// Block-Jacobi preconditioner blocks in the constrained space, in place: a slave's
    /// block becomes P D P + (I - P) d, and each tie adds the slave's stiffness along its
    /// row to the master nodes (weighted by w^2), which the masters feel through T^T K T.
    pub fn precondition_blocks(&self, d: &mut [Mat3]) {
        for nr in self.nodes.iter() {
            let ds = d[nr.node];
            for row in &nr.rows {
                if row.masters.is_empty() {
                    continue;
                }
                let kc = dot(&row.dir, &matvec(&ds, &row.dir));
                for &(m, w) in &row.masters {
                    for i in 0..3 {
                        for j in 0..3 {
                            d[m][i][j] += w * w * kc * row.dir[i] * row.dir[j];
                        }
                    }
                }
            }
        }
        for nr in &self.nodes {
            let p = &nr.proj;
            let dn = d[nr.node];
            let pdp = crate::math::matmul(p, &crate::math::matmul(&dn, p));
            let s = (dn[0][0] + dn[1][1] + dn[2][2]).abs() / 3.0;
            let mut m = pdp;
            for i in 0..3 {
                for j in 0..3 {
                    m[i][j] += s * (IDENTITY[i][j] - p[i][j]);
                }
            }
            d[nr.node] = m;
        }
    }

    /// After inverting the blocks: z = P M^-1 P r on constrained nodes.
    pub fn project_inverse_blocks(&self, minv: &mut [Mat3]) {
        for nr in &self.nodes {
            let p = &nr.proj;
            minv[nr.node] = crate::math::matmul(p, &crate::math::matmul(&minv[nr.node], p));
        }
    }
}

/// Inverse of the leading k x k block (k <= 3) of a symmetric positive definite matrix.
fn invert_small(g: &Mat3, k: usize) -> Mat3 {
    let mut out = [[0.0; 3]; 3];
    match k {
        0 => {}
        1 => out[0][0] = 1.0 / g[0][0],
        2 => {
            let det = g[0][0] * g[1][1] - g[0][1] * g[1][0];
            out[0][0] = g[1][1] / det;
            out[1][1] = g[0][0] / det;
            out[0][1] = -g[0][1] / det;
            out[1][0] = -g[1][0] / det;
        }
        _ => out = crate::math::inverse(g).0,
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dirichlet(node: usize, dir: Vec3, value: f64, k: usize) -> RowSpec {
        RowSpec {
            node,
            row: Row {
                dir,
                value,
                masters: vec![],
                kind: RowKind::Dirichlet(k),
            },
        }
    }

    #[test]
    fn skew_and_component_conditions_meet_at_their_intersection() {
        // u_x = 0 and u . n = -0.1 with n at 20 degrees from y: the node must satisfy both.
        let phi = 20f64.to_radians();
        let n = [-phi.sin(), phi.cos(), 0.0];
        let c = Constraints::new(
            1,
            vec![
                dirichlet(0, [1.0, 0.0, 0.0], 0.0, 0),
                dirichlet(0, n, -0.1, 1),
            ],
        )
        .unwrap();
        let mut u = vec![[0.3, 0.2, 0.1]];
        c.impose(&mut u);
        assert!(u[0][0].abs() < 1e-15);
        assert!((dot(&u[0], &n) + 0.1).abs() < 1e-15);
        assert_eq!(u[0][2], 0.1);
    }

    #[test]
    fn reduce_is_the_transpose_of_expand() {
        // Node 2 tied along n to nodes 0 and 1 with weights 0.25/0.75, node 3 tied to node 2
        // (a chain), node 2 also has a skew Dirichlet row.
        let n = [0.6, 0.8, 0.0];
        let specs = vec![
            RowSpec {
                node: 3,
                row: Row {
                    dir: [0.0, 0.0, 1.0],
                    value: 0.0,
                    masters: vec![(2, 1.0)],
                    kind: RowKind::Contact {
                        constraint: 1,
                        component: 0,
                    },
                },
            },
            dirichlet(2, [1.0, 1.0, 0.0], 0.0, 0),
            RowSpec {
                node: 2,
                row: Row {
                    dir: n,
                    value: 0.0,
                    masters: vec![(0, 0.25), (1, 0.75)],
                    kind: RowKind::Contact {
                        constraint: 0,
                        component: 0,
                    },
                },
            },
        ];
        let c = Constraints::new(4, specs).unwrap();
        let v: Vec<Vec3> = vec![
            [0.1, -0.2, 0.3],
            [0.5, 0.4, -0.6],
            [0.7, 0.1, 0.2],
            [-0.3, 0.9, 0.8],
        ];
        let w: Vec<Vec3> = vec![
            [0.2, 0.3, -0.1],
            [-0.4, 0.6, 0.5],
            [0.9, -0.8, 0.7],
            [0.1, 0.2, -0.3],
        ];
        let mut tv = v.clone();
        c.expand(&mut tv);
        let mut ttw = w.clone();
        c.reduce(&mut ttw, None);
        let lhs: f64 = tv.iter().zip(&w).map(|(a, b)| dot(a, b)).sum();
        let rhs: f64 = v.iter().zip(&ttw).map(|(a, b)| dot(a, b)).sum();
        assert!((lhs - rhs).abs() < 1e-14, "{lhs} vs {rhs}");
        // The chain is resolved: node 3's z follows node 2's, which follows the masters, and
        // node 2 keeps its skew Dirichlet row. The rows (1,1,0)/sqrt(2) and (0.6,0.8,0) are
        // 8 degrees apart: the Gram system's condition number is about 200, so round-off is
        // bounded by about 200 eps |u| ~ 1e-13 |u|.
        let scale = tv.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
        let tol = 1e-13 * scale;
        assert!((tv[3][2] - tv[2][2]).abs() < tol);
        assert!((dot(&tv[2], &n) - (0.25 * dot(&tv[0], &n) + 0.75 * dot(&tv[1], &n))).abs() < tol);
        assert!((tv[2][0] + tv[2][1]).abs() < tol, "{:?}", tv[2]);
    }
}
