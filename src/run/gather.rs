//! Rank 0's global-order copies of the owned per-node and per-element arrays.

use crate::comm::Comm;
use crate::math::Vec3;
use crate::mesh::local::LocalMesh;
use std::ops::Range;

/// Chunks of the result file per round of a gather: rank 0 receives the values of one
/// range of `ROUND_CHUNKS * CHUNK_ROWS` global ids at a time (4096), written as they come
/// (`Gather::stream`), or the whole array and a round (`Gather::place`), not the whole
/// twice. A round of a fixed size bounds what rank 0 holds for it by the round, not the
/// mesh (a sixteenth of the array had been 1.6 MB of stress a round at 128000 elements).
/// One chunk a round: at four (16384 ids) the stress's round received, placed and
/// recovered took rank 0 2.7 MB above what it held, the peak of its steps at n = 40 on 8
/// ranks; at one, 0.7 MB.
const ROUND_CHUNKS: usize = 1;

/// The ids each round covers (a multiple of the result file's chunk, so that each chunk of
/// a field written round by round is written once) and the number of rounds.
fn rounds(total: usize) -> (usize, usize) {
    let per = ROUND_CHUNKS * crate::output::CHUNK_ROWS;
    (per, total.div_ceil(per))
}

/// The global ids of the owned entries of one kind (nodes or elements): this rank's, in its
/// order, which is ascending (`LocalMesh` numbers its owned nodes and elements so), and how
/// many there are in all. Each round sends its entries' ids with their values, so that rank
/// 0 keeps no list of every rank's ids (8 MB at 10^6 elements).
pub(super) struct Ids {
    own: Vec<u32>,
    total: usize,
}

impl Ids {
    fn new(own: Vec<u32>, total: usize) -> Self {
        assert!(
            own.is_sorted_by(|a, b| a < b),
            "a rank's owned ids ascend in its local order"
        );
        Ids { own, total }
    }

    /// The positions in `own` of the ids in `range`, starting at `*at` (the end of the
    /// previous round's), which it moves past them: a round's entries without a pass over
    /// every owned entry per round.
    fn run(&self, range: &Range<u32>, at: &mut usize) -> Range<usize> {
        let start = *at;
        while *at < self.own.len() && range.contains(&self.own[*at]) {
            *at += 1;
        }
        start..*at
    }
}

/// Gathers the owned entries of a per-node or per-element array onto rank 0, in global
/// order.
pub(super) struct Gather {
    pub(super) nodes: Ids,
    pub(super) elements: Ids,
}

impl Gather {
    pub(super) fn new(mesh: &LocalMesh, num_nodes: usize, num_elements: usize) -> Self {
        let owned = mesh.node_global[..mesh.num_owned_nodes].to_vec();
        let elems: Vec<u32> = mesh
            .element_global
            .iter()
            .zip(&mesh.element_owned)
            .filter(|(_, &o)| o)
            .map(|(&g, _)| g)
            .collect();
        Gather {
            nodes: Ids::new(owned, num_nodes),
            elements: Ids::new(elems, num_elements),
        }
    }

    /// The array whose owned entries (in the order of `ids.own`) are `local`, whole and in
    /// global order on rank 0 (empty elsewhere). Collective.
    pub(super) fn place<const W: usize, C: Comm + ?Sized>(
        &self,
        comm: &C,
        local: &[[f64; W]],
        ids: &Ids,
    ) -> Vec<[f64; W]> {
        let mut out = if comm.is_root() {
            vec![[0.0; W]; ids.total]
        } else {
            Vec::new()
        };
        self.stream(comm, local, ids, |first, part| {
            out[first..first + part.len()].copy_from_slice(part);
        });
        out
    }

    /// The ranges of global element ids of the rounds in which rank 0 receives per-element
    /// values (`stream`'s rounds).
    pub(super) fn element_rounds(&self) -> impl Iterator<Item = Range<u32>> {
        let total = self.elements.total;
        let (per, count) = rounds(total);
        (0..count).map(move |r| (r * per) as u32..((r + 1) * per).min(total) as u32)
    }

    /// The array whose owned entries are `local` (as `place` takes them), given on rank 0 to
    /// `put` a range of global ids at a time, in order: `put(first, values of ids first..)`.
    /// Collective.
    pub(super) fn stream<const W: usize, C: Comm + ?Sized>(
        &self,
        comm: &C,
        local: &[[f64; W]],
        ids: &Ids,
        put: impl FnMut(usize, &[[f64; W]]),
    ) {
        assert_eq!(local.len(), ids.own.len(), "a value per owned entry");
        let fill = |_: &Range<u32>, run: Range<usize>, send: &mut Vec<f64>| {
            for k in run {
                send.push(f64::from(ids.own[k]));
                send.extend_from_slice(&local[k]);
            }
        };
        Self::in_rounds(comm, ids, fill, put);
    }

