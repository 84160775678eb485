//! The first coarse level built from its rows split over the ranks. Rank r holds the rows
//! of aggregates r L .. (r + 1) L (L = ceil(aggregates / ranks), `held`), as measured
//! (`measure`), and builds from them what the levels below need, each piece the same bits
//! as `cycle::Hierarchy::build` computes it from the whole operator:
//!
//! - the diagonal and the strength graph's edges, row by row, gathered;
//! - the inverses of the held nodes' blocks, kept on the rank (`BlockInverse::of_nodes`);
//! - the smoother's bound, by products of the held rows and their D^-1, each gathered
//!   (`Held`, `Split`'s rule);
//! - the tentative prolongator in the rows the held rows reach (`reached_by`);
//! - the smoothed prolongator's rows of the held nodes, gathered whole (every rank needs
//!   P^T for the cycle and P's rows to form P^T A P);
//! - P^T A P in turns: rank 0 sums the terms of its rows of A, each rank then goes on
//!   from the sums the rank before it sent, in the order of the rows, so every entry is
//!   the one sum the whole product forms (`triple::triple_product_part`); by groups of
//!   the product's rows, so that the ranks work at once on different groups (`pipelined`).
//!
//! The last rank takes the product's symmetric part and gives each rank its rows of the
//! next level (those of its aggregates by `held`), from which that level is built the
//! same way (`build_level`, in f64: only the first level is rounded to f32), and so on
//! down to the level solved directly, or one aggregation no longer coarsens: its rows are
//! gathered and it is built whole on every rank (`Hierarchy::build`). A rank so holds its
//! rows of every coarse operator above the coarsest instead of all of them (on the block
//! on block at n = 80, 35 million entries of the first: half of them on each of 2 ranks;
//! at n = 40 the second level's 181188 entries, 2.65 MB that every rank held whole). A
//! level's unknowns must come in nodes of six for its rows to be held in blocks: where an
//! aggregate of the level above dropped a mode, the level is built whole. The same bits
//! as the levels built whole: the block on block at n = 40 and a cube of 87808 elements
//! (mpi-tests/cube_three_levels.toml) on 1, 2, 3 and 16 ranks against the binary that
//! built them whole.

use super::aggregation::{aggregate, Graph};
use super::block_rows::{BlockRows, View};
use super::blocks::BlockInverse;
use super::cycle::{self, FirstLevel, Hierarchy, Op, Product, SplitBuffers};
use super::halo::Halo;
use super::prolongation::Prolongation;
use super::prolongator::{smooth_nodes, tentative, Tentative, MODES};
use super::smoother::Chebyshev;
use super::smoother::{hash_value, Space};
use super::sparse::{node_of, Csr, Rows};
use super::split::Split;
use super::transfer::RigidModes;
use super::triple::{triple_product_part, Picked, TRIPLE_BLOCKS};
use crate::comm::Comm;
use std::cell::RefCell;
use std::convert::Infallible;
use std::ops::Range;

/// The aggregates whose rows of the first coarse level this rank holds.
pub fn held<C: Comm + ?Sized>(comm: &C, aggregates: usize) -> Range<usize> {
    held_by(aggregates, comm.size(), comm.rank())
}

/// The aggregates rank `rank` of `ranks` holds: `per` = ceil(aggregates / ranks) from
/// rank * per on (fewer on the last, none past the end), so that its rows start where
/// `Split` places them (rank * 6 per) even when it holds none.
fn held_by(aggregates: usize, ranks: usize, rank: usize) -> Range<usize> {
    let per = aggregates.div_ceil(ranks).max(1);
    let lo = rank * per;
    lo..(lo + per).min(aggregates).max(lo)
}

/// Rows of the first coarse level per rank (the last rank's padded): `held`'s count, in
/// unknowns.
pub fn rows_per_rank<C: Comm + ?Sized>(comm: &C, aggregates: usize) -> usize {
    MODES * aggregates.div_ceil(comm.size()).max(1)
}

