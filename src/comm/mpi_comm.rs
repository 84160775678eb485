//! The MPI implementation of `Comm` (rsmpi over OpenMPI). The only file that uses `mpi`.

use super::communicator::Comm;
use super::Traffic;
use mpi::collective::SystemOperation;
use mpi::datatype::{Partition, PartitionMut};
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;
use mpi::Count;
use std::cell::Cell;

const HALO_TAG: i32 = 17;
/// The tag of `chain`'s messages (apart from the halo's).
const CHAIN_TAG: i32 = 18;
/// The tag of `scatter_f64`'s messages.
const SCATTER_TAG: i32 = 19;

pub struct MpiComm {
    _universe: mpi::environment::Universe,
    world: SimpleCommunicator,
    /// What this rank has sent (`Comm::traffic`).
    sent: Cell<Traffic>,
}

impl MpiComm {
    /// Initialises MPI (once per process). A panic on any rank aborts the whole job, so no
    /// rank waits forever in a collective for a rank that died.
    pub fn init() -> Option<Self> {
        let universe = mpi::initialize()?;
        let world = universe.world();
        if world.size() > 1 {
            let default = std::panic::take_hook();
            std::panic::set_hook(Box::new(move |info| {
                default(info);
                let w = SimpleCommunicator::world();
                w.abort(70);
            }));
        }
        Some(MpiComm {
            _universe: universe,
            world,
            sent: Cell::new(Traffic::default()),
        })
    }

    /// Counts `messages` point-to-point messages of `bytes` in all.
    fn count_messages(&self, messages: usize, bytes: usize) {
        let mut t = self.sent.get();
        t.messages += messages as u64;
        t.bytes += bytes as u64;
        self.sent.set(t);
    }

    /// Counts one collective call to which this rank contributes `bytes` and which brings
    /// it `received`.
    fn count_collective(&self, bytes: usize, received: usize) {
        let mut t = self.sent.get();
        t.collectives += 1;
        t.collective_bytes += bytes as u64;
        t.collective_received += received as u64;
        self.sent.set(t);
    }

    /// Ends the job on every rank with `code` (for a failure seen by one rank only).
    pub fn abort(&self, code: i32) -> ! {
        self.world.abort(code)
    }
}

/// True when this process was started by mpirun (OpenMPI or a PMI launcher).
pub fn launched_by_mpirun() -> bool {
    ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"]
        .iter()
        .any(|v| std::env::var_os(v).is_some())
}

fn varcount_gather<T: Equivalence + Default + Clone>(
    world: &SimpleCommunicator,
    local: &[T],
) -> Vec<Vec<T>> {
    let root = world.process_at_rank(0);
    let n = local.len() as Count;
    if world.rank() == 0 {
        let mut counts = vec![0 as Count; world.size() as usize];
        root.gather_into_root(&n, &mut counts[..]);
        let displs: Vec<Count> = counts
            .iter()
            .scan(0, |acc, &c| {
                let d = *acc;
                *acc += c;
                Some(d)
            })
            .collect();
        let total: Count = counts.iter().sum();
        let mut buf = vec![T::default(); total as usize];
        {
            let mut part = PartitionMut::new(&mut buf[..], &counts[..], &displs[..]);
            root.gather_varcount_into_root(local, &mut part);
        }
        // Split from the last rank's part down, each part cut off and the rest shrunk: the
        // parts and what is left of the buffer are never more than the whole and one part
        // (a copy of every part beside the buffer was twice the whole on rank 0).
        let mut parts: Vec<Vec<T>> = Vec::with_capacity(counts.len());
        for &d in displs.iter().rev() {
            parts.push(buf.split_off(d as usize));
            buf.shrink_to_fit();
        }
        parts.reverse();
        parts
    } else {
        root.gather_into(&n);
        root.gather_varcount_into(local);
        Vec::new()
    }
}

impl Comm for MpiComm {
    fn rank(&self) -> usize {
        self.world.rank() as usize
    }

