//! The elements around each node of a mesh: held for every node (`NodeElements`: the node
//! graph of the colouring and of the memory estimate), or as the fine aggregation reads
//! them, node by node in ascending order (`super::aggregation::StrongMesh`). Held for a window
//! of nodes only where the node numbering allows it: an element's nodes span at most
//! `band` ids, so the elements around node a are those whose lowest node lies in
//! a - band..=a, and once the elements of lowest node up to a have been added, node a's
//! list is complete and the lists of the nodes before it are no longer read. The window
//! holds band + 1 lists; the elements around every node (`NodeElements`) were 36 B per
//! node of the whole mesh on every rank while the run was set up (5.2 MB of the block on
//! block at n = 40, the largest of the set-up's peak on 16 ranks beside the mesh itself).

use crate::mesh::{Connectivity, GlobalMesh};

/// The elements around every node of a hexahedral mesh: node a's are
/// elems[ptr[a]..ptr[a + 1]], in element order. With the elements, the node graph (a node's
/// neighbours are the nodes of its elements) at a third of the graph's size.
pub struct NodeElements {
    ptr: Vec<usize>,
    elems: Vec<u32>,
}

impl NodeElements {
    pub fn of_mesh(mesh: &GlobalMesh) -> Self {
        Self::of_connectivity(mesh.num_nodes(), &mesh.elements)
    }

    /// The elements around every node of `elements`, whose nodes are 0..n.
    pub fn of_connectivity(n: usize, elements: &Connectivity) -> Self {
        let mut ptr = vec![0usize; n + 1];
        for e in elements.iter() {
            for &a in e {
                ptr[a as usize + 1] += 1;
            }
        }
        for a in 0..n {
            ptr[a + 1] += ptr[a];
        }
        let mut next = ptr.clone();
        let mut elems = vec![0u32; ptr[n]];
        for (k, e) in elements.iter().enumerate() {
            for &a in e {
                elems[next[a as usize]] = k as u32;
                next[a as usize] += 1;
            }
        }
        NodeElements { ptr, elems }
    }

    /// Nodes of the mesh.
    pub fn len(&self) -> usize {
        self.ptr.len() - 1
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The elements around node a, ascending.
    pub fn of(&self, a: usize) -> &[u32] {
        &self.elems[self.ptr[a]..self.ptr[a + 1]]
    }

    /// Calls `f` for every node of every element of node a (a itself and repeats included).
    pub fn each_neighbour(&self, elements: &Connectivity, a: usize, mut f: impl FnMut(u32)) {
        for &e in &self.elems[self.ptr[a]..self.ptr[a + 1]] {
            for &b in elements.element(e as usize) {
                f(b);
            }
        }
    }
}

/// The elements around each node: all of them (`NodeElements`, where the numbering's band
/// is too wide for a window to be smaller), or a window of nodes.
pub enum Around {
    Whole(NodeElements),
    Window(Window),
}

/// A window's band is used while it is at most this fraction of the nodes: a ring of
/// band + 1 lists costs about 24 B per node of the band against `NodeElements`' 36 B per
/// node of the mesh, beside the lists' entries.
const BAND_FRACTION: usize = 4;

impl Around {
    /// The elements around each of the `n` nodes of `elements`.
    pub fn new(n: usize, elements: &Connectivity) -> Self {
        let band = elements
            .iter()
            .map(|e| {
                let lo = e.iter().min().copied().unwrap_or(0);
                let hi = e.iter().max().copied().unwrap_or(0);
                (hi - lo) as usize
            })
            .max()
            .unwrap_or(0);
        if (band + 1) * BAND_FRACTION > n.max(1) {
            Around::Whole(NodeElements::of_connectivity(n, elements))
        } else {
            Around::Window(Window::new(n, elements, band))
        }
    }