/// Every rank's rows (`rows`, numbered from the first held one) gathered into the whole
/// matrix, rank after rank (collective).
pub fn gather_rows<C: Comm + ?Sized>(comm: &C, rows: &Csr) -> Csr {
    let mut whole = Csr::empty(rows.cols);
    for r in 0..comm.size() {
        let mut bytes = if r == comm.rank() {
            rows.to_bytes()
        } else {
            Vec::new()
        };
        comm.broadcast_bytes(r, &mut bytes);
        whole.append_bytes(&bytes);
    }
    whole
}

/// The least number of groups of its rows P^T A P is formed in on more ranks than one
/// (`pipelined`).
const PIPELINE_GROUPS: usize = 8;

/// Rows of P a rank sends at a time while P^T is formed.
const TRANSPOSE_PIECE: usize = 4096;

/// One pass over the rows of P every rank holds some of (`own`: this rank's, those of the
/// aggregates `held_by` gives it of `aggregates`, six rows each), rank after rank, a piece
/// at a time (collective): the rows `keep` of P^T (each row's entries in the order of the
/// rows they come from: the bits of those rows of `gather_rows(comm, own).transpose()`)
/// and the rows `picked` (increasing) of P, without P or P^T held whole.
pub fn gathered<C: Comm + ?Sized>(
    comm: &C,
    own: &Csr,
    aggregates: usize,
    keep: Range<usize>,
    picked: &[u32],
) -> (Csr, Picked) {
    let (size, n) = (comm.size(), MODES * aggregates);
    let mut slot = vec![u32::MAX; n];
    for (s, &r) in picked.iter().enumerate() {
        slot[r as usize] = s as u32;
    }
    let mut rows = Csr::empty(own.cols);
    // The entries of each row of P^T in `keep`, summed over the ranks.
    let mut count = vec![0i64; own.cols];
    for &j in &own.idx {
        count[j as usize] += 1;
    }
    comm.sum_i64(&mut count);
    let mut ptr = vec![0usize; keep.len() + 1];
    for (j, c) in count[keep.clone()].iter().enumerate() {
        ptr[j + 1] = ptr[j] + *c as usize;
    }
    drop(count);
    let nnz = ptr[keep.len()];
    let (mut idx, mut val) = (vec![0u32; nnz], vec![0.0f64; nnz]);
    let mut next = ptr[..keep.len()].to_vec();
    for r in 0..size {
        let held = held_by(aggregates, size, r);
        let count = MODES * held.len();
        for start in (0..count).step_by(TRANSPOSE_PIECE) {
            let end = (start + TRANSPOSE_PIECE).min(count);
            let mut bytes = if r == comm.rank() {
                own.rows_to_bytes(start..end)
            } else {
                Vec::new()
            };
            comm.broadcast_bytes(r, &mut bytes);
            let piece = Csr::from_bytes(&bytes);
            drop(bytes);
            let first = MODES * held.start + start;
            for q in 0..piece.rows {
                let (c, v) = piece.row(q);
                let i = first + q;
                if slot[i] != u32::MAX {
                    rows.idx.extend_from_slice(c);
                    rows.val.extend_from_slice(v);
                    rows.ptr.push(rows.idx.len());
                    rows.rows += 1;
                }
                for (&j, &x) in c.iter().zip(v) {
                    if keep.contains(&(j as usize)) {
                        let k = &mut next[j as usize - keep.start];
                        idx[*k] = i as u32;
                        val[*k] = x;
                        *k += 1;
                    }
                }
            }
        }
    }
    let pt = Csr {
        rows: keep.len(),
        cols: n,
        ptr,
        idx,
        val,
    };
    (pt, Picked::new(slot, rows))
}

/// Every rank's values, in rank order.
fn gather<C: Comm + ?Sized>(comm: &C, mine: &[f64]) -> Vec<f64> {
    comm.all_gather_f64(mine).concat()
}

