//! A sparse Cholesky factor for a coarse level that a V-cycle solves poorly but a direct
//! solve handles cheaply (a first coarse level of a thin, graded mesh: its aggregates are
//! small, the next level is much coarser, and a few sweeps leave most of the error).
//!
//! - Ordering: nested dissection of the level's node graph by breadth-first level sets
//!   (the middle level of a breadth-first search from a pseudo-peripheral node separates
//!   the rest; both sides are ordered first, the separator last), node by node with the
//!   node's unknowns together, then postordered on the elimination tree (the same fill,
//!   each chain of columns side by side for the supernodes). No coordinates, only the
//!   graph: any level of any mesh.
//! - Factor: by supernodes (`supernodal::Factor::dropping`, dense blocks). A pivot lost
//!   to cancellation (a mode the earlier ones span) or an unknown without stiffness drops
//!   out, as in the dense factor: its solution component is zero. The up-looking (row by
//!   row) factor on the elimination tree here is its reference in the tests, and counts
//!   the factor's entries without factoring (`analyse`).
//!
//! Everything is a fixed sequence of operations on data every rank holds alike: bitwise the
//! same factor and solves on every rank.

use super::aggregation::Graph;
use super::elimination::{etree, postorder, reach};
use super::sparse::{node_of, Csr};

/// Node sets at most this large are not dissected further.
const LEAF: usize = 32;

/// The factor: L column by column (rows below the diagonal, in increasing order), its
/// diagonal, and the permutation (`perm[k]` is the unknown eliminated k-th).
pub struct SparseCholesky {
    perm: Vec<usize>,
    colptr: Vec<usize>,
    rowidx: Vec<u32>,
    val: Vec<f64>,
    /// The diagonal of L; 0 for an unknown left out.
    diag: Vec<f64>,
    work: Vec<f64>,
}

/// The nested-dissection order of the nodes of a graph: METIS's (`METIS_NodeND`), or the
/// breadth-first one below where METIS fails.
fn dissection_order(g: &Graph) -> Vec<usize> {
    partition::nested_dissection(&g.ptr, &g.adj).unwrap_or_else(|| level_set_order(g))
}

/// The nested-dissection order of the nodes of a graph by breadth-first level sets.
fn level_set_order(g: &Graph) -> Vec<usize> {
    let n = g.len();
    let mut order = Vec::with_capacity(n);
    let mut mark = vec![u32::MAX; n];
    let mut level = vec![0u32; n];
    // Sets to order, processed last-in first-out (its members carry the set's tag in `mark`
    // while it is split); every set is written out as its separator after its parts, so a
    // set's output is reserved up front: (nodes, slot in `out` where its block starts).
    let mut out = vec![usize::MAX; n];
    let mut stack: Vec<(Vec<usize>, usize)> = vec![((0..n).collect(), 0)];
    let mut tag = 0u32;
    while let Some((set, start)) = stack.pop() {
        if set.len() <= LEAF {
            for (k, &i) in set.iter().enumerate() {
                out[start + k] = i;
            }
            continue;
        }
        tag += 1;
        for &i in &set {
            mark[i] = tag;
        }
        // A breadth-first search within the set from its first node, then again from the
        // last node reached (a pseudo-peripheral node).
        let bfs = |from: usize, level: &mut [u32]| -> Vec<usize> {
            let mut seen = vec![from];
            level[from] = 0;
            let mut head = 0;
            let mut visited = std::collections::HashSet::new();
            visited.insert(from);
            while head < seen.len() {
                let i = seen[head];
                head += 1;
                for &j in g.neighbours(i) {
                    let j = j as usize;
                    if mark[j] == tag && visited.insert(j) {
                        level[j] = level[i] + 1;
                        seen.push(j);
                    }
                }
            }
            seen
        };
        let first = bfs(set[0], &mut level);
        if first.len() < set.len() {
            // Disconnected: the reached component and the rest are ordered separately.
            let reached: std::collections::HashSet<usize> = first.iter().copied().collect();
            let rest: Vec<usize> = set
                .iter()
                .copied()
                .filter(|i| !reached.contains(i))
                .collect();
            let mut comp = first;
            comp.sort_unstable();
            let len = comp.len();
            stack.push((comp, start));
            stack.push((rest, start + len));
            continue;
        }
        let far = *first.last().expect("a non-empty set");
        let seen = bfs(far, &mut level);
        let middle = level[seen[seen.len() / 2]];
        let (mut a, mut b, mut s) = (Vec::new(), Vec::new(), Vec::new());
        for &i in &set {
            match level[i].cmp(&middle) {
                std::cmp::Ordering::Less => a.push(i),
                std::cmp::Ordering::Greater => b.push(i),
                std::cmp::Ordering::Equal => s.push(i),
            }
        }
        if a.is_empty() || b.is_empty() {
            // No separation (a dense cluster): keep the set's order.
            for (k, &i) in set.iter().enumerate() {
                out[start + k] = i;
            }
            continue;
        }
        let (la, lb) = (a.len(), b.len());
        for (k, &i) in s.iter().enumerate() {
            out[start + la + lb + k] = i;
        }
        stack.push((a, start));
        stack.push((b, start + la));
    }
    order.extend(out);
    order
}

