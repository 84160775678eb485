//! Does a run fit the memory it may use? The estimate against every bound: the machine's
//! (MemAvailable, the cgroup's headroom) shared by the ranks on the machine (rank 0 at its
//! peak with the whole mesh, the others without it), the address space limit per process
//! (rank 0's peak).

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
    /// Whether rank 0 is one of them.
    pub root_here: bool,
    /// The bound the run exceeds (the first, tightest first), if any.
    pub exceeded: Option<Bound>,
}

/// What the ranks on this machine (`here`: how many, and whether rank 0 is one) need
/// against `b`.
fn need(e: &Estimate, (ranks_here, root_here): (usize, bool), b: &Bound) -> f64 {
    if b.shared {
        e.on_machine(ranks_here, root_here)
    } else {
        e.per_rank()
    }
}

/// Compares the estimate for `ranks` ranks (under mpirun when `mpi`), `here.0` of them on
/// this machine, rank 0 among them when `here.1`, with `bounds`.
pub fn check_fit(
    c: &Counts,
    ranks: usize,
    mpi: bool,
    here: (usize, bool),
    bounds: &[Bound],
) -> Fit {
    let e = estimate_run(c, ranks, mpi);
    let exceeded = bounds.iter().find(|b| need(&e, here, b) > b.bytes).cloned();
    Fit {
        counts: *c,
        estimate: e,
        ranks_here: here.0,
        root_here: here.1,
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
        let here = need(e, (self.ranks_here, self.root_here), b);
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
        assert!(check_fit(&c, 1, true, (1, true), &[bound(one * 1.01, true)]).fits());
        let f = check_fit(&c, 1, true, (1, true), &[bound(one * 0.99, true)]);
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
        let e = estimate(&c, 2);
        let two = e.per_rank();
        let both = two + (two - e.whole_mesh);
        assert!(!check_fit(&c, 2, true, (2, true), &[bound(both * 0.99, true)]).fits());
        assert!(check_fit(&c, 2, true, (2, true), &[bound(both * 1.01, true)]).fits());
        assert!(check_fit(&c, 2, true, (2, true), &[bound(two * 1.01, false)]).fits());
    }

    /// Rank 0 alone holds the whole mesh: a machine's ranks need rank 0's peak once (when
    /// rank 0 is there) and the rest without the whole mesh.
    #[test]
    fn a_machine_counts_the_whole_mesh_once() {
        let c = Counts {
            elements: 1_000_000,
            nodes: 1_000_000,
            multilevel: true,
            ..Counts::default()
        };
        let e = estimate(&c, 16);
        assert!(e.whole_mesh > 0.0);
        let rest = e.fixed + e.share + e.coarse;
        assert_eq!(e.other_rank(), rest);
        assert_eq!(e.on_machine(8, true), e.per_rank() + 7.0 * rest);
        assert_eq!(e.on_machine(8, false), 8.0 * rest);
        assert_eq!(e.total(), e.per_rank() + 15.0 * rest);
        assert_eq!(estimate(&c, 1).total(), estimate(&c, 1).per_rank());
        // The check: 8 ranks with rank 0 fit where 8 times rank 0's peak would not.
        let b = [bound(e.on_machine(8, true) * 1.01, true)];
        assert!(check_fit(&c, 16, true, (8, true), &b).fits());
        assert!(e.per_rank() * 8.0 > b[0].bytes);
        let b = [bound(e.on_machine(8, false) * 0.99, true)];
        assert!(!check_fit(&c, 16, true, (8, false), &b).fits());
    }
}
