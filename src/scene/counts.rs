//! A scene's size from its file alone: elements and nodes of its generated blocks, counted
//! from `divisions` without building the mesh, for the memory estimate that comes before
//! any allocation (`solver check`, `solver run`).

use super::types::{BodyDef, Integration, SceneFile};
use super::validate::SceneError;
use crate::fem::Formulation;
use crate::memory::Counts;
use crate::problem::{
    uses_full_tangent, Kinematics, Preconditioner, Problem, NEARLY_INCOMPRESSIBLE,
};
use std::path::Path;

/// Node and element ids are 32-bit, and some sums double them: the mesh may have at most
/// this many of each (the limit the mesh builder checks too).
pub const MAX_IDS: u64 = u32::MAX as u64 / 2;

/// What the memory estimate needs of a scene.
#[derive(serde::Serialize, serde::Deserialize, Clone, Debug, PartialEq)]
pub struct SceneSize {
    pub counts: Counts,
    /// The scene's `solver.preconditioner` (the two-level choice of `counts` follows it).
    pub preconditioner: Preconditioner,
    /// A body is plastic (`auto` then may choose the full tangent preconditioner).
    pub plastic: bool,
    /// Set when the counts exceed the 32-bit ids: the error naming the body's divisions.
    pub beyond_ids: Option<SceneError>,
    /// The largest over the generated blocks of an element's longest diagonal over its
    /// shortest edge (`elongation`; infinite where it is not known): above the multilevel
    /// aggregation's strong ratio, the blocks do not aggregate as the count assumes
    /// (`preflight::aggregated_as_counted`).
    pub elongation: f64,
}

impl SceneSize {
    /// With the preconditioner a run uses instead of the scene's, if any.
    pub fn with_override(mut self, p: Option<Preconditioner>) -> Self {
        if let Some(p) = p {
            self.preconditioner = p;
            self.counts.two_level = two_level(p);
            self.counts.multilevel = multilevel(p, self.counts.nodes, self.plastic);
            self.counts.tangent = uses_full_tangent(p, self.plastic, self.counts.nodes);
        }
        self
    }

    /// Counted without the full tangent: `auto` refused its factorization
    /// (`solver::choice`: a 3-D mesh's fill) and preconditions the plastic body as it would
    /// any other.
    pub fn without_tangent(mut self) -> Self {
        self.counts.tangent = false;
        self.counts.multilevel = multilevel(self.preconditioner, self.counts.nodes, false);
        self
    }

    /// The id-range error, if any, as a `Result`.
    pub fn ids(&self) -> Result<(), SceneError> {
        self.beyond_ids.clone().map_or(Ok(()), Err)
    }
}

/// Whether the multilevel hierarchy is built: by name, or under `auto` on meshes above the
/// size it keeps Jacobi alone on (on standby below MULTILEVEL_NODES, from the start from
/// there up: `solver::choice`), unless the full tangent preconditions instead.
fn multilevel(p: Preconditioner, nodes: u64, plastic: bool) -> bool {
    match p {
        Preconditioner::Multilevel => true,
        Preconditioner::Auto => nodes > 300 && !uses_full_tangent(p, plastic, nodes),
        _ => false,
    }
}

/// Whether the two-level coarse space is built: by name only.
fn two_level(p: Preconditioner) -> bool {
    p == Preconditioner::TwoLevel
}

