//! The elimination tree and the row patterns of a sparse Cholesky factor, which both
//! factorisations (`sparse_cholesky`, column by column, and `supernodal`) use.

use super::sparse::Csr;

/// The elimination tree of P A P^T (parent of each column, usize::MAX at a root), by
/// Liu's algorithm with path compression.
pub(super) fn etree(a: &Csr, perm: &[usize], inv: &[usize]) -> Vec<usize> {
    let n = a.rows;
    let mut parent = vec![usize::MAX; n];
    let mut ancestor = vec![usize::MAX; n];
    for k in 0..n {
        for &q in a.row(perm[k]).0 {
            let mut i = inv[q as usize];
            while i < k {
                let next = ancestor[i];
                ancestor[i] = k;
                if next == usize::MAX {
                    parent[i] = k;
                    break;
                }
                i = next;
            }
        }
    }
    parent
}

/// A postorder of the elimination tree `parent`: every column after its descendants, each
/// subtree's columns together (roots and children taken in increasing order). Renumbering
/// the columns by it keeps the factor's fill and entries as they are (every column keeps
/// its ancestors after it), but puts each chain of the tree's columns side by side, where a
/// supernode can hold them: the unknowns of a node that decouple into groups (in-plane and
/// out-of-plane ones on a plane-strain slab) otherwise alternate and break every chain.
/// `post[k]` is the column placed k-th.
pub(super) fn postorder(parent: &[usize]) -> Vec<usize> {
    let n = parent.len();
    // Children lists, each in increasing order (columns visited in increasing order).
    let mut head = vec![usize::MAX; n];
    let mut next = vec![usize::MAX; n];
    for j in (0..n).rev() {
        let p = parent[j];
        if p != usize::MAX {
            next[j] = head[p];
            head[p] = j;
        }
    }
    let mut post = Vec::with_capacity(n);
    let mut stack = Vec::new();
    for root in (0..n).filter(|&j| parent[j] == usize::MAX) {
        stack.push(root);
        while let Some(&j) = stack.last() {
            let c = head[j];
            if c == usize::MAX {
                post.push(j);
                stack.pop();
            } else {
                // The first child not yet visited: unlinked, then descended into.
                head[j] = next[c];
                stack.push(c);
            }
        }
    }
    post
}

/// The columns j < k of row k of L in topological order (each column before the columns
/// its updates reach): the union of the tree paths from the entries of A's row k to k.
#[allow(clippy::too_many_arguments)]
pub(super) fn reach(
    a: &Csr,
    perm: &[usize],
    inv: &[usize],
    parent: &[usize],
    k: usize,
    flag: &mut [usize],
    stack: &mut Vec<usize>,
    pattern: &mut Vec<usize>,
) {
    pattern.clear();
    flag[k] = k;
    for &q in a.row(perm[k]).0 {
        let mut i = inv[q as usize];
        if i > k {
            continue;
        }
        stack.clear();
        while flag[i] != k {
            stack.push(i);
            flag[i] = k;
            i = parent[i];
        }
        // The path from the entry up to the first column already in the pattern, pushed
        // so the column nearest the leaf comes first once reversed below.
        pattern.extend(stack.iter().rev());
    }
    // Paths were appended root-side first; a column must come before its ancestors.
    pattern.sort_unstable();
}