impl SparseCholesky {
    /// The node graph of `a` (unknowns grouped by `node_ptr`), ordered by nested
    /// dissection, and the number of entries of each column of L below its diagonal,
    /// without factoring; None as soon as L would hold more than `budget` entries.
    pub fn analyse(a: &Csr, node_ptr: &[usize], budget: usize) -> Option<(Vec<usize>, Vec<usize>)> {
        let nodes = node_ptr.len() - 1;
        let node_of = node_of(node_ptr);
        let mut edges = Vec::new();
        for p in 0..a.rows {
            for &q in a.row(p).0 {
                let (i, j) = (node_of[p], node_of[q as usize]);
                if i < j {
                    edges.push((i, j));
                }
            }
        }
        let g = Graph::from_edges(nodes, &edges);
        let mut dissected = Vec::with_capacity(a.rows);
        for i in dissection_order(&g) {
            dissected.extend(node_ptr[i]..node_ptr[i + 1]);
        }
        // Postordered (`elimination::postorder`): the same fill, wider supernodes.
        let mut inv = vec![0usize; a.rows];
        for (k, &i) in dissected.iter().enumerate() {
            inv[i] = k;
        }
        let parent = etree(a, &dissected, &inv);
        let perm: Vec<usize> = postorder(&parent)
            .into_iter()
            .map(|k| dissected[k])
            .collect();
        let counts = column_counts(a, &perm, budget)?;
        Some((perm, counts))
    }

    /// The entries below the diagonal of the factor of a matrix with one unknown per node
    /// of `g` and its pattern (every node coupled to itself and its neighbours), in this
    /// factor's nested-dissection order, without factoring (what `analyse` would count for
    /// a matrix of 1 x 1 node blocks), and the sum of the squares of its column counts (the
    /// factorization's work, up to a constant). None as soon as the entries exceed
    /// `budget`.
    pub fn graph_factor_entries(g: &Graph, budget: usize) -> Option<(usize, f64)> {
        let a = pattern(g);
        let perm = dissection_order(g);
        column_counts(&a, &perm, budget).map(|c| {
            let flops = c.iter().map(|&k| (k * k) as f64).sum();
            (c.iter().sum(), flops)
        })
    }

    /// Factors `a` in the order `perm` (from `analyse`, with its column counts), column by
    /// column: the reference of `supernodal::Factor::dropping`, which the coarse levels use.
    #[cfg(test)]
    pub(super) fn new(a: &Csr, perm: Vec<usize>, counts: &[usize]) -> Self {
        Self::factor(a, perm, counts, None)
    }

    /// `new`, except that a pivot below `floor` times its diagonal entry is raised to that
    /// (never dropped), column by column: the reference of `supernodal::Factor`, which the
    /// full tangent uses.
    #[cfg(test)]
    pub(super) fn column_modified(a: &Csr, perm: Vec<usize>, counts: &[usize], floor: f64) -> Self {
        Self::factor(a, perm, counts, Some(floor))
    }