    /// The elements around node a (in no set order).
    pub fn of(&mut self, elements: &Connectivity, a: usize) -> &[u32] {
        match self {
            Around::Whole(w) => w.of(a),
            Around::Window(w) => w.of(elements, a),
        }
    }
}

/// The elements around the nodes of a window: node b's at `ring[b % ring.len()]`, for the
/// nodes from `low` on whose elements have been added (those of lowest node below `fed`).
pub struct Window {
    /// The elements by lowest node: node a's are by_low[ptr[a]..ptr[a + 1]].
    ptr: Vec<u32>,
    by_low: Vec<u32>,
    ring: Vec<Vec<u32>>,
    fed: usize,
    low: usize,
}

impl Window {
    fn new(n: usize, elements: &Connectivity, band: usize) -> Self {
        let lowest = |e: &[u32]| e.iter().min().copied().unwrap_or(0) as usize;
        let mut ptr = vec![0u32; n + 1];
        for e in elements.iter() {
            ptr[lowest(e) + 1] += 1;
        }
        for a in 0..n {
            ptr[a + 1] += ptr[a];
        }
        let mut next = ptr.clone();
        let mut by_low = vec![0u32; elements.len()];
        for (k, e) in elements.iter().enumerate() {
            let a = lowest(e);
            by_low[next[a] as usize] = k as u32;
            next[a] += 1;
        }
        Window {
            ptr,
            by_low,
            ring: vec![Vec::new(); band + 1],
            fed: 0,
            low: 0,
        }
    }

    /// The elements around node a. Reading nodes in ascending order costs one pass over
    /// the elements; a node below the last one read starts the window again from node 0.
    fn of(&mut self, elements: &Connectivity, a: usize) -> &[u32] {
        let len = self.ring.len();
        if a < self.low {
            self.ring.iter_mut().for_each(Vec::clear);
            (self.fed, self.low) = (0, 0);
        }
        // The lists of the nodes passed are not read again (a slot holds no other node's:
        // node b's entries are added only while b < low + len).
        while self.low < a {
            self.ring[self.low % len].clear();
            self.low += 1;
        }
        // An element of lowest node m <= a has its nodes in m..=m + band, of which those
        // from a on are in the window (a + band < low + len).
        while self.fed <= a {
            let m = self.fed;
            for &k in &self.by_low[self.ptr[m] as usize..self.ptr[m + 1] as usize] {
                for &b in elements.element(k as usize) {
                    if b as usize >= self.low {
                        let list = &mut self.ring[b as usize % len];
                        if list.last() != Some(&k) {
                            list.push(k);
                        }
                    }
                }
            }
            self.fed += 1;
        }
        &self.ring[a % len]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A strip of hexahedra numbered along it (y slowest) (a narrow band) and the same strip with its
    /// nodes numbered in a scattered order (a wide band): both give each node the elements
    /// `NodeElements` gives it, read in ascending order, twice over, and in any order.
    #[test]
    fn a_window_gives_every_node_the_elements_around_it() {
        let block = crate::mesh::block::generate(
            &[
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 9.0, 0.0],
                [0.0, 9.0, 0.0],
                [0.0, 0.0, 1.0],
                [1.0, 0.0, 1.0],
                [1.0, 9.0, 1.0],
                [0.0, 9.0, 1.0],
            ],
            2,
            20,
            2,
        )
        .expect("memory");
        let n = block.coords.len();
        let scatter: Vec<u32> = (0..n as u32).map(|a| (a * 11) % n as u32).collect();
        let scattered: Vec<[u32; 8]> = block
            .elements
            .iter()
            .map(|e| e.map(|a| scatter[a as usize]))
            .collect();
        for (elements, windowed) in [
            (Connectivity::from_fixed(&block.elements), true),
            (Connectivity::from_fixed(&scattered), false),
        ] {
            let whole = NodeElements::of_connectivity(n, &elements);
            let mut around = Around::new(n, &elements);
            assert_eq!(matches!(around, Around::Window(_)), windowed);
            let order = (0..n)
                .chain(0..n)
                .chain((0..n).rev())
                .chain((0..n).step_by(3));
            for a in order {
                let mut got = around.of(&elements, a).to_vec();
                got.sort_unstable();
                assert_eq!(got, whole.of(a), "node {a}");
            }
        }
    }
}
