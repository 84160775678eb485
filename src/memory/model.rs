//! The memory model: the peak resident memory of a rank from the scene's counts alone
//! (elements, nodes, formulation, preconditioner, ranks), before anything is allocated;
//! for a loaded mesh also from its multilevel first coarse level, counted on the mesh
//! (`Counts::coarse_pairs` and after: docs/memory.md, "The first coarse level counted on
//! the mesh").
//!
//! The byte counts per element and per node are those of the data structures that hold
//! them (listed at each constant), so a scene whose ratio of nodes to elements or whose
//! formulation differs from the calibration scene is still counted right. Only the fixed
//! cost of the runtime (the binary, HDF5, MPI) and the coarse space's aggregate count were
//! calibrated, against the measured peaks (VmHWM) of the block on block at n = 10, 20, 40 on
//! 1 and 2 ranks with every preconditioner: the counts then came within -17% .. +15% of
//! every peak, the 10^6-element run's included (tests/memory.rs checks 25%; the README's
//! "Memory" section has the table).

/// What the estimate needs to know about a scene.
#[derive(serde::Serialize, serde::Deserialize, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    pub elements: u64,
    pub nodes: u64,
    /// Elements of fully integrated bodies (`integration = "full"`, also with
    /// `mean_dilatation`): their Gauss-point gradients are kept.
    pub full_elements: u64,
    /// Elements that keep a reference geometry of their own: all but those of linear
    /// bodies' generated blocks, which share a few shapes (`solver::shapes`).
    pub shaped_elements: u64,
    /// Of those, the 10-node tetrahedra (a loaded mesh's): each keeps its composite
    /// geometry (`TET10_GEOMETRY_PER_ELEMENT`) in place of a hexahedron's shape and
    /// Gauss-point gradients. Counted in `elements`, `full_elements` and `shaped_elements`
    /// as well.
    pub tet_elements: u64,
    /// The two-level preconditioner will be used (its dense coarse operator).
    pub two_level: bool,
    /// The multilevel hierarchy will be built (also under `auto` on meshes of 301 to
    /// 19999 nodes, where it waits for a hard model problem).
    pub multilevel: bool,
    /// A contact pair has Coulomb friction: the friction-coupled model problem's BiCGStab
    /// vectors (solver/cg/coupled.rs).
    pub friction: bool,
    /// A body is not linear elastic under small strain, or a pressure follows the surface:
    /// the model solve's nonlinear path and its vectors (solver/cg).
    pub nonlinear: bool,
    /// The full tangent preconditioner will be used: its factor on every rank.
    pub tangent: bool,
    /// Elements of small-kinematics plastic bodies integrated at Gauss points: each may
    /// hold its elastic matrix (`Assembly::mark_elastic`) where the full tangent is built
    /// or friction couples a nonlinear body's model problem.
    pub plastic_point_elements: u64,
    /// Integration-point states of the plastic bodies' elements (`fem::history`: 8 per
    /// fully integrated hexahedron, 1 + hourglass slots per mean one, 4 per composite
    /// tetrahedron).
    pub history_points: u64,
    /// Nodes held by a prescribed displacement (counted on a loaded mesh; 0 from the
    /// divisions alone, where they are a block's faces and the per-node bytes cover them).
    pub constrained_nodes: u64,
    /// The full tangent's entries: 9 per ordered pair of nodes that share an element (a node
    /// with itself included), counted from the blocks' divisions or on a loaded mesh; 0 when
    /// not counted (then `TANGENT_ENTRIES_PER_NODE` per node).
    pub tangent_entries: u64,
    /// The entries of the full tangent's factor, counted on a loaded mesh's node graph in
    /// the factor's order (`solver::choice::node_factor`); 0 when not counted (then
    /// `TANGENT_FILL` x nodes^(4/3)).
    pub tangent_factor_entries: u64,
    /// The multilevel hierarchy's first coarse level when the mesh is known (a loaded
    /// scene, `precond::multilevel::size`): the 6 x 6 blocks its measurement stores, its
    /// entries, and those of its sparse factor where it is predicted factored (0 when
    /// not). All 0 when the counts come from generated blocks alone, whose aggregates are
    /// the calibration's.
    pub coarse_pairs: u64,
    pub coarse_entries: u64,
    /// The level's V-cycle is predicted slow (poor aggregates): its factor is tried.
    pub coarse_slow: bool,
    pub coarse_factor_entries: u64,
}