/// The size of the scene at `path` refined by `factor`, from its generated blocks. None
/// when the file does not read, parse or refine, or a body's divisions are out of range
/// (loading the scene then reports that, cheaply and the same way every time), or a body
/// comes from a Gmsh file (its counts need the mesh read: load the scene and use
/// [`problem_size`]).
pub fn scene_size(path: &Path, factor: u32) -> Option<SceneSize> {
    let file = path.display().to_string();
    let text = super::text::utf8_text(std::fs::read(path).ok()?).ok()?;
    let text = if factor > 1 {
        let default_name = path
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_else(|| "scene".into());
        super::refine::refine_scene_text(&text, factor, &default_name).ok()?
    } else {
        text
    };
    let raw: SceneFile = toml::from_str(&text).ok()?;
    let preconditioner = raw
        .solver
        .preconditioner
        .as_deref()
        .and_then(Preconditioner::from_name)
        .unwrap_or_default();
    let mut counts = Counts::default();
    let mut plastic = false;
    let mut beyond_ids = None;
    let mut elongated: f64 = 0.0;
    for (i, b) in raw.body.iter().enumerate() {
        let (e, n) = block_counts(b)?;
        elongated = elongated.max(elongation(b));
        // A node's neighbours along one axis of d divisions: 3 inside, 2 at the ends; the
        // block's (node, neighbour) pairs are the product over the axes of 3 d + 1.
        let pairs: u64 = b.divisions?.iter().map(|&d| 3 * d as u64 + 1).product();
        counts.tangent_entries = counts.tangent_entries.saturating_add(9 * pairs);
        counts.elements = counts.elements.saturating_add(e);
        counts.nodes = counts.nodes.saturating_add(n);
        if b.integration == Integration::Full {
            counts.full_elements = counts.full_elements.saturating_add(e);
        }
        // A linear body's generated box shares its few shapes (`solver::shapes`); any
        // other body's elements keep their own geometry (a block given by its corners
        // too: its elements differ in shape unless it is a parallelepiped).
        // Not when nearly incompressible: bulk over shear modulus 2 (1 + nu) / (3 (1 - 2 nu))
        // at least 49 (`problem::NEARLY_INCOMPRESSIBLE`).
        let material = b.material.params();
        let nu = material.young_poisson().1;
        let shared = b.box_.is_some()
            && material.is_linear()
            && 2.0 * (1.0 + nu) < NEARLY_INCOMPRESSIBLE * 3.0 * (1.0 - 2.0 * nu)
            && raw.kinematics == Kinematics::Small;
        if !shared {
            counts.shaped_elements = counts.shaped_elements.saturating_add(e);
        }
        if material.is_plastic()
            && b.integration == Integration::Full
            && raw.kinematics == Kinematics::Small
        {
            counts.plastic_point_elements = counts.plastic_point_elements.saturating_add(e);
        }
        if material.is_plastic() {
            let points = if b.integration == Integration::Full {
                crate::fem::history::points(Formulation::Full)
            } else {
                crate::fem::history::MEAN_POINTS
            };
            counts.history_points = counts.history_points.saturating_add(e * points as u64);
        }
        plastic |= material.is_plastic();
        counts.nonlinear |= !material.is_linear() || raw.kinematics != Kinematics::Small;
        if beyond_ids.is_none() && (counts.elements > MAX_IDS || counts.nodes > MAX_IDS) {
            beyond_ids = Some(SceneError {
                file: file.clone(),
                key: format!("body[{i}].divisions"),
                message: format!(
                    "the mesh would have {} elements and {} nodes up to this body, more than the \
                     {MAX_IDS} the solver's 32-bit ids can number; use fewer divisions",
                    counts.elements, counts.nodes
                ),
            });
        }
    }
    counts.two_level = two_level(preconditioner);
    counts.multilevel = multilevel(preconditioner, counts.nodes, plastic);
    counts.tangent = uses_full_tangent(preconditioner, plastic, counts.nodes);
    Some(SceneSize {
        counts,
        preconditioner,
        plastic,
        beyond_ids,
        elongation: elongated,
    })
}

/// An element's longest diagonal over its shortest edge in a generated block (infinite
/// where not known): edges per parametric direction, a box's, or the longest and shortest
/// of the corners' four (node order 0-1, 0-3, 0-4), over the divisions. The multilevel
/// preconditioner's count from the divisions (`memory::model`, calibrated on blocks of
/// cubes, ratio 1.73) assumes a node aggregated with its 26 neighbours; beyond its strong
/// ratio (`multilevel::transfer::STRONG_RATIO`, 2) diagonal neighbours are weakly coupled
/// and not aggregated together, and the aggregates shrink (`preflight`).
fn elongation(b: &BodyDef) -> f64 {
    let Some(d) = b.divisions else {
        return f64::INFINITY;
    };
    let d = d.map(|x| x.max(1) as f64);
    let edges: [(f64, f64); 3] = if let Some(bx) = &b.box_ {
        std::array::from_fn(|i| {
            let h = (bx.max[i] - bx.min[i]).abs() / d[i];
            (h, h)
        })
    } else if let Some(c) = b.corners.as_deref().filter(|c| c.len() == 8) {
        let length = |a: usize, b: usize| {
            (0..3)
                .map(|i| (c[a][i] - c[b][i]).powi(2))
                .sum::<f64>()
                .sqrt()
        };
        let along = [
            [(0, 1), (3, 2), (4, 5), (7, 6)],
            [(0, 3), (1, 2), (4, 7), (5, 6)],
            [(0, 4), (1, 5), (2, 6), (3, 7)],
        ];
        std::array::from_fn(|i| {
            let l = along[i].map(|(a, b)| length(a, b) / d[i]);
            (
                l.iter().copied().fold(f64::INFINITY, f64::min),
                l.iter().copied().fold(0.0, f64::max),
            )
        })
    } else {
        return f64::INFINITY;
    };
    let shortest = edges.iter().map(|e| e.0).fold(f64::INFINITY, f64::min);
    let diagonal = edges.iter().map(|e| e.1 * e.1).sum::<f64>().sqrt();
    if shortest > 0.0 {
        diagonal / shortest
    } else {
        f64::INFINITY
    }
}