/// A level's near-nullspace: the first coarse level's rigid-body modes, formed row by row
/// when asked for, or the rows of a level below it.
pub enum Modes {
    Rigid(RigidModes),
    Rows(Vec<[f64; MODES]>),
}

impl Modes {
    fn row(&self, i: usize) -> [f64; MODES] {
        match self {
            Modes::Rigid(m) => m.row(i),
            Modes::Rows(b) => b[i],
        }
    }

    fn rows(&self) -> Vec<[f64; MODES]> {
        match self {
            Modes::Rigid(m) => m.rows(),
            Modes::Rows(b) => b.clone(),
        }
    }
}

/// Builds the hierarchy from this rank's rows of the first coarse level (`rows`, those of
/// the aggregates `held` of `aggregates`, numbered from the first held one), its
/// near-nullspace `b` and the bodies of its nodes (collective). The rows are kept in
/// blocks from the start (`BlockRows`, which gives each sparse row back, bit for bit): the
/// sparse rows and the blocks were both held through the build, the largest part of its
/// peak.
#[allow(clippy::too_many_arguments)]
pub fn build<C: Comm + ?Sized>(
    comm: &C,
    blocks: BlockRows,
    held: Range<usize>,
    aggregates: usize,
    b: Modes,
    body: Vec<u32>,
    degree: usize,
    sweeps: usize,
) -> Hierarchy {
    build_level(
        comm,
        blocks,
        (held, aggregates),
        b,
        body,
        (degree, sweeps),
        true,
    )
}

/// `build` for a level of `aggregates` of whose rows this rank holds those of `held`: the
/// first coarse level (`round`: in f32, as measured) or one below it, built the same way
/// from the rows of it this rank holds (in f64, as `Hierarchy::build` keeps the levels it
/// builds), down to the level solved directly or one that no longer coarsens, built
/// whole (collective).
fn build_level<C: Comm + ?Sized>(
    comm: &C,
    blocks: BlockRows,
    (held, aggregates): (Range<usize>, usize),
    b: Modes,
    body: Vec<u32>,
    (degree, sweeps): (usize, usize),
    round: bool,
) -> Hierarchy {
    let n = MODES * aggregates;
    let first = MODES * held.start;
    let node_ptr: Vec<usize> = (0..=aggregates).map(|k| MODES * k).collect();
    let diag = diagonal(comm, &blocks, first..first + MODES * held.len());
    let whole = |rows: Csr| {
        let a = gather_rows(comm, &rows);
        drop(rows);
        Hierarchy::build(a, node_ptr.clone(), b.rows(), body.clone(), degree, sweeps)
    };
    if diag.iter().filter(|&&d| d > 0.0).count() <= cycle::COARSEST {
        return whole(blocks.to_csr());
    }
    // The strength graph and the aggregates of the next level.
    let ks = first..first + MODES * held.len();
    let (agg, nc) = next_aggregates(
        comm,
        &mut View::new(&blocks),
        ks.clone(),
        &diag,
        &node_ptr,
        &body,
    );
    let coarse_body = cycle::coarse_bodies(&agg, nc, &body);
    // Of the tentative prolongator, P's rows of the held nodes need only the rows their
    // rows of A reach (their columns: the held rows themselves among them).
    let reached = reached_by(&mut View::new(&blocks), ks.clone(), n);
    let tent = tentative(&agg, nc, &node_ptr, |i| b.row(i), Some(&reached));
    if cycle::stops_coarsening(tent.p.cols, n) {
        return whole(blocks.to_csr());
    }
    // What the cycle's products exchange: the unknowns the held rows reach (rounding to
    // f32 below changes values, not the pattern).
    let halo = Halo::new(comm, &reached, ks.clone(), rows_per_rank(comm, aggregates));
    drop(reached);
    // The first level, which the cycle smooths: in f32 for every use below (the node
    // blocks, the smoother's bound, P^T A P) and the cycle's products.
    let blocks = if round {
        rounded(comm, blocks, &diag)
    } else {
        blocks
    };
    let mut view = View::new(&blocks);
    // Node-block relaxation: the inverses of the held nodes' blocks, on this rank only.
    let inv = BlockInverse::inverses(&mut view, &node_ptr, held.clone());
    let dinv = BlockInverse::of_nodes(&node_ptr, held.clone(), inv);
    // The smoother's bound, by products of the held rows gathered (`Split`).
    let op = Op::Rows(blocks);
    let cheb = smoother_bound(
        comm,
        &op,
        &dinv,
        (first, MODES * held.len()),
        aggregates,
        degree,
    );
    let Op::Rows(blocks) = op else {
        unreachable!("the first level's rows are blocks")
    };
    let mut view = View::new(&blocks);
    let own_next = next_rows(comm, tent.p.cols, nc);
    let (transfer, ac) = galerkin(
        comm,
        &mut view,
        (held.clone(), aggregates),
        &dinv,
        cheb.lmax,
        (&tent.p, own_next.clone()),
    );
    // `below` needs the tentative prolongator's columns and the next level's modes only.
    let tent = Tentative {
        p: Csr::empty(tent.p.cols),
        ..tent
    };
    let (rest, rest_split) = below(comm, ac, own_next, (tent, coarse_body), (degree, sweeps));
    let nnz = gather(comm, &[blocks.nnz() as f64]).iter().sum::<f64>() as usize;
    let live = diag.iter().map(|&d| d > 0.0).collect();
    let first_level = FirstLevel {
        rows: blocks,
        halo,
        dinv,
        own: ks,
        cheb,
        transfer,
        n,
        nnz,
        node_ptr,
        live,
    };
    Hierarchy::above(first_level, rest, rest_split)
}