/// What every rank holds of the whole mesh at the run's peak, after its setup: the whole
/// mesh's connectivity (32), element bodies (4) and coordinates (24 per node) are freed
/// once the run is set up (`Problem::outline`), before any step; the decomposition's element
/// part (4) and per-rank element lists (4) and rank 0's copy of the mesh for the result
/// file's header (36) stand for what remains of the peaks they were calibrated on (the
/// setup's, the file's); rank 0 adds what a step's output adds (OUTPUT_PER_ELEMENT).
const GLOBAL_PER_ELEMENT: f64 = 4.0 + 4.0 + 36.0 + OUTPUT_PER_ELEMENT;
/// Node owner (4) and per-rank node lists (4); on rank 0 the result file's coordinates
/// (24) and what a step's output adds (OUTPUT_PER_NODE).
const GLOBAL_PER_NODE: f64 = 4.0 + 4.0 + 24.0 + OUTPUT_PER_NODE;
/// What rank 0's step output adds to the peak of a run without the multilevel hierarchy,
/// per element and per node: calibrated on the two-level runs of the block on block at
/// n = 40 on 1 and 2 ranks (177.1 and 139.9 MiB against 173.7 and 142.6). It was the
/// gathered fields and their write buffers, 2 x 48 and 2 x 88, when rank 0 gathered a whole
/// step at once, then 96 and 176 when it gathered field by field; since each field goes to
/// the file a range of entries at a time (`run::fields`), rank 0 holds a round's buffers
/// (the contact pressure since only at the nodes in contact, 8 per node before), and the
/// rest of these
/// bytes is the runs' other peaks (the file's copy of the mesh while it is written, the
/// closing check reading the file back). The multilevel hierarchy's build, where such runs
/// peak, holds none of it.
const OUTPUT_PER_ELEMENT: f64 = 20.0;
const OUTPUT_PER_NODE: f64 = 112.0;
// METIS's dual graph of the whole mesh (about 170 bytes per element with its copies) is
// freed before the rank's share is built, so it is not part of the peak (the 2-rank peaks
// at n = 40 are 4% and 13% below the counts without it).
/// The rank's elements: local connectivity (32), global id (4), owned flag (1), body (4),
/// the index of its shape (8) and the step's stress (48).
const LOCAL_PER_ELEMENT: f64 = 41.0 + 8.0 + 48.0;
/// The reference geometry of an element (`Geometry`, 304), held per element but for linear
/// bodies whose elements share shapes.
const SHAPE_PER_ELEMENT: f64 = 304.0;
/// Gauss-point gradients of a fully integrated element shape (`GaussGeometry`).
const GAUSS_PER_ELEMENT: f64 = 1600.0;
/// A 10-node tetrahedron's reference geometry (`tet10::composite::Geometry`: its 12
/// sub-tetrahedra's inverse edge matrices and volumes, the projection's coefficients, the
/// four points' weights and the volume), whatever its formulation. Counted as a
/// hexahedron's shape and gradients (1904) the L-bracket of 21819 10-node tetrahedra was
/// estimated 19% above its peak (heaptrack: 1392 bytes an element held, 30.4 MB).
const TET10_GEOMETRY_PER_ELEMENT: f64 = 12.0 * 72.0 + 12.0 * 8.0 + 48.0 * 8.0 + 4.0 * 8.0 + 8.0;
/// An elastic element matrix (24 x 24, boxed) and its slot (`ElasticMatrices`), and the
/// element's two marks.
const ELASTIC_MATRIX_PER_ELEMENT: f64 = 4608.0 + 8.0 + 2.0;
/// The consistent tangent of such an element while the full tangent is built
/// (`assembly::Tangents`: 24 x 24 and its offset; a tet10's 30 x 30 is 7200).
const TANGENT_MATRIX_PER_ELEMENT: f64 = 4608.0 + 8.0;
/// A plastic element's state at one integration point, committed and the scratch a step's
/// commit fills (`Assembly::history`, `scratch`: 13 f64 each). The restart file takes it a
/// round of elements at a time (`run::plastic::stream_history`), so rank 0 adds no copy.
const HISTORY_PER_POINT: f64 = 2.0 * 13.0 * 8.0;
/// A node with constraint rows (`constraints::NodeRows`: the node's Gram inverse and
/// projector, its rows' lists, 256; a row, 72; the row's master references and force slots,
/// about 40): a plane-strain slab holds every node along z (the Hertz example x4, 24886
/// rows: 9 MB).
const CONSTRAINED_PER_NODE: f64 = 256.0 + 72.0 + 40.0;
/// The rank's nodes: coordinates, global id, owner (32); the CG vectors (7 x 24) and the
/// inverse 3x3 diagonal blocks (72); the displacement and its previous value and the
/// step's reaction, contact force, status and gap (2 x 24 + 88).
const LOCAL_PER_NODE: f64 = 32.0 + 168.0 + 72.0 + 48.0 + 88.0;
/// The nonlinear path's CG vectors: the previous residual, Newton-Krylov's direction and the
/// finite-difference probe's three (5 x 24).
const NONLINEAR_PER_NODE: f64 = 5.0 * 24.0;
/// The friction-coupled model problem's vectors (8 x 24), allocated when a node slips.
const FRICTION_PER_NODE: f64 = 8.0 * 24.0;
/// Aggregates of the coarse space: aimed at 6^3 nodes each, at most 400 (precond::coarse);
/// the cells cut by the bodies' bounds make more (128 at 18522 nodes: 1.5 x 18522 / 216).
const COARSE_NODES_PER_AGGREGATE: f64 = 216.0 / 1.5;
const COARSE_MAX_AGGREGATES: f64 = 400.0;
/// The multilevel hierarchy per node of the whole mesh: a part split over the ranks and a
/// part every rank holds whole, beside the first coarse level's prolongator (below). What
/// the hierarchy holds through the CG loops, where its runs now peak (the build frees CG's
/// z, pu and q and the fine level's vectors), counted at n = 80 on 2 ranks (heaptrack's
/// sizes of 2026-11-30, per node of the mesh): split, the first coarse operator's rows
/// (135: about 34 entries per node in 6 x 6 blocks, one of each symmetric pair, 8.1 bytes
/// an entry), the fine smoother's two vectors (48), the fine aggregates' plan (20), the
/// first coarse level's node-block inverses and vectors (23): 226; whole, the second
/// coarse level's operator (15), the first coarse level's restricted residual, correction
/// and gather buffer (5), the levels below (2): 22. Calibrated, the constants are 170 and
/// 75 (the split's 56 moved to the whole part): the smallest largest error over the block
/// on block with multilevel by name at n = 20 on 1 and 2 ranks, n = 40 on 1, 2, 3, 8, 16
/// and n = 80 on 2 (55.3, 49.1, 155.0, 107.5, 91.6, 71.0, 69.1, 483.6 MiB measured; -17.6%
/// to +18.9%). The whole part stands also for what every rank holds while the run is set
/// up (the whole mesh, its aggregation, the partition), where runs on many ranks peak
/// (n = 40 on 16 ranks: 66 MiB at the setup, 47 to 56 through the steps), and the rest of
/// the model (the rank's share, the whole mesh's part) counts more per node at n = 80 than
/// it holds: with the counted 226 and 22, n = 40 on 16 ranks would be estimated 28% low,
/// n = 80 on 2 ranks 14% high. Before each rank kept only its rows of the first coarse
/// level, the estimate was 1000 bytes per node on every rank (71.0, 346.0 and 1575.5 MiB
/// at n = 20, 40 on one rank and n = 80 on 2 then); with 330 and 129 (its build's peak,
/// calibrated when every rank held the whole mesh and the levels' vectors whole) n = 80
/// on 2 ranks peaked at 527.2 MiB against 711.1 estimated. Since every coarse level above
/// the coarsest is held as each rank's rows (`multilevel::first`), the second coarse
/// level's operator (15) is counted in the split part: 185 and 60. Since the first coarse
/// level's restriction and correction fetch what they read (`multilevel/halo.rs`, no
/// gathered vectors) and the fine aggregation reads a window of the mesh, what every rank
/// holds whole per node is the levels below (2) and, while the run is set up, the fine
/// aggregation of the whole node graph (its shortest distances and marks, 12; the
/// aggregate of every node and its phase-1 copy, 8): 22. With 60 the 10^6-element run on
/// 2 ranks was estimated 23.4% above its peak (567.6 against 460.0 MiB, 2026-12-01);
/// with 22, +15.0%, and n = 40 on 1 to 16 ranks -1.8% to +4.5% (+1.7% to +13.8% with 60).
const MULTILEVEL_SPLIT_PER_NODE: f64 = 185.0;
const MULTILEVEL_WHOLE_PER_NODE: f64 = 22.0;
const MULTILEVEL_PROLONGATOR_PER_NODE: f64 = 69.0;
/// The prolongator's rows split over more ranks than one, in full 6 x 6 blocks: 8.1 bytes
/// per entry instead of 12 (`multilevel::prolongation`).
const MULTILEVEL_PROLONGATOR_BLOCKS_PER_NODE: f64 = MULTILEVEL_PROLONGATOR_PER_NODE * 8.1 / 12.0;
/// Where the first coarse level is counted on the mesh (`Counts::coarse_pairs`): the
/// measurement's buffer of the rank's rows, an f64 and a state byte for each entry of the
/// 6 x 6 blocks it stores (`measure::Blocks`: the diagonal's and one of each symmetric
/// pair), at least the per-node split above. On a poorly aggregated mesh it is larger:
/// 8.2 MB on the Hertz example x2 when every block of its 27380 was stored (3.4 nodes per
/// aggregate; heaptrack), against 2.0 MB at the 330 bytes per node the split part then had.
const MEASURE_PER_ENTRY: f64 = 8.0 + 1.0;
/// And the build of the levels from it, per entry of the first coarse level
/// (`first::build_level`: P^T's rows, P's, the level's blocks and their f32 copy), where
/// that exceeds both (a mesh of small aggregates: their P has more entries per node).
const LEVEL_PER_ENTRY: f64 = 13.0;
/// A first coarse level factored (`cycle::Hierarchy::finish`) is held whole on every rank
/// as sparse rows while its factor is formed (a u32 column and an f64 value, grown by
/// doubling: 15.9 and 17.0 bytes per entry measured on the plate with a hole and the Hertz
/// example x2) beside the factor (a u32 row and an f64 value per entry).
const WHOLE_LEVEL_PER_ENTRY: f64 = 16.0;
const FACTOR_PER_ENTRY: f64 = 12.0;
/// Its analysis (`SparseCholesky::analyse`) beside the whole level before the factor:
/// the aggregate pairs of every entry above the diagonal (8 bytes each, about 4 per entry)
/// and the graph made of them (7.6 per entry): 16.8 and 32.3 MB at 4.25 million entries
/// on the plate with a hole's x2 mesh (heaptrack, when that analysis also decided whether
/// the factor fits).
const ANALYSIS_PER_ENTRY: f64 = 4.0 + 7.6;
/// Whether it fits is decided first on the level's node pattern gathered whole
/// (`factor_choice`: a u32 column and an f64 count per block, the graph made of it and
/// its counts, about 40 bytes a block), a block 36 entries or fewer: where it does not
/// fit, this is all the slow V-cycle adds.
const PATTERN_PER_ENTRY: f64 = 40.0 / 36.0;
/// The full tangent preconditioner on every rank, per node of the whole mesh: the
/// assembled tangent has at most 27 neighbours x 9 entries per node (a hexahedral mesh's
/// node graph; a slab one element thick, 18; counted where known: `Counts::tangent_entries`), held at the build's peak as the gathered (row, column, value) triples
/// (24 bytes) and their u32 copy (16); then the matrix (12) beside its Cholesky factor
/// (12 bytes per entry). The factor's entries by nested dissection grow as n^(4/3) on a
/// 3-D mesh; TANGENT_FILL x n^(4/3) bounds the measured ones: the plane-strain punch at
/// 40 x 40 and 80 x 80 (3362 and 13122 nodes) factored into 0.69 and 3.70 million entries
/// (TANGENT_FILL x n^(4/3): 0.69 and 4.17 million). The order kept between builds holds
/// the matrix's pattern (4 bytes per entry) through the next build's peak. On a loaded mesh
/// the factor's entries are counted instead (`Counts::tangent_factor_entries`): 7.5 million
/// for an L-bracket of 13910 Gmsh hexahedra's nodes that factored into 7.2 million, where
/// TANGENT_FILL gives 4.5.
const TANGENT_ENTRIES_PER_NODE: f64 = 27.0 * 9.0;
const TANGENT_FILL: f64 = 13.5;

