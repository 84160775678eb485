//! Aggregates of nodes with the six rigid-body modes of each: the space Q that the two-level
//! coarse space (coarse.rs) and the multilevel preconditioner's fine-level transfer
//! (multilevel/transfer.rs) restrict to and prolong from. A column of Q is one mode of one
//! aggregate, projected on the free directions of constrained nodes.
//!
//! Restriction Q^T r sums each aggregate on the rank that owns its lowest node, over its
//! nodes in global node order (values of nodes owned elsewhere fetched first), and every
//! rank gathers every aggregate's coefficients (or those of the aggregates it holds,
//! `restrict_held`): the coarse vector is bitwise the same on every rank and on any number
//! of ranks.

use crate::comm::{message, Comm, ExchangePlan};
use crate::constraints::Constraints;
use crate::math::{matvec, Vec3};
use crate::mesh::local::LocalMesh;
use crate::mesh::whole::Whole;
use std::cell::RefCell;

/// Rigid-body modes per aggregate.
pub const MODES: usize = 6;

/// Values of the six modes of an aggregate at a node with scaled offset d.
#[inline]
pub fn modes(d: &Vec3) -> [Vec3; MODES] {
    [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, -d[2], d[1]],
        [d[2], 0.0, -d[0]],
        [-d[1], d[0], 0.0],
    ]
}

/// Where a node value comes from when an aggregate's coefficients are summed.
#[derive(Clone, Copy)]
enum Src {
    Local(u32),
    Remote(u32),
}

pub struct Aggregates {
    /// Per local node (owned, then ghosts): its aggregate.
    agg: Vec<u32>,
    /// Every aggregate's centre and scale: a node's offset is (x - centre) / scale, formed
    /// from the owned node's coordinates where it is used (not kept: 24 bytes per owned
    /// node, 12.7 MB per rank at 10^6 elements on 2 ranks).
    centre: Vec<Vec3>,
    scale: Vec<f64>,
    /// The aggregates this rank sums: aggregate `sum_agg[i]` over the sources
    /// `src[sum_ptr[i]..sum_ptr[i + 1]]`, in global node order (a fetched node's offset is
    /// `far_offset`'s).
    sum_agg: Vec<u32>,
    sum_ptr: Vec<u32>,
    src: Vec<Src>,
    far_offset: Vec<Vec3>,
    fetch: ExchangePlan,
    /// Fetched node values and this rank's coefficients as a message, reused.
    scratch: RefCell<(Vec<Vec3>, Vec<f64>)>,
}

/// A node's offset from its aggregate's centre, scaled.
#[inline]
fn scaled(x: &Vec3, centre: &Vec3, scale: f64) -> Vec3 {
    std::array::from_fn(|i| (x[i] - centre[i]) / scale)
}

impl Aggregates {
    /// The aggregate of every local node (owned, then ghosts).
    pub fn of_local_nodes(&self) -> &[u32] {
        &self.agg
    }

    /// Owned node l's scaled offset from its aggregate's centre (`x` the owned positions).
    #[inline]
    fn offset(&self, x: &[Vec3], l: usize) -> Vec3 {
        let k = self.agg[l] as usize;
        scaled(&x[l], &self.centre[k], self.scale[k])
    }

    /// Aggregate k's centre and scale.
    pub fn centre_and_scale(&self, k: usize) -> (Vec3, f64) {
        (self.centre[k], self.scale[k])
    }

    /// The plan for aggregates made on the whole mesh (collective): rank 0, which holds
    /// `whole` (the whole mesh, the aggregate of every global node and every aggregate's
    /// centre and scale), makes each rank's `Part` and sends it; every rank is given the
    /// centres and scales (`centre_scale`, read on rank 0).
    pub fn scattered<C: Comm + ?Sized>(
        comm: &C,
        mesh: &LocalMesh,
        whole: Option<(&Whole, &[u32])>,
        (centre, scale): (Vec<Vec3>, Vec<f64>),
    ) -> Self {
        let members = whole.map(|(_, agg)| Members::new(agg, centre.len()));
        let part = message::scatter(comm, |r| {
            let (Some((w, agg)), Some(members)) = (whole, &members) else {
                unreachable!("rank 0 holds the whole mesh's aggregates")
            };
            let (nodes, owned) = w.nodes_of(r);
            Part::of(
                (agg, &w.mesh.coords, members),
                (&centre, &scale),
                &nodes,
                owned,
            )
        });
        drop(members);
        Self::from_part(comm, mesh, part, (centre, scale))
    }