    #[cfg(test)]
    fn factor(a: &Csr, perm: Vec<usize>, counts: &[usize], floor: Option<f64>) -> Self {
        let n = a.rows;
        let mut inv = vec![0usize; n];
        for (k, &i) in perm.iter().enumerate() {
            inv[i] = k;
        }
        let parent = etree(a, &perm, &inv);
        let mut colptr = vec![0usize; n + 1];
        for k in 0..n {
            colptr[k + 1] = colptr[k] + counts[k];
        }
        let mut rowidx = vec![0u32; colptr[n]];
        let mut val = vec![0.0; colptr[n]];
        let mut fill = colptr.clone();
        let mut diag = vec![0.0; n];
        let scale = a.diagonal().iter().fold(0.0f64, |m, d| m.max(d.abs()));
        let mut x = vec![0.0; n];
        let mut flag = vec![usize::MAX; n];
        let mut stack = Vec::new();
        let mut pattern = Vec::new();
        for k in 0..n {
            // Row k of L: solve L[0..k, 0..k] y = A[0..k, k] on the pattern reached
            // through the elimination tree.
            reach(
                a,
                &perm,
                &inv,
                &parent,
                k,
                &mut flag,
                &mut stack,
                &mut pattern,
            );
            let (c, v) = a.row(perm[k]);
            let mut akk = 0.0;
            for (&q, &w) in c.iter().zip(v) {
                let j = inv[q as usize];
                if j < k {
                    x[j] = w;
                } else if j == k {
                    akk = w;
                }
            }
            let mut d = akk;
            for &j in &pattern {
                let xj = x[j];
                x[j] = 0.0;
                if diag[j] == 0.0 {
                    continue;
                }
                let y = xj / diag[j];
                for p in colptr[j]..fill[j] {
                    x[rowidx[p] as usize] -= val[p] * y;
                }
                d -= y * y;
                rowidx[fill[j]] = k as u32;
                val[fill[j]] = y;
                fill[j] += 1;
            }
            diag[k] = match floor {
                Some(f) => d.max(f * akk.abs().max(1e-14 * scale)).sqrt(),
                None if d > 1e-10 * akk && akk > 1e-14 * scale => d.sqrt(),
                None => 0.0,
            };
        }
        // Columns of dropped pivots or entries of dropped rows were not written: close
        // the gaps so every column is contiguous.
        let mut w = 0;
        let mut ptr = vec![0usize; n + 1];
        for j in 0..n {
            for p in colptr[j]..fill[j] {
                rowidx[w] = rowidx[p];
                val[w] = val[p];
                w += 1;
            }
            ptr[j + 1] = w;
        }
        rowidx.truncate(w);
        val.truncate(w);
        SparseCholesky {
            perm,
            colptr: ptr,
            rowidx,
            val,
            diag,
            work: vec![0.0; n],
        }
    }

    /// Entries stored below the diagonal.
    pub fn nnz(&self) -> usize {
        self.val.len()
    }

    /// The permuted `x` into the work vector, then the forward substitution L y = P x
    /// there (column by column: each entry's updates in the order of the columns).
    fn forward(&mut self, x: &[f64]) {
        let n = self.diag.len();
        let y = &mut self.work;
        for k in 0..n {
            y[k] = x[self.perm[k]];
        }
        for j in 0..n {
            if self.diag[j] == 0.0 {
                y[j] = 0.0;
                continue;
            }
            y[j] /= self.diag[j];
            let yj = y[j];
            let (a, b) = (self.colptr[j], self.colptr[j + 1]);
            for (&r, &v) in self.rowidx[a..b].iter().zip(&self.val[a..b]) {
                y[r as usize] -= v * yj;
            }
        }
    }

    /// x <- A^-1 x (zero on the unknowns left out).
    pub fn solve(&mut self, x: &mut [f64]) {
        let n = self.diag.len();
        self.forward(x);
        let y = &mut self.work;
        for j in (0..n).rev() {
            if self.diag[j] == 0.0 {
                y[j] = 0.0;
                continue;
            }
            let mut s = y[j];
            for p in self.colptr[j]..self.colptr[j + 1] {
                s -= self.val[p] * y[self.rowidx[p] as usize];
            }
            y[j] = s / self.diag[j];
        }
        for k in 0..n {
            x[self.perm[k]] = y[k];
        }
    }
}

/// The matrix of a graph's pattern: every node coupled to itself and its neighbours (ones).
fn pattern(g: &Graph) -> Csr {
    let n = g.len();
    let mut t = Vec::new();
    for i in 0..n {
        t.push((i as u32, i as u32, 1.0));
        t.extend(g.neighbours(i).iter().map(|&j| (i as u32, j, 1.0)));
    }
    Csr::from_triplets(n, n, t)
}