/// The full tangent's bytes at its build's peak for `nodes` nodes, `entries` entries and
/// `factor_entries` in its factor (0: not counted).
fn tangent_bytes(nodes: f64, entries: u64, factor_entries: u64) -> f64 {
    let a = if entries > 0 {
        entries as f64
    } else {
        TANGENT_ENTRIES_PER_NODE * nodes
    };
    let factor = if factor_entries > 0 {
        factor_entries as f64
    } else {
        TANGENT_FILL * nodes.powf(4.0 / 3.0)
    };
    (40.0 * a).max(12.0 * (a + factor)) + 4.0 * a
}

/// The multilevel hierarchy at the peak of its build on one of `ranks` ranks: per node, or
/// from its first coarse level where the mesh counted it, with the factor predicted there.
fn multilevel_bytes(c: &Counts, ranks: usize) -> f64 {
    let n = c.nodes as f64;
    let mut split = MULTILEVEL_SPLIT_PER_NODE * n;
    let mut whole = MULTILEVEL_WHOLE_PER_NODE * n;
    // P^T on one rank; P's rows and P^T's split over more.
    let prolongator = match ranks {
        1 => MULTILEVEL_PROLONGATOR_PER_NODE * n,
        r => 2.0 * MULTILEVEL_PROLONGATOR_BLOCKS_PER_NODE * n / r as f64,
    };
    if c.coarse_pairs > 0 {
        split = split
            .max(MEASURE_PER_ENTRY * 36.0 * c.coarse_pairs as f64)
            .max(LEVEL_PER_ENTRY * c.coarse_entries as f64);
    }
    let entries = c.coarse_entries as f64;
    if c.coarse_slow && c.coarse_factor_entries > 0 {
        whole += WHOLE_LEVEL_PER_ENTRY * entries
            + (ANALYSIS_PER_ENTRY * entries).max(FACTOR_PER_ENTRY * c.coarse_factor_entries as f64);
    } else if c.coarse_slow {
        whole += PATTERN_PER_ENTRY * entries;
    }
    whole + prolongator + split / ranks as f64
}

