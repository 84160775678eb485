//! Helpers shared by the integration tests.
#![allow(dead_code)]

pub mod bad_scene;
pub mod hill;
pub mod paths;
pub mod punch;
pub mod restart;
pub mod scenes;
pub mod stacked;
pub mod synthetic;
pub mod tets;

#[allow(unused_imports)]
pub use paths::{fresh_dir, gmsh, paper_scene, repo, solver, stderr_text};

use std::path::PathBuf;

use solver::comm::SerialComm;
use solver::problem::Problem;
use solver::run::{run, GlobalState, RunOptions, RunSummary};
use solver::scene::parse_scene;

pub fn problem(text: &str) -> Problem {
    parse_scene(text, "test.toml", "test").unwrap_or_else(|e| panic!("scene rejected: {e}"))
}

/// A serial run of `p`, writing its result to `output` if given; a run that stops early
/// says why in the summary's `failure`.
pub fn run_serial(p: &Problem, output: Option<PathBuf>) -> (RunSummary, GlobalState) {
    run(
        &SerialComm,
        p,
        &RunOptions {
            output,
            verbosity: 0,
            export_operator: None,
            final_state: true,
            partition: Default::default(),
        },
    )
    .expect("run starts")
}

/// A serial run of `p` that must complete.
pub fn solve(p: &Problem) -> (RunSummary, GlobalState) {
    let (summary, state) = run_serial(p, None);
    if let Some(f) = &summary.failure {
        panic!("run failed: {f}");
    }
    (summary, state)
}

/// The CG iterations of all steps of a run.
pub fn cg_iterations(s: &RunSummary) -> u64 {
    s.steps.iter().map(|r| r.cg_iterations).sum()
}

/// The largest difference of a displacement component between `a` and `b`, and the largest
/// displacement component of `b` (the scale).
pub fn max_displacement_difference(a: &GlobalState, b: &GlobalState) -> (f64, f64) {
    let scale = b
        .displacement
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let diff = a
        .displacement
        .iter()
        .zip(&b.displacement)
        .flat_map(|(x, y)| (0..3).map(move |i| (x[i] - y[i]).abs()))
        .fold(0.0f64, f64::max);
    (diff, scale)
}

/// Deterministic pseudo-random numbers in [-1, 1) (xorshift), for distorted meshes.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed.max(1))
    }
    pub fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

pub fn rel_err(a: f64, b: f64, scale: f64) -> f64 {
    (a - b).abs() / scale
}
