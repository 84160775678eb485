//! Helpers shared by the integration tests.
#![allow(dead_code)]

pub mod bad_scene;
pub mod paths;

#[allow(unused_imports)]
pub use paths::{fresh_dir, paper_scene, repo, solver, stderr_text};

use solver::comm::SerialComm;
use solver::problem::Problem;
use solver::run::{run, GlobalState, RunOptions, RunSummary};
use solver::scene::parse_scene;

pub fn problem(text: &str) -> Problem {
    parse_scene(text, "test.toml", "test").unwrap_or_else(|e| panic!("scene rejected: {e}"))
}

pub fn solve(p: &Problem) -> (RunSummary, GlobalState) {
    let (summary, state) = run(
        &SerialComm,
        p,
        &RunOptions {
            output: None,
            verbosity: 0,
        },
    )
    .expect("run starts");
    if let Some(f) = &summary.failure {
        panic!("run failed: {f}");
    }
    (summary, state)
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
