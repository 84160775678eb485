//! A coarse space for the CG preconditioner: the two-level additive preconditioner
//! M^-1 = (nodal block Jacobi) + Q Kc^-1 Q^T, where the columns of Q are the six rigid-body
//! modes of aggregates of nodes (the nodes of one body inside one cell of a uniform grid of
//! cell size H, several elements wide) projected on the free directions of constrained
//! nodes, and Kc = Q^T A Q is the operator of the model problem (constraints included)
//! seen through them. Jacobi takes care of the wavelengths near the element size, the coarse
//! space of those longer than H; CG iterations grow like H/h instead of like the number of
//! elements along the body.
//!
//! Kc is measured, not assembled: the aggregates are coloured so that two aggregates of one
//! colour never touch (27 colours of a 3 x 3 x 3 cell pattern, times the bodies sharing a
//! cell), and one operator application per colour and mode gives every aggregate's coupling
//! to its neighbour of that colour (162 applications for one body per cell).
//!
//! Everything is independent of the partition: aggregates come from the global mesh; a
//! coarse coefficient is summed by one rank over its aggregate's nodes in global node order
//! (values of nodes owned elsewhere are fetched first); every rank factors the same Kc and
//! solves the same coarse system. Results stay bitwise identical on any number of ranks.

use super::aggregates::{Aggregates, MODES};
use super::dense_cholesky::DenseCholesky;
use crate::comm::{message, Comm};
use crate::constraints::Constraints;
use crate::math::Vec3;
use crate::memory::AllocError;
use crate::mesh::local::LocalMesh;
use crate::mesh::whole::Whole;
use crate::mesh::GlobalMesh;
use crate::problem::Problem;
use std::collections::HashMap;

/// At most this many aggregates (a dense coarse factor of (6 x this)^2 values per rank).
const MAX_AGGREGATES: usize = 400;
/// Aim at aggregates about this many nodes wide.
const NODES_PER_SIDE: f64 = 6.0;

pub struct CoarseSpace {
    num_aggregates: usize,
    /// Colour of each aggregate.
    color: Vec<u16>,
    num_colors: usize,
    /// For each aggregate and colour, the neighbouring aggregate of that colour (it may be
    /// the aggregate itself), or u32::MAX.
    neighbour: Vec<u32>,
    /// The aggregates (offsets scaled by the cell size H) and their summation plan.
    aggregates: Aggregates,
    /// The factor of Kc, when set up.
    factor: Option<DenseCholesky>,
    /// A short description for the log.
    pub summary: String,
}

impl CoarseSpace {
    /// Builds the aggregates and the summation plan (collective), or says why a coarse
    /// space is not used for this mesh: the cell size, the aggregates (cell and body), their
    /// colours and neighbours, their centres, and which rank sums each. Made on rank 0 from
    /// the whole mesh (`whole`) and sent.
    pub fn new<C: Comm + ?Sized>(
        comm: &C,
        problem: &Problem,
        whole: Option<&Whole>,
        mesh: &LocalMesh,
    ) -> Result<Self, String> {
        let made = whole.map(|w| Made::of(problem, &w.mesh));
        let space: Result<Space, String> =
            message::broadcast(comm, made.as_ref().map(|m| m.space.clone()).as_ref());
        let Space {
            color,
            num_colors,
            neighbour,
            centre,
            h,
        } = space?;
        let na = centre.len();
        let agg = made.map(|m| m.agg);
        let aggregates =
            Aggregates::scattered(comm, mesh, whole.zip(agg.as_deref()), (centre, vec![h; na]));
        Ok(CoarseSpace {
            num_aggregates: na,
            color,
            num_colors,
            neighbour,
            aggregates,
            factor: None,
            summary: format!(
                "coarse space: {na} aggregates ({} unknowns), cell size {h:.4e}, {num_colors} colours",
                MODES * na
            ),
        })
    }

    pub fn dim(&self) -> usize {
        MODES * self.num_aggregates
    }

    pub fn is_set_up(&self) -> bool {
        self.factor.is_some()
    }

    pub fn invalidate(&mut self) {
        self.factor = None;
    }

    pub fn num_colors(&self) -> usize {
        self.num_colors
    }

    /// The probe vector of colour `c` and mode `m` on the owned nodes (projected on the free
    /// directions of constrained nodes); ghosts are zero. `nodes`: the owned nodes' count
    /// and the local mesh's positions.
    pub fn probe(
        &self,
        cons: &Constraints,
        (c, m): (usize, usize),
        nodes: (usize, &[Vec3]),
        v: &mut [Vec3],
    ) {
        self.aggregates.probe(cons, &self.color, c, m, nodes, v);
    }

    /// Q^T r: every aggregate's six coefficients, the same on every rank. Collective.
    /// `x`: the local mesh's positions.
    pub fn restrict<C: Comm + ?Sized>(&self, comm: &C, x: &[Vec3], r: &[Vec3], out: &mut Vec<f64>) {
        out.clear();
        out.resize(self.dim(), 0.0);
        self.aggregates.restrict(comm, x, r, out);
    }