/// Entries below the diagonal in each column of L (its row patterns by `reach`); None once
/// their total passes `budget`.
fn column_counts(a: &Csr, perm: &[usize], budget: usize) -> Option<Vec<usize>> {
    let n = a.rows;
    let mut inv = vec![0usize; n];
    for (k, &i) in perm.iter().enumerate() {
        inv[i] = k;
    }
    let parent = etree(a, perm, &inv);
    let mut counts = vec![0usize; n];
    let mut total = 0;
    let (mut flag, mut stack, mut pattern) = (vec![usize::MAX; n], Vec::new(), Vec::new());
    for k in 0..n {
        reach(
            a,
            perm,
            &inv,
            &parent,
            k,
            &mut flag,
            &mut stack,
            &mut pattern,
        );
        for &j in &pattern {
            counts[j] += 1;
        }
        total += pattern.len();
        if total > budget {
            return None;
        }
    }
    Some(counts)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::precond::multilevel::smoother::hash_value;

    #[test]
    fn metis_orders_a_grid_with_less_fill_than_level_sets() {
        // The node graph of a 16^3 hexahedral grid (27-point neighbourhoods): the factor's
        // entries below the diagonal in METIS's nested-dissection order against the level
        // sets' (measured 0.49 against 0.94 million; on the Hertz example x4's first
        // coarse level 2.36 against 4.74 million). METIS must not do worse: the coarse
        // levels and the full tangent take its order for that.
        let m = 16;
        let id = |i: usize, j: usize, k: usize| (i + m * (j + m * k)) as u32;
        let mut edges = Vec::new();
        for k in 0..m {
            for j in 0..m {
                for i in 0..m {
                    // Every node within one cell in each axis (i + a - 1 for a in 0..3).
                    for c in 0..27 {
                        let (a, b, d) = (c % 3, (c / 3) % 3, c / 9);
                        let (x, y, z) = (i + a, j + b, k + d);
                        if c != 13
                            && (1..=m).contains(&x)
                            && (1..=m).contains(&y)
                            && (1..=m).contains(&z)
                        {
                            edges.push((id(i, j, k), id(x - 1, y - 1, z - 1)));
                        }
                    }
                }
            }
        }
        let g = Graph::from_edges(m * m * m, &edges);
        let count = |perm: Vec<usize>| {
            column_counts(&pattern(&g), &perm, usize::MAX)
                .unwrap()
                .iter()
                .sum::<usize>()
        };
        let (metis, levels) = (count(dissection_order(&g)), count(level_set_order(&g)));
        assert!(metis <= levels, "METIS {metis} against level sets {levels}");
    }

    #[test]
    fn solves_a_grid_laplacian_and_drops_a_dead_unknown() {
        // The 2-D 5-point Laplacian on a 20 x 20 grid with Dirichlet boundary (condition
        // number about 200), two unknowns per node (the second one of node 7 without
        // stiffness): the solution comes back to 1e-12 and the dead unknown is 0.
        let m = 20;
        let id = |i: usize, j: usize| i + m * j;
        let mut t = Vec::new();
        for j in 0..m {
            for i in 0..m {
                for c in 0..2u32 {
                    let a = 2 * id(i, j) as u32 + c;
                    if id(i, j) == 7 && c == 1 {
                        continue;
                    }
                    t.push((a, a, 4.0));
                    for (x, y) in [(i + 1, j), (i, j + 1)] {
                        if x < m && y < m && !(id(x, y) == 7 && c == 1) {
                            let b = 2 * id(x, y) as u32 + c;
                            t.push((a, b, -1.0));
                            t.push((b, a, -1.0));
                        }
                    }
                }
            }
        }
        let n = 2 * m * m;
        let a = Csr::from_triplets(n, n, t);
        let node_ptr: Vec<usize> = (0..=m * m).map(|i| 2 * i).collect();
        assert!(SparseCholesky::analyse(&a, &node_ptr, 1000).is_none());
        let (perm, counts) = SparseCholesky::analyse(&a, &node_ptr, usize::MAX).expect("in budget");
        let mut sorted = perm.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..n).collect::<Vec<_>>());
        let mut f = SparseCholesky::new(&a, perm, &counts);
        let x_true: Vec<f64> = (0..n)
            .map(|i| if i == 15 { 0.0 } else { hash_value(i as u64) })
            .collect();
        let mut x = vec![0.0; n];
        a.mul_into(&x_true, &mut x);
        f.solve(&mut x);
        for i in 0..n {
            assert!(
                (x[i] - x_true[i]).abs() < 1e-12,
                "{i}: {} vs {}",
                x[i],
                x_true[i]
            );
        }
        // Nested dissection keeps the fill well below the dense triangle (79800 entries).
        assert!(f.nnz() < 20000, "{}", f.nnz());
    }
}
