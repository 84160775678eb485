//! A validated scene: the mesh with resolved sets, materials, loads, time steps and solver
//! settings. Built once by `scene::load_scene`; nothing here refers to names any more.

use crate::fem::Formulation;
use crate::material::Material;
use crate::math::Vec3;
use crate::mesh::GlobalMesh;

mod contact_pair;
mod function;
mod kinematics;
mod outline;

pub use contact_pair::{ContactPair, Discretization, Tributaries};
pub use function::PiecewiseLinear;
pub use kinematics::Kinematics;
pub use outline::{frame_of, BoundaryFace, Retained};

#[derive(serde::Serialize, serde::Deserialize, Clone, Debug)]
pub struct BodyModel {
    pub material: Material,
    pub formulation: Formulation,
    pub density: f64,
}

#[derive(serde::Serialize, serde::Deserialize, Clone, Debug)]
pub struct NodeSet {
    pub name: String,
    pub nodes: Vec<u32>,
}

#[derive(serde::Serialize, serde::Deserialize, Clone, Debug)]
pub struct SideSet {
    pub name: String,
    pub faces: Vec<(u32, u8)>,
}

/// u . direction = function(t) on every node of the set.
#[derive(serde::Serialize, serde::Deserialize, Clone, Debug)]
pub struct Dirichlet {
    pub node_set: usize,
    pub direction: Vec3,
    pub function: PiecewiseLinear,
}

#[derive(serde::Serialize, serde::Deserialize, Clone, Debug)]
pub struct Pressure {
    pub side_set: usize,
    pub function: PiecewiseLinear,
}

#[derive(serde::Serialize, serde::Deserialize, Clone, Debug)]
pub struct Traction {
    pub side_set: usize,
    pub vector: Vec3,
    pub function: PiecewiseLinear,
}

#[derive(serde::Serialize, serde::Deserialize, Clone, Debug)]
pub struct BodyForce {
    pub body: usize,
    /// Force per unit reference volume (density times acceleration).
    pub force_density: Vec3,
    pub function: PiecewiseLinear,
}

#[derive(serde::Serialize, serde::Deserialize, Clone, Debug)]
pub struct SolverSettings {
    /// Converged when |r| <= tolerance * reference force.
    pub tolerance: f64,
    /// CG iterations allowed for one load step's model problem.
    pub max_iterations: usize,
    /// Extrapolate the previous step's increment as the starting guess.
    pub predictor: bool,
    /// How many times a failing step may be halved.
    pub max_cutbacks: usize,
    /// Contact updates allowed in one load step.
    pub max_contact_updates: usize,
    pub preconditioner: Preconditioner,
    /// How the model problem of nonlinear bodies is solved.
    pub nonlinear: NonlinearSolver,
}

/// The solver of the model problem when a body is nonlinear.
#[derive(serde::Serialize, serde::Deserialize, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum NonlinearSolver {
    /// Today the nonlinear CG: Newton-Krylov measured slower on every plastic scene tried
    /// (docs/plasticity-solve.md).
    #[default]
    Auto,
    /// The paper's nonlinear preconditioned CG.
    Cg,
    /// Newton-Krylov: linear PCG on the consistent tangent, an energy line search.
    Newton,
}

impl NonlinearSolver {
    /// The names a scene (`solver.nonlinear`) and the command line (`--nonlinear`) use.
    pub const NAMES: [&'static str; 3] = ["auto", "cg", "newton"];

    /// The solver of a name of [`Self::NAMES`].
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "auto" => Some(NonlinearSolver::Auto),
            "cg" => Some(NonlinearSolver::Cg),
            "newton" => Some(NonlinearSolver::Newton),
            _ => None,
        }
    }
}

/// The CG preconditioner.
#[derive(serde::Serialize, serde::Deserialize, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Preconditioner {
    /// By the mesh and its bodies (`solver::choice`): multilevel from `MULTILEVEL_NODES`
    /// nodes up, block Jacobi with multilevel on standby below, the full tangent for small
    /// plastic meshes.
    #[default]
    Auto,
    /// Nodal block Jacobi.
    Jacobi,
    /// Nodal block Jacobi plus a coarse space of aggregate rigid-body modes.
    TwoLevel,
    /// Smoothed aggregation over several levels (src/precond/multilevel/).
    Multilevel,
    /// The model problem's tangent assembled and factored (src/solver/cg/full_tangent.rs).
    Tangent,
}

impl Preconditioner {
    /// The names a scene (`solver.preconditioner`) and the command line (`--preconditioner`)
    /// use, in that order.
    pub const NAMES: [&'static str; 5] = ["auto", "jacobi", "two_level", "multilevel", "tangent"];

    /// The preconditioner of a name of [`Self::NAMES`].
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "auto" => Some(Preconditioner::Auto),
            "jacobi" => Some(Preconditioner::Jacobi),
            "two_level" => Some(Preconditioner::TwoLevel),
            "multilevel" => Some(Preconditioner::Multilevel),
            "tangent" => Some(Preconditioner::Tangent),
            _ => None,
        }
    }
}

