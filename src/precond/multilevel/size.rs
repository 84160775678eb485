//! The first coarse level's size from the mesh alone, for the memory estimate made before
//! the solve (`memory::model`): the aggregates of the node graph (the build's own
//! aggregation, `Transfer::new`), the aggregate pairs the measurement of the first coarse
//! operator holds (`Colouring`'s reach: one ring of the node graph; the ties of contact,
//! unknown before the solve, left out), and, where the aggregates are poor, the entries of
//! the sparse factor that then replaces the coarse levels (`Hierarchy::finish`).

use super::aggregation::Graph;
use super::colouring::{reach_of, Ties};
use super::factor_choice::{fit, Fit};
use super::transfer::fine_aggregates;
use crate::mesh::GlobalMesh;
use crate::precond::aggregates::modes;

/// Aggregates of fewer corner nodes (elements' vertices: every node of a hexahedral mesh,
/// a tet10 mesh's but its edge midpoints) than this on average make a first coarse level
/// whose V-cycle is slow (its rate above `cycle::SLOW_RATE`), and it is factored. Measured
/// in nodes of every kind per aggregate: the generated blocks aggregate 25 to 27 nodes
/// each (rate 0.56, not factored); the Hertz example 3.8 and x2 3.4 (one element thick),
/// its tetrahedral version 6.2, the Gmsh plate with a hole (hexahedra split from
/// tetrahedra) 10.9, the bracket (10-node tetrahedra on a block of hexahedra) 17.4, two
/// rings of 10-node tetrahedra (tests/adjust.rs's, 17064 nodes) 21.0 and a cube of them
/// (run/tet/cube.geo at h = 0.08, 16194 nodes, 2314 corners) 25.0, 3.6 corners (rates
/// 0.66 to 0.93, factored). Counted in all nodes, the cube's aggregates looked as large as
/// the blocks' (estimated 37% low): a tetrahedral mesh's aggregates span a few vertices
/// and their edges' midpoints. The rate that decides is known only once the level is
/// built: this is a threshold between the measured cases, not a bound (it was 20 until
/// the rings, estimated 36% low at 20).
pub const POOR_AGGREGATE_NODES: f64 = 23.0;

/// The same threshold for a generated block (a structured grid) whose elements are too
/// elongated for its aggregates to be the cubes' 27 nodes (`scene::counts`): there only an
/// aggregate no larger than a node and its six edge neighbours (the stars of a grid whose
/// diagonal neighbours are all weakly coupled) made a slow V-cycle. Measured: blocks of
/// 0.05 x 0.025 x 0.05 elements, 4.5 nodes an aggregate (rate 0.83, too large to factor);
/// 0.15 x 0.033 x 0.033, 7.9 (rate 0.55); 0.1 x 0.05 x 0.05, 10.2 (0.57); 0.05 x 0.025 x
/// 0.025, 10.3 (0.57): with the threshold of unstructured meshes the last three were
/// estimated 2 to 5 times their peaks.
pub const POOR_BLOCK_AGGREGATE_NODES: f64 = 7.0;

/// What the estimate needs of the first coarse level.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FirstLevel {
    pub aggregates: u64,
    /// Pairs (k, j) of aggregates where k sees j, k = j included: the 6 x 6 blocks of the
    /// operator's pattern.
    pub pairs: u64,
    /// The operator's entries: of each pair's block, the products of the two aggregates'
    /// live modes (a mode is live where some free direction of a node of the aggregate
    /// moves with it; a plane-strain slab's aggregates on one face keep 3 of their 6).
    pub entries: u64,
    /// The aggregates are poor (`first_level`'s threshold): the level's V-cycle is predicted
    /// slow, and its factor is tried.
    pub poor: bool,
    /// The entries of its sparse factor when the aggregates are poor and the factor fits
    /// (`factor_choice::fit`: its blocks by nested dissection, diagonal ones included, at
    /// the operator's mean entries per block); 0 when it is not predicted factored.
    pub factor_entries: u64,
}

impl FirstLevel {
    /// The 6 x 6 blocks the measurement holds on one rank (`measure::Blocks`): the
    /// diagonal's and one of each symmetric pair (a block below the diagonal is read from
    /// its transpose; on more ranks those whose transpose is another rank's are held too).
    pub fn measured_blocks(&self) -> u64 {
        (self.pairs + self.aggregates) / 2
    }
}