/// The whole diagonal of a level from this rank's `rows` of it (collective).
fn diagonal<C: Comm + ?Sized>(comm: &C, blocks: &BlockRows, rows: Range<usize>) -> Vec<f64> {
    let (mut cols, mut vals) = (Vec::new(), Vec::new());
    let own: Vec<f64> = rows
        .map(|r| {
            blocks.row_into(r, &mut cols, &mut vals);
            cols.binary_search(&(r as u32)).map_or(0.0, |k| vals[k])
        })
        .collect();
    gather(comm, &own)
}

/// The rows of the next level (of `n` unknowns, `aggregates` aggregates) this rank holds:
/// where each of its aggregates kept its six modes (its unknowns in nodes of six, as this
/// level's), those of its aggregates by `held`; else all of them, and that level is built
/// whole (`below`).
fn next_rows<C: Comm + ?Sized>(comm: &C, n: usize, aggregates: usize) -> Range<usize> {
    if n == MODES * aggregates {
        let next = held_by(aggregates, comm.size(), comm.rank());
        MODES * next.start..MODES * next.end
    } else {
        0..n
    }
}

/// The hierarchy below a level from this rank's rows `ac` of its coarse operator (rows
/// `own` of it, numbered from the first: all of them where the coarse unknowns are not in
/// nodes of six) and the level's tentative prolongator and coarse bodies, with the buffers
/// of its first level where that is held as every rank's rows on more ranks than one
/// (collective).
fn below<C: Comm + ?Sized>(
    comm: &C,
    ac: Csr,
    own: Range<usize>,
    (tent, body): (Tentative, Vec<u32>),
    (degree, sweeps): (usize, usize),
) -> (Hierarchy, Option<SplitBuffers>) {
    let (n, nc) = (tent.p.cols, tent.node_ptr.len() - 1);
    let in_rows = n == MODES * nc;
    let rows = in_rows
        .then(|| BlockRows::of_rows(|r| ac.row(r - own.start), (n, n), own.start, own.len()))
        .flatten();
    let rest = match rows {
        Some(rows) => {
            drop(ac);
            let held = own.start / MODES..own.end / MODES;
            let levels = (degree, sweeps);
            build_level(
                comm,
                rows,
                (held, nc),
                Modes::Rows(tent.b),
                body,
                levels,
                false,
            )
        }
        None => {
            let a = if in_rows { gather_rows(comm, &ac) } else { ac };
            Hierarchy::build(a, tent.node_ptr, tent.b, body, degree, sweeps)
        }
    };
    let split = (comm.size() > 1 && rest.is_split())
        .then(|| SplitBuffers::new(n, own, rows_per_rank(comm, nc), comm.size()));
    (rest, split)
}

