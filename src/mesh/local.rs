//! A rank's view of the mesh: owned elements and one layer of ghost elements (every
//! element touching an owned node), owned nodes first, then ghost nodes, and the halo
//! exchange plan. Local elements are in ascending global order, so every owned node sums
//! its element contributions in the same order as a one-rank run: the nodal forces are
//! bitwise the same on any number of ranks.

use super::{Connectivity, GlobalMesh};
use crate::comm::{message, Comm, ExchangePlan};
use crate::fem::kind::ElementKind;
use crate::math::Vec3;
use partition::Decomposition;

#[derive(Clone, Debug)]
pub struct LocalMesh {
    pub num_owned_nodes: usize,
    pub node_global: Vec<u32>,
    pub coords: Vec<Vec3>,
    pub elements: Connectivity,
    pub element_global: Vec<u32>,
    pub element_owned: Vec<bool>,
    pub element_body: Vec<u32>,
    /// The element kind of every body.
    pub body_kind: Vec<ElementKind>,
    /// Owned node values (local indices) to the ghost copies (local indices) on other ranks.
    pub halo: ExchangePlan,
    /// The owners of a piece of the global nodes (`OwnerPiece`; contact constraints reach
    /// nodes of any rank: `owners` asks the rank that holds a node's piece).
    owners: OwnerPiece,
}

/// The owning ranks of the global nodes `first..first + owner.len()`: rank r holds nodes
/// r B to (r + 1) B - 1, B = ceil(nodes / ranks), so that no rank holds every node's.
#[derive(Clone, Debug)]
struct OwnerPiece {
    first: usize,
    per_rank: usize,
    owner: Vec<u32>,
}

/// A rank's part as a message: the rank that partitions the mesh makes every rank's
/// (`LocalMesh::new`) and sends it (`run::decompose`); read back, it is the same part.
impl message::Message for LocalMesh {
    fn write(&self, w: &mut message::Writer<'_>) {
        w.index(self.num_owned_nodes);
        w.put(&self.node_global);
        w.put(&self.coords);
        w.put(&self.elements);
        w.put(&self.element_global);
        w.put(&self.element_owned);
        w.put(&self.element_body);
        w.index(self.body_kind.len());
        for k in &self.body_kind {
            w.id(match k {
                ElementKind::Hex8 => 0,
                ElementKind::Tet10 => 1,
            });
        }
        w.put(&self.halo.send);
        w.put(&self.halo.recv);
        w.index(self.owners.first);
        w.index(self.owners.per_rank);
        w.put(&self.owners.owner);
    }
    fn read(r: &mut message::Reader) -> Option<Self> {
        let num_owned_nodes = r.index()?;
        let node_global: Vec<u32> = r.get()?;
        let coords: Vec<Vec3> = r.get()?;
        let elements: Connectivity = r.get()?;
        let element_global: Vec<u32> = r.get()?;
        let owned = r.index()?;
        let element_owned = (0..owned)
            .map(|_| r.flag())
            .collect::<Option<Vec<bool>>>()?;
        let element_body: Vec<u32> = r.get()?;
        let kinds = r.index()?;
        let body_kind = (0..kinds)
            .map(|_| match r.id()? {
                0 => Some(ElementKind::Hex8),
                1 => Some(ElementKind::Tet10),
                _ => None,
            })
            .collect::<Option<Vec<_>>>()?;
        let halo = ExchangePlan {
            send: r.get()?,
            recv: r.get()?,
        };
        let owners = OwnerPiece {
            first: r.index()?,
            per_rank: r.index()?,
            owner: r.get()?,
        };
        let consistent = num_owned_nodes <= node_global.len()
            && coords.len() == node_global.len()
            && elements.len() == element_global.len()
            && element_owned.len() == element_global.len()
            && element_body.len() == element_global.len();
        consistent.then_some(LocalMesh {
            num_owned_nodes,
            node_global,
            coords,
            elements,
            element_global,
            element_owned,
            element_body,
            body_kind,
            halo,
            owners,
        })
    }
}

impl LocalMesh {
    pub fn new(global: &GlobalMesh, decomposition: &Decomposition, rank: usize) -> Self {
        let part = decomposition.part(rank);
        let node_global = part.local_nodes();
        let global_to_local = part.global_to_local();
        let coords = node_global
            .iter()
            .map(|&g| global.coords[g as usize])
            .collect();
        let element_global = part.local_elements();
        let elements = global
            .elements
            .select(element_global.iter().map(|&e| e as usize), |n| {
                global_to_local[&n]
            });
        let element_owned = element_global
            .iter()
            .map(|&e| part.owns_element(e))
            .collect();
        let element_body = element_global
            .iter()
            .map(|&e| global.element_body[e as usize])
            .collect();
        let map = |lists: &[(usize, Vec<u32>)]| -> Vec<(usize, Vec<u32>)> {
            lists
                .iter()
                .map(|(r, ids)| (*r, ids.iter().map(|g| global_to_local[g]).collect()))
                .collect()
        };
        let (owned, ghosts) = node_global.split_at(part.num_owned_nodes());
        debug_assert!(
            owned.is_sorted() && ghosts.is_sorted(),
            "owned and ghost node ids ascending (`local_node` searches them)"
        );
        LocalMesh {
            num_owned_nodes: part.num_owned_nodes(),
            node_global,
            coords,
            elements,
            element_global,
            element_owned,
            element_body,
            body_kind: global.bodies.iter().map(|b| b.kind).collect(),
            halo: ExchangePlan {
                send: map(&part.send),
                recv: map(&part.recv),
            },
            owners: {
                let all = decomposition.node_owner();
                let per_rank = all.len().div_ceil(decomposition.parts().len()).max(1);
                let first = (rank * per_rank).min(all.len());
                let last = (first + per_rank).min(all.len());
                OwnerPiece {
                    first,
                    per_rank,
                    owner: all[first..last].to_vec(),
                }
            },
        }
    }

