//! Before a run allocates its mesh: the scene's size from its file, the memory estimate per
//! rank against what this machine and this process may use, and the refusal when it does
//! not fit (or the warning, with `--force`).

use crate::comm::{self, Comm};
use crate::memory::{self, available, check_fit, Fit};
use crate::precond::multilevel::size::POOR_AGGREGATE_NODES;
use crate::problem::Problem;
use crate::scene::counts::{problem_size, SceneSize};
use std::hash::{Hash, Hasher};

/// This machine's host name.
fn host_name() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .map(|s| s.trim().to_string())
        .unwrap_or_default()
}

/// How many ranks of the run share this machine (the same host name), and whether rank 0
/// is one of them: they share its memory.
pub fn ranks_on_this_machine<C: Comm + ?Sized>(comm: &C) -> (usize, bool) {
    if comm.size() == 1 {
        return (1, true);
    }
    let mut h = std::collections::hash_map::DefaultHasher::new();
    host_name().hash(&mut h);
    // 52 bits travel exactly as an f64.
    let mine = (h.finish() >> 12) as f64;
    let all = comm.all_gather_f64(&[mine]);
    let here = all.iter().filter(|v| v.first() == Some(&mine)).count();
    (here, all[0].first() == Some(&mine))
}

/// The size of a loaded scene (`scene::counts::problem_size`) with, where the multilevel
/// hierarchy will be built, its first coarse level counted on the mesh
/// (`precond::multilevel::size`): the aggregates of an unstructured mesh are not the
/// generated blocks' 27 nodes, and a poorly aggregated level is factored.
pub fn loaded_size(p: &Problem) -> SceneSize {
    let mut size = problem_size(p);
    if tangent_passed_over(p, &size).is_some() {
        size = size.without_tangent();
    }
    if size.counts.tangent {
        size.counts.tangent_entries = tangent_entries(&p.mesh);
        // Under `auto` (below TANGENT_NODES nodes, where the run counts the same factor to
        // decide on it): a node pair of the node graph's factor is a 3 x 3 block of the
        // tangent's, a node a lower triangle of 6 (fewer where a direction is held). By
        // name, on a mesh of any size, `TANGENT_FILL` stands for it.
        if p.solver.preconditioner == crate::problem::Preconditioner::Auto {
            size.counts.tangent_factor_entries = crate::solver::choice::node_factor(&p.mesh)
                .map_or(0, |(below, _)| 9 * below as u64 + 6 * size.counts.nodes);
        }
    }
    with_first_level(p, size, POOR_AGGREGATE_NODES)
}

/// Whether a scene's generated blocks aggregate as the count from their divisions assumes
/// (every neighbour of a node strongly coupled, as in a block of cubes): their elements'
/// elongation within the aggregation's strong ratio. A box of 40^3 elements of 0.05 x
/// 0.025 x 0.05 (elongation 2.45) aggregates 4.5 nodes each, a first coarse level of 10.8
/// million entries: estimated 78.2 MiB from its divisions, it peaked at 345.6.
pub fn aggregated_as_counted(size: &SceneSize) -> bool {
    size.elongation <= crate::precond::multilevel::transfer::STRONG_RATIO
}

/// `size` with, where the multilevel hierarchy will be built, its first coarse level
/// counted on the loaded mesh (`precond::multilevel::size`), poor below `poor_below` nodes
/// an aggregate: `POOR_AGGREGATE_NODES`, or `POOR_BLOCK_AGGREGATE_NODES` for generated
/// blocks counted from their divisions whose elements are too elongated to aggregate as
/// counted (`aggregated_as_counted`).
pub fn with_first_level(p: &Problem, mut size: SceneSize, poor_below: f64) -> SceneSize {
    if size.counts.multilevel && !size.counts.two_level && !size.counts.tangent {
        let first = crate::precond::multilevel::size::first_level(&p.mesh, &held(p), poor_below);
        size.counts.coarse_pairs = first.measured_blocks();
        size.counts.coarse_entries = first.entries;
        size.counts.coarse_slow = first.poor;
        size.counts.coarse_factor_entries = first.factor_entries;
    }
    size
}

/// The full tangent's entries on `mesh`: 9 per ordered pair of nodes that share an element,
/// each node with itself included.
fn tangent_entries(mesh: &crate::mesh::GlobalMesh) -> u64 {
    let around = crate::precond::multilevel::around::NodeElements::of_mesh(mesh);
    let mut seen = vec![usize::MAX; around.len()];
    let mut pairs = 0u64;
    for a in 0..around.len() {
        around.each_neighbour(&mesh.elements, a, |b| {
            if seen[b as usize] != a {
                seen[b as usize] = a;
                pairs += 1;
            }
        });
    }
    9 * pairs
}

/// Why `auto`, which takes the full tangent for a plastic body of the scene's size, does
/// not (`solver::choice`: its factorization's work, counted on the mesh), if it does not.
/// The estimate then counts what runs instead (a cube of tetrahedra at h = 0.08, 16194
/// nodes: 307 MiB estimated with the tangent, 86 MiB measured under `auto`).
pub fn tangent_passed_over(p: &Problem, size: &SceneSize) -> Option<String> {
    if !size.counts.tangent || p.solver.preconditioner != crate::problem::Preconditioner::Auto {
        return None;
    }
    crate::solver::choice::tangent_refused(p, &p.mesh)
        .map(|why| format!("not the full tangent: {why}"))
}

/// Bits 0, 1, 2 of every node: held in x, y, z by a displacement along that axis (one
/// along an oblique direction is left out: the modes then count as live, the larger
/// estimate).
fn held(p: &Problem) -> Vec<u8> {
    let mut fixed = vec![0u8; p.mesh.num_nodes()];
    for d in &p.dirichlet {
        let Some(axis) = (0..3).find(|&i| d.direction[i].abs() == 1.0) else {
            continue;
        };
        if (0..3).any(|i| i != axis && d.direction[i] != 0.0) {
            continue;
        }
        for &a in &p.node_sets[d.node_set].nodes {
            fixed[a as usize] |= 1 << axis;
        }
    }
    fixed
}

/// What the gate decided.
pub enum Gate {
    /// Run: the fit (this rank's), and the refusal overridden by `--force`, if any.
    Go {
        fit: Box<Fit>,
        forced: Option<String>,
    },
    /// Do not run: the message (the same on every rank).
    Refuse(String),
}

/// Compares the scene's estimate with the memory of every rank's machine and process.
/// Collective: every rank takes the same branch.
pub fn memory_gate<C: Comm + ?Sized>(comm: &C, size: &SceneSize, mpi: bool, force: bool) -> Gate {
    let here = ranks_on_this_machine(comm);
    let fit = Box::new(check_fit(
        &size.counts,
        comm.size(),
        mpi,
        here,
        &available::bounds(),
    ));
    let refused = comm::first_error(comm, fit.refusal());
    match refused {
        None => Gate::Go { fit, forced: None },
        Some(m) if force => Gate::Go {
            fit,
            forced: Some(m),
        },
        Some(m) => Gate::Refuse(m),
    }
}

/// The estimate and the memory this rank may use, in one line for the log.
pub fn fit_line(fit: &Fit) -> String {
    let bounds: Vec<String> = available::bounds()
        .iter()
        .map(|b| format!("{} ({})", memory::format_bytes(b.bytes), b.source))
        .collect();
    format!(
        "{}; available {}",
        memory::fit::estimate_line(&fit.estimate),
        if bounds.is_empty() {
            "unknown".to_string()
        } else {
            bounds.join(", ")
        }
    )
}