/// Bits 0, 1, 2 of `fixed[a]`: node a is held in x, y, z (from the scene's displacements);
/// aggregates of fewer corner nodes than `poor_below` on average are poor
/// (`POOR_AGGREGATE_NODES`, or `POOR_BLOCK_AGGREGATE_NODES` on a generated block).
pub fn first_level(mesh: &GlobalMesh, fixed: &[u8], poor_below: f64) -> FirstLevel {
    let n = mesh.num_nodes();
    if n == 0 {
        return FirstLevel::default();
    }
    let (agg_of, na) = fine_aggregates(mesh);
    let graph = Graph::of_mesh(mesh);
    let (reach_ptr, reach) = reach_of(&graph, &agg_of, na, &Ties::from_pairs(Vec::new()));
    drop(graph);
    let live = live_modes(mesh, fixed, &agg_of, na);
    let mut entries = 0u64;
    let mut edges = Vec::new();
    for j in 0..na {
        for &k in &reach[reach_ptr[j]..reach_ptr[j + 1]] {
            entries += (live[j] * live[k as usize]) as u64;
            if (k as usize) > j {
                edges.push((j as u32, k));
            }
        }
    }
    let pairs = reach.len() as u64;
    drop(reach);
    let mut corner = vec![false; n];
    for (e, nodes) in mesh.elements.iter().enumerate() {
        for &a in &nodes[..mesh.kind(e).corners()] {
            corner[a as usize] = true;
        }
    }
    let corners = corner.iter().filter(|&&c| c).count();
    drop(corner);
    let poor = (corners as f64) < poor_below * na as f64;
    let factor_entries = if poor {
        let g = Graph::from_edges(na, &edges);
        drop(edges);
        match fit(&g, pairs as usize, entries as f64) {
            Fit::Fits { entries } => entries,
            Fit::TooFull | Fit::TooDear { .. } => 0,
        }
    } else {
        0
    };
    FirstLevel {
        aggregates: na as u64,
        pairs,
        entries,
        poor,
        factor_entries,
    }
}

/// The live modes of every aggregate (`aggregates::modes` at the nodes' offsets from the
/// aggregate's centre, less the directions each node is held in).
fn live_modes(mesh: &GlobalMesh, fixed: &[u8], agg_of: &[u32], na: usize) -> Vec<usize> {
    let mut centre = vec![[0.0f64; 3]; na];
    let mut count = vec![0usize; na];
    for (a, x) in mesh.coords.iter().enumerate() {
        let k = agg_of[a] as usize;
        (0..3).for_each(|i| centre[k][i] += x[i]);
        count[k] += 1;
    }
    for k in 0..na {
        (0..3).for_each(|i| centre[k][i] /= count[k].max(1) as f64);
    }
    let mut live = vec![0u8; na];
    for (a, x) in mesh.coords.iter().enumerate() {
        let k = agg_of[a] as usize;
        let d = crate::math::sub(x, &centre[k]);
        let held = fixed.get(a).copied().unwrap_or(0);
        for (m, v) in modes(&d).iter().enumerate() {
            if (0..3).any(|i| held & (1 << i) == 0 && v[i] != 0.0) {
                live[k] |= 1 << m;
            }
        }
    }
    live.iter().map(|l| l.count_ones() as usize).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three hexahedra in a row (16 nodes, so one aggregate per node): each of the 8 end
    /// nodes sees the 8 nodes of its element, each of the 8 middle ones the 12 of its two,
    /// so 160 pairs; a lone node's rotations vanish at its own centre, leaving 3 live
    /// modes (9 entries a pair), 2 where every node is held in z (4 a pair). 16 nodes in
    /// 16 aggregates are poor ones: the factor is predicted, between the operator's lower
    /// triangle with its diagonal ((160 - 16) / 2 + 16 blocks) and a full one (136).
    #[test]
    fn a_row_of_three_elements_counts_its_pairs_entries_and_factor() {
        let coords = (0..16)
            .map(|a| {
                let (i, r) = (a / 4, a % 4);
                [i as f64, (r % 2) as f64, (r / 2) as f64]
            })
            .collect();
        let mesh = crate::mesh::hexahedra_in_a_row(coords);
        let free = first_level(&mesh, &[], POOR_AGGREGATE_NODES);
        assert_eq!((free.aggregates, free.pairs, free.entries), (16, 160, 1440));
        // Stored by the measurement on one rank: the 16 diagonal blocks and one of each of
        // the 72 symmetric pairs.
        assert_eq!(free.measured_blocks(), 16 + (160 - 16) / 2);
        assert!(free.poor);
        assert_eq!(free.factor_entries % 9, 0);
        assert!(
            (88 * 9..=136 * 9).contains(&free.factor_entries),
            "{free:?}"
        );
        let held = first_level(&mesh, &[4; 16], POOR_AGGREGATE_NODES);
        assert_eq!((held.pairs, held.entries), (160, 640));
        assert_eq!(held.factor_entries * 9, free.factor_entries * 4);
    }
}
