//! The `Comm` trait: what the solver asks of the parallel machine.

/// What the solver needs from the parallel machine. Implementations: `SerialComm` (one
/// rank) and the MPI one. Collective calls must be made by every rank in the same order.
pub trait Comm {
    fn rank(&self) -> usize;
    fn size(&self) -> usize;
    fn is_root(&self) -> bool {
        self.rank() == 0
    }
    /// Element-wise sum of integer arrays over all ranks (exact, so order-independent).
    fn sum_i64(&self, values: &mut [i64]);
    /// Element-wise maximum over all ranks.
    fn max_f64(&self, values: &mut [f64]);
    /// Element-wise minimum over all ranks.
    fn min_i64(&self, values: &mut [i64]);
    /// Point-to-point exchange: send each (rank, data) and fill each receive buffer, whose
    /// length the caller knows.
    fn exchange(&self, send: &[(usize, Vec<f64>)], recv: &mut [(usize, Vec<f64>)]);
    /// Gathers variable-length data on rank 0 (one entry per rank, in rank order);
    /// other ranks get an empty vector.
    fn gather_f64(&self, local: &[f64]) -> Vec<Vec<f64>>;
    fn gather_u64(&self, local: &[u64]) -> Vec<Vec<u64>>;
    /// Broadcasts bytes from `root` to every rank.
    fn broadcast_bytes(&self, root: usize, data: &mut Vec<u8>);
    /// Hands `items` along the ranks in order (collective): for each item in turn, rank r
    /// receives what rank r - 1 made of it (`None` on rank 0), `step(item, received)`
    /// makes this rank's, and that goes on to rank r + 1 (the last rank's is not sent)
    /// without waiting for rank r + 1 to take it, so a rank goes on with its next items
    /// while the ranks after it work on the earlier ones. Every send has completed when
    /// the call returns.
    fn chain(&self, items: usize, step: &mut dyn FnMut(usize, Option<Vec<u8>>) -> Vec<u8>);
    /// Rank 0 makes each rank's part in turn (`make(r)`, called on rank 0 only, r in rank
    /// order) and sends it before making the next, so it holds one part at a time; every
    /// rank returns its own (collective).
    fn scatter_f64(&self, make: &mut dyn FnMut(usize) -> Vec<f64>) -> Vec<f64>;
    /// Every rank sends `send[r]` (possibly empty) to rank r and receives one buffer from
    /// every rank, in rank order.
    fn all_to_all_f64(&self, send: &[Vec<f64>]) -> Vec<Vec<f64>>;
    /// Every rank receives every rank's `local`, in rank order.
    fn all_gather_f64(&self, local: &[f64]) -> Vec<Vec<f64>>;
    /// `all_gather_f64` as one buffer, every rank's `local` in rank order, and each rank's
    /// length: the gathered values held once (split into one list per rank, they are
    /// copied part by part).
    fn all_gather_f64_flat(&self, local: &[f64]) -> (Vec<f64>, Vec<usize>);
    /// `all_gather_f64` for blocks of one length on every rank, into `out` (rank r's block
    /// at r * local.len(); out.len() = size * local.len()), allocating nothing.
    fn all_gather_equal_f64(&self, local: &[f64], out: &mut [f64]);
    /// What this rank has sent so far (nothing on one rank).
    fn traffic(&self) -> super::Traffic {
        super::Traffic::default()
    }
}
