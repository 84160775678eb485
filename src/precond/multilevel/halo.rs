//! The exchange of a coarse level held as rows split over the ranks (`super::Split`): the
//! other ranks' unknowns this rank's rows reach, fetched from them before a product, in
//! place of every rank's rows gathered; the same for the rows of P^T a rank restricts with
//! and for the aggregates of its owned nodes, which the coarse correction is prolonged to.
//! Gathering the first coarse level's vector for each of these brought every rank 3.4 MB
//! a CG iteration at n = 40 (its 32928 unknowns, 263 kB, about 13 times), the same on 2
//! and 16 ranks and growing with the mesh; each reads only the unknowns of its own rows
//! and of those of a few neighbouring ranks (0.07 MB a CG iteration on 16 ranks).

use crate::comm::plan::ExchangePlan;
use crate::comm::Comm;
use std::ops::Range;

/// What a split level's products exchange, fixed when the level is built: the project's
/// point-to-point plan (`ExchangePlan`) over the level's unknowns, one value each.
pub struct Halo {
    plan: ExchangePlan,
}

impl Halo {
    /// From the unknowns this rank's rows reach (`reached`, over the whole level), its rows
    /// being `own` of a level whose rows go `per` to a rank (rank r holds r per to
    /// (r + 1) per - 1; collective).
    pub fn new<C: Comm + ?Sized>(
        comm: &C,
        reached: &[bool],
        own: Range<usize>,
        per: usize,
    ) -> Halo {
        // Each unknown held elsewhere, asked of its holder and written in its own place.
        let wanted: Vec<(u32, u32)> = (0..reached.len())
            .filter(|&c| reached[c] && !own.contains(&c))
            .map(|c| (c as u32, c as u32))
            .collect();
        let owners: Vec<usize> = wanted.iter().map(|&(c, _)| c as usize / per).collect();
        let first = own.start;
        Halo {
            plan: ExchangePlan::fetch(comm, &wanted, &owners, |c| Some(c as usize - first)),
        }
    }

    /// Puts into `all` (the whole level's vector) the other ranks' values of the unknowns
    /// this rank's rows reach, sending them those of `mine` (this rank's rows) theirs reach
    /// (collective among the ranks concerned).
    pub fn fetch<C: Comm + ?Sized>(&self, comm: &C, mine: &[f64], all: &mut [f64]) {
        let (src, _) = mine.as_chunks::<1>();
        let (dst, _) = all.as_chunks_mut::<1>();
        self.plan.run(comm, src, dst);
    }
}
