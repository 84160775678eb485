//! The one point-to-point exchange plan: which entries of a source array go to which rank,
//! and where each rank writes what it receives. The mesh's halo (owned node values to the
//! ghost copies), the constraints' master fetches and force pushes and the coarse spaces'
//! fetches are all such plans.

use super::communicator::Comm;
use super::message;

#[derive(Clone, Debug, Default)]
pub struct ExchangePlan {
    /// (rank, indices of the source entries sent to it)
    pub send: Vec<(usize, Vec<u32>)>,
    /// (rank, indices of the destination entries its message fills)
    pub recv: Vec<(usize, Vec<u32>)>,
}

impl ExchangePlan {
    pub fn is_empty(&self) -> bool {
        self.send.is_empty() && self.recv.is_empty()
    }

    /// The plan that brings remote values to this rank: `wanted` lists (global id, slot)
    /// pairs, `owners` the rank holding each one's value and `local` its index there. Each
    /// owner learns what it is asked for. Collective.
    pub fn fetch<C: Comm + ?Sized>(
        comm: &C,
        wanted: &[(u32, u32)],
        owners: &[usize],
        local: impl Fn(u32) -> Option<usize>,
    ) -> Self {
        let mut slots: Vec<Vec<u32>> = vec![Vec::new(); comm.size()];
        let mut request: Vec<Vec<u32>> = vec![Vec::new(); comm.size()];
        for (&(global, slot), &r) in wanted.iter().zip(owners) {
            slots[r].push(slot);
            request[r].push(global);
        }
        let asked = message::all_to_all(comm, &request);
        let mut plan = ExchangePlan::default();
        for (r, ids) in asked.into_iter().enumerate() {
            if !ids.is_empty() {
                let here = ids
                    .iter()
                    .map(|&g| local(g).expect("a value is requested from its owner") as u32)
                    .collect();
                plan.send.push((r, here));
            }
        }
        plan.recv = nonempty(slots);
        plan
    }

    /// Sends `src`'s entries and writes the received ones into `dst`. Collective among the
    /// ranks of the plan.
    pub fn run<const K: usize, C: Comm + ?Sized>(
        &self,
        comm: &C,
        src: &[[f64; K]],
        dst: &mut [[f64; K]],
    ) {
        if !self.is_empty() {
            let send = self.messages(src);
            self.deliver(comm, send, dst);
        }
    }

    /// `run` with one array as both source and destination.
    pub fn run_in_place<const K: usize, C: Comm + ?Sized>(&self, comm: &C, buf: &mut [[f64; K]]) {
        if !self.is_empty() {
            let send = self.messages(buf);
            self.deliver(comm, send, buf);
        }
    }

    fn messages<const K: usize>(&self, src: &[[f64; K]]) -> Vec<(usize, Vec<f64>)> {
        self.send
            .iter()
            .map(|(r, idx)| (*r, idx.iter().flat_map(|&i| src[i as usize]).collect()))
            .collect()
    }

    fn deliver<const K: usize, C: Comm + ?Sized>(
        &self,
        comm: &C,
        send: Vec<(usize, Vec<f64>)>,
        dst: &mut [[f64; K]],
    ) {
        let mut recv: Vec<(usize, Vec<f64>)> = self
            .recv
            .iter()
            .map(|(r, idx)| (*r, vec![0.0; K * idx.len()]))
            .collect();
        comm.exchange(&send, &mut recv);
        for ((_, idx), (_, buf)) in self.recv.iter().zip(&recv) {
            for (k, &i) in idx.iter().enumerate() {
                dst[i as usize].copy_from_slice(&buf[K * k..K * (k + 1)]);
            }
        }
    }
}

/// The (rank, list) pairs of the ranks with a non-empty list.
pub fn nonempty(lists: Vec<Vec<u32>>) -> Vec<(usize, Vec<u32>)> {
    lists
        .into_iter()
        .enumerate()
        .filter(|(_, l)| !l.is_empty())
        .collect()
}
