//! Whether the first coarse level's sparse factor is formed once its V-cycle is slow
//! (`cycle::Hierarchy::finish`), and what the memory estimate predicts of it (`size`):
//! both from the level's node graph (a node's unknowns are its aggregate's modes, a pair
//! of nodes a block of the operator), counted before the level is gathered whole.

use super::aggregation::Graph;
use super::op::Op;
use super::sparse::{node_of, Csr};
use super::sparse_cholesky::SparseCholesky;
use std::ops::Range;

/// The fill budget of that factor, in entries of the level's operator: a solve with L costs
/// about 4 nnz(L) flops, the V-cycles it replace sweeps x (2 degree + 1) - 1 level products
/// of 2 nnz(A) flops (18 nnz(A) with the defaults), so a factor at the budget costs up to
/// twice as much per application; it replaces only a V-cycle too slow to serve (Hertz x2
/// and x4: 3.1-4.4, and far fewer CG iterations: `cycle::SLOW_RATE`).
pub const FILL: usize = 8;
/// The work of that factorization allowed, in entries of the level's operator: the sum
/// over L's columns of their entries below the diagonal squared (the column's updates,
/// up to a constant) at most this times nnz(A). A V-cycle on the level costs about
/// 18 nnz(A) flops (`FILL`), so this is the work of 30 V-cycles: a model problem
/// the preconditioner serves well takes 30 to 90 CG iterations (the generated blocks),
/// and a factorization dearer than that is paid back only by saving more of them than
/// such a problem has, which is not known at the build. Measured with and without the
/// factor (work / nnz(A) counted on the level's unknowns, and what the factor did to the
/// run; `fit`'s count on the node graph, which decides, is within 4% of it: 33, 43 and
/// 169 V-cycles for the plate, the first L-bracket and the cantilever against 34, 43, 176):
/// the Hertz example x1, x2 and tetrahedral 87-96, 209-219, 165-190 (x2: 768 -> 495 CG
/// iterations, 3.9 s -> 2.1 s; the others within 4%); the bracket example and x2 94 and
/// 302-315 (9.3 -> 8.4 s, 83.5 -> 68.1 s); a J2 Gmsh L-bracket of 10-node tetrahedra 495
/// (25.2 -> 22.7 s). Where it did not pay: the Gmsh plate with a hole 607 (1.78 -> 1.90 s,
/// 61.0 -> 79.6 MiB); Gmsh L-brackets of hexahedra 779 and 1486 and of 10-node tetrahedra
/// 856 (29 to 42 CG iterations either way; 1.61 -> 1.67 s, 3.97 -> 4.19 s, 3.66 ->
/// 4.13 s); a cantilever of 1 x 0.25 x 0.25 elements 3161 (a V-cycle rate of 0.86: 34 ->
/// 30 CG iterations, 1.19 -> 3.25 s, 82 -> 275 MiB).
pub const FACTOR_WORK: f64 = 540.0;

/// What the node graph says of the factor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Fit {
    /// It is formed: about this many entries (diagonal blocks included).
    Fits { entries: u64 },
    /// Its entries would exceed `FILL` times the operator's.
    TooFull,
    /// Its work would exceed `FACTOR_WORK`: that of this many V-cycles on the level.
    TooDear { cycles: f64 },
}

/// The factor of a level whose node graph is `g`, with `pairs` node pairs (k sees j, k = j
/// included: the blocks of its pattern) and `entries` entries, s^2 = entries / pairs a
/// block on average: a node column of k nodes below the diagonal is s columns of about
/// s k entries, its work s^3 k^2 (`SparseCholesky::graph_factor_entries` counts k and
/// k^2 in the order the factor takes).
pub fn fit(g: &Graph, pairs: usize, entries: f64) -> Fit {
    if pairs == 0 {
        return Fit::TooFull;
    }
    let nodes = g.ptr.len() - 1;
    let per_block = entries / pairs as f64;
    match SparseCholesky::graph_factor_entries(g, FILL * pairs) {
        None => Fit::TooFull,
        Some((below, work)) => {
            let work = per_block.powf(1.5) * work;
            if work > FACTOR_WORK * entries {
                Fit::TooDear {
                    cycles: work / (18.0 * entries),
                }
            } else {
                Fit::Fits {
                    entries: ((below + nodes) as f64 * per_block).round() as u64,
                }
            }
        }
    }
}

/// `fit` for the first coarse level `op` (`whole_op`: its operator whole, where the build
/// kept it), its unknowns grouped by `node_ptr`, this rank holding `rows` of it: the node
/// pattern, gathered by `gather` where the rows are split (a value a block: not the level's
/// entries, which only a factor that fits gathers).
pub fn level_fit(
    whole_op: Option<&Csr>,
    op: &Op,
    node_ptr: &[usize],
    rows: Range<usize>,
    gather: impl Fn(Csr) -> Csr,
) -> Fit {
    let pattern = match (whole_op, op) {
        (Some(a), _) | (None, Op::Sparse(a)) => node_pattern(a.rows, 0, node_ptr, |r, c| {
            c.clear();
            c.extend_from_slice(a.row(r).0)
        }),
        (None, Op::Rows(held)) => {
            let mut vals = Vec::new();
            gather(node_pattern(rows.len(), rows.start, node_ptr, |r, c| {
                held.row_into(r, c, &mut vals)
            }))
        }
    };
    let entries = pattern.val.iter().sum();
    fit(&graph_of(&pattern), pattern.nnz(), entries)
}