    /// Records the coarse coefficients of A applied to probe (c, m).
    pub fn record(&self, c: usize, m: usize, restricted: &[f64], kc: &mut [f64]) {
        let n = self.dim();
        for k in 0..self.num_aggregates {
            let j = self.neighbour[k * self.num_colors + c];
            if j == u32::MAX {
                continue;
            }
            for l in 0..MODES {
                kc[(MODES * k + l) * n + MODES * j as usize + m] = restricted[MODES * k + l];
            }
        }
    }

    /// Symmetrises and factors Kc (dense Cholesky; coarse unknowns with no stiffness of
    /// their own, such as the modes of an aggregate held by Dirichlet conditions, are left
    /// out). Returns the number of unknowns kept; fails only when the memory for the
    /// factor is refused.
    pub fn factor(&mut self, mut kc: Vec<f64>) -> Result<usize, AllocError> {
        let n = self.dim();
        for i in 0..n {
            for j in 0..i {
                let s = 0.5 * (kc[i * n + j] + kc[j * n + i]);
                kc[i * n + j] = s;
                kc[j * n + i] = s;
            }
        }
        let f = DenseCholesky::try_new(&kc, n, "the coarse operator's factor")?;
        let kept = f.num_kept();
        self.factor = Some(f);
        Ok(kept)
    }

    /// z += Q Kc^-1 Q^T r on the owned nodes. Collective.
    pub fn apply<C: Comm + ?Sized>(
        &self,
        comm: &C,
        cons: &Constraints,
        nodes: (usize, &[Vec3]),
        r: &[Vec3],
        z: &mut [Vec3],
        work: &mut Vec<f64>,
    ) {
        let Some(f) = &self.factor else {
            return;
        };
        self.restrict(comm, nodes.1, r, work);
        f.solve_term_by_term(work);
        self.aggregates.prolong_add(cons, nodes, work, z);
    }
}

/// The box around every node.
fn bounding_box(coords: &[Vec3]) -> (Vec3, Vec3) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for x in coords {
        for i in 0..3 {
            lo[i] = lo[i].min(x[i]);
            hi[i] = hi[i].max(x[i]);
        }
    }
    (lo, hi)
}

/// Each node's aggregate key (its cell, its body) and the cell size. The cell size: about
/// NODES_PER_SIDE nodes per aggregate side, and wide enough that everything one node
/// couples to (its elements, a contact tie and the slave's own elements) lies in its cell
/// or the next one; grown until there are few enough aggregates.
fn aggregate_keys(
    problem: &Problem,
    g: &GlobalMesh,
    lo: &Vec3,
    hi: &Vec3,
) -> (Vec<([u32; 3], u32)>, f64) {
    let n = g.num_nodes();
    let mut span = 0.0f64;
    for e in 0..g.num_elements() {
        let x = g.elements.element(e).iter().map(|&n| &g.coords[n as usize]);
        for i in 0..3 {
            let (a, b) = x
                .clone()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                    (a.min(p[i]), b.max(p[i]))
                });
            span = span.max(b - a);
        }
    }
    let reach = problem
        .contacts
        .iter()
        .map(|c| c.normal_tolerance.max(c.tangential_tolerance))
        .fold(0.0, f64::max);
    let volume: f64 = (0..3).map(|i| (hi[i] - lo[i]).max(span)).product();
    let per_node = volume / n as f64;
    let target = (per_node * NODES_PER_SIDE.powi(3)).cbrt();
    let mut h = target.max(2.0 * span + reach);
    let key_of = |x: &Vec3, h: f64| -> [u32; 3] {
        std::array::from_fn(|i| ((x[i] - lo[i]) / h).floor().max(0.0) as u32)
    };
    loop {
        let keys: Vec<([u32; 3], u32)> = (0..n)
            .map(|a| {
                (
                    key_of(&g.coords[a], h),
                    g.body_of_node(a).unwrap_or(0) as u32,
                )
            })
            .collect();
        let mut distinct = keys.clone();
        distinct.sort_unstable();
        distinct.dedup();
        if distinct.len() <= MAX_AGGREGATES {
            return (keys, h);
        }
        h *= 1.25;
    }
}

/// An aggregate's key: its cell and its body.
type Key = ([u32; 3], u32);

/// Each node's aggregate key, the cell size, and the distinct keys sorted by cell.
fn cells(problem: &Problem, g: &GlobalMesh) -> (Vec<Key>, f64, Vec<Key>) {
    let (lo, hi) = bounding_box(&g.coords);
    let (keys, h) = aggregate_keys(problem, g, &lo, &hi);
    let mut list = keys.clone();
    list.sort_unstable_by_key(|&(c, b)| (c[2], c[1], c[0], b));
    list.dedup();
    (keys, h, list)
}

/// Why the coarse space would not be used for this scene's mesh (`CoarseSpace::new`'s
/// refusal), from the mesh alone: for the memory estimate before the run, which then counts
/// what `auto` runs instead.
pub fn refusal(problem: &Problem) -> Option<String> {
    colours(&cells(problem, &problem.mesh).2).err()
}