/// The Chebyshev smoother's bound of the level whose rows `op` and node-block inverses
/// `dinv` this rank holds (`len` unknowns from the level's `first`), by the power
/// iteration on whole vectors (`Held`; collective).
fn smoother_bound<C: Comm + ?Sized>(
    comm: &C,
    op: &Op,
    dinv: &BlockInverse,
    (first, len): (usize, usize),
    aggregates: usize,
    degree: usize,
) -> Chebyshev {
    let n = MODES * aggregates;
    let per = rows_per_rank(comm, aggregates);
    let (mut mine, mut all) = (vec![0.0; per], vec![0.0; per * comm.size()]);
    let mut space = Held {
        a: op,
        dinv,
        first,
        len,
        split: RefCell::new(Split {
            comm,
            rows: &mut mine,
            all: &mut all,
        }),
    };
    let (mut v, mut y, mut w) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let Ok(cheb) = Chebyshev::estimate(&mut space, degree, &mut v, &mut y, &mut w);
    cheb
}

/// The first level seen by its smoother's power iteration (`Chebyshev::estimate`) on whole
/// vectors, from this rank's rows: the product's rows and the node blocks' inverses
/// (`dinv`, the held nodes', `len` unknowns from the level's `first`), each gathered
/// whole after it (`Split`). Every entry is the one the whole level computes, so the bound
/// is the same bits on any number of ranks, and no rank holds every node's inverse.
struct Held<'a, 's, C: Comm + ?Sized> {
    a: &'a Op,
    dinv: &'a BlockInverse,
    first: usize,
    len: usize,
    split: RefCell<Split<'s, C>>,
}

impl<C: Comm + ?Sized> Space for Held<'_, '_, C> {
    type Error = Infallible;
    fn apply(&mut self, x: &[f64], y: &mut [f64]) -> Result<(), Infallible> {
        self.split.get_mut().mul_whole(self.a, x, y);
        Ok(())
    }
    fn inv_diag(&self, r: &[f64], z: &mut [f64]) {
        let split = &mut *self.split.borrow_mut();
        let (held, pad) = split.rows.split_at_mut(self.len);
        if self.len > 0 {
            self.dinv.apply(&r[self.first..self.first + self.len], held);
        }
        pad.fill(0.0);
        split.comm.all_gather_equal_f64(split.rows, split.all);
        z.copy_from_slice(&split.all[..z.len()]);
    }
    fn dot(&self, a: &[f64], b: &[f64]) -> f64 {
        a.iter().zip(b).map(|(x, y)| x * y).sum()
    }
    fn start(&self, v: &mut [f64]) {
        for (i, x) in v.iter_mut().enumerate() {
            *x = hash_value(i as u64);
        }
    }
}

/// This rank's rows of the level in f32, raised on the diagonal to stay at least the
/// measured operator (`BlockRows::round_dominant`; `diag` the level's whole diagonal), on
/// every rank or, where one cannot round them, on none (collective).
fn rounded<C: Comm + ?Sized>(comm: &C, mut blocks: BlockRows, diag: &[f64]) -> BlockRows {
    let rounding = blocks.rounding(diag);
    if !crate::comm::any(comm, rounding.is_none()) {
        blocks.round_dominant(rounding.expect("every rank can round"));
    }
    blocks
}

