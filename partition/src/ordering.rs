//! A fill-reducing order of a graph's vertices by METIS's nested dissection
//! (`METIS_NodeND`), for the sparse Cholesky factors of the solver's preconditioners.
//! METIS is deterministic for the same graph and options (its default seed): every rank
//! that orders the same graph gets the same order.

use crate::metis_lock::{METIS_LOCK, METIS_SEED};
use metis_sys as m;

/// The vertices of the graph (`xadj`/`adjncy`: each vertex's neighbours, without itself,
/// every edge in both directions) in METIS's nested-dissection order: `order[k]` is the
/// vertex eliminated k-th. None when METIS fails (out of memory) or the graph does not fit
/// its 32-bit indices.
pub fn nested_dissection(xadj: &[usize], adjncy: &[u32]) -> Option<Vec<usize>> {
    let n = xadj.len().checked_sub(1)?;
    if n == 0 {
        return Some(Vec::new());
    }
    let mut nvtxs = m::idx_t::try_from(n).ok()?;
    let mut x: Vec<m::idx_t> = xadj
        .iter()
        .map(|&v| m::idx_t::try_from(v).ok())
        .collect::<Option<_>>()?;
    let mut adj: Vec<m::idx_t> = adjncy
        .iter()
        .map(|&v| m::idx_t::try_from(v).ok())
        .collect::<Option<_>>()?;
    let mut options = [0 as m::idx_t; m::METIS_NOPTIONS as usize];
    let mut perm = vec![0 as m::idx_t; n];
    let mut iperm = vec![0 as m::idx_t; n];
    // SAFETY: the options array has METIS_NOPTIONS entries; METIS_SetDefaultOptions only
    // writes them.
    unsafe { m::METIS_SetDefaultOptions(options.as_mut_ptr()) };
    options[m::moptions_et_METIS_OPTION_NUMBERING as usize] = 0;
    options[m::moptions_et_METIS_OPTION_SEED as usize] = METIS_SEED as m::idx_t;
    // METIS's random state is process-global: a partition or another order computed at
    // the same time on another thread would change this one (the tests run in threads).
    let _guard = METIS_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    // SAFETY: xadj has n + 1 entries, adjncy xadj[n] entries below n, perm and iperm n
    // entries each; METIS reads the graph and writes perm and iperm only (no vertex
    // weights: null).
    let status = unsafe {
        m::METIS_NodeND(
            &mut nvtxs,
            x.as_mut_ptr(),
            adj.as_mut_ptr(),
            std::ptr::null_mut(),
            options.as_mut_ptr(),
            perm.as_mut_ptr(),
            iperm.as_mut_ptr(),
        )
    };
    if status != m::rstatus_et_METIS_OK {
        return None;
    }
    // METIS's perm[k] is the vertex numbered k-th (its "perm" is our order).
    perm.into_iter().map(|v| usize::try_from(v).ok()).collect()
}

#[cfg(test)]
mod tests {
    use super::nested_dissection;

    #[test]
    fn orders_every_vertex_once_and_the_same_every_time() {
        // A 9 x 9 grid graph with an isolated vertex at the end: a permutation of all 82,
        // the same on a second call (what every rank relies on).
        let m = 9;
        let n = m * m + 1;
        let mut adj: Vec<Vec<u32>> = vec![Vec::new(); n];
        for j in 0..m {
            for i in 0..m {
                let a = i + m * j;
                if i + 1 < m {
                    adj[a].push((a + 1) as u32);
                    adj[a + 1].push(a as u32);
                }
                if j + 1 < m {
                    adj[a].push((a + m) as u32);
                    adj[a + m].push(a as u32);
                }
            }
        }
        let mut xadj = vec![0];
        let mut flat = Vec::new();
        for row in &mut adj {
            row.sort_unstable();
            flat.extend(row.iter().copied());
            xadj.push(flat.len());
        }
        let order = nested_dissection(&xadj, &flat).expect("METIS orders a grid");
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..n).collect::<Vec<_>>());
        assert_eq!(nested_dissection(&xadj, &flat), Some(order));
        assert_eq!(nested_dissection(&[0], &[]), Some(Vec::new()));
    }
}
