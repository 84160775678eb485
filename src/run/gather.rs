//! Rank 0's global-order copies of the owned per-node and per-element arrays.

use crate::comm::Comm;
use crate::math::Vec3;
use crate::mesh::local::LocalMesh;

/// Rounds of a gather: rank 0 receives the values of one range of global ids at a time, so
/// that it holds the whole array and an eighth of it, not the whole twice.
const ROUNDS: usize = 8;

/// The global ids of the owned entries of one kind (nodes or elements): this rank's, in its
/// order, and on rank 0 every rank's.
pub(super) struct Ids {
    own: Vec<u32>,
    all: Vec<Vec<u32>>,
    total: usize,
}

impl Ids {
    fn new<C: Comm + ?Sized>(comm: &C, own: Vec<u32>, total: usize) -> Self {
        let wide: Vec<u64> = own.iter().map(|&g| u64::from(g)).collect();
        let all = comm
            .gather_u64(&wide)
            .into_iter()
            .map(|ids| ids.into_iter().map(|g| g as u32).collect())
            .collect();
        Ids { own, all, total }
    }
}

/// Gathers the owned entries of a per-node or per-element array onto rank 0, in global
/// order.
pub(super) struct Gather {
    pub(super) nodes: Ids,
    pub(super) elements: Ids,
}

impl Gather {
    pub(super) fn new<C: Comm + ?Sized>(
        comm: &C,
        mesh: &LocalMesh,
        num_nodes: usize,
        num_elements: usize,
    ) -> Self {
        let owned = mesh.node_global[..mesh.num_owned_nodes].to_vec();
        let elems: Vec<u32> = mesh
            .element_global
            .iter()
            .zip(&mesh.element_owned)
            .filter(|(_, &o)| o)
            .map(|(&g, _)| g)
            .collect();
        Gather {
            nodes: Ids::new(comm, owned, num_nodes),
            elements: Ids::new(comm, elems, num_elements),
        }
    }

    /// The array whose owned entries (in the order of `ids.own`) are `local`, whole and in
    /// global order on rank 0 (empty elsewhere). Collective.
    pub(super) fn place<const W: usize, C: Comm + ?Sized>(
        &self,
        comm: &C,
        local: &[[f64; W]],
        ids: &Ids,
    ) -> Vec<[f64; W]> {
        assert_eq!(local.len(), ids.own.len(), "a value per owned entry");
        let root = comm.is_root();
        let mut out = if root {
            vec![[0.0; W]; ids.total]
        } else {
            Vec::new()
        };
        let per = ids.total.div_ceil(ROUNDS).max(1) as u32;
        let mut send: Vec<f64> = Vec::new();
        for round in 0..ROUNDS as u32 {
            let range = per * round..per.saturating_mul(round + 1);
            send.clear();
            for (&g, v) in ids.own.iter().zip(local) {
                if range.contains(&g) {
                    send.extend_from_slice(v);
                }
            }
            let parts = comm.gather_f64(&send);
            if !root {
                continue;
            }
            for (part, all) in parts.iter().zip(&ids.all) {
                let picked = all.iter().filter(|g| range.contains(g));
                for (v, &g) in part.chunks_exact(W).zip(picked) {
                    out[g as usize].copy_from_slice(v);
                }
            }
        }
        out
    }

    pub(super) fn nodes<C: Comm + ?Sized>(
        &self,
        comm: &C,
        mesh: &LocalMesh,
        v: &[Vec3],
    ) -> Vec<Vec3> {
        self.place(comm, &v[..mesh.num_owned_nodes], &self.nodes)
    }

    pub(super) fn elements<C: Comm + ?Sized>(&self, comm: &C, v: &[[f64; 6]]) -> Vec<[f64; 6]> {
        self.place(comm, v, &self.elements)
    }
}