/// The aggregates of the level below (and their number), from the strength graph's edges
/// of this rank's rows `ks`, gathered (collective).
fn next_aggregates<C: Comm + ?Sized>(
    comm: &C,
    view: &mut View,
    ks: Range<usize>,
    diag: &[f64],
    node_ptr: &[usize],
    body: &[u32],
) -> (Vec<u32>, usize) {
    let mut edges = Vec::new();
    cycle::strong_edges(view, ks, diag, &node_of(node_ptr), body, &mut edges);
    // Each node pair comes once for every entry between them: once is enough.
    edges.sort_unstable();
    edges.dedup();
    let flat: Vec<f64> = edges
        .iter()
        .flat_map(|&(i, j)| [i as f64, j as f64])
        .collect();
    drop(edges);
    let flat = gather(comm, &flat);
    let edges: Vec<(u32, u32)> = flat
        .chunks_exact(2)
        .map(|e| (e[0] as u32, e[1] as u32))
        .collect();
    drop(flat);
    let mut graph = Graph::from_edges(node_ptr.len() - 1, &edges);
    drop(edges);
    aggregate(&mut graph, &cycle::active_nodes(diag, node_ptr))
}

/// Which of the level's `n` unknowns the rows `ks` of A reach (their columns).
fn reached_by(view: &mut View, ks: Range<usize>, n: usize) -> Vec<bool> {
    let mut reached = vec![false; n];
    for k in ks {
        for &m in view.row(k).0 {
            reached[m as usize] = true;
        }
    }
    reached
}

/// The prolongator P (this rank's rows of P and P^T, or P^T whole on one rank) and the
/// rows `next` of P^T A P (its symmetric part; numbered from the first) from this rank's
/// rows of A (those of the nodes `held`) and the tentative prolongator: P's rows of the
/// held nodes; of P^T, a range of rows; of P, the rows this rank's rows of A reach; P^T A
/// P in turns, each rank going on from the sums of the rank before it (collective).
fn galerkin<C: Comm + ?Sized>(
    comm: &C,
    view: &mut View,
    (held, aggregates): (Range<usize>, usize),
    dinv: &BlockInverse,
    lmax: f64,
    (tentative, next): (&Csr, Range<usize>),
) -> (Prolongation, Csr) {
    let ks = MODES * held.start..MODES * held.end;
    let own_p = smooth_nodes(
        view,
        dinv,
        lmax,
        tentative,
        held.clone(),
        (held.start, ks.start),
    );
    // Of P, the product needs only the rows its rows of A reach.
    let reached = reached_by(view, ks.clone(), MODES * aggregates);
    let rows: Vec<u32> = (0..reached.len() as u32)
        .filter(|&m| reached[m as usize])
        .collect();
    drop(reached);
    let (size, coarse) = (comm.size(), own_p.cols);
    let pt_per = coarse.div_ceil(size).max(1);
    let keep = (comm.rank() * pt_per).min(coarse)..((comm.rank() + 1) * pt_per).min(coarse);
    // On more ranks than one the product runs on the transpose of this rank's rows of P
    // (`local`), and this rank's range of P^T is gathered after it, so that the two are
    // not held beside the product's rows of P and its sums.
    let one = size == 1;
    let (pt, p) = gathered(
        comm,
        &own_p,
        aggregates,
        if one { keep.clone() } else { 0..0 },
        &rows,
    );
    drop(rows);
    // The product's rows of P^T restricted to `ks`: on one rank P^T itself, else the
    // transpose of this rank's rows of P, numbered as the level's, which stands for those
    // rows until the product is formed (their transpose again, the same rows and bits: the
    // columns of each row of P are sorted).
    let local = (!one).then(|| {
        let mut t = own_p.transpose();
        t.idx.iter_mut().for_each(|k| *k += ks.start as u32);
        t.cols = MODES * aggregates;
        t
    });
    let own_cols = own_p.cols;
    drop(own_p);
    let ac = match &local {
        None => {
            let sums =
                triple_product_part((&pt, 0..pt.rows), view, ks.clone(), &p, TRIPLE_BLOCKS, None);
            let sym = sums.into_symmetric_part();
            if next == (0..sym.rows) {
                sym
            } else {
                rows_of(&sym, next)
            }
        }
        Some(local) => pipelined(comm, local, view, ks.clone(), (&p, next)),
    };
    drop(p);
    let transfer = match local {
        None => Prolongation::Whole(pt),
        Some(mut t) => {
            t.idx.iter_mut().for_each(|k| *k -= ks.start as u32);
            t.cols = ks.len();
            let own_p = t.transpose();
            drop(t);
            let (pt, _) = gathered(comm, &own_p, aggregates, keep, &[]);
            debug_assert_eq!(own_p.cols, own_cols);
            let p_per = rows_per_rank(comm, aggregates);
            // The restriction's exchange: the level's unknowns this rank's range of P^T
            // reads.
            let mut reached = vec![false; pt.cols];
            pt.idx.iter().for_each(|&c| reached[c as usize] = true);
            let halo = Halo::new(comm, &reached, ks.clone(), p_per);
            drop(reached);
            let mut transfer = Prolongation::split(own_p, p_per, pt, pt_per, size, comm.rank());
            transfer.set_halo(halo);
            transfer
        }
    };
    (transfer, ac)
}