/// Colour of each aggregate (of `list`, sorted by cell): the cell's place in a 3 x 3 x 3
/// pattern, and the body's slot among the bodies of its cell; and the number of colours.
fn colours(list: &[([u32; 3], u32)]) -> Result<(Vec<u16>, usize), String> {
    let na = list.len();
    let mut slot = vec![0u16; na];
    for k in 1..na {
        if list[k].0 == list[k - 1].0 {
            slot[k] = slot[k - 1] + 1;
        }
    }
    let slots = slot.iter().copied().max().unwrap_or(0) as usize + 1;
    if slots > 2 {
        return Err(format!(
            "{slots} bodies share one coarse cell (the coarse space handles two)"
        ));
    }
    let pattern = |c: &[u32; 3]| (c[0] % 3 + 3 * (c[1] % 3) + 9 * (c[2] % 3)) as u16;
    let color = (0..na)
        .map(|k| pattern(&list[k].0) + 27 * slot[k])
        .collect();
    Ok((color, 27 * slots))
}

/// For each aggregate and colour, the neighbouring aggregate of that colour (in its cell
/// or the 26 around it), u32::MAX when none.
fn neighbours(list: &[([u32; 3], u32)], color: &[u16], num_colors: usize) -> Vec<u32> {
    let mut neighbour = vec![u32::MAX; list.len() * num_colors];
    for (k, (c, _)) in list.iter().enumerate() {
        for dz in -1i64..=1 {
            for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    let m = [c[0] as i64 + dx, c[1] as i64 + dy, c[2] as i64 + dz];
                    if m.iter().any(|&v| v < 0) {
                        continue;
                    }
                    let cell = [m[0] as u32, m[1] as u32, m[2] as u32];
                    let first = list.partition_point(|&(cc, _)| {
                        (cc[2], cc[1], cc[0]) < (cell[2], cell[1], cell[0])
                    });
                    for (j, &(cj, _)) in list.iter().enumerate().skip(first) {
                        if cj != cell {
                            break;
                        }
                        neighbour[k * num_colors + color[j] as usize] = j as u32;
                    }
                }
            }
        }
    }
    neighbour
}

/// Centres: the mean of each aggregate's nodes, summed in global node order.
fn centres(coords: &[Vec3], agg: &[u32], na: usize) -> Vec<Vec3> {
    let mut centre = vec![[0.0; 3]; na];
    let mut count = vec![0usize; na];
    for (a, x) in coords.iter().enumerate() {
        let k = agg[a] as usize;
        for i in 0..3 {
            centre[k][i] += x[i];
        }
        count[k] += 1;
    }
    for k in 0..na {
        for i in 0..3 {
            centre[k][i] /= count[k] as f64;
        }
    }
    centre
}

/// What every rank is given of the coarse space made on the whole mesh: each aggregate's
/// colour, its neighbour of each colour and its centre, and the cell size.
#[derive(Clone)]
struct Space {
    color: Vec<u16>,
    num_colors: usize,
    neighbour: Vec<u32>,
    centre: Vec<Vec3>,
    h: f64,
}

impl message::Message for Space {
    fn write(&self, w: &mut message::Writer<'_>) {
        w.put(
            &self
                .color
                .iter()
                .map(|&c| u32::from(c))
                .collect::<Vec<u32>>(),
        );
        w.index(self.num_colors);
        w.put(&self.neighbour);
        w.put(&self.centre);
        w.real(self.h);
    }
    fn read(r: &mut message::Reader) -> Option<Self> {
        let color: Vec<u32> = r.get()?;
        Some(Space {
            color: color
                .into_iter()
                .map(|c| u16::try_from(c).ok())
                .collect::<Option<_>>()?,
            num_colors: r.index()?,
            neighbour: r.get()?,
            centre: r.get()?,
            h: r.real()?,
        })
    }
}

/// The coarse space made on the whole mesh (rank 0): the aggregate of every node, and the
/// space, or why there is none.
struct Made {
    agg: Vec<u32>,
    space: Result<Space, String>,
}

impl Made {
    fn of(problem: &Problem, g: &GlobalMesh) -> Made {
        let (keys, h, list) = cells(problem, g);
        let index: HashMap<([u32; 3], u32), u32> = list
            .iter()
            .enumerate()
            .map(|(k, &key)| (key, k as u32))
            .collect();
        let na = list.len();
        let (color, num_colors) = match colours(&list) {
            Ok(c) => c,
            Err(why) => {
                return Made {
                    agg: Vec::new(),
                    space: Err(why),
                }
            }
        };
        let neighbour = neighbours(&list, &color, num_colors);
        let agg: Vec<u32> = keys.iter().map(|k| index[k]).collect();
        let centre = centres(&g.coords, &agg, na);
        Made {
            agg,
            space: Ok(Space {
                color,
                num_colors,
                neighbour,
                centre,
                h,
            }),
        }
    }
}
