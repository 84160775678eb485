//! The exchange of a coarse level held as rows split over the ranks (`super::Split`): the
//! other ranks' unknowns this rank's rows reach, fetched from them before a product, in
//! place of every rank's rows gathered; the same for the rows of P^T a rank restricts with
//! and for the aggregates of its owned nodes, which the coarse correction is prolonged to.
//! Gathering the first coarse level's vector for each of these brought every rank 3.4 MB
//! a CG iteration at n = 40 (its 32928 unknowns, 263 kB, about 13 times), the same on 2
//! and 16 ranks and growing with the mesh; each reads only the unknowns of its own rows
//! and of those of a few neighbouring ranks (0.07 MB a CG iteration on 16 ranks).

use crate::comm::{message, Comm};
use std::ops::Range;

/// What a split level's products exchange, fixed when the level is built.
pub struct Halo {
    /// Each rank whose rows this rank's rows reach, with those unknowns (the level's
    /// numbering, ascending).
    recv: Vec<(usize, Vec<u32>)>,
    /// Each rank whose rows reach this rank's, with the rows it reads (counted from this
    /// rank's first row, ascending).
    send: Vec<(usize, Vec<u32>)>,
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
        let mut need: Vec<Vec<u32>> = vec![Vec::new(); comm.size()];
        for (c, _) in reached.iter().enumerate().filter(|(_, &r)| r) {
            if !own.contains(&c) {
                need[c / per].push(c as u32);
            }
        }
        let asked = message::all_to_all(comm, &need);
        let first = own.start as u32;
        let listed = |lists: Vec<Vec<u32>>| {
            lists
                .into_iter()
                .enumerate()
                .filter(|(_, l)| !l.is_empty())
                .collect::<Vec<_>>()
        };
        Halo {
            recv: listed(need),
            send: listed(asked)
                .into_iter()
                .map(|(r, rows)| (r, rows.into_iter().map(|c| c - first).collect()))
                .collect(),
        }
    }

    /// Puts into `all` (the whole level's vector) the other ranks' values of the unknowns
    /// this rank's rows reach, sending them those of `mine` (this rank's rows) theirs reach
    /// (collective among the ranks concerned).
    pub fn fetch<C: Comm + ?Sized>(&self, comm: &C, mine: &[f64], all: &mut [f64]) {
        let send: Vec<(usize, Vec<f64>)> = self
            .send
            .iter()
            .map(|(r, rows)| (*r, rows.iter().map(|&i| mine[i as usize]).collect()))
            .collect();
        let mut recv: Vec<(usize, Vec<f64>)> = self
            .recv
            .iter()
            .map(|(r, cols)| (*r, vec![0.0; cols.len()]))
            .collect();
        comm.exchange(&send, &mut recv);
        for ((_, cols), (_, vals)) in self.recv.iter().zip(&recv) {
            for (&c, &v) in cols.iter().zip(vals) {
                all[c as usize] = v;
            }
        }
    }
}
