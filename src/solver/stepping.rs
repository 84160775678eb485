//! Load stepping through the scene's time segments: predictor, model solve, and automatic
//! cut-back of a step that fails.

use super::assembly::Assembly;
use super::cg::{Cg, CgSettings, ModelOutcome, Problem as ModelProblem, SolveFailure};
use super::constraints::Dirichlet;
use super::loads::Loads;
use crate::comm::Comm;
use crate::math::Vec3;
use crate::mesh::local::LocalMesh;
use crate::problem::Problem;
use std::time::Instant;

/// What one load step did.
#[derive(Clone, Copy, Debug, Default)]
pub struct StepRecord {
    pub step: usize,
    pub time: f64,
    pub cg_iterations: u64,
    pub contact_updates: u64,
    pub residual: f64,
    pub reference: f64,
    pub cutbacks: u64,
    pub wall_time: f64,
}

/// A step that could not be completed even after cutting it back.
#[derive(Clone, Debug)]
pub struct StepFailure {
    pub step: usize,
    pub time: f64,
    pub cause: SolveFailure,
    pub cutbacks: usize,
}

impl std::fmt::Display for StepFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "step {} (t = {}) failed after {} cut-backs: {}",
            self.step, self.time, self.cutbacks, self.cause
        )
    }
}

pub struct Stepper<'a, C: Comm + ?Sized> {
    comm: &'a C,
    problem: &'a Problem,
    asm: Assembly<'a>,
    loads: Loads,
    bc: Dirichlet,
    cg: Cg,
    pub u: Vec<Vec3>,
    u_prev: Vec<Vec3>,
    pub time: f64,
    dt_prev: f64,
    reference_floor: f64,
    length_scale: f64,
}

impl<'a, C: Comm + ?Sized> Stepper<'a, C> {
    pub fn new(comm: &'a C, problem: &'a Problem, mesh: &'a LocalMesh) -> Self {
        let n = mesh.num_nodes();
        Stepper {
            comm,
            problem,
            asm: Assembly::new(mesh, &problem.body_models),
            loads: Loads::new(problem, mesh),
            bc: Dirichlet::new(problem, mesh),
            cg: Cg::new(n),
            u: vec![[0.0; 3]; n],
            u_prev: vec![[0.0; 3]; n],
            time: problem.start_time,
            dt_prev: 0.0,
            reference_floor: 0.0,
            length_scale: problem.mesh.bounding_diagonal(),
        }
    }

    pub fn assembly(&self) -> &Assembly<'a> {
        &self.asm
    }

    pub fn dirichlet(&self) -> &Dirichlet {
        &self.bc
    }

    /// Internal and external force at the last converged state.
    pub fn forces(&self) -> (&[Vec3], &[Vec3]) {
        self.cg.forces()
    }

    /// Advances to `target` (the end of load step `step`, 1-based), cutting back as needed.
    pub fn advance(&mut self, step: usize, target: f64) -> Result<StepRecord, StepFailure> {
        let start = Instant::now();
        let mut record = StepRecord {
            step,
            time: target,
            ..Default::default()
        };
        let mut dt = target - self.time;
        let mut cutbacks = 0usize;
        let mut use_predictor = self.problem.solver.predictor;
        while self.time < target {
            let t_new = if self.time + dt >= target - 1e-12 * dt.abs() {
                target
            } else {
                self.time + dt
            };
            let h = t_new - self.time;
            let mut trial = self.u.clone();
            if use_predictor && self.dt_prev > 0.0 {
                let ratio = h / self.dt_prev;
                for (a, v) in trial.iter_mut().enumerate() {
                    for i in 0..3 {
                        v[i] += ratio * (self.u[a][i] - self.u_prev[a][i]);
                    }
                }
            }
            let values = self.bc.constrained_values(t_new);
            self.bc.impose(&mut trial, &values);
            let settings = CgSettings {
                tolerance: self.problem.solver.tolerance,
                max_iterations: self.problem.solver.max_iterations,
                reference_floor: self.reference_floor,
                length_scale: self.length_scale,
            };
            let pb = ModelProblem {
                comm: self.comm,
                asm: &self.asm,
                loads: &self.loads,
                bc: &self.bc,
                time: t_new,
            };
            let result = self.cg.solve(&pb, &mut trial, &settings);
            match result {
                Ok(ModelOutcome {
                    iterations,
                    residual,
                    reference,
                }) => {
                    record.cg_iterations += iterations as u64;
                    record.residual = residual;
                    record.reference = reference;
                    self.u_prev = std::mem::replace(&mut self.u, trial);
                    self.dt_prev = h;
                    self.time = t_new;
                    // Later steps are judged against at least a fraction of the largest force
                    // seen so far, so a step that unloads to zero does not chase round-off.
                    self.reference_floor = self.reference_floor.max(reference);
                }
                Err(cause) => {
                    if let SolveFailure::NotConverged { iterations, .. }
                    | SolveFailure::NonPositiveCurvature { iterations }
                    | SolveFailure::NonFinite { iterations } = cause
                    {
                        record.cg_iterations += iterations as u64;
                    }
                    if use_predictor && self.dt_prev > 0.0 {
                        // First retry the same step from the last converged state.
                        use_predictor = false;
                    } else if cutbacks < self.problem.solver.max_cutbacks {
                        cutbacks += 1;
                        dt = h / 2.0;
                    } else {
                        return Err(StepFailure {
                            step,
                            time: t_new,
                            cause,
                            cutbacks,
                        });
                    }
                }
            }
        }
        record.cutbacks = cutbacks as u64;
        record.wall_time = start.elapsed().as_secs_f64();
        Ok(record)
    }
}