/// The runtime before any mesh: the binary, HDF5 and, under mpirun, MPI and its buffers.
/// Calibrated: one rank without mpirun, one rank under mpirun, more ranks.
const FIXED_SERIAL: f64 = 20.0 * MIB;
const FIXED_MPI_ONE_RANK: f64 = 30.0 * MIB;
const FIXED_MPI_RANKS: f64 = 30.0 * MIB;

const MIB: f64 = 1024.0 * 1024.0;

/// The estimated peak of one rank, in bytes, split by what it is for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    pub ranks: usize,
    /// The runtime before any mesh.
    pub fixed: f64,
    /// What every rank (or rank 0) holds of the whole mesh.
    pub whole_mesh: f64,
    /// The rank's share of the mesh, with its ghost layer.
    pub share: f64,
    /// The coarse operator of the two-level preconditioner (dense, on every rank), the
    /// multilevel hierarchy, or the full tangent and its factor (on every rank).
    pub coarse: f64,
}

impl Estimate {
    /// Peak resident bytes of the largest rank (rank 0).
    pub fn per_rank(&self) -> f64 {
        self.fixed + self.whole_mesh + self.share + self.coarse
    }

    /// Peak resident bytes of a rank other than rank 0: rank 0's less the whole mesh,
    /// which rank 0 alone holds while the run is set up. (Measured on the block on block
    /// at n = 80: ranks 1 to 15 of 16 peak at 105.2 to 113.2 MiB against 103.3 estimated,
    /// ranks 1 to 7 of 8 at 150.3 to 157.8 against 153.6.)
    pub fn other_rank(&self) -> f64 {
        self.fixed + self.share + self.coarse
    }

