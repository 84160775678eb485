//! The scaling model of `bench --scaling`: the per-rank memory fitted as a + b/P, and the
//! time of one CG iteration on P ranks from a latency-bandwidth model of the counted
//! messages beside the measured compute rate, predicted for strong scaling (the measured
//! mesh on more ranks) and weak scaling (the same share per rank on more ranks).

/// The network the prediction assumes: per-message latency (s) and bandwidth (bytes/s).
/// A current InfiniBand cluster: about 1.5 us and 10 GB/s per link (HDR is 1 us and
/// 25 GB/s; stating the slower figures keeps the prediction on the safe side).
pub const LATENCY_S: f64 = 1.5e-6;
pub const BANDWIDTH: f64 = 10e9;

/// Least-squares fit of y = a + b / x over the points (x, y); `None` for fewer than two
/// distinct x.
pub fn fit_inverse(points: &[(f64, f64)]) -> Option<(f64, f64)> {
    let n = points.len() as f64;
    let (sx, sy) = points
        .iter()
        .fold((0.0, 0.0), |(sx, sy), &(x, y)| (sx + 1.0 / x, sy + y));
    let (sxx, sxy) = points.iter().fold((0.0, 0.0), |(sxx, sxy), &(x, y)| {
        (sxx + 1.0 / (x * x), sxy + y / x)
    });
    let det = n * sxx - sx * sx;
    if points.len() < 2 || det.abs() <= 1e-12 * n * sxx {
        return None;
    }
    let b = (n * sxy - sx * sy) / det;
    let a = (sy - b * sx) / n;
    Some((a, b))
}

/// What one CG iteration costs on one rank, measured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Iteration {
    /// Compute time of one CG iteration of the whole mesh on one rank (s).
    pub compute_s: f64,
    /// The part of it every rank repeats whatever the rank count (s): the levels of the
    /// multilevel hierarchy built whole on every rank.
    pub replicated_s: f64,
    /// Point-to-point messages a rank sends per iteration once it has all its neighbours
    /// (the largest count measured).
    pub messages: f64,
    /// Bytes the busiest rank sends per iteration on `bytes_ranks` ranks.
    pub bytes: f64,
    pub bytes_ranks: f64,
    /// Collective calls per iteration.
    pub collectives: f64,
    /// Bytes the collectives bring a rank per iteration (measured on `bytes_ranks` ranks):
    /// mostly the split coarse levels' vectors, gathered whole on every rank, so of the
    /// size of the levels and not of the rank's part.
    pub received: f64,
}

impl Iteration {
    /// Seconds per CG iteration on `p` ranks, with the whole problem `scale` times the
    /// measured one (strong scaling: 1; weak scaling: p, each rank keeping its share of
    /// one rank's problem). The halo bytes of a rank go with its part's surface, (size per
    /// rank)^(2/3); a collective costs a latency and 8 bytes per level of a binary tree,
    /// and what the collectives bring a rank goes with the whole problem (`scale`): the
    /// levels gathered whole grow with the mesh and not with the part.
    pub fn seconds(&self, p: f64, scale: f64) -> f64 {
        let per_rank = scale / p;
        let compute = (self.compute_s - self.replicated_s) * per_rank + self.replicated_s * scale;
        if p <= 1.0 {
            return compute;
        }
        let surface = (per_rank * self.bytes_ranks).powf(2.0 / 3.0);
        let bytes = self.bytes * surface;
        let tree = p.log2().ceil();
        let comm = self.messages * LATENCY_S
            + bytes / BANDWIDTH
            + self.collectives * tree * (LATENCY_S + 8.0 / BANDWIDTH)
            + self.received * scale / BANDWIDTH;
        compute + comm
    }

    /// Parallel efficiency on `p` ranks: strong scaling (t(1) / (p t(p))).
    pub fn strong_efficiency(&self, p: f64) -> f64 {
        self.seconds(1.0, 1.0) / (p * self.seconds(p, 1.0))
    }

    /// Weak scaling efficiency (t(1) / t(p), the problem p times larger).
    pub fn weak_efficiency(&self, p: f64) -> f64 {
        self.seconds(1.0, 1.0) / self.seconds(p, p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fit_recovers_a_and_b_of_exact_points() {
        let pts: Vec<(f64, f64)> = [1.0, 2.0, 4.0, 8.0, 16.0]
            .iter()
            .map(|&p| (p, 82.3 + 110.0 / p))
            .collect();
        let (a, b) = fit_inverse(&pts).unwrap();
        // Exact data: only rounding in the normal equations (~1e-13 relative).
        assert!(
            (a - 82.3).abs() < 1e-9 && (b - 110.0).abs() < 1e-9,
            "{a} {b}"
        );
        assert!(fit_inverse(&[(2.0, 1.0), (2.0, 3.0)]).is_none());
    }

    #[test]
    fn without_communication_or_replication_the_model_scales_perfectly() {
        let it = Iteration {
            compute_s: 0.01,
            replicated_s: 0.0,
            messages: 0.0,
            bytes: 0.0,
            bytes_ranks: 2.0,
            collectives: 0.0,
            received: 0.0,
        };
        for p in [2.0, 64.0, 1024.0] {
            // Pure arithmetic on exactly representable ratios (~1e-16).
            assert!((it.strong_efficiency(p) - 1.0).abs() < 1e-12);
            assert!((it.weak_efficiency(p) - 1.0).abs() < 1e-12);
        }
        // A replicated half: Amdahl's 1 / (p (1/2 + 1/(2p))) = 2 / (p + 1).
        let amdahl = Iteration {
            replicated_s: 0.005,
            ..it
        };
        assert!((amdahl.strong_efficiency(3.0) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn halo_bytes_shrink_with_the_part_in_strong_scaling() {
        let it = Iteration {
            compute_s: 0.0,
            replicated_s: 0.0,
            messages: 0.0,
            bytes: 1e6,
            bytes_ranks: 8.0,
            collectives: 0.0,
            received: 0.0,
        };
        // At the measured rank count the model gives the measured bytes' time; 8 times the
        // ranks quarter the surface (8^(2/3) = 4).
        assert!((it.seconds(8.0, 1.0) - 1e6 / BANDWIDTH).abs() < 1e-15);
        assert!((it.seconds(64.0, 1.0) - 0.25e6 / BANDWIDTH).abs() < 1e-15);
        // Weak scaling keeps each rank's surface.
        assert!((it.seconds(64.0, 64.0 / 8.0) - 1e6 / BANDWIDTH).abs() < 1e-15);
    }

    #[test]
    fn what_the_collectives_bring_grows_with_the_whole_problem() {
        let it = Iteration {
            compute_s: 0.0,
            replicated_s: 0.0,
            messages: 0.0,
            bytes: 0.0,
            bytes_ranks: 8.0,
            collectives: 0.0,
            received: 1e6,
        };
        // Strong scaling: the same levels gathered whatever the rank count; weak scaling:
        // 64 times the problem, 64 times the bytes (exact ratios of ~1e-4 s: 1e-15).
        assert!((it.seconds(8.0, 1.0) - 1e6 / BANDWIDTH).abs() < 1e-15);
        assert!((it.seconds(1024.0, 1.0) - 1e6 / BANDWIDTH).abs() < 1e-15);
        assert!((it.seconds(64.0, 64.0) - 64e6 / BANDWIDTH).abs() < 1e-15);
    }
}
