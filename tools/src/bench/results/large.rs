//! The large section's results (`--large`): the constants of the run, the memory check
//! before it, each rank count's outcome. The runner (`large.rs`) produces them and the
//! report (`report/large.rs`) reads them.

use crate::block::{marginal_bytes, speedup, BlockCase, BLOCK_SCENE};
use crate::machine::RunInfo;
use crate::runner::process::MIB;
use crate::runner::solver::{repo_root, Compare, Precond};
use crate::stats::Stat;

/// Refinement factor of the large run: n = 80, 2 x 512000 elements.
pub const LARGE_REFINE: usize = 8;
/// Refinement factors of the pilot runs whose peak memory predicts the large run's.
pub const LARGE_PILOT: [usize; 2] = [2, 4];
/// The large run starts only when ranks x its predicted peak per rank x this fits in the
/// machine's MemAvailable.
pub const LARGE_MEMORY_MARGIN: f64 = 1.25;
/// It is stopped when the machine's MemAvailable falls below this (bytes) ...
pub const LARGE_MIN_AVAILABLE: f64 = 1024.0 * MIB;
/// ... or after this long.
pub const LARGE_TIMEOUT_S: f64 = 6.0 * 3600.0;
/// Rank counts of `--large` without `--ranks`.
pub const LARGE_DEFAULT_RANKS: [usize; 1] = [2];

/// The memory check before a large run.
pub struct MemoryEstimate {
    /// (n, elements, peak MiB per rank) of the pilot runs.
    pub pilot: Vec<(usize, usize, f64)>,
    /// Growth of the peak per element added per rank between the pilots, bytes.
    pub marginal_bytes: f64,
    /// Elements of the large run.
    pub elements: usize,
    pub predicted_mib_per_rank: f64,
    pub available_mib: Option<f64>,
    pub fits: bool,
}

impl MemoryEstimate {
    /// From the two pilot runs on `ranks` ranks, against `available_mib`.
    pub fn new(
        pilot: &[&BlockCase],
        ranks: usize,
        available_mib: Option<f64>,
    ) -> Result<MemoryEstimate, String> {
        let [a, b] = pilot else {
            return Err("the memory estimate needs two pilot runs".into());
        };
        let per_rank = |c: &BlockCase| c.elements() as f64 / ranks as f64;
        let de = per_rank(b) - per_rank(a);
        let (peak_a, peak_b) = (a.runs.peak_mib.median, b.runs.peak_mib.median);
        let marginal_bytes = (peak_b - peak_a) * MIB / de;
        let last_refine = LARGE_PILOT[LARGE_PILOT.len() - 1];
        let elements = (b.elements() as f64 * (LARGE_REFINE as f64 / last_refine as f64).powi(3))
            .round() as usize;
        // Linear in elements per rank through the larger pilot; if the peak did not grow
        // (a measurement gone wrong), in proportion to it.
        let predicted_mib_per_rank = if marginal_bytes > 0.0 {
            peak_b + marginal_bytes * (elements as f64 / ranks as f64 - per_rank(b)) / MIB
        } else {
            peak_b * elements as f64 / b.elements() as f64
        };
        let fits = available_mib.is_some_and(|avail| {
            ranks as f64 * predicted_mib_per_rank * LARGE_MEMORY_MARGIN <= avail
        });
        Ok(MemoryEstimate {
            pilot: pilot
                .iter()
                .map(|c| (c.n, c.elements(), c.runs.peak_mib.median))
                .collect(),
            marginal_bytes,
            elements,
            predicted_mib_per_rank,
            available_mib,
            fits,
        })
    }

    /// The check in one sentence (progress, report and the reason a run did not start).
    pub fn text(&self, ranks: usize) -> String {
        let pilot: Vec<String> = self
            .pilot
            .iter()
            .map(|(n, e, p)| format!("n = {n} ({e} elements) {p:.1} MiB"))
            .collect();
        format!(
            "pilot peaks per rank {}; {:.0} B per element added per rank; predicted {:.0} MiB \
             per rank, {:.0} MiB on {ranks} rank(s), x {LARGE_MEMORY_MARGIN} against {} \
             available: {}",
            pilot.join(", "),
            self.marginal_bytes,
            self.predicted_mib_per_rank,
            ranks as f64 * self.predicted_mib_per_rank,
            self.available_mib
                .map_or("unknown".to_string(), |m| format!("{m:.0} MiB")),
            if self.fits { "fits" } else { "does not fit" }
        )
    }
}

/// The memory model's estimate of the large run's peak per rank on `ranks` ranks under
/// mpirun (what `solver check --refine 8 --ranks R` prints and `solver run` checks), MiB.
pub fn model_estimate_mib(ranks: usize, precond: Precond) -> Option<f64> {
    use solver::problem::Preconditioner;
    let scene = repo_root().join(BLOCK_SCENE);
    let named = match precond {
        Precond::Multilevel => Preconditioner::Multilevel,
        Precond::Auto => Preconditioner::Auto,
        _ => Preconditioner::TwoLevel,
    };
    let size =
        solver::scene::counts::scene_size(&scene, LARGE_REFINE as u32)?.with_override(Some(named));
    Some(solver::memory::estimate_run(&size.counts, ranks, true).per_rank() / MIB)
}

/// The model's estimate beside the measured peak, in one sentence.
pub fn model_text(ranks: usize, precond: Precond, measured_mib: Option<f64>) -> String {
    match (model_estimate_mib(ranks, precond), measured_mib) {
        (Some(e), Some(m)) => format!(
            "memory model {e:.1} MiB per rank, measured peak {m:.1} MiB ({:+.1}%)",
            100.0 * (e / m - 1.0)
        ),
        (Some(e), None) => format!("memory model {e:.1} MiB per rank, no measured peak"),
        (None, _) => "memory model: the scene's counts could not be read".into(),
    }
}

