//! Communication between ranks. Everything above this module is generic over `Comm`, so
//! `cargo test` runs the same solver code serially that `mpirun` runs in parallel.

mod communicator;
pub mod exact_sum;
pub mod message;
pub mod mpi_comm;
pub mod plan;
mod serial;
mod traffic;

pub use communicator::Comm;
pub use exact_sum::ExactSum;
pub use mpi_comm::MpiComm;
pub use plan::ExchangePlan;
pub use serial::SerialComm;
pub use traffic::Traffic;

use crate::math::Vec3;

/// Reproducible global dot product of the first `n` nodes (the owned ones) of two nodal
/// vectors: summed exactly, rounded once, identical on any number of ranks.
pub fn dot<C: Comm + ?Sized>(comm: &C, a: &[Vec3], b: &[Vec3], n: usize) -> f64 {
    global_sum(comm, local_dot(a, b, n))
}

/// The exact sum of the products of the first `n` nodes.
fn local_dot(a: &[Vec3], b: &[Vec3], n: usize) -> ExactSum {
    exact_sum::exact_dot(a[..n].as_flattened(), b[..n].as_flattened())
}

/// Rounds an exact local accumulator's global total once.
pub fn global_sum<C: Comm + ?Sized>(comm: &C, acc: ExactSum) -> f64 {
    if comm.size() == 1 {
        return acc.to_f64();
    }
    let mut limbs = acc.limbs().to_vec();
    comm.sum_i64(&mut limbs);
    ExactSum::from_limbs(&limbs).to_f64()
}

/// Reproducible global 2-norm of the owned part of a nodal vector.
pub fn norm<C: Comm + ?Sized>(comm: &C, a: &[Vec3], n: usize) -> f64 {
    dot(comm, a, a, n).sqrt()
}

pub fn max_f64<C: Comm + ?Sized>(comm: &C, x: f64) -> f64 {
    let mut v = [x];
    comm.max_f64(&mut v);
    v[0]
}

pub fn sum_u64<C: Comm + ?Sized>(comm: &C, x: u64) -> u64 {
    let mut v = [x as i64];
    comm.sum_i64(&mut v);
    v[0] as u64
}

pub fn any<C: Comm + ?Sized>(comm: &C, b: bool) -> bool {
    let mut v = [b as i64];
    comm.sum_i64(&mut v);
    v[0] > 0
}

/// Every rank learns the error of the lowest-numbered failing rank, if any, so all ranks
/// take the same branch and stop with the same message.
pub fn first_error<C: Comm + ?Sized>(comm: &C, local: Option<String>) -> Option<String> {
    let key = comm.rank() as i64;
    lowest_error(comm, local.map(|m| (key, m)))
}

/// Every rank learns the error with the lowest key (a global element id, say), so the
/// message does not depend on how the mesh is split among ranks. Ties go to the lower rank.
pub fn lowest_error<C: Comm + ?Sized>(comm: &C, local: Option<(i64, String)>) -> Option<String> {
    let mut key = [local.as_ref().map_or(i64::MAX, |(k, _)| *k)];
    comm.min_i64(&mut key);
    if key[0] == i64::MAX {
        return None;
    }
    let mut who = [if local.as_ref().is_some_and(|(k, _)| *k == key[0]) {
        comm.rank() as i64
    } else {
        i64::MAX
    }];
    comm.min_i64(&mut who);
    let root = who[0] as usize;
    let mut bytes = if comm.rank() == root {
        local.map(|(_, m)| m).unwrap_or_default().into_bytes()
    } else {
        Vec::new()
    };
    comm.broadcast_bytes(root, &mut bytes);
    Some(String::from_utf8_lossy(&bytes).into_owned())
}

#[cfg(test)]
mod dispatch_tests {
    use super::*;

    /// The exact dot product with the processor's fused multiply-add (where it has one)
    /// rounds to the bits of the portable one, on terms whose products round.
    #[test]
    fn the_dispatched_dot_gives_the_bits_of_the_portable_one() {
        let a: Vec<Vec3> = (0..1000)
            .map(|k| std::array::from_fn(|i| ((3 * k + i) as f64 * 0.37).sin() * 1e3))
            .collect();
        let b: Vec<Vec3> = (0..1000)
            .map(|k| std::array::from_fn(|i| 1.0 / ((3 * k + i) as f64 + 0.7)))
            .collect();
        let comm = serial::SerialComm;
        let want = local_dot(&a, &b, a.len()).to_f64();
        assert_eq!(dot(&comm, &a, &b, a.len()).to_bits(), want.to_bits());
    }
}