    /// The ranks that own global nodes `nodes` (collective: each asks the ranks that hold
    /// their owners, `OwnerPiece`, in two exchanges).
    pub fn owners<C: Comm + ?Sized>(&self, comm: &C, nodes: &[u32]) -> Vec<usize> {
        if comm.size() == 1 {
            return vec![0; nodes.len()];
        }
        let per = self.owners.per_rank;
        let mut ask: Vec<Vec<u32>> = vec![Vec::new(); comm.size()];
        for &g in nodes {
            ask[g as usize / per].push(g);
        }
        let asked = message::all_to_all(comm, &ask);
        let answers: Vec<Vec<u32>> = asked
            .iter()
            .map(|ids| {
                let at = |g: u32| g as usize - self.owners.first;
                ids.iter().map(|&g| self.owners.owner[at(g)]).collect()
            })
            .collect();
        drop(asked);
        let mut got: Vec<std::vec::IntoIter<u32>> = message::all_to_all(comm, &answers)
            .into_iter()
            .map(|v| v.into_iter())
            .collect();
        nodes
            .iter()
            .map(|&g| {
                got[g as usize / per]
                    .next()
                    .expect("an owner per node asked") as usize
            })
            .collect()
    }

    /// Local index of a global node owned by this rank.
    pub fn owned_node(&self, global: u32) -> Option<usize> {
        self.local_node(global)
            .filter(|&l| l < self.num_owned_nodes)
    }

    /// Local index of a global element owned by this rank.
    pub fn owned_element(&self, global: u32) -> Option<usize> {
        self.element_global
            .binary_search(&global)
            .ok()
            .filter(|&e| self.element_owned[e])
    }

    pub fn num_nodes(&self) -> usize {
        self.node_global.len()
    }

    /// Local index of a global node (owned or ghost): a binary search in the owned ids,
    /// then in the ghost ids (each list is ascending), instead of a map of every local
    /// node (17 B per local node: 9 MiB per rank of the block on block at n = 80 on 2
    /// ranks).
    pub fn local_node(&self, global: u32) -> Option<usize> {
        let (owned, ghosts) = self.node_global.split_at(self.num_owned_nodes);
        owned
            .binary_search(&global)
            .ok()
            .or_else(|| ghosts.binary_search(&global).ok().map(|i| i + owned.len()))
    }

    /// The kind of local element `e` (its body's).
    #[inline]
    pub fn kind(&self, e: usize) -> ElementKind {
        self.body_kind[self.element_body[e] as usize]
    }

    /// The node positions of local element `e`, of `N` nodes (its kind's).
    pub fn element_coords<const N: usize>(&self, e: usize) -> [Vec3; N] {
        let el = self.elements.fixed::<N>(e);
        std::array::from_fn(|a| self.coords[el[a] as usize])
    }

    /// Copies owned values to the ghost copies on neighbouring ranks.
    pub fn exchange<C: Comm + ?Sized>(&self, comm: &C, data: &mut [Vec3]) {
        self.halo.run_in_place(comm, data);
    }

    /// The plan that fetches the values of remote nodes from their owners: `wanted` lists
    /// (global node, slot of the destination array). Collective.
    pub fn fetch_plan<C: Comm + ?Sized>(&self, comm: &C, wanted: &[(u32, u32)]) -> ExchangePlan {
        let ids: Vec<u32> = wanted.iter().map(|w| w.0).collect();
        let owners = self.owners(comm, &ids);
        drop(ids);
        ExchangePlan::fetch(comm, wanted, &owners, |g| self.owned_node(g))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ranks_part_travels_as_words_and_back() {
        // A block of 4 x 3 x 2 elements dealt round three parts (parts that interleave):
        // each part's words, read back and written again, are the same words, and the
        // part read back has the fields of the one sent.
        let corners = crate::mesh::block::box_corners(&[0.0; 3], &[1.0, 0.7, 0.3]);
        let b = crate::mesh::block::generate(&corners, 4, 3, 2).unwrap();
        let g = GlobalMesh {
            coords: b.coords,
            elements: Connectivity::from_fixed(&b.elements),
            element_body: vec![0; 24],
            bodies: vec![super::super::Body {
                name: "b".into(),
                kind: ElementKind::Hex8,
                first_node: 0,
                num_nodes: 60,
                first_element: 0,
                num_elements: 24,
            }],
            freed: None,
        };
        let element_part: Vec<u32> = (0..24).map(|e| (e * 5 % 3) as u32).collect();
        let d = Decomposition::try_new(60, &g.elements, &element_part, 3).unwrap();
        for r in 0..3 {
            let sent = LocalMesh::new(&g, &d, r);
            let words = message::words_of(&sent);
            let back: LocalMesh = message::decode::<LocalMesh>(&words)
                .and_then(|mut v| v.pop())
                .expect("a part decodes");
            assert_eq!(message::words_of(&back), words);
            assert_eq!(back.node_global, sent.node_global);
            assert_eq!(back.coords, sent.coords);
            assert_eq!(back.elements, sent.elements);
            assert_eq!(back.element_owned, sent.element_owned);
            assert_eq!(back.halo.recv, sent.halo.recv);
            assert_eq!(back.owners.owner, sent.owners.owner);
        }
    }
}
