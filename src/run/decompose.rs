//! The element partition over the ranks (`Partition`), made for rank 0, which holds the
//! whole mesh: METIS on the whole mesh, or the groups of the element centres
//! (`partition::Groups`), each partitioned by METIS on the first rank of its parts alone,
//! so that no METIS run holds the whole mesh's graph (about 230 bytes per element) and the
//! groups' runs go on at once. Results do not depend on the partition (bitwise the same on
//! any number of ranks): it decides only what each rank computes and sends.

use crate::comm::{self, message, Comm};
use crate::mesh::{Connectivity, GlobalMesh};
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

/// The part (rank) of every element, on rank 0, which holds the whole mesh `whole` (the
/// other ranks get an empty list; collective, and a failure is every rank's): METIS on the
/// whole mesh there, or by groups: rank 0 cuts the groups (the element centres freed once
/// they are cut) and sends each group's elements to the first rank of its parts, one group
/// at a time; each such rank runs METIS on its group alone while the others run on theirs,
/// and rank 0 gathers their parts. The parts `partition::partition_for_ranks` gives.
pub fn element_parts<C: Comm + ?Sized>(
    comm: &C,
    whole: Option<&GlobalMesh>,
    num_elements: usize,
    method: Partition,
) -> Result<Vec<u32>, String> {
    let ranks = comm.size();
    let parts = if method.groups(ranks) && partition::grouped(num_elements, ranks) {
        by_groups(comm, whole)
    } else {
        whole.map(|mesh| {
            partition::partition_elements(mesh.num_nodes(), &mesh.elements, ranks)
                .map_err(|e| e.to_string())
        })
    };
    let failure = parts.as_ref().and_then(|p| p.as_ref().err().cloned());
    match comm::first_error(comm, failure) {
        Some(e) => Err(e),
        None => Ok(parts.and_then(Result::ok).unwrap_or_default()),
    }
}

/// `element_parts` by groups: on rank 0 the parts or the first group's failure, None on
/// the other ranks. Collective.
fn by_groups<C: Comm + ?Sized>(
    comm: &C,
    whole: Option<&GlobalMesh>,
) -> Option<Result<Vec<u32>, String>> {
    let groups = whole.map(|mesh| Groups::new(&centres(mesh), comm.size()));
    let mut members = groups.as_ref().map(Groups::members);
    // A group's elements and its parts, to the first rank of its parts; nothing elsewhere.
    let (elements, first, count): (Connectivity, usize, usize) = message::scatter(comm, |r| {
        let (Some(mesh), Some(groups), Some(members)) = (whole, &groups, &mut members) else {
            unreachable!("rank 0 holds the whole mesh and its groups")
        };
        let g = groups.of_part(r);
        let parts = groups.parts(g);
        if parts.start != r {
            return (Connectivity::new(), 0, 0);
        }
        if r == 0 {
            // Rank 0 reads its own group from the whole mesh (below): no copy.
            return (Connectivity::new(), parts.start, parts.len());
        }
        let ids = std::mem::take(&mut members[g]);
        let elements = mesh.elements.select(ids.iter().map(|&e| e as usize), |n| n);
        (elements, parts.start, parts.len())
    });
    drop(members);
    let mine: Vec<Result<Vec<u32>, String>> = if count > 0 {
        let parts = match (whole, &groups) {
            (Some(mesh), Some(groups)) => {
                partition::partition_group(&mesh.elements, groups, groups.of_part(first))
            }
            _ => partition::partition_group_elements(&elements, first..first + count),
        };
        vec![parts.map_err(|e| {
            format!(
                "{e} (partitioning the elements of the group of ranks {first} to {})",
                first + count - 1
            )
        })]
    } else {
        Vec::new()
    };
    drop(elements);
    // The leaders' lists, in rank order: group order.
    let lists = message::gather(comm, &mine);
    drop(mine);
    let groups = groups?;
    let lists = lists.into_iter().collect::<Result<Vec<_>, _>>();
    Some(lists.map(|lists| groups.assemble(|g| &lists[g])))
}
