//! One rank, no MPI.

use super::communicator::Comm;

#[derive(Clone, Copy, Debug, Default)]
pub struct SerialComm;

impl Comm for SerialComm {
    fn rank(&self) -> usize {
        0
    }
    fn size(&self) -> usize {
        1
    }
    fn sum_i64(&self, _values: &mut [i64]) {}
    fn max_f64(&self, _values: &mut [f64]) {}
    fn min_i64(&self, _values: &mut [i64]) {}
    fn exchange(&self, send: &[(usize, Vec<f64>)], recv: &mut [(usize, Vec<f64>)]) {
        debug_assert!(
            send.is_empty() && recv.is_empty(),
            "a single rank has no neighbours"
        );
    }
    fn gather_f64(&self, local: &[f64]) -> Vec<Vec<f64>> {
        vec![local.to_vec()]
    }
    fn gather_u64(&self, local: &[u64]) -> Vec<Vec<u64>> {
        vec![local.to_vec()]
    }
    fn broadcast_bytes(&self, _root: usize, _data: &mut Vec<u8>) {}
    fn chain(&self, items: usize, step: &mut dyn FnMut(usize, Option<Vec<u8>>) -> Vec<u8>) {
        for item in 0..items {
            step(item, None);
        }
    }
    fn scatter_f64(&self, make: &mut dyn FnMut(usize) -> Vec<f64>) -> Vec<f64> {
        make(0)
    }
    fn all_to_all_f64(&self, send: &[Vec<f64>]) -> Vec<Vec<f64>> {
        vec![send[0].clone()]
    }
    fn all_gather_f64(&self, local: &[f64]) -> Vec<Vec<f64>> {
        vec![local.to_vec()]
    }
    fn all_gather_f64_flat(&self, local: &[f64]) -> (Vec<f64>, Vec<usize>) {
        (local.to_vec(), vec![local.len()])
    }
    fn all_gather_equal_f64(&self, local: &[f64], out: &mut [f64]) {
        out.copy_from_slice(local);
    }
}
