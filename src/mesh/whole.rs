//! What a run's set-up reads on rank 0 alone (`Whole`): the whole mesh, and how it is
//! decomposed over the ranks. From them rank 0 makes what every rank needs of the whole
//! mesh (the fine aggregates, the element shapes, the scales) and sends each rank its
//! part, so that no other rank holds the whole mesh while the run is set up.

use super::GlobalMesh;
use partition::Decomposition;
use std::borrow::Cow;

/// The whole mesh on rank 0 while the run is set up, with the decomposition (None on one
/// rank: the rank holds every node).
pub struct Whole<'m> {
    pub mesh: Cow<'m, GlobalMesh>,
    decomposition: Option<&'m Decomposition>,
}

impl<'m> Whole<'m> {
    /// The whole mesh of a run over the ranks of `decomposition`.
    pub fn new(mesh: Cow<'m, GlobalMesh>, decomposition: &'m Decomposition) -> Self {
        Whole {
            mesh,
            decomposition: Some(decomposition),
        }
    }

    /// The whole mesh of a run on one rank.
    pub fn one_rank(mesh: Cow<'m, GlobalMesh>) -> Self {
        Whole {
            mesh,
            decomposition: None,
        }
    }

    /// Rank `r`'s local nodes (owned, then ghosts, each ascending: `LocalMesh`'s order) and
    /// how many of them it owns.
    pub fn nodes_of(&self, r: usize) -> (Vec<u32>, usize) {
        match self.decomposition {
            Some(d) => (d.part(r).local_nodes(), d.part(r).num_owned_nodes()),
            None => {
                let n = self.mesh.num_nodes();
                ((0..n as u32).collect(), n)
            }
        }
    }
}
