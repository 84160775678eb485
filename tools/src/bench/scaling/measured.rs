//! What `--scaling` measured: each rank count's run, the runtime's peak, the fit and the
//! model of one CG iteration built from them.

use super::model::Iteration;
use crate::block::BlockCase;
use crate::runner::log::number_after;

/// The block scene's refinement (n = 10 x 4 = 40 elements per edge).
pub const SCALING_REFINE: usize = 4;
pub const SCALING_RANKS: [usize; 5] = [1, 2, 4, 8, 16];
/// The tiny scene whose peak on `RUNTIME_RANKS` ranks is the runtime's fixed cost.
pub const RUNTIME_SCENE: &str = "run/scenes/paper/capture_release.toml";
pub const RUNTIME_RANKS: usize = 8;

/// What the busiest rank sent per CG iteration (the solver's `communication` line).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sent {
    pub messages: f64,
    pub bytes: f64,
    pub collectives: f64,
    /// Bytes the collectives brought the rank (the levels gathered whole among them).
    pub received: f64,
    /// Wall time of one iteration in the CG loops (their time over their iterations).
    pub seconds: f64,
}

/// Reads the per-iteration counts and time from a solver log.
pub fn sent_per_iteration(log: &str) -> Option<Sent> {
    let line = log
        .lines()
        .find(|l| l.starts_with("communication per rank"))?;
    let loops = &line[line.find("in the CG loops (")? + "in the CG loops (".len()..];
    let iterations: f64 = loops.split_whitespace().next()?.parse().ok()?;
    let seconds: f64 = number_after(loops, "iterations, ")?;
    let per = &line[line.find("per CG iteration: ")? + "per CG iteration: ".len()..];
    Some(Sent {
        seconds: seconds / iterations.max(1.0),
        messages: per.split_whitespace().next()?.parse().ok()?,
        bytes: number_after(per, "messages, ")?,
        collectives: number_after(per, "bytes, ")?,
        received: number_after(per, "collective bytes, ")?,
    })
}

/// One rank count's run.
pub struct Point {
    pub case: BlockCase,
    pub sent: Option<Sent>,
}

impl Point {
    pub fn ranks(&self) -> usize {
        self.case.ranks
    }
    pub fn peak_mib(&self) -> f64 {
        self.case.runs.peak_mib.median
    }
    /// Wall time of one iteration of the CG loops (each model problem's setup excluded).
    pub fn seconds_per_iteration(&self) -> f64 {
        self.sent.map_or(f64::NAN, |s| s.seconds)
    }
}

/// What `--scaling` measured and fitted.
pub struct Scaling {
    pub points: Vec<Point>,
    pub runtime_mib: Option<f64>,
    /// peak = a + b / P (MiB).
    pub fit: Option<(f64, f64)>,
    pub iteration: Option<Iteration>,
    pub failures: Vec<String>,
}

impl Scaling {
    /// a less the runtime's peak: what every rank holds whatever the rank count.
    pub fn replicated_mib(&self) -> Option<f64> {
        Some(self.fit?.0 - self.runtime_mib?)
    }
    /// The replicated part over the 1-rank peak.
    pub fn replicated_fraction(&self) -> Option<f64> {
        let one = self.points.iter().find(|p| p.ranks() == 1)?;
        Some(self.replicated_mib()? / one.peak_mib())
    }
}

/// The model of one CG iteration from the measured points: compute from 1 rank, the
/// replicated part from 1 and 2 ranks (t2 = (t1 - r) / 2 + r, both on real cores), the
/// messages and collectives of the largest rank count, its bytes and what its collectives
/// brought.
pub fn iteration_of(points: &[Point]) -> Option<Iteration> {
    let at = |r: usize| points.iter().find(|p| p.ranks() == r);
    let (one, two) = (at(1)?, at(2)?);
    let t1 = one.seconds_per_iteration();
    let t2 = two.seconds_per_iteration();
    let last = points
        .iter()
        .filter(|p| p.sent.is_some())
        .max_by_key(|p| p.ranks())?;
    let sent = last.sent?;
    let messages = points
        .iter()
        .filter_map(|p| p.sent.map(|s| s.messages))
        .fold(0.0, f64::max);
    // On a loaded machine the 2-rank run may not be faster: then nothing is learnt about
    // the replicated part and the model takes none (its prediction is then an upper
    // bound; the report says so).
    let replicated_s = if t2 < t1 {
        (2.0 * t2 - t1).clamp(0.0, t1)
    } else {
        0.0
    };
    Some(Iteration {
        compute_s: t1,
        replicated_s,
        messages,
        bytes: sent.bytes,
        bytes_ranks: last.ranks() as f64,
        collectives: sent.collectives,
        received: sent.received,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_communication_line_is_read_back() {
        let line = "communication per rank (largest; mean): during the steps 337 messages (329), 4077216 bytes (2494052), 1788 collectives (1788) of 1872976 bytes (1776144); in the CG loops (300 iterations, 3.000 s) 300 messages (300), 1 bytes (1), 2 collectives (2) of 3 bytes (3); per CG iteration: 1.13 messages, 13636 bytes, 5.98 collectives, 6264 collective bytes, 52000 bytes received in collectives (largest rank)";
        let s = sent_per_iteration(&format!("done: x\n{line}\n")).unwrap();
        assert_eq!(
            s,
            Sent {
                messages: 1.13,
                bytes: 13636.0,
                collectives: 5.98,
                received: 52000.0,
                seconds: 0.01
            }
        );
        assert!(sent_per_iteration("done: 1 steps").is_none());
    }
}