    fn size(&self) -> usize {
        self.world.size() as usize
    }

    fn sum_i64(&self, values: &mut [i64]) {
        self.count_collective(std::mem::size_of_val(values), std::mem::size_of_val(values));
        let local = values.to_vec();
        self.world
            .all_reduce_into(&local[..], values, SystemOperation::sum());
    }

    fn max_f64(&self, values: &mut [f64]) {
        self.count_collective(std::mem::size_of_val(values), std::mem::size_of_val(values));
        let local = values.to_vec();
        self.world
            .all_reduce_into(&local[..], values, SystemOperation::max());
    }

    fn min_i64(&self, values: &mut [i64]) {
        self.count_collective(std::mem::size_of_val(values), std::mem::size_of_val(values));
        let local = values.to_vec();
        self.world
            .all_reduce_into(&local[..], values, SystemOperation::min());
    }

    fn exchange(&self, send: &[(usize, Vec<f64>)], recv: &mut [(usize, Vec<f64>)]) {
        let bytes = send
            .iter()
            .map(|(_, d)| std::mem::size_of_val(&d[..]))
            .sum();
        self.count_messages(send.len(), bytes);
        let world = &self.world;
        mpi::request::scope(|scope| {
            let requests: Vec<_> = send
                .iter()
                .map(|(r, data)| {
                    world.process_at_rank(*r as i32).immediate_send_with_tag(
                        scope,
                        &data[..],
                        HALO_TAG,
                    )
                })
                .collect();
            for (r, buf) in recv.iter_mut() {
                world
                    .process_at_rank(*r as i32)
                    .receive_into_with_tag(&mut buf[..], HALO_TAG);
            }
            for req in requests {
                req.wait();
            }
        });
    }

    fn gather_f64(&self, local: &[f64]) -> Vec<Vec<f64>> {
        let parts = varcount_gather(&self.world, local);
        self.count_collective(std::mem::size_of_val(local), words_in(&parts) * 8);
        parts
    }

    fn gather_u64(&self, local: &[u64]) -> Vec<Vec<u64>> {
        let parts = varcount_gather(&self.world, local);
        self.count_collective(std::mem::size_of_val(local), words_in(&parts) * 8);
        parts
    }

    fn scatter_f64(&self, make: &mut dyn FnMut(usize) -> Vec<f64>) -> Vec<f64> {
        if self.rank() != 0 {
            let (part, _) = self
                .world
                .process_at_rank(0)
                .receive_vec_with_tag::<f64>(SCATTER_TAG);
            return part;
        }
        let own = make(0);
        for r in 1..self.size() {
            let part = make(r);
            self.count_messages(1, std::mem::size_of_val(&part[..]));
            self.world
                .process_at_rank(r as i32)
                .send_with_tag(&part[..], SCATTER_TAG);
        }
        own
    }

    fn all_to_all_f64(&self, send: &[Vec<f64>]) -> Vec<Vec<f64>> {
        let size = self.size();
        assert_eq!(send.len(), size, "one send buffer per rank");
        let send_counts: Vec<Count> = send.iter().map(|b| b.len() as Count).collect();
        let mut recv_counts = vec![0 as Count; size];
        self.world
            .all_to_all_into(&send_counts[..], &mut recv_counts[..]);
        let flat: Vec<f64> = send.iter().flatten().copied().collect();
        let send_displs = displacements(&send_counts);
        let recv_displs = displacements(&recv_counts);
        let total: Count = recv_counts.iter().sum();
        self.count_collective(8 * flat.len(), 8 * total as usize);
        let mut buf = vec![0.0f64; total as usize];
        {
            let sp = Partition::new(&flat[..], &send_counts[..], &send_displs[..]);
            let mut rp = PartitionMut::new(&mut buf[..], &recv_counts[..], &recv_displs[..]);
            self.world.all_to_all_varcount_into(&sp, &mut rp);
        }
        drop(flat);
        let counts: Vec<usize> = recv_counts.iter().map(|&c| c as usize).collect();
        split(buf, &counts)
    }