    /// The plan from this rank's part (collective: the fetch of the nodes it sums and does
    /// not own).
    fn from_part<C: Comm + ?Sized>(
        comm: &C,
        mesh: &LocalMesh,
        part: Part,
        (centre, scale): (Vec<Vec3>, Vec<f64>),
    ) -> Self {
        let mut wanted = Vec::new();
        let src = part
            .members
            .iter()
            .map(|&gid| match mesh.owned_node(gid) {
                Some(l) => Src::Local(l as u32),
                None => {
                    wanted.push((gid, wanted.len() as u32));
                    Src::Remote(wanted.len() as u32 - 1)
                }
            })
            .collect();
        debug_assert_eq!(wanted.len(), part.far_offset.len());
        let fetch = mesh.fetch_plan(comm, &wanted);
        let scratch = (
            vec![[0.0; 3]; wanted.len()],
            Vec::with_capacity(part.sum_agg.len() * (MODES + 1)),
        );
        Aggregates {
            agg: part.agg,
            centre,
            scale,
            sum_agg: part.sum_agg,
            sum_ptr: part.sum_ptr,
            src,
            far_offset: part.far_offset,
            fetch,
            scratch: RefCell::new(scratch),
        }
    }

    /// out = Q^T r: every aggregate's six coefficients (`out` holds MODES per aggregate),
    /// the same on every rank. Collective.
    /// `x` holds the owned nodes' positions (the local mesh's, owned first).
    pub fn restrict<C: Comm + ?Sized>(&self, comm: &C, x: &[Vec3], r: &[Vec3], out: &mut [f64]) {
        if comm.size() == 1 {
            self.sums(comm, x, r, |k, acc| {
                out[MODES * k..MODES * (k + 1)].copy_from_slice(&acc);
            });
            return;
        }
        let mut mine = std::mem::take(&mut self.scratch.borrow_mut().1);
        mine.clear();
        self.sums(comm, x, r, |k, acc| {
            message::push(&mut mine, &(k as u32, acc))
        });
        for part in comm.all_gather_f64(&mine) {
            for (k, coefficients) in message::items::<(u32, [f64; MODES])>(&part) {
                let k = k as usize;
                out[MODES * k..MODES * (k + 1)].copy_from_slice(&coefficients);
            }
        }
        self.scratch.borrow_mut().1 = mine;
    }

    /// `restrict`'s coefficients of this rank's aggregates only, where each rank holds
    /// `per` aggregates in rank order (`multilevel::first::held`): each aggregate's sum
    /// goes to the rank that holds it, and `out` gets six per held aggregate. No rank holds
    /// the whole coarse vector. The same bits as `restrict`'s. Collective.
    pub fn restrict_held<C: Comm + ?Sized>(
        &self,
        comm: &C,
        x: &[Vec3],
        r: &[Vec3],
        per: usize,
        out: &mut [f64],
    ) {
        let mut send = vec![Vec::new(); comm.size()];
        self.sums(comm, x, r, |k, acc| {
            message::push(&mut send[k / per], &(k as u32, acc));
        });
        let first = comm.rank() * per;
        for part in comm.all_to_all_f64(&send) {
            for (k, coefficients) in message::items::<(u32, [f64; MODES])>(&part) {
                let k = k as usize - first;
                out[MODES * k..MODES * (k + 1)].copy_from_slice(&coefficients);
            }
        }
    }

    /// Each aggregate this rank sums (`sum_agg`) and its six coefficients, to `each`.
    fn sums<C: Comm + ?Sized>(
        &self,
        comm: &C,
        x: &[Vec3],
        r: &[Vec3],
        mut each: impl FnMut(usize, [f64; MODES]),
    ) {
        let far = &mut self.scratch.borrow_mut().0;
        self.fetch.run(comm, r, far);
        for (i, k) in self.sum_agg.iter().enumerate() {
            let mut acc = [0.0; MODES];
            let range = self.sum_ptr[i] as usize..self.sum_ptr[i + 1] as usize;
            for s in &self.src[range] {
                let v = match *s {
                    Src::Local(l) => &r[l as usize],
                    Src::Remote(q) => &far[q as usize],
                };
                // A node without force adds +-0 to sums that start at +0 (a probe's
                // response is zero at most nodes): the same bits without it.
                if *v == [0.0; 3] {
                    continue;
                }
                let d = match *s {
                    Src::Local(l) => self.offset(x, l as usize),
                    Src::Remote(q) => self.far_offset[q as usize],
                };
                for (m, phi) in modes(&d).iter().enumerate() {
                    acc[m] += phi[0] * v[0] + phi[1] * v[1] + phi[2] * v[2];
                }
            }
            each(*k as usize, acc);
        }
    }