/// How the large run on one rank count went.
pub enum LargeOutcome {
    Finished(Box<BlockCase>),
    Failed(String),
    /// Not started (the pilots failed or the memory does not suffice).
    NotRun(String),
}

pub struct LargeRun {
    pub ranks: usize,
    pub precond: Precond,
    pub estimate: Result<MemoryEstimate, String>,
    pub outcome: LargeOutcome,
}

impl LargeRun {
    pub fn finished(&self) -> Option<&BlockCase> {
        match &self.outcome {
            LargeOutcome::Finished(c) => Some(c),
            _ => None,
        }
    }

    /// Growth of the peak per rank from the larger pilot to the large run, per element
    /// added per rank (bytes).
    pub fn marginal_bytes(&self) -> Option<f64> {
        let c = self.finished()?;
        let &(_, e, peak) = self.estimate.as_ref().ok()?.pilot.last()?;
        marginal_bytes((e, peak), c)
    }
}

/// Everything `--large` measured.
pub struct Large {
    pub info: RunInfo,
    pub precond: Precond,
    pub runs: Vec<LargeRun>,
    /// The first finished run's result file against the second's.
    pub compare: Option<Result<Compare, String>>,
}

impl Large {
    pub fn finished(&self) -> Vec<&BlockCase> {
        self.runs.iter().filter_map(LargeRun::finished).collect()
    }

    /// Speed-up of the fewest ranks over the most, when both finished.
    pub fn speedup(&self) -> Option<Stat> {
        let f = self.finished();
        let a = f.iter().min_by_key(|c| c.ranks)?;
        let b = f.iter().max_by_key(|c| c.ranks)?;
        (a.ranks < b.ranks).then(|| speedup(a, b))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::fixture::case;

    /// Pilots at n = 20 and 40 on 2 ranks with peaks of 48 and 160 MiB (8000 and 64000
    /// elements per rank): 112 MiB over 56000 elements, so n = 80 (512000 per rank) needs
    /// 160 + 112 x 448000 / 56000 = 1056 MiB per rank, 2640 MiB on 2 ranks with the
    /// margin. Tolerances: a few roundings of numbers of order 1e3.
    #[test]
    fn memory_estimate_extrapolates_the_pilots() {
        let t = Precond::TwoLevel;
        let (a, b) = (case(20, 2, t, 239, Ok(4.4)), case(40, 2, t, 377, Ok(4.4)));
        let e = MemoryEstimate::new(&[&a, &b], 2, Some(2700.0)).unwrap();
        assert_eq!(e.elements, 1_024_000);
        assert!((e.marginal_bytes - 112.0 * MIB / 56000.0).abs() < 1e-9);
        assert!((e.predicted_mib_per_rank - 1056.0).abs() < 1e-9);
        assert!(e.fits);
        assert!(
            !MemoryEstimate::new(&[&a, &b], 2, Some(2600.0))
                .unwrap()
                .fits
        );
        assert!(!MemoryEstimate::new(&[&a, &b], 2, None).unwrap().fits);
        assert!(e
            .text(2)
            .ends_with("x 1.25 against 2700 MiB available: fits"));
        assert!(MemoryEstimate::new(&[&a], 2, None).is_err());
    }

    /// The model's estimate of the n = 80 run is the scene's own (2 x 80^3 elements, 2 x
    /// 81^3 nodes) and is shown beside a measured peak with their difference.
    #[test]
    fn model_estimate_beside_the_peak() {
        let c = solver::memory::Counts {
            elements: 2 * 80 * 80 * 80,
            nodes: 2 * 81 * 81 * 81,
            full_elements: 2 * 80 * 80 * 80,
            shaped_elements: 0,
            two_level: true,
            multilevel: false,
            friction: false,
            nonlinear: false,
            tangent: false,
            plastic_point_elements: 0,
            ..solver::memory::Counts::default()
        };
        let want = solver::memory::estimate_run(&c, 2, true).per_rank() / MIB;
        let got = model_estimate_mib(2, Precond::TwoLevel).unwrap();
        assert_eq!(got, want);
        let text = model_text(2, Precond::TwoLevel, Some(want / 1.1));
        assert!(text.ends_with("MiB (+10.0%)"), "{text}");
        assert!(text.starts_with(&format!("memory model {want:.1} MiB per rank")));
    }

    /// A peak that did not grow between the pilots is scaled with the elements instead.
    #[test]
    fn memory_estimate_without_growth() {
        let t = Precond::TwoLevel;
        let (a, mut b) = (case(20, 2, t, 239, Ok(4.4)), case(40, 2, t, 377, Ok(4.4)));
        b.runs.peak_mib = a.runs.peak_mib;
        let e = MemoryEstimate::new(&[&a, &b], 2, Some(1e6)).unwrap();
        assert_eq!(e.predicted_mib_per_rank, 48.0 * 8.0);
    }

    /// The marginal bytes of a large run over its larger pilot, per element added per rank.
    #[test]
    fn marginal_bytes_of_the_large_run() {
        let t = Precond::TwoLevel;
        let (a, b) = (case(20, 2, t, 239, Ok(4.4)), case(40, 2, t, 377, Ok(4.4)));
        let run = LargeRun {
            ranks: 2,
            precond: t,
            estimate: MemoryEstimate::new(&[&a, &b], 2, Some(1e6)),
            outcome: LargeOutcome::Finished(Box::new(case(80, 2, t, 716, Ok(4.4)))),
        };
        // 160 -> 1056 MiB from 64000 to 512000 elements per rank.
        let m = run.marginal_bytes().unwrap();
        assert!((m - 896.0 * MIB / 448000.0).abs() < 1e-9, "{m}");
    }
}
