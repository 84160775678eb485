//! Partitions into many parts without METIS on the whole mesh: the element centres are cut
//! by recursive coordinate bisection into groups of at most [`GROUP_PARTS`] parts (each
//! group's element count in proportion to its parts), then METIS partitions each group's
//! elements alone (`partition_group`: the group's dual graph, its nodes numbered
//! locally). A rank so partitions only its group: METIS's memory (about 230 bytes per
//! element of the graph it is given, measured on the block on block at n = 40) follows
//! the rank's share of the mesh instead of the whole mesh, and the groups' results are
//! exchanged (by the solver; no MPI in here). The bisection is a function of the centres
//! and the part count alone (ties broken by element id), so every rank computes the same
//! groups, and the partition is the same whichever rank computes a group.

use std::ops::Range;

use crate::Cells;

/// Parts per group: METIS partitions a group's elements (about this many ranks' shares)
/// into its parts; the cuts between groups are planes.
pub const GROUP_PARTS: usize = 2;

/// From this many parts a run partitions by groups unless told otherwise: METIS's graph of
/// the whole mesh (about 230 bytes per element) then outweighs a rank's share of the mesh
/// (about 1.5 kB per element on one rank, the block on block at n = 40 with multilevel,
/// over the ranks), so it would be the largest part of every rank's peak. Measured cuts,
/// groups against METIS on the whole mesh at 8 and 16 parts: the block on block n = 40
/// 0.92 and 0.93 times, the Hertz example 1.11 and 1.09, the bolted clamp 0.81 and 1.10,
/// the Gmsh bracket 1.40 and 1.33.
pub const GROUPED_RANKS: usize = 8;

/// The groups of a partition into `nparts` parts.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Groups {
    /// The group of every element.
    pub group: Vec<u32>,
    /// Group g holds parts first[g]..first[g + 1] (GROUP_PARTS each, fewer in the last).
    first: Vec<usize>,
}

impl Groups {
    /// Cuts the elements (their centres) into the groups of `nparts` parts.
    pub fn new(centres: &[[f64; 3]], nparts: usize) -> Groups {
        let count = nparts.div_ceil(GROUP_PARTS).max(1);
        let first: Vec<usize> = (0..=count).map(|g| (g * GROUP_PARTS).min(nparts)).collect();
        let mut group = vec![0u32; centres.len()];
        let mut ids: Vec<u32> = (0..centres.len() as u32).collect();
        bisect(centres, &mut ids, 0..count, &first, &mut group);
        Groups { group, first }
    }

    /// The number of groups.
    pub fn count(&self) -> usize {
        self.first.len() - 1
    }

    /// The parts of group `g`.
    pub fn parts(&self, g: usize) -> Range<usize> {
        self.first[g]..self.first[g + 1]
    }

    /// The group that holds part `p`.
    pub fn of_part(&self, p: usize) -> usize {
        p / GROUP_PARTS
    }

    /// The elements of group `g`, ascending.
    pub fn elements(&self, g: usize) -> Vec<u32> {
        (0..self.group.len() as u32)
            .filter(|&e| self.group[e as usize] as usize == g)
            .collect()
    }

    /// The elements of every group, ascending (one pass over the elements).
    pub fn members(&self) -> Vec<Vec<u32>> {
        let mut members = vec![Vec::new(); self.count()];
        for (e, &g) in self.group.iter().enumerate() {
            members[g as usize].push(e as u32);
        }
        members
    }

    /// The part of every element from each group's parts of its elements (ascending
    /// element order, as `partition_group` gives them).
    pub fn assemble<'a>(&self, mut parts_of: impl FnMut(usize) -> &'a [u32]) -> Vec<u32> {
        let mut next = vec![0usize; self.count()];
        let lists: Vec<&[u32]> = (0..self.count()).map(&mut parts_of).collect();
        self.group
            .iter()
            .map(|&g| {
                let k = &mut next[g as usize];
                *k += 1;
                lists[g as usize][*k - 1]
            })
            .collect()
    }
}

/// Assigns `ids` to the groups `gs`: a single group takes them all; else they are split at
/// the median (weighted by the parts on each side) of the longest extent of their centres'
/// box, smaller coordinates (then smaller ids) to the lower half of the groups.
fn bisect(c: &[[f64; 3]], ids: &mut [u32], gs: Range<usize>, first: &[usize], out: &mut [u32]) {
    if gs.len() == 1 || ids.is_empty() {
        for &e in ids.iter() {
            out[e as usize] = gs.start as u32;
        }
        return;
    }
    let mid = gs.start + gs.len() / 2;
    let (parts, left) = (
        first[gs.end] - first[gs.start],
        first[mid] - first[gs.start],
    );
    // Rounded to the nearest element; exact in u128.
    let k = ((ids.len() as u128 * left as u128 + parts as u128 / 2) / parts as u128) as usize;
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &e in ids.iter() {
        for i in 0..3 {
            lo[i] = lo[i].min(c[e as usize][i]);
            hi[i] = hi[i].max(c[e as usize][i]);
        }
    }
    let axis = (0..3).fold(0, |a, i| if hi[i] - lo[i] > hi[a] - lo[a] { i } else { a });
    if k > 0 && k < ids.len() {
        ids.select_nth_unstable_by(k, |&a, &b| {
            c[a as usize][axis]
                .total_cmp(&c[b as usize][axis])
                .then(a.cmp(&b))
        });
    }
    let (l, r) = ids.split_at_mut(k);
    bisect(c, l, gs.start..mid, first, out);
    bisect(c, r, mid..gs.end, first, out);
}

/// The elements `ids` with their nodes numbered locally (0 .. the count returned): what
/// METIS partitions of a group.
pub(crate) fn local_mesh(elements: &dyn Cells, ids: &[u32]) -> (usize, Sub) {
    let mut nodes: Vec<u32> = ids
        .iter()
        .flat_map(|&e| elements.nodes(e as usize).iter().copied())
        .collect();
    nodes.sort_unstable();
    nodes.dedup();
    let mut sub = Sub {
        ptr: vec![0],
        nodes: Vec::new(),
    };
    for &e in ids {
        for n in elements.nodes(e as usize) {
            let local = nodes.binary_search(n).expect("a node of the group") as u32;
            sub.nodes.push(local);
        }
        sub.ptr.push(sub.nodes.len());
    }
    (nodes.len(), sub)
}

/// Some elements, their nodes numbered locally.
pub(crate) struct Sub {
    ptr: Vec<usize>,
    nodes: Vec<u32>,
}

impl Cells for Sub {
    fn count(&self) -> usize {
        self.ptr.len() - 1
    }
    fn nodes(&self, e: usize) -> &[u32] {
        &self.nodes[self.ptr[e]..self.ptr[e + 1]]
    }
}

/// Whether a partition of `elements` elements into `nparts` parts asked to be made by
/// groups is: more than one group, fewer parts than elements.
pub fn grouped(elements: usize, nparts: usize) -> bool {
    nparts > GROUP_PARTS && nparts < elements
}