    /// z += Q y on the owned nodes (positions `x`).
    pub fn prolong_add(
        &self,
        cons: &Constraints,
        (owned, x): (usize, &[Vec3]),
        y: &[f64],
        z: &mut [Vec3],
    ) {
        for (l, k) in self.agg.iter().enumerate().take(owned) {
            let yk = &y[MODES * *k as usize..MODES * (*k as usize + 1)];
            let mut v = [0.0; 3];
            for (m, phi) in modes(&self.offset(x, l)).iter().enumerate() {
                for i in 0..3 {
                    v[i] += phi[i] * yk[m];
                }
            }
            if let Some(p) = cons.projector(l) {
                v = matvec(p, &v);
            }
            for i in 0..3 {
                z[l][i] += v[i];
            }
        }
    }

    /// The probe of colour `c` and mode `m` on the owned nodes: mode m of every aggregate
    /// of that colour (`colour` of each aggregate; projected on the free directions of
    /// constrained nodes); zero on the other nodes and the ghosts.
    #[allow(clippy::too_many_arguments)]
    pub fn probe(
        &self,
        cons: &Constraints,
        colour: &[u16],
        c: usize,
        m: usize,
        (owned, x): (usize, &[Vec3]),
        v: &mut [Vec3],
    ) {
        v.iter_mut().for_each(|w| *w = [0.0; 3]);
        for (l, k) in self.agg.iter().enumerate().take(owned) {
            if colour[*k as usize] as usize == c {
                let phi = modes(&self.offset(x, l))[m];
                v[l] = match cons.projector(l) {
                    Some(p) => matvec(p, &phi),
                    None => phi,
                };
            }
        }
    }
}

/// The nodes of every aggregate, ascending (each aggregate's list: `nodes[ptr[k]..ptr[k +
/// 1]]`), on the rank that holds the whole mesh's aggregates.
struct Members {
    ptr: Vec<usize>,
    nodes: Vec<u32>,
}

impl Members {
    fn new(agg: &[u32], na: usize) -> Self {
        let mut ptr = vec![0usize; na + 1];
        for &k in agg {
            ptr[k as usize + 1] += 1;
        }
        for k in 0..na {
            ptr[k + 1] += ptr[k];
        }
        let mut next = ptr.clone();
        let mut nodes = vec![0u32; agg.len()];
        for (a, &k) in agg.iter().enumerate() {
            nodes[next[k as usize]] = a as u32;
            next[k as usize] += 1;
        }
        Members { ptr, nodes }
    }

    fn of(&self, k: usize) -> &[u32] {
        &self.nodes[self.ptr[k]..self.ptr[k + 1]]
    }
}

/// What one rank needs of the whole mesh's aggregates: the aggregate of each of its local
/// nodes, and the aggregates whose lowest node it owns (which it sums), each with its nodes
/// in global order and the scaled offsets of those it does not own, in that order.
struct Part {
    agg: Vec<u32>,
    sum_agg: Vec<u32>,
    sum_ptr: Vec<u32>,
    members: Vec<u32>,
    far_offset: Vec<Vec3>,
}

impl Part {
    /// The part of the rank of local nodes `nodes`, the first `owned` of them its own:
    /// from the aggregate of every global node, their positions and the aggregates' nodes.
    fn of(
        (agg, coords, members): (&[u32], &[Vec3], &Members),
        (centre, scale): (&[Vec3], &[f64]),
        nodes: &[u32],
        owned: usize,
    ) -> Part {
        let owns = |g: u32| nodes[..owned].binary_search(&g).is_ok();
        let mut sums: Vec<u32> = nodes[..owned]
            .iter()
            .map(|&g| agg[g as usize])
            .filter(|&k| owns(members.of(k as usize)[0]))
            .collect();
        sums.sort_unstable();
        sums.dedup();
        let (mut sum_ptr, mut list, mut far_offset) = (vec![0u32], Vec::new(), Vec::new());
        for &k in &sums {
            for &g in members.of(k as usize) {
                list.push(g);
                if !owns(g) {
                    let k = k as usize;
                    far_offset.push(scaled(&coords[g as usize], &centre[k], scale[k]));
                }
            }
            sum_ptr.push(list.len() as u32);
        }
        Part {
            agg: nodes.iter().map(|&g| agg[g as usize]).collect(),
            sum_agg: sums,
            sum_ptr,
            members: list,
            far_offset,
        }
    }
}