/// True when every body is linear (small kinematics, elastic): f_int(u) = K u, and the
/// model problem is linear (then friction is coupled to the normal force in it, and
/// slipping nodes carry Coulomb's tangent).
pub fn linear_models(models: &[BodyModel]) -> bool {
    models.iter().all(|m| m.material.linear().is_some())
}

/// Bulk over shear modulus from which a body counts as nearly incompressible (Poisson's
/// ratio 0.49 and above): `auto` then picks the multilevel preconditioner
/// (`solver::choice`), and the body is not evaluated by element matrices
/// (`solver::shapes::Plan`).
pub const NEARLY_INCOMPRESSIBLE: f64 = 49.0;

/// Whether the material's bulk modulus is at least NEARLY_INCOMPRESSIBLE times its shear
/// modulus.
pub fn nearly_incompressible(material: &crate::material::Material) -> bool {
    let (lambda, mu) = material.lambda_mu();
    lambda + 2.0 * mu / 3.0 >= NEARLY_INCOMPRESSIBLE * mu
}

/// Under `auto`, meshes from this many nodes up take the multilevel preconditioner from
/// the start (`solver::choice`). Up to 200000 nodes they took two-level with multilevel on
/// standby, until multilevel was the faster and the leaner there too (2026-12-01, the
/// block on block under `auto` against `--preconditioner multilevel`: n = 30, 59582 nodes,
/// 264 against 77 CG iterations, 10.3 against 4.5 s and 158.1 against 89.0 MiB on one
/// rank, 9.8 against 3.0 s and 147.0 against 69.1 MiB per rank on two; n = 40, 137842
/// nodes, on two ranks 377 against 81 CG iterations, 9.8 against 5.4 s, 120.8 against 97.2
/// MiB; the same at n = 30 with neo-Hookean blocks under large kinematics, 378 against 236
/// CG iterations, 39.1 against 21.1 s, 198.5 against 122.2 MiB). At n = 80 (1062882 nodes)
/// on 2 ranks: 94 CG iterations, 478.8 MiB per rank, 981 bytes per element, against 716
/// iterations, 136.7 s and 331.2 MiB with two-level (2026-11-30).
pub const MULTILEVEL_NODES: usize = 20_000;

/// Under `auto`, a mesh with a plastic body and fewer nodes than this uses the full tangent
/// preconditioner (`solver::choice`). Every rank holds the whole factor, so the bound is
/// that of a factor one machine holds many times over: the plane-strain punch at 80 x 80
/// (13122 nodes) factors into 3.7 million entries (45 MiB).
pub const TANGENT_NODES: usize = MULTILEVEL_NODES;

/// Whether a run uses the full tangent preconditioner: by name, or under `auto` where a
/// body is plastic (its tangent softens by orders of magnitude where it yields, which
/// block Jacobi and the multilevel hierarchy, built on the operator's elastic structure,
/// do not follow: docs/plasticity-solve.md) on fewer than TANGENT_NODES nodes.
pub fn uses_full_tangent(p: Preconditioner, plastic: bool, nodes: u64) -> bool {
    match p {
        Preconditioner::Tangent => true,
        Preconditioner::Auto => plastic && nodes < TANGENT_NODES as u64,
        _ => false,
    }
}

impl Default for SolverSettings {
    fn default() -> Self {
        SolverSettings {
            tolerance: 1e-10,
            max_iterations: 20_000,
            predictor: true,
            max_cutbacks: 6,
            max_contact_updates: 200,
            preconditioner: Preconditioner::Auto,
            nonlinear: NonlinearSolver::Auto,
        }
    }
}

#[derive(serde::Serialize, serde::Deserialize, Clone, Debug)]
pub struct Problem {
    pub name: String,
    /// The scene file's full text, kept for the result file.
    pub text: String,
    pub file: String,
    pub kinematics: Kinematics,
    pub mesh: GlobalMesh,
    pub body_models: Vec<BodyModel>,
    pub node_sets: Vec<NodeSet>,
    pub side_sets: Vec<SideSet>,
    pub dirichlet: Vec<Dirichlet>,
    pub pressures: Vec<Pressure>,
    pub tractions: Vec<Traction>,
    pub body_forces: Vec<BodyForce>,
    pub contacts: Vec<ContactPair>,
    pub start_time: f64,
    /// End time of every load step, in order.
    pub step_times: Vec<f64>,
    pub solver: SolverSettings,
    pub output_every: usize,
    /// What a run reads of the whole mesh once `mesh` is its outline (`outline`); None
    /// while `mesh` is the whole mesh.
    pub retained: Option<Box<Retained>>,
}

impl Problem {
    pub fn node_set(&self, name: &str) -> Option<&NodeSet> {
        self.node_sets.iter().find(|s| s.name == name)
    }

    pub fn side_set(&self, name: &str) -> Option<&SideSet> {
        self.side_sets.iter().find(|s| s.name == name)
    }
}

