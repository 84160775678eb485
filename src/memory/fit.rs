//! Does a run fit the memory it may use? The estimate per rank against every bound: the
//! machine's (MemAvailable, the cgroup's headroom) shared by the ranks on the machine, the
//! address space limit per process.

use super::available::Bound;
use super::bytes::format_bytes as fb;
use super::model::{estimate, estimate_run, ranks_on_one_machine, ranks_to_fit, Counts, Estimate};

/// The comparison of a run's estimate with the memory it may use.
#[derive(Clone, Debug, PartialEq)]
pub struct Fit {
    pub counts: Counts,
    pub estimate: Estimate,
    /// Ranks of the run on this machine.
    pub ranks_here: usize,
    /// The bound the run exceeds (the first, tightest first), if any.
    pub exceeded: Option<Bound>,
}

/// What the ranks on this machine need against `b`.
fn need(e: &Estimate, ranks_here: usize, b: &Bound) -> f64 {
    if b.shared {
        e.per_rank() * ranks_here as f64
    } else {
        e.per_rank()
    }
}

/// Compares the estimate for `ranks` ranks (under mpirun when `mpi`), `ranks_here` of
/// them on this machine, with `bounds`.
pub fn check_fit(c: &Counts, ranks: usize, mpi: bool, ranks_here: usize, bounds: &[Bound]) -> Fit {
    let e = estimate_run(c, ranks, mpi);
    let exceeded = bounds
        .iter()
        .find(|b| need(&e, ranks_here, b) > b.bytes)
        .cloned();
    Fit {
        counts: *c,
        estimate: e,
        ranks_here,
        exceeded,
    }
}

impl Fit {
    pub fn fits(&self) -> bool {
        self.exceeded.is_none()
    }

    /// Why the run does not fit and what would: the estimate, what is available, how many
    /// ranks fit on this machine and how many machines like it would run the scene.
    pub fn refusal(&self) -> Option<String> {
        let b = self.exceeded.as_ref()?;
        let (c, e) = (&self.counts, &self.estimate);
        let here = need(e, self.ranks_here, b);
        let machine = if b.shared && self.ranks_here > 1 {
            format!(" ({} on this machine)", fb(here))
        } else {
            String::new()
        };
        let mut s = format!(
            "not enough memory: {} elements and {} nodes need an estimated {} per rank on {} \
             rank(s){machine}, but {} is available ({})",
            c.elements,
            c.nodes,
            fb(e.per_rank()),
            e.ranks,
            fb(b.bytes),
            b.source
        );
        if b.shared && self.ranks_here > 1 {
            let k = ranks_on_one_machine(c, b.bytes, self.ranks_here);
            if k > 0 {
                s += &format!("; {k} rank(s) would fit on this machine");
            }
        }
        let (unit, each) = if b.shared {
            ("machines like this one", ", one rank each")
        } else {
            ("ranks", " with this limit each")
        };
        match ranks_to_fit(c, b.bytes) {
            Some(m) => {
                s += &format!(
                    "; it would fit on {m} {unit}{each} ({} per rank)",
                    fb(estimate(c, m).per_rank())
                )
            }
            None => {
                s += &format!(
                    "; no number of {unit} fits it{each}: rank 0 holds the whole mesh ({}) while the run is set up",
                    fb(e.whole_mesh)
                )
            }
        }
        s += ". `solver run --force` runs it anyway";
        Some(s)
    }
}

/// The estimate in one line (what `solver check` and `solver run -v` print).
pub fn estimate_line(e: &Estimate) -> String {
    format!(
        "memory: estimated peak {} per rank on {} rank(s), {} in all (runtime {}, whole mesh {}, \
         the rank's share {}, preconditioner {})",
        fb(e.per_rank()),
        e.ranks,
        fb(e.total()),
        fb(e.fixed),
        fb(e.whole_mesh),
        fb(e.share),
        fb(e.coarse)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bound(bytes: f64, shared: bool) -> Bound {
        Bound {
            bytes,
            source: "test".into(),
            shared,
        }
    }

    /// 10^6 elements and nodes: what fits and what does not follows from the model's own
    /// numbers, so the test checks the comparison and the arithmetic of the message.
    #[test]
    fn refusal_names_estimate_available_and_ranks() {
        let c = Counts {
            elements: 1_000_000,
            nodes: 1_000_000,
            full_elements: 1_000_000,
            shaped_elements: 1_000_000,
            two_level: false,
            multilevel: false,
            friction: false,
            nonlinear: false,
            tangent: false,
            plastic_point_elements: 0,
            ..Counts::default()
        };
        let one = estimate(&c, 1).per_rank();
        assert!(check_fit(&c, 1, true, 1, &[bound(one * 1.01, true)]).fits());
        let f = check_fit(&c, 1, true, 1, &[bound(one * 0.99, true)]);
        assert!(!f.fits());
        let m = ranks_to_fit(&c, one * 0.99).unwrap();
        assert!(m >= 2);
        assert!(estimate(&c, m).per_rank() <= one * 0.99);
        assert!(estimate(&c, m - 1).per_rank() > one * 0.99);
        let text = f.refusal().unwrap();
        assert!(
            text.contains(&format!("it would fit on {m} machines")),
            "{text}"
        );
        assert!(text.contains("1000000 elements"), "{text}");
        // Two ranks on one machine share it; a per-process limit is not shared.
        let two = estimate(&c, 2).per_rank();
        assert!(!check_fit(&c, 2, true, 2, &[bound(two * 1.5, true)]).fits());
        assert!(check_fit(&c, 2, true, 2, &[bound(two * 1.5, false)]).fits());
    }
}