    /// `ranks` of the run's ranks on one machine, rank 0 among them when `root`.
    pub fn on_machine(&self, ranks: usize, root: bool) -> f64 {
        if root && ranks > 0 {
            self.per_rank() + (ranks - 1) as f64 * self.other_rank()
        } else {
            ranks as f64 * self.other_rank()
        }
    }

    /// All ranks together.
    pub fn total(&self) -> f64 {
        self.on_machine(self.ranks, true)
    }
}

/// Elements (or nodes) of one rank's share of `n` over `ranks` ranks, with its ghost layer:
/// about two faces of a cube of the share.
fn share_of(n: u64, ranks: usize) -> f64 {
    let own = n as f64 / ranks as f64;
    if ranks == 1 {
        own
    } else {
        (own + 2.0 * own.powf(2.0 / 3.0)).min(n as f64)
    }
}

/// The estimated peak of the largest rank when the scene runs on `ranks` ranks under
/// mpirun (`mpi`; a one-rank run without mpirun when not).
pub fn estimate_run(c: &Counts, ranks: usize, mpi: bool) -> Estimate {
    let ranks = ranks.max(1);
    let (e, n) = (c.elements as f64, c.nodes as f64);
    let mut whole_mesh = e * GLOBAL_PER_ELEMENT + n * GLOBAL_PER_NODE;
    if c.multilevel && !c.two_level {
        whole_mesh -= e * OUTPUT_PER_ELEMENT + n * OUTPUT_PER_NODE;
    }
    // The hexahedra's shares; the tetrahedra keep a geometry of their own kind.
    let (full_share, shaped_share, tet_share) = if c.elements == 0 {
        (0.0, 0.0, 0.0)
    } else {
        (
            c.full_elements.saturating_sub(c.tet_elements) as f64 / e,
            c.shaped_elements.saturating_sub(c.tet_elements) as f64 / e,
            c.tet_elements as f64 / e,
        )
    };
    let matrix_share = if c.elements == 0 || !(c.tangent || (c.friction && c.nonlinear)) {
        0.0
    } else {
        c.plastic_point_elements as f64 / e
    };
    let history_share = if c.elements == 0 {
        0.0
    } else {
        c.history_points as f64 / e
    };
    let per_element = LOCAL_PER_ELEMENT
        + history_share * HISTORY_PER_POINT
        + shaped_share * (SHAPE_PER_ELEMENT + full_share * GAUSS_PER_ELEMENT)
        + tet_share * TET10_GEOMETRY_PER_ELEMENT
        + matrix_share * ELASTIC_MATRIX_PER_ELEMENT
        + if c.tangent {
            matrix_share * TANGENT_MATRIX_PER_ELEMENT
        } else {
            0.0
        };
    let per_node = LOCAL_PER_NODE
        + if c.friction { FRICTION_PER_NODE } else { 0.0 }
        + if c.nonlinear { NONLINEAR_PER_NODE } else { 0.0 };
    let constrained_share = if c.nodes == 0 {
        0.0
    } else {
        c.constrained_nodes as f64 / n
    };
    let per_node = per_node + constrained_share * CONSTRAINED_PER_NODE;
    let share = share_of(c.elements, ranks) * per_element + share_of(c.nodes, ranks) * per_node;
    let coarse = if c.tangent {
        tangent_bytes(n, c.tangent_entries, c.tangent_factor_entries)
    } else if c.two_level {
        let aggregates = (n / COARSE_NODES_PER_AGGREGATE)
            .ceil()
            .clamp(1.0, COARSE_MAX_AGGREGATES);
        // Dense, 6 rigid-body modes per aggregate. The assembled operator and its Cholesky
        // factor are both held while it is factored, but not at the run's peak: one of
        // them is counted (measured: 24.5 MiB more than Jacobi at n = 40, 1500 unknowns).
        let dim = 6.0 * aggregates;
        8.0 * dim * dim
    } else if c.multilevel {
        multilevel_bytes(c, ranks)
    } else {
        0.0
    };
    Estimate {
        ranks,
        fixed: match (mpi, ranks) {
            (false, _) => FIXED_SERIAL,
            (true, 1) => FIXED_MPI_ONE_RANK,
            (true, _) => FIXED_MPI_RANKS,
        },
        whole_mesh,
        share,
        coarse,
    }
}

