//! The element partition over the ranks (`Partition`), made in parallel: METIS on the
//! whole mesh, or the groups of the element centres (`partition::Groups`, the same on
//! every rank), each partitioned by METIS on the first rank of its parts alone, and every
//! group's parts gathered to every rank: the parts `partition::partition_for_ranks` gives,
//! without any rank running METIS on the whole mesh (about 230 bytes per element of its
//! graph). Results do not depend on the partition (bitwise the same on any number of
//! ranks): it decides only what each rank computes and sends.

use crate::comm::Comm;
use crate::mesh::GlobalMesh;
use partition::{Groups, PartitionError};

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

/// The part (rank) of every element (collective). A group's failure is every rank's.
pub fn element_parts<C: Comm + ?Sized>(
    comm: &C,
    mesh: &GlobalMesh,
    method: Partition,
) -> Result<Vec<u32>, String> {
    let ranks = comm.size();
    if !(method.groups(ranks) && partition::grouped(mesh.num_elements(), ranks)) {
        return partition::partition_elements(mesh.num_nodes(), &mesh.elements, ranks)
            .map_err(|e| e.to_string());
    }
    let groups = Groups::new(&centres(mesh), ranks);
    let g = groups.of_part(comm.rank());
    let mine: Option<Result<Vec<u32>, PartitionError>> = (groups.parts(g).start == comm.rank())
        .then(|| partition::partition_group(&mesh.elements, &groups, g));
    // A leader's parts, or its failure as the single value -1.
    let send: Vec<f64> = match &mine {
        Some(Ok(parts)) => parts.iter().map(|&p| f64::from(p)).collect(),
        Some(Err(_)) => vec![-1.0],
        None => Vec::new(),
    };
    let all = comm.all_gather_f64(&send);
    drop(send);
    if let Some(r) = (0..ranks).find(|&r| all[r].first() == Some(&-1.0)) {
        let mut message = match &mine {
            Some(Err(e)) if r == comm.rank() => e.to_string().into_bytes(),
            _ => Vec::new(),
        };
        comm.broadcast_bytes(r, &mut message);
        return Err(format!(
            "{} (partitioning the elements of group {} on rank {r})",
            String::from_utf8_lossy(&message),
            groups.of_part(r)
        ));
    }
    drop(mine);
    let lists: Vec<Vec<u32>> = (0..groups.count())
        .map(|g| {
            all[groups.parts(g).start]
                .iter()
                .map(|&p| p as u32)
                .collect()
        })
        .collect();
    drop(all);
    Ok(groups.assemble(|g| &lists[g]))
}