    /// `stream` with the owned entries formed a round at a time: `local(range, n)` gives
    /// the n values of the owned entries whose global ids are in `range`, in the order of
    /// `ids.own` (flat, W per entry), so that no rank holds the whole local array either.
    /// Collective.
    pub(super) fn stream_with<const W: usize, C: Comm + ?Sized>(
        &self,
        comm: &C,
        ids: &Ids,
        mut local: impl FnMut(&Range<u32>, usize) -> Vec<f64>,
        put: impl FnMut(usize, &[[f64; W]]),
    ) {
        let fill = |range: &Range<u32>, run: Range<usize>, send: &mut Vec<f64>| {
            let values = local(range, run.len());
            assert_eq!(
                values.len(),
                W * run.len(),
                "a value per owned entry in the round"
            );
            for (&g, v) in ids.own[run].iter().zip(values.chunks_exact(W)) {
                send.push(f64::from(g));
                send.extend_from_slice(v);
            }
        };
        Self::in_rounds(comm, ids, fill, put);
    }

    /// The rounds of `stream` and `stream_with`: `fill(range, run, send)` puts each owned
    /// entry of the round (`run`: their positions in `ids.own`) in `send` as its global id
    /// (exact in an f64) and its W values; rank 0 places them by id and gives the round to
    /// `put`.
    fn in_rounds<const W: usize, C: Comm + ?Sized>(
        comm: &C,
        ids: &Ids,
        mut fill: impl FnMut(&Range<u32>, Range<usize>, &mut Vec<f64>),
        mut put: impl FnMut(usize, &[[f64; W]]),
    ) {
        let (per, count) = rounds(ids.total);
        let mut at = 0;
        let mut out: Vec<[f64; W]> = Vec::new();
        for round in 0..count {
            let lo = round * per;
            let hi = (lo + per).min(ids.total);
            let range = lo as u32..hi as u32;
            let run = ids.run(&range, &mut at);
            let mut send = Vec::with_capacity((W + 1) * run.len());
            fill(&range, run, &mut send);
            let parts = comm.gather_f64(&send);
            drop(send);
            if !comm.is_root() {
                continue;
            }
            out.clear();
            out.resize(hi - lo, [0.0; W]);
            for part in &parts {
                for e in part.chunks_exact(W + 1) {
                    out[e[0] as usize - lo].copy_from_slice(&e[1..]);
                }
            }
            drop(parts);
            put(lo, &out);
        }
    }

    pub(super) fn nodes<C: Comm + ?Sized>(
        &self,
        comm: &C,
        mesh: &LocalMesh,
        v: &[Vec3],
    ) -> Vec<Vec3> {
        self.place(comm, &v[..mesh.num_owned_nodes], &self.nodes)
    }

    pub(super) fn elements<C: Comm + ?Sized>(&self, comm: &C, v: &[[f64; 6]]) -> Vec<[f64; 6]> {
        self.place(comm, v, &self.elements)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rounds_cover_the_ids_in_whole_chunks_of_the_result_file() {
        let chunk = crate::output::CHUNK_ROWS;
        for total in [
            0,
            1,
            7,
            chunk - 1,
            chunk,
            chunk + 1,
            8 * chunk,
            1_061_208,
            1 << 24,
        ] {
            let (per, count) = rounds(total);
            assert!(per > 0 && per.is_multiple_of(chunk), "{total}: {per}");
            // A round's size does not grow with the array.
            assert_eq!(per, ROUND_CHUNKS * chunk, "{total}");
            assert!(count * per >= total && (count == 0 || (count - 1) * per < total));
        }
        // The 10^6-element block's 1,061,208 nodes: 260 rounds of 4096 ids.
        assert_eq!(rounds(1_061_208), (4096, 260));
    }

    #[test]
    fn a_round_takes_the_owned_entries_of_its_range_in_turn() {
        let ids = Ids::new(vec![0, 2, 4, 7, 9], 10);
        let mut at = 0;
        let mut taken = Vec::new();
        for range in [0..3, 3..6, 6..10] {
            taken.push(ids.own[ids.run(&range, &mut at)].to_vec());
        }
        assert_eq!(taken, vec![vec![0, 2], vec![4], vec![7, 9]]);
        assert_eq!(at, 5);
    }
}