/// The estimate of a run on `ranks` ranks under mpirun.
pub fn estimate(c: &Counts, ranks: usize) -> Estimate {
    estimate_run(c, ranks, true)
}

/// The fewest ranks, one per machine, whose estimate per rank fits `available` bytes (None
/// when even one rank per element would not: the whole-mesh data alone is too large).
pub fn ranks_to_fit(c: &Counts, available: f64) -> Option<usize> {
    let fits = |r: usize| estimate(c, r).per_rank() <= available;
    let limit = (c.elements as usize).max(1);
    if !fits(limit) {
        return None;
    }
    // The estimate falls as ranks grow (the whole-mesh part stays): bisect.
    let (mut lo, mut hi) = (1usize, limit);
    if fits(lo) {
        return Some(lo);
    }
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if fits(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}

/// The most ranks that fit together on one machine with `available` bytes (0 when not
/// even one).
pub fn ranks_on_one_machine(c: &Counts, available: f64, asked: usize) -> usize {
    (1..=asked.max(1))
        .rev()
        .find(|&r| estimate(c, r).total() <= available)
        .unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Without the first coarse level counted the hierarchy is the per-node count; with it,
    /// the measurement's blocks where they exceed that (split over the ranks), and a
    /// predicted factor with the level held whole beside it on every rank.
    #[test]
    fn the_first_coarse_level_adds_its_blocks_and_factor() {
        let base = Counts {
            elements: 1000,
            nodes: 1331,
            multilevel: true,
            ..Counts::default()
        };
        let n = 1331.0;
        for ranks in [1, 2, 4] {
            let r = ranks as f64;
            let per_node = estimate(&base, ranks).coarse;
            // The prolongator: P^T whole on one rank, P and P^T split over more, in 6 x 6
            // blocks (8.1 bytes per entry instead of 12).
            let p = if ranks == 1 {
                69.0
            } else {
                2.0 * 69.0 * 8.1 / 12.0 / r
            };
            // The same terms summed in another order: equal to rounding.
            let want = n * (22.0 + p) + n * 185.0 / r;
            assert!((per_node - want).abs() < 1e-12 * want, "{per_node} {want}");
            let few = Counts {
                coarse_pairs: 1,
                coarse_entries: 36,
                ..base
            };
            assert_eq!(estimate(&few, ranks).coarse, per_node);
            let poor = Counts {
                coarse_pairs: 10_000,
                coarse_entries: 200_000,
                coarse_slow: true,
                coarse_factor_entries: 500_000,
                ..base
            };
            // The same terms summed in another order: equal to rounding.
            let want =
                n * (22.0 + p) + 9.0 * 36.0 * 10_000.0 / r + 16.0 * 200_000.0 + 12.0 * 500_000.0;
            let got = estimate(&poor, ranks).coarse;
            assert!((got - want).abs() < 1e-12 * want, "{got} {want}");
            // Slow but its factor too large or too dear: the node pattern only.
            let tried = Counts {
                coarse_factor_entries: 0,
                ..poor
            };
            let want = n * (22.0 + p) + 9.0 * 36.0 * 10_000.0 / r + 40.0 / 36.0 * 200_000.0;
            assert!((estimate(&tried, ranks).coarse - want).abs() < 1e-6 * want);
            // Small aggregates: the level's build, 13 bytes an entry, above the blocks the
            // measurement holds.
            let small = Counts {
                coarse_entries: 1_000_000,
                coarse_slow: false,
                coarse_factor_entries: 0,
                ..poor
            };
            let want = n * (22.0 + p) + 13.0 * 1_000_000.0 / r;
            assert!((estimate(&small, ranks).coarse - want).abs() < 1e-6 * want);
        }
    }
}
