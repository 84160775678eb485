//! The solver library as the bench sees it: every item the bench takes from the `solver`
//! and `partition` crates is imported here and nowhere else, so that a module moving
//! inside the library is one line to fix here. The two functions below turn a scene text
//! the bench generated into a problem, and a problem into its one-rank local mesh.

pub use partition::Decomposition;
pub use solver::comm::SerialComm;
pub use solver::contact::mortar::{ties as mortar_ties, Face, Tie};
pub use solver::contact::search::{Interaction, MasterSurface};
pub use solver::fem::{ElementKind, Formulation};
pub use solver::material::Material;
pub use solver::math::{add, dot, norm, scale, sub, Mat3, Vec3, ZERO33};
pub use solver::mesh::local::LocalMesh;
pub use solver::output::{rfc3339_now, ResultFile};
pub use solver::problem::{PiecewiseLinear, Problem};
pub use solver::run::{run as run_analysis, RunOptions};
pub use solver::scene::{load_scene_refined, parse_scene, Kinematics};
pub use solver::solver::assembly::Assembly;
pub use solver::solver::shapes::Plan;

/// A scene the bench generated, parsed as the solver would parse a file.
pub fn parse(text: &str) -> Result<Problem, String> {
    parse_scene(text, "bench", "bench").map_err(|e| format!("generated scene rejected: {e}"))
}

/// The whole mesh of `problem` as rank 0 of a one-part decomposition.
pub fn local_mesh(problem: &Problem) -> Result<LocalMesh, String> {
    let mesh = &problem.mesh;
    let d = Decomposition::partition(mesh.num_nodes(), &mesh.elements, 1)
        .map_err(|e| format!("partition failed: {e}"))?;
    Ok(LocalMesh::new(mesh, &d, 0))
}
