//! The element partition over the ranks (`Partition`), made by the rank that holds the
//! whole mesh: METIS on the whole mesh, or the groups of the element centres
//! (`partition::Groups`), each partitioned by METIS in turn, so that no METIS run holds
//! the whole mesh's graph (about 230 bytes per element). Results do not depend on the
//! partition (bitwise the same on any number of ranks): it decides only what each rank
//! computes and sends.

use crate::mesh::GlobalMesh;
use partition::Groups;

/// How the elements are partitioned over the ranks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Partition {
    /// By groups from `partition::GROUPED_RANKS` ranks, else METIS on the whole mesh.
    #[default]
    Auto,
    Metis,
    Groups,
}

impl Partition {
    pub const NAMES: [&'static str; 3] = ["auto", "metis", "groups"];

    pub fn from_name(name: &str) -> Option<Partition> {
        match name {
            "auto" => Some(Partition::Auto),
            "metis" => Some(Partition::Metis),
            "groups" => Some(Partition::Groups),
            _ => None,
        }
    }

    /// Whether `ranks` ranks partition by groups.
    pub fn groups(self, ranks: usize) -> bool {
        match self {
            Partition::Auto => ranks >= partition::GROUPED_RANKS,
            Partition::Metis => false,
            Partition::Groups => true,
        }
    }
}

/// The centre (node mean) of every element.
pub fn centres(mesh: &GlobalMesh) -> Vec<[f64; 3]> {
    mesh.elements
        .iter()
        .map(|el| {
            let mut c = [0.0; 3];
            for &n in el {
                for i in 0..3 {
                    c[i] += mesh.coords[n as usize][i];
                }
            }
            c.map(|x| x / el.len() as f64)
        })
        .collect()
}

/// The part (rank) of every element, on the rank that holds the whole mesh (rank 0): the
/// parts `partition::partition_for_ranks` gives, the groups' METIS runs one after the
/// other, so that no more than one group's graph is held at a time, and the element
/// centres freed once the groups are cut.
pub fn element_parts(
    mesh: &GlobalMesh,
    method: Partition,
    ranks: usize,
) -> Result<Vec<u32>, String> {
    if !(method.groups(ranks) && partition::grouped(mesh.num_elements(), ranks)) {
        return partition::partition_elements(mesh.num_nodes(), &mesh.elements, ranks)
            .map_err(|e| e.to_string());
    }
    let groups = Groups::new(&centres(mesh), ranks);
    let lists = (0..groups.count())
        .map(|g| {
            partition::partition_group(&mesh.elements, &groups, g)
                .map_err(|e| format!("{e} (partitioning the elements of group {g})"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(groups.assemble(|g| &lists[g]))
}
