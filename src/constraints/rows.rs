//! The rows of a constraint set and what it keeps per constrained node and per level of
//! dependency: the types that the set (mod.rs) and its building phases (build.rs) share.

use crate::comm::ExchangePlan;
use crate::math::{Mat3, Vec3};
use std::ops::Range;

/// Chains of constrained nodes deeper than this are circular dependencies.
pub(super) const MAX_DEPTH: usize = 64;

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
    /// Master nodes (global ids, on any rank) and weights.
    pub masters: Vec<(u32, f64)>,
    pub kind: RowKind,
}

/// A row as given, before the independent subset is chosen.
pub struct RowSpec {
    /// Local index of the constrained node; it must be owned by this rank.
    pub node: usize,
    pub row: Row,
}

/// Where a master value lives: an owned local node or a slot of the fetched values.
#[derive(Clone, Copy, Debug)]
pub(super) enum Src {
    Local(u32),
    Remote(u32),
}

pub(super) struct NodeRows {
    pub(super) node: usize,
    pub(super) global: u32,
    pub(super) rows: Vec<Row>,
    /// Per row, per master: where its value is.
    pub(super) refs: Vec<Vec<Src>>,
    /// Per row, per master: the slot of the force this tie passes to the master.
    pub(super) out: Vec<Vec<u32>>,
    /// Slots of the forces this node receives, in key order (a range of `incoming`).
    pub(super) incoming: Range<usize>,
    /// Inverse of the Gram matrix of the kept rows (leading k x k block).
    pub(super) ginv: Mat3,
    pub(super) proj: Mat3,
    /// Index of the node's first row in the flat multiplier array.
    pub(super) first: usize,
}

pub(super) struct Level {
    /// Range of `Constraints::nodes`.
    pub(super) nodes: Range<usize>,
    /// Master values this level reads from other ranks.
    pub(super) fetch: ExchangePlan,
    /// Forces this level's ties pass to masters on other ranks.
    pub(super) push: ExchangePlan,
}

/// A circular master/slave dependency between constrained nodes (a global node id).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CircularDependency(pub u32);

/// Inverse of the leading k x k block (k <= 3) of a symmetric positive definite matrix.
pub(super) fn invert_small(g: &Mat3, k: usize) -> Mat3 {
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
