//! Rank 0's global-order copies of the owned per-node and per-element arrays.

use crate::comm::Comm;
use crate::math::Vec3;
use crate::mesh::local::LocalMesh;

/// Gathers the owned entries of a per-node array onto rank 0, in global node order.
pub(super) struct Gather {
    pub(super) node_ids: Vec<Vec<u64>>,
    pub(super) element_ids: Vec<Vec<u64>>,
    pub(super) num_nodes: usize,
    pub(super) num_elements: usize,
}

impl Gather {
    pub(super) fn new<C: Comm + ?Sized>(
        comm: &C,
        mesh: &LocalMesh,
        num_nodes: usize,
        num_elements: usize,
    ) -> Self {
        let owned: Vec<u64> = mesh.node_global[..mesh.num_owned_nodes]
            .iter()
            .map(|&g| g as u64)
            .collect();
        let elems: Vec<u64> = mesh
            .element_global
            .iter()
            .zip(&mesh.element_owned)
            .filter(|(_, &o)| o)
            .map(|(&g, _)| g as u64)
            .collect();
        Gather {
            node_ids: comm.gather_u64(&owned),
            element_ids: comm.gather_u64(&elems),
            num_nodes,
            num_elements,
        }
    }

    pub(super) fn place<const W: usize, C: Comm + ?Sized>(
        &self,
        comm: &C,
        local: &[[f64; W]],
        ids: &[Vec<u64>],
        total: usize,
    ) -> Vec<[f64; W]> {
        let parts = comm.gather_f64(local.as_flattened());
        if !comm.is_root() {
            return Vec::new();
        }
        // Zeroed pages are resident only once written, and each part goes once placed: rank
        // 0 holds about the whole and one part, not the parts beside the whole.
        let mut out = vec![[0.0; W]; total];
        for (part, ids) in parts.into_iter().zip(ids) {
            for (k, &g) in ids.iter().enumerate() {
                out[g as usize].copy_from_slice(&part[W * k..W * (k + 1)]);
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
        self.place(
            comm,
            &v[..mesh.num_owned_nodes],
            &self.node_ids,
            self.num_nodes,
        )
    }

    pub(super) fn elements<C: Comm + ?Sized>(&self, comm: &C, v: &[[f64; 6]]) -> Vec<[f64; 6]> {
        self.place(comm, v, &self.element_ids, self.num_elements)
    }
}