    fn all_gather_f64(&self, local: &[f64]) -> Vec<Vec<f64>> {
        let (buf, counts) = self.all_gather_f64_flat(local);
        split(buf, &counts)
    }

    fn all_gather_f64_flat(&self, local: &[f64]) -> (Vec<f64>, Vec<usize>) {
        let size = self.size();
        let n = local.len() as Count;
        let mut counts = vec![0 as Count; size];
        self.world.all_gather_into(&n, &mut counts[..]);
        let displs = displacements(&counts);
        let total: Count = counts.iter().sum();
        self.count_collective(std::mem::size_of_val(local), 8 * total as usize);
        let mut buf = vec![0.0f64; total as usize];
        {
            let mut rp = PartitionMut::new(&mut buf[..], &counts[..], &displs[..]);
            self.world.all_gather_varcount_into(local, &mut rp);
        }
        (buf, counts.iter().map(|&c| c as usize).collect())
    }

    fn all_gather_equal_f64(&self, local: &[f64], out: &mut [f64]) {
        debug_assert_eq!(out.len(), local.len() * self.size());
        self.count_collective(std::mem::size_of_val(local), std::mem::size_of_val(out));
        self.world.all_gather_into(local, out);
    }

    fn broadcast_bytes(&self, root: usize, data: &mut Vec<u8>) {
        let p = self.world.process_at_rank(root as i32);
        let mut len = data.len() as u64;
        p.broadcast_into(&mut len);
        if self.rank() == root {
            self.count_collective(data.len(), 0);
        } else {
            self.count_collective(0, len as usize);
        }
        data.resize(len as usize, 0);
        if len > 0 {
            p.broadcast_into(&mut data[..]);
        }
    }

    fn chain(&self, items: usize, step: &mut dyn FnMut(usize, Option<Vec<u8>>) -> Vec<u8>) {
        let (rank, size) = (self.rank(), self.size());
        // Each item's bytes stay in their slot until every send has completed.
        let mut slots: Vec<Vec<u8>> = vec![Vec::new(); items];
        mpi::request::scope(|scope| {
            let mut sends = Vec::new();
            for (item, slot) in slots.iter_mut().enumerate() {
                let received = (rank > 0).then(|| {
                    self.world
                        .process_at_rank(rank as i32 - 1)
                        .receive_vec_with_tag::<u8>(CHAIN_TAG)
                        .0
                });
                *slot = step(item, received);
                if rank + 1 < size {
                    self.count_messages(1, slot.len());
                    let data: &Vec<u8> = slot;
                    sends.push(
                        self.world
                            .process_at_rank(rank as i32 + 1)
                            .immediate_send_with_tag(scope, &data[..], CHAIN_TAG),
                    );
                }
            }
            for send in sends {
                send.wait();
            }
        });
    }

    fn traffic(&self) -> Traffic {
        self.sent.get()
    }
}

/// The values in all the parts.
fn words_in<T>(parts: &[Vec<T>]) -> usize {
    parts.iter().map(Vec::len).sum()
}

fn displacements(counts: &[Count]) -> Vec<Count> {
    counts
        .iter()
        .scan(0, |acc, &c| {
            let d = *acc;
            *acc += c;
            Some(d)
        })
        .collect()
}

/// The parts of `buf`, `counts[r]` values of rank r's in rank order, one list each: taken
/// from its end, the buffer shrunk past each, so that the values are held about once while
/// they are split, not twice (a gather of the whole tangent's triplets is 24 bytes an
/// entry).
fn split(mut buf: Vec<f64>, counts: &[usize]) -> Vec<Vec<f64>> {
    debug_assert_eq!(counts.iter().sum::<usize>(), buf.len());
    let mut parts = Vec::with_capacity(counts.len());
    for &c in counts.iter().rev() {
        parts.push(buf.split_off(buf.len() - c));
        buf.shrink_to_fit();
    }
    parts.reverse();
    parts
}