impl message::Message for Part {
    fn write(&self, w: &mut message::Writer<'_>) {
        w.put(&self.agg);
        w.put(&self.sum_agg);
        w.put(&self.sum_ptr);
        w.put(&self.members);
        w.put(&self.far_offset);
    }
    fn read(r: &mut message::Reader) -> Option<Self> {
        Some(Part {
            agg: r.get()?,
            sum_agg: r.get()?,
            sum_ptr: r.get()?,
            members: r.get()?,
            far_offset: r.get()?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_modes_are_rigid() {
        // The rotation modes are omega x d: orthogonal to d, the same length as d's part
        // normal to the axis.
        let d = [0.3, -0.7, 1.1];
        for (m, axis) in [(3usize, 0usize), (4, 1), (5, 2)] {
            let v = modes(&d)[m];
            assert!(crate::math::dot(&v, &d).abs() < 1e-16);
            assert_eq!(v[axis], 0.0);
            let normal: f64 = (0..3).filter(|&i| i != axis).map(|i| d[i] * d[i]).sum();
            assert!((crate::math::dot(&v, &v) - normal).abs() < 1e-15);
        }
    }

    #[test]
    fn each_aggregate_is_summed_once_by_the_owner_of_its_lowest_node() {
        // Twelve nodes on a line; aggregate 1 (nodes 3..7) crosses from rank 0's nodes
        // (0..6) into rank 1's (6..12).
        let agg = [0u32, 0, 0, 1, 1, 1, 1, 2, 2, 2, 3, 3];
        let coords: Vec<Vec3> = (0..12).map(|i| [i as f64, 0.0, 0.0]).collect();
        let members = Members::new(&agg, 4);
        assert_eq!(members.of(1), [3, 4, 5, 6]);
        let centre = vec![
            [1.0, 0.0, 0.0],
            [4.5, 0.0, 0.0],
            [8.0, 0.0, 0.0],
            [10.5, 0.0, 0.0],
        ];
        let scale = vec![1.0, 1.5, 1.0, 0.5];
        let whole = (&agg[..], &coords[..], &members);
        // Each rank's local nodes: owned ascending, then ghosts ascending.
        let zero: Vec<u32> = (0..8).collect();
        let one: Vec<u32> = [6, 7, 8, 9, 10, 11, 4, 5].to_vec();
        let p0 = Part::of(whole, (&centre, &scale), &zero, 6);
        let p1 = Part::of(whole, (&centre, &scale), &one, 6);
        assert_eq!(p0.agg, [0, 0, 0, 1, 1, 1, 1, 2]);
        assert_eq!(p1.agg, [1, 2, 2, 2, 3, 3, 1, 1]);
        assert_eq!(
            (p0.sum_agg.as_slice(), p1.sum_agg.as_slice()),
            (&[0, 1][..], &[2, 3][..])
        );
        assert_eq!(p0.sum_ptr, [0, 3, 7]);
        assert_eq!(p0.members, [0, 1, 2, 3, 4, 5, 6]);
        // Node 6 is rank 1's: its offset from aggregate 1's centre, scaled, comes along.
        assert_eq!(p0.far_offset, [[1.0, 0.0, 0.0]]);
        assert_eq!(
            (p1.sum_ptr.as_slice(), p1.members.as_slice()),
            (&[0, 3, 5][..], &[7, 8, 9, 10, 11][..])
        );
        assert!(p1.far_offset.is_empty());
        // The part travels as words and back.
        let back: Part = message::decode::<Part>(&message::words_of(&p0))
            .and_then(|mut v| v.pop())
            .expect("a part decodes");
        assert_eq!(
            (back.agg, back.members, back.far_offset),
            (p0.agg, p0.members, p0.far_offset)
        );
    }
}
