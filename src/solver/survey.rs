//! What the stepper reads of the whole mesh (`Survey`): made on rank 0, which alone holds
//! the whole mesh while the run is set up, and given to every rank, so that every rank
//! makes the same choices from the same values.

use super::choice::{tangent_decision, TangentDecision};
use super::shapes::Plan;
use crate::comm::message::{self, Message, Reader, Writer};
use crate::comm::Comm;
use crate::fem::ElementKind;
use crate::mesh::GlobalMesh;
use crate::problem::Problem;

/// The values the stepper's set-up takes from the whole mesh.
pub struct Survey {
    /// Whether the full tangent is factored, or why not (`choice::tangent_decision`).
    pub tangent: TangentDecision,
    /// Which bodies are evaluated by element matrices (`shapes::Plan`).
    pub plan: Plan,
    /// The diagonal of the mesh's bounding box.
    pub length_scale: f64,
    /// The largest Young's modulus times the smallest element size.
    pub stiffness_scale: f64,
}

impl Survey {
    /// The survey of `whole` (rank 0's, read there only) on every rank. Collective.
    pub fn given<C: Comm + ?Sized>(
        comm: &C,
        problem: &Problem,
        whole: Option<&GlobalMesh>,
    ) -> Self {
        message::broadcast(comm, whole.map(|w| Survey::of(problem, w)).as_ref())
    }

    fn of(problem: &Problem, whole: &GlobalMesh) -> Self {
        Survey {
            tangent: tangent_decision(problem, whole),
            plan: Plan::new(whole, &problem.body_models),
            length_scale: whole.bounding_diagonal(),
            stiffness_scale: stiffness_scale(problem, whole),
        }
    }
}

impl Message for Survey {
    fn write(&self, w: &mut Writer<'_>) {
        w.put(&self.tangent);
        w.put(&self.plan.matrices);
        w.real(self.plan.grid);
        w.put(&self.plan.shapes);
        w.real(self.length_scale);
        w.real(self.stiffness_scale);
    }
    fn read(r: &mut Reader) -> Option<Self> {
        Some(Survey {
            tangent: r.get()?,
            plan: Plan {
                matrices: r.get()?,
                grid: r.real()?,
                shapes: r.get()?,
            },
            length_scale: r.real()?,
            stiffness_scale: r.real()?,
        })
    }
}

/// Largest Young's modulus times the smallest element size.
fn stiffness_scale(problem: &Problem, mesh: &GlobalMesh) -> f64 {
    let e_max = problem
        .body_models
        .iter()
        .map(|m| {
            let (l, mu) = m.material.lambda_mu();
            mu * (3.0 * l + 2.0 * mu) / (l + mu)
        })
        .fold(0.0, f64::max);
    let h_min = (0..mesh.num_elements())
        .filter_map(|e| match mesh.kind(e) {
            ElementKind::Hex8 => crate::fem::element::volume(&mesh.element_coords(e)).ok(),
            ElementKind::Tet10 => crate::fem::tet10::geometry(&mesh.element_coords(e))
                .ok()
                .map(|g| crate::fem::tet10::volume(&g)),
        })
        .fold(f64::INFINITY, f64::min)
        .cbrt();
    e_max * if h_min.is_finite() { h_min } else { 0.0 }
}