/// Rows `range` of `m`, numbered from the first.
fn rows_of(m: &Csr, range: Range<usize>) -> Csr {
    let mut out = Csr::empty(m.cols);
    for r in range {
        let (c, v) = m.row(r);
        out.idx.extend_from_slice(c);
        out.val.extend_from_slice(v);
        out.end_row();
    }
    out
}

/// P^T A P on more ranks than one, by groups of its rows (`pt`'s rows, the product's: at
/// least 8, and 4 per rank), each group's sums handed on rank after rank: rank r forms
/// its part of a group (the terms of its rows `ks` of A) on from the sums rank r - 1
/// sent it and sends them on to rank r + 1, so every entry is the one sum the whole
/// product forms, while the ranks work at once on different groups (a pipeline, instead
/// of each rank waiting for the whole product of the ranks before it). A group's terms
/// come mostly from one rank (the next level's aggregates are numbered as the rows the
/// ranks hold), so the groups go through the pipeline in the order of that rank, the last
/// rank's first: the ranks before it pass them on at little cost, and each rank has its
/// own groups' terms to sum while the ranks after it sum theirs. The last rank holds the
/// whole product, takes its symmetric part and gives it to every rank a group at a time,
/// of which each rank keeps its rows `next` (numbered from the first; collective).
fn pipelined<C: Comm + ?Sized>(
    comm: &C,
    pt: &Csr,
    view: &mut View,
    ks: Range<usize>,
    (p, next): (&Picked, Range<usize>),
) -> Csr {
    let (rank, last) = (comm.rank(), comm.size() - 1);
    let per = pt
        .rows
        .div_ceil(PIPELINE_GROUPS.max(4 * comm.size()))
        .max(1);
    let groups: Vec<Range<usize>> = (0..pt.rows)
        .step_by(per)
        .map(|g| g..(g + per).min(pt.rows))
        .collect();
    // Each group's terms on this rank (its entries of P^T, all in `ks`), every rank's.
    let terms: Vec<f64> = groups
        .iter()
        .map(|g| (pt.ptr[g.end] - pt.ptr[g.start]) as f64)
        .collect();
    let all = comm.all_gather_f64(&terms);
    let mut order: Vec<(usize, usize)> = (0..terms.len())
        .map(|g| {
            let home = (0..all.len()).fold(0, |h, r| if all[r][g] > all[h][g] { r } else { h });
            (last - home, g)
        })
        .collect();
    order.sort_unstable();
    let mut parts: Vec<Option<Csr>> = vec![None; terms.len()];
    comm.chain(order.len(), &mut |i, received| {
        let g = order[i].1;
        let seed = received.map(|b| Csr::from_bytes(&b));
        let rows = groups[g].clone();
        let part = triple_product_part((pt, rows), view, ks.clone(), p, 1, seed.as_ref());
        drop(seed);
        if rank < last {
            part.to_bytes()
        } else {
            parts[g] = Some(part);
            Vec::new()
        }
    });
    let mut whole = Csr::empty(pt.rows);
    for part in parts.into_iter().flatten() {
        whole.append(&part);
    }
    if rank == last {
        whole = whole.into_symmetric_part();
    }
    // Every rank keeps its rows `next`, from the groups as the last rank sends them.
    let mut mine = Csr::empty(pt.rows);
    for range in groups {
        let mut bytes = if rank == last {
            whole.rows_to_bytes(range.clone())
        } else {
            Vec::new()
        };
        comm.broadcast_bytes(last, &mut bytes);
        let piece = if rank == last {
            drop(bytes);
            rows_of(&whole, range.clone())
        } else {
            Csr::from_bytes(&bytes)
        };
        let wanted = range.start.max(next.start)..range.end.min(next.end);
        if !wanted.is_empty() {
            let local = wanted.start - range.start..wanted.end - range.start;
            mine.append(&rows_of(&piece, local));
        }
    }
    mine
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::precond::multilevel::triple::RowsOf;

    #[test]
    fn the_rows_gathered_piece_by_piece_are_those_of_the_matrix_and_its_transpose_bit_for_bit() {
        // 1000 aggregates (6000 rows, pieces of 4096 rows and a last one of 1904), entries
        // with values that round, an explicit zero among them, some rows empty.
        let aggregates = 1000;
        let mut t = Vec::new();
        for i in 0..MODES * aggregates {
            for j in 0..37u32 {
                if (i as u32 * 11 + j * 7) % 13 < 3 && !i.is_multiple_of(17) {
                    let v = if (i + j as usize).is_multiple_of(29) {
                        0.0
                    } else {
                        0.1 * (i as f64 + 0.3) / (j as f64 + 1.7)
                    };
                    t.push((i as u32, j, v));
                }
            }
        }
        let own = Csr::from_triplets(MODES * aggregates, 37, t);
        let want = own.transpose();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let picked: Vec<u32> = (0..MODES as u32 * 1000).filter(|r| r % 7 < 2).collect();
        // The whole transpose, and rows 5..23 of it (a rank's range of them).
        for keep in [0..37, 5..23] {
            let comm = &crate::comm::SerialComm;
            let (got, p) = gathered(comm, &own, aggregates, keep.clone(), &picked);
            assert_eq!((got.rows, got.cols), (keep.len(), want.cols));
            for (g, w) in keep.enumerate() {
                let (gc, gv) = got.row(g);
                let (wc, wv) = want.row(w);
                assert_eq!((gc, bits(gv)), (wc, bits(wv)), "row {w} of P^T");
            }
            for &r in &picked {
                let (pc, pv) = p.row_of(r as usize);
                let (oc, ov) = own.row(r as usize);
                assert_eq!((pc, bits(pv)), (oc, bits(ov)), "row {r} of P");
            }
        }
    }

    #[test]
    fn the_held_aggregates_tile_the_level_and_start_where_split_places_them() {
        for aggregates in [1usize, 5, 151, 1000] {
            for ranks in 1..=100 {
                let per = aggregates.div_ceil(ranks);
                let mut next = 0;
                for rank in 0..ranks {
                    let h = held_by(aggregates, ranks, rank);
                    assert_eq!(h.start, rank * per, "{aggregates} {ranks} {rank}");
                    if !h.is_empty() {
                        assert_eq!(h.start, next);
                        next = h.end;
                    }
                }
                assert_eq!(next, aggregates, "{aggregates} aggregates on {ranks} ranks");
            }
        }
    }
}
