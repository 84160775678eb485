//! What the nonlinear CG spent its iterations on, counted per load step for the `-vv` log:
//! restarts and why, the step's probes and corrections, the preconditioner's rebuilds, and
//! the residual's reduction over windows of iterations (a preconditioner that went stale
//! shows as a rate that worsens within a model problem; one that never fitted, as a poor
//! rate from the start).

use crate::comm::Traffic;
use std::fmt::Write;

/// Iterations per window of the reduction rate.
pub const WINDOW: usize = 50;
/// Model problems per trace whose rates are kept.
const MAX_PROBLEMS: usize = 64;

#[derive(Clone, Debug, Default)]
pub struct CgTrace {
    pub model_problems: usize,
    pub iterations: usize,
    /// Internal-force evaluations (each probe, step and correction is one).
    pub force_evaluations: usize,
    /// Polak-Ribiere+ clipped beta to zero.
    pub restarts_pr: usize,
    /// r.p <= 0: the direction replaced by the preconditioned residual.
    pub restarts_descent: usize,
    /// Block Jacobi rebuilt within a model problem (a restart each).
    pub jacobi_rebuilds: usize,
    /// Step halvings (an element failed at the full step).
    pub halvings: usize,
    /// Secant corrections tried, and those refused (an element failed).
    pub secants: usize,
    pub secants_refused: usize,
    /// Multilevel hierarchy builds, coarse-operator builds.
    pub ml_builds: usize,
    pub coarse_builds: usize,
    /// Load increments that kept the multilevel hierarchy of an earlier one.
    pub ml_kept: usize,
    /// log10 of the residual's reduction per window of iterations, per model problem (the
    /// first MAX_PROBLEMS, at most 400 windows each).
    pub rates: Vec<Vec<f64>>,
    recording: bool,
    /// What this rank sent during the CG loops (after each model problem's setup), and
    /// the traffic count at the current loop's start.
    pub traffic: Traffic,
    loop_start: Option<(Traffic, std::time::Instant)>,
    /// Wall time in the CG loops (s).
    pub loop_seconds: f64,
    /// Contact updates between model problems (the search with its ghost exchange,
    /// capture, release and the Coulomb update), and their wall time (s).
    pub contact_updates: usize,
    pub contact_seconds: f64,
}

impl CgTrace {
    /// Starts a model problem's CG loop; `sent` is this rank's traffic count now.
    pub(super) fn start(&mut self, sent: Traffic) {
        self.model_problems += 1;
        self.loop_start = Some((sent, std::time::Instant::now()));
        // Rates of the first model problems only: a stepper nobody takes the trace from
        // (the tests drive it directly) keeps a bounded record.
        self.recording = self.rates.len() < MAX_PROBLEMS;
        if self.recording {
            self.rates.push(Vec::new());
        }
    }

    /// Ends the CG loop started last (if any); `sent` is this rank's traffic count now.
    pub(super) fn end_loop(&mut self, sent: Traffic) {
        if let Some((start, at)) = self.loop_start.take() {
            self.traffic += sent.since(&start);
            self.loop_seconds += at.elapsed().as_secs_f64();
        }
    }

    /// Counts a contact update that took `seconds`.
    pub fn contact_update(&mut self, seconds: f64) {
        self.contact_updates += 1;
        self.contact_seconds += seconds;
    }

    /// Records the residual at iteration `it`; `window_start` holds the residual at the
    /// window's start.
    pub(super) fn record(&mut self, it: usize, rnorm: f64, window_start: &mut f64) {
        self.iterations += 1;
        if it.is_multiple_of(WINDOW) && rnorm > 0.0 && *window_start > 0.0 {
            if let Some(r) = self
                .rates
                .last_mut()
                .filter(|r| r.len() < 400 && self.recording)
            {
                r.push((rnorm / *window_start).log10());
            }
            *window_start = rnorm;
        }
    }

    /// One line for the log.
    pub fn summary(&self) -> String {
        let mut s = format!(
            "CG trace: {} model problem(s), {} iterations, {} force evaluations; restarts: Polak-Ribiere {}, descent {}, Jacobi rebuilds {}; halvings {}, secants {} (refused {}); multilevel builds {} (kept at {} new increments), coarse builds {}",
            self.model_problems,
            self.iterations,
            self.force_evaluations,
            self.restarts_pr,
            self.restarts_descent,
            self.jacobi_rebuilds,
            self.halvings,
            self.secants,
            self.secants_refused,
            self.ml_builds,
            self.ml_kept,
            self.coarse_builds
        );
        for (k, r) in self.rates.iter().enumerate().filter(|(_, r)| !r.is_empty()) {
            let _ = write!(s, "; problem {} log10 reduction per {WINDOW}:", k + 1);
            for v in r {
                let _ = write!(s, " {v:.2}");
            }
        }
        s
    }
}
