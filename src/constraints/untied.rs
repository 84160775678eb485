//! Nodes held by rows without master terms (prescribed displacements only: a support, a
//! symmetry plane, the plane-strain direction of every node of a slab) packed for the
//! loops that run in every CG iteration. A constrained node's rows live on the heap, each
//! with its own lists of masters and force slots: reading them costs a few cache misses
//! per node, which on a plane-strain mesh (every node held along z) took 19% of a run.
//! Here each such node is 20 bytes (its node, its rows' first multiplier, the forces it
//! receives) and a shape: its rows' directions, values, Gram inverse and projector, one
//! copy shared by every node with the same bits. The arithmetic is the general path's,
//! operation for operation: the same bits.

use super::rows::NodeRows;
use crate::math::{dot, matvec, Mat3, Vec3};
use std::collections::HashMap;

/// One node held by rows without masters.
pub(super) struct Untied {
    pub(super) node: u32,
    pub(super) shape: u32,
    /// Its first row's index in the flat multiplier array.
    pub(super) first: u32,
    /// The slots of the forces it receives (a range of `Constraints::incoming`).
    pub(super) incoming: [u32; 2],
}

/// Rows without masters as the loops read them.
pub(super) struct Shape {
    pub(super) k: usize,
    pub(super) dirs: [Vec3; 3],
    pub(super) ginv: Mat3,
    pub(super) proj: Mat3,
    /// The row forces of the rows' values, G^-1 b, and of zero values.
    pub(super) l_values: Vec3,
    pub(super) l_zero: Vec3,
}

/// The nodes of `nodes` (the first dependency level, `level0`) whose rows have no masters,
/// packed with their shapes, and the indices of the others in order.
pub(super) fn split(
    nodes: &[NodeRows],
    level0: std::ops::Range<usize>,
) -> (Vec<Untied>, Vec<Shape>, Vec<u32>) {
    let (mut untied, mut shapes, mut tied) = (Vec::new(), Vec::new(), Vec::new());
    let mut known: HashMap<Vec<u64>, u32> = HashMap::new();
    for s in level0 {
        let nr = &nodes[s];
        let fits = u32::try_from(nr.node).is_ok()
            && u32::try_from(nr.first).is_ok()
            && u32::try_from(nr.incoming.end).is_ok();
        if !fits || nr.rows.iter().any(|r| !r.masters.is_empty()) {
            tied.push(s as u32);
            continue;
        }
        let k = nr.rows.len();
        let mut dirs = [[0.0; 3]; 3];
        let mut values = [0.0; 3];
        for (i, row) in nr.rows.iter().enumerate() {
            dirs[i] = row.dir;
            values[i] = row.value;
        }
        let shape = Shape {
            k,
            dirs,
            ginv: nr.ginv,
            proj: nr.proj,
            l_values: matvec(&nr.ginv, &values),
            l_zero: matvec(&nr.ginv, &[0.0; 3]),
        };
        let key: Vec<u64> = std::iter::once(k as u64)
            .chain(dirs.iter().flatten().map(|v| v.to_bits()))
            .chain(values.iter().map(|v| v.to_bits()))
            .chain(nr.ginv.iter().flatten().map(|v| v.to_bits()))
            .chain(nr.proj.iter().flatten().map(|v| v.to_bits()))
            .collect();
        let next = shapes.len() as u32;
        let id = *known.entry(key).or_insert(next);
        if id == next {
            shapes.push(shape);
        }
        untied.push(Untied {
            node: nr.node as u32,
            shape: id,
            first: nr.first as u32,
            incoming: [nr.incoming.start as u32, nr.incoming.end as u32],
        });
    }
    (untied, shapes, tied)
}

/// u <- T u + g on the packed nodes (`Constraints::apply`'s arithmetic: b = the values or
/// zero, l = G^-1 b, u = P u + sum_i l_i c_i).
pub(super) fn apply(untied: &[Untied], shapes: &[Shape], u: &mut [Vec3], with_values: bool) {
    for un in untied {
        let sh = &shapes[un.shape as usize];
        let l = if with_values {
            &sh.l_values
        } else {
            &sh.l_zero
        };
        let node = un.node as usize;
        let mut x = matvec(&sh.proj, &u[node]);
        for i in 0..sh.k {
            for d in 0..3 {
                x[d] += l[i] * sh.dirs[i][d];
            }
        }
        u[node] = x;
    }
}

/// r <- T^T r on the packed nodes (`Constraints::reduce`'s arithmetic: the forces received
/// added in order, the row forces G^-1 C r written to `multipliers` negated, r = P r).
pub(super) fn reduce(
    (untied, shapes): (&[Untied], &[Shape]),
    incoming: &[u32],
    force: &[Vec3],
    r: &mut [Vec3],
    mut multipliers: Option<&mut [f64]>,
) {
    for un in untied {
        let sh = &shapes[un.shape as usize];
        let node = un.node as usize;
        for &k in &incoming[un.incoming[0] as usize..un.incoming[1] as usize] {
            let f = force[k as usize];
            for d in 0..3 {
                r[node][d] += f[d];
            }
        }
        let rs = r[node];
        if let Some(out) = multipliers.as_deref_mut() {
            let mut c = [0.0; 3];
            for i in 0..sh.k {
                c[i] = dot(&sh.dirs[i], &rs);
            }
            let mu = matvec(&sh.ginv, &c);
            for i in 0..sh.k {
                out[un.first as usize + i] = -mu[i];
            }
        }
        r[node] = matvec(&sh.proj, &rs);
    }
}