/// The node pattern of the rows `first..first + rows` of a level whose unknowns
/// `node_ptr` groups into nodes (the rows are whole nodes; those past the level's last
/// are none), `row(r, cols)` giving row r's
/// columns: a row per node, its columns the nodes it is coupled to, each value the
/// entries of that block.
pub fn node_pattern(
    rows: usize,
    first: usize,
    node_ptr: &[usize],
    mut row: impl FnMut(usize, &mut Vec<u32>),
) -> Csr {
    let node_of = node_of(node_ptr);
    let mut out = Csr::empty(node_ptr.len() - 1);
    let (mut cols, mut reach) = (Vec::new(), Vec::new());
    // The last rank's rows may run past the level's.
    let last = (first + rows).min(node_of.len());
    let mut r = first;
    while r < last {
        let end = node_ptr[node_of[r] as usize + 1].min(last);
        reach.clear();
        for q in r..end {
            row(q, &mut cols);
            reach.extend(cols.iter().map(|&c| node_of[c as usize]));
        }
        reach.sort_unstable();
        for (k, &j) in reach.iter().enumerate() {
            if k > 0 && reach[k - 1] == j {
                *out.val.last_mut().expect("a block begun") += 1.0;
            } else {
                out.idx.push(j);
                out.val.push(1.0);
            }
        }
        out.end_row();
        r = end;
    }
    out
}

/// The graph of a node pattern (`node_pattern`, whole).
pub fn graph_of(pattern: &Csr) -> Graph {
    let mut edges = Vec::with_capacity(pattern.nnz() / 2);
    for i in 0..pattern.rows {
        for &j in pattern.row(i).0 {
            if (i as u32) < j {
                edges.push((i as u32, j));
            }
        }
    }
    Graph::from_edges(pattern.ptr.len() - 1, &edges)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two nodes of two unknowns each, fully coupled: one block pair each way, four
    /// entries a block.
    #[test]
    fn the_node_pattern_counts_each_blocks_entries() {
        let t = (0..4u32)
            .flat_map(|i| (0..4u32).map(move |j| (i, j, 1.0)))
            .collect();
        let a = Csr::from_triplets(4, 4, t);
        let of = |r: usize, c: &mut Vec<u32>| *c = a.row(r).0.to_vec();
        let p = node_pattern(4, 0, &[0, 2, 4], of);
        assert_eq!(p.rows, 2);
        assert_eq!(p.nnz(), 4);
        assert_eq!(p.val, vec![4.0; 4]);
        // The second node's rows alone, as a rank holding only them gives them.
        let q = node_pattern(2, 2, &[0, 2, 4], of);
        assert_eq!((q.rows, q.nnz()), (1, 2));
        assert_eq!(q.row(0).0, &[0, 1]);
    }

    /// The nodes of an nx x ny x nz grid, each coupled to its 26 neighbours (a level of
    /// aggregates of a 3-D mesh), and the pairs of its pattern.
    fn grid(nx: i64, ny: i64, nz: i64) -> (Graph, usize) {
        let id = |x: i64, y: i64, z: i64| (x + nx * (y + ny * z)) as u32;
        let mut edges = Vec::new();
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    for (dx, dy, dz) in (0..27).map(|k| (k % 3 - 1, k / 3 % 3 - 1, k / 9 - 1)) {
                        let (u, v, w) = (x + dx, y + dy, z + dz);
                        if (0..nx).contains(&u) && (0..ny).contains(&v) && (0..nz).contains(&w) {
                            edges.push((id(x, y, z), id(u, v, w)));
                        }
                    }
                }
            }
        }
        let g = Graph::from_edges((nx * ny * nz) as usize, &edges);
        let pairs = g.adj.len() + g.ptr.len() - 1;
        (g, pairs)
    }

    /// The work grows faster on a 3-D level than on a thin one: a cube of 10^3 aggregates
    /// costs 87 V-cycles to factor, more than `FACTOR_WORK`'s 30, a slab of 40 x 40 x 1
    /// (1600 aggregates) less; a cube of 6^3 fits. Full 6 x 6 blocks.
    #[test]
    fn a_cube_of_aggregates_is_too_dear_and_a_slab_is_not() {
        let fits = |(g, pairs): (Graph, usize)| fit(&g, pairs, 36.0 * pairs as f64);
        match fits(grid(10, 10, 10)) {
            Fit::TooDear { cycles } => assert!(cycles > 30.0, "{cycles}"),
            other => panic!("cube: {other:?}"),
        }
        assert!(matches!(fits(grid(40, 40, 1)), Fit::Fits { .. }));
        assert!(matches!(fits(grid(6, 6, 6)), Fit::Fits { .. }));
    }

    /// A path of nodes factors without fill: its entries are the pattern's lower half
    /// and diagonal, and its work is small, so it fits.
    #[test]
    fn a_path_fits_and_counts_its_entries() {
        let n = 50u32;
        let edges: Vec<(u32, u32)> = (1..n).map(|i| (i - 1, i)).collect();
        let g = Graph::from_edges(n as usize, &edges);
        let pairs = n as usize + 2 * (n as usize - 1);
        let fit = fit(&g, pairs, 36.0 * pairs as f64);
        // Nested dissection of a path: each separator node's column reaches at most
        // its two neighbours' separators, so L has at most 2 n blocks below.
        match fit {
            Fit::Fits { entries } => assert!(
                (36 * n as u64..=36 * 3 * n as u64).contains(&entries),
                "{entries}"
            ),
            other => panic!("{other:?}"),
        }
    }
}