/// (elements, nodes) of a generated block; None for a Gmsh body or divisions that loading
/// refuses.
fn block_counts(b: &BodyDef) -> Option<(u64, u64)> {
    if b.gmsh_volume.is_some() {
        return None;
    }
    let d = b.divisions?;
    if d.iter().any(|&x| !(1..=10_000).contains(&x)) {
        return None;
    }
    // At most 10^12 elements and (10^4 + 1)^3 nodes per block: no overflow in u64.
    let elements = d.iter().map(|&x| x as u64).product();
    let nodes = d.iter().map(|&x| x as u64 + 1).product();
    Some((elements, nodes))
}

/// The size of a loaded scene (the only way for Gmsh meshes).
pub fn problem_size(p: &Problem) -> SceneSize {
    let m = &p.mesh;
    let full_elements = m
        .bodies
        .iter()
        .zip(&p.body_models)
        .filter(|(_, model)| !matches!(model.formulation, Formulation::Mean { .. }))
        .map(|(b, _)| b.num_elements as u64)
        .sum();
    let nodes = m.num_nodes() as u64;
    let plastic = p.body_models.iter().any(|b| b.material.is_plastic());
    let pre = p.solver.preconditioner;
    SceneSize {
        counts: Counts {
            elements: m.num_elements() as u64,
            nodes,
            full_elements,
            // Conservative: which elements share shapes is known once the assembly
            // counts them.
            shaped_elements: m.num_elements() as u64,
            tet_elements: m
                .bodies
                .iter()
                .filter(|b| b.kind == crate::fem::ElementKind::Tet10)
                .map(|b| b.num_elements as u64)
                .sum(),
            two_level: two_level(pre),
            multilevel: multilevel(pre, nodes, plastic),
            tangent: uses_full_tangent(pre, plastic, nodes),
            friction: p.contacts.iter().any(|c| c.mu > 0.0),
            nonlinear: !crate::problem::linear_models(&p.body_models)
                || (p.kinematics == Kinematics::Large && !p.pressures.is_empty()),
            plastic_point_elements: m
                .bodies
                .iter()
                .zip(&p.body_models)
                .filter(|(_, model)| {
                    model.material.is_plastic()
                        && !model.material.is_large()
                        && !matches!(model.formulation, Formulation::Mean { .. })
                })
                .map(|(b, _)| b.num_elements as u64)
                .sum(),
            history_points: m
                .bodies
                .iter()
                .zip(&p.body_models)
                .filter(|(_, model)| model.material.is_plastic())
                .map(|(b, model)| {
                    (b.num_elements * crate::fem::history::points_of(b.kind, model.formulation))
                        as u64
                })
                .sum(),
            constrained_nodes: constrained_nodes(p),
            ..Counts::default()
        },
        preconditioner: pre,
        plastic,
        beyond_ids: None,
        // Counted on the mesh where it is loaded (`preflight::loaded_size`).
        elongation: 0.0,
    }
}

/// The nodes of a loaded scene that a prescribed displacement holds.
fn constrained_nodes(p: &Problem) -> u64 {
    let mut held = vec![false; p.mesh.num_nodes()];
    for d in &p.dirichlet {
        for &a in &p.node_sets[d.node_set].nodes {
            held[a as usize] = true;
        }
    }
    held.iter().filter(|&&h| h).count() as u64
}