impl Problem {
    /// This problem for a run: the whole mesh as an outline, with what the run reads of it
    /// (`Retained`); the whole mesh is `self.mesh`, for the setup.
    pub fn outline(&self) -> Problem {
        let retained = self.retained_of(&self.mesh);
        Problem {
            mesh: self.mesh.outline(),
            retained: Some(Box::new(retained)),
            name: self.name.clone(),
            text: self.text.clone(),
            file: self.file.clone(),
            kinematics: self.kinematics,
            body_models: self.body_models.clone(),
            node_sets: self.node_sets.clone(),
            side_sets: self.side_sets.clone(),
            dirichlet: self.dirichlet.clone(),
            pressures: self.pressures.clone(),
            tractions: self.tractions.clone(),
            body_forces: self.body_forces.clone(),
            contacts: self.contacts.clone(),
            start_time: self.start_time,
            step_times: self.step_times.clone(),
            solver: self.solver.clone(),
            output_every: self.output_every,
        }
    }

    /// `outline` without copying: the problem for a run and its whole mesh, which the
    /// caller frees once the run is set up.
    pub fn into_outline(mut self) -> (Problem, GlobalMesh) {
        let retained = self.retained_of(&self.mesh);
        let outline = self.mesh.outline();
        let whole = std::mem::replace(&mut self.mesh, outline);
        self.retained = Some(Box::new(retained));
        (self, whole)
    }

    /// The reference position of node `n` (one the run keeps on an outline: of a contact
    /// pair or a prescribed node set).
    pub fn reference_position(&self, n: u32) -> Vec3 {
        match &self.retained {
            Some(r) => r.position(n),
            None => self.mesh.coords[n as usize],
        }
    }

    /// The centre and size of body `b`'s nodes (`frame_of`).
    pub fn body_frame(&self, b: usize) -> (Vec3, f64) {
        match &self.retained {
            Some(r) => r.frame(b),
            None => {
                let body = &self.mesh.bodies[b];
                outline::frame_of(
                    &self.mesh.coords[body.first_node..body.first_node + body.num_nodes],
                )
            }
        }
    }

    /// The boundary faces of the contact pairs' master bodies (`boundary_of`).
    pub fn master_boundary(&self) -> std::borrow::Cow<'_, [BoundaryFace]> {
        match &self.retained {
            Some(r) => std::borrow::Cow::Borrowed(r.master_boundary()),
            None => std::borrow::Cow::Owned(outline::boundary_of(
                &self.mesh,
                &outline::master_bodies_of(&self.contacts, &self.mesh),
            )),
        }
    }

    /// What a run of this problem reads of the whole mesh `mesh` after its setup.
    fn retained_of(&self, mesh: &GlobalMesh) -> Retained {
        let prescribed = self
            .dirichlet
            .iter()
            .map(|bc| self.node_sets[bc.node_set].nodes.as_slice());
        Retained::of(&self.contacts, prescribed, mesh)
    }
}

/// A human-readable summary of a problem (what `solver check` prints).
pub fn summary(p: &Problem) -> String {
    use std::fmt::Write;
    let m = &p.mesh;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "scene '{}' ({}), kinematics {:?}",
        p.name, p.file, p.kinematics
    );
    let _ = writeln!(
        s,
        "  {} bodies, {} elements, {} nodes",
        m.bodies.len(),
        m.num_elements(),
        m.num_nodes()
    );
    for (b, model) in m.bodies.iter().zip(&p.body_models) {
        let _ = writeln!(
            s,
            "  body '{}': {} elements {}..{}, nodes {}..{}, {:?}, {:?}",
            b.name,
            b.kind.name(),
            b.first_element + 1,
            b.first_element + b.num_elements,
            b.first_node + 1,
            b.first_node + b.num_nodes,
            model.material,
            model.formulation
        );
    }
    for ns in &p.node_sets {
        let _ = writeln!(s, "  node set '{}': {} nodes", ns.name, ns.nodes.len());
    }
    for ss in &p.side_sets {
        let _ = writeln!(s, "  side set '{}': {} faces", ss.name, ss.faces.len());
    }
    let _ = writeln!(
        s,
        "  {} prescribed directions, {} pressures, {} tractions, {} body forces",
        p.dirichlet.len(),
        p.pressures.len(),
        p.tractions.len(),
        p.body_forces.len()
    );
    for c in &p.contacts {
        let _ = writeln!(
            s,
            "  contact '{}'{}: {} master faces, {} slave nodes, {}, tolerances normal {:e} tangential {:e} capture {:e}{}",
            c.name,
            if c.discretization == Discretization::Mortar { " (mortar)" } else { "" },
            c.master_faces.len(),
            c.slave_nodes.len(),
            if c.mu > 0.0 { format!("Coulomb mu = {}", c.mu) } else { "frictionless".into() },
            c.normal_tolerance,
            c.tangential_tolerance,
            c.capture_tolerance,
            c.smoothing_width.map(|w| format!(", normal smoothing width {w}")).unwrap_or_default()
        );
    }
    let _ = write!(
        s,
        "  {} steps from t = {} to t = {}; tolerance {:e}",
        p.step_times.len(),
        p.start_time,
        p.step_times.last().copied().unwrap_or(p.start_time),
        p.solver.tolerance
    );
    s
}
