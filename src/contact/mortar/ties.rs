//! A mortar pair's slave nodes as kinematic ties: the integrals of every slave face against
//! the master faces it overlaps, summed per slave node into its weights
//! w_k = int Phi_j N_k / int Phi_j over master nodes k (they sum to 1), its averaged
//! normal and its weighted gap. Pure: the caller brings the faces' current positions.

use super::segment::{integrate, SlaveFace};
use crate::math::{dot, norm, scale, sub, Vec3};
use std::collections::BTreeMap;

/// A slave node whose overlapped part of its dual basis integrates to less than this
/// fraction of its area is not tied: its support lies mostly beyond the master surface
/// (the dual function is negative near the far corners, so the integral falls to zero
/// and below about a third of an element beyond the master's edge), and its weights
/// would be large and of mixed sign.
pub const COVERED: f64 = 0.25;

/// A face with its global node ids, current corner positions and the unit outward normal
/// its constraints take (a master face's; unused for a slave face).
#[derive(Clone, Copy, Debug)]
pub struct Face {
    pub nodes: [u32; 4],
    pub x: [Vec3; 4],
    pub normal: Vec3,
}

impl Face {
    /// The face with the normal of the corners `x` (current), or of `reference`
    /// (small kinematics: the directions of linear theory, as node-to-face contact).
    pub fn new(nodes: [u32; 4], x: [Vec3; 4], reference: Option<[Vec3; 4]>) -> Face {
        let c = reference.unwrap_or(x);
        let n = crate::math::cross(&sub(&c[2], &c[0]), &sub(&c[3], &c[1]));
        Face {
            nodes,
            x,
            normal: scale(&n, 1.0 / norm(&n)),
        }
    }
}

/// A slave node's mortar tie.
#[derive(Clone, Debug, PartialEq)]
pub struct Tie {
    pub slave: u32,
    /// Unit normal from the master toward the slave: the master faces' outward normals
    /// averaged over the node's support (weighted by the integral of its standard shape
    /// function over each overlap). Along the master's normals, as node-to-face contact,
    /// so that a flat master gives one fixed normal however the slave deforms (the slave's
    /// own normals would turn with it, and the set would settle only as that iteration
    /// converges).
    pub normal: Vec3,
    /// int Phi_j over the overlapped slave surface: the area the node's multiplier acts on.
    pub area: f64,
    /// Master nodes (ascending) and weights.
    pub masters: Vec<(u32, f64)>,
    /// The weighted gap, normal . (x_j - sum_k w_k x_k), at the positions given.
    pub gap: f64,
    /// The master face (index in the slice given) that carries most of the node's weight.
    pub face: u32,
    /// x_j - sum_k w_k x_k at the positions the tie was made at (or, for a node that
    /// sticks again, at the start of the step): the tangential part is where a sticking
    /// node is held relative to its master point.
    pub offset: Vec3,
}

#[derive(Default)]
struct Sums {
    area: f64,
    full: f64,
    normal: Vec3,
    masters: BTreeMap<u32, f64>,
    /// (int Phi_j over the overlap with a master face, that face): the largest.
    best: (f64, u32),
}

/// The ties of the slave nodes in `wanted` (ascending) from the slave faces and master
/// faces (each in a fixed order: the sums run in that order, so the result is the same
/// wherever it is computed), with master faces overlapped up to `reach` along the normal.
/// `position` gives a node's current position.
pub fn ties(
    slave: &[Face],
    master: &[Face],
    wanted: &[u32],
    reach: f64,
    position: impl Fn(u32) -> Vec3,
) -> Vec<Tie> {
    let mut sums: BTreeMap<u32, Sums> = BTreeMap::new();
    let boxes: Vec<([f64; 3], [f64; 3])> = master.iter().map(|f| bounds(&f.x, 0.0)).collect();
    let grid = Grid::new(&boxes);
    for f in slave {
        let mine: Vec<usize> = (0..4)
            .filter(|&a| wanted.binary_search(&f.nodes[a]).is_ok())
            .collect();
        if mine.is_empty() {
            continue;
        }
        let Some(sf) = SlaveFace::new(&f.x) else {
            continue;
        };
        for &a in &mine {
            sums.entry(f.nodes[a]).or_default().full += sf.areas[a];
        }
        let (lo, hi) = bounds(&f.x, reach);
        for fm in grid.candidates(&lo, &hi) {
            let (m, (mlo, mhi)) = (&master[fm], &boxes[fm]);
            if (0..3).any(|i| mlo[i] > hi[i] || mhi[i] < lo[i]) {
                continue;
            }
            let Some(o) = integrate(&sf, &m.x, reach) else {
                continue;
            };
            for &a in &mine {
                let s = sums.get_mut(&f.nodes[a]).expect("entered above");
                s.area += o.d[a];
                for i in 0..3 {
                    s.normal[i] += o.n[a] * m.normal[i];
                }
                if outweighs((o.d[a], fm as u32), s.best) {
                    s.best = (o.d[a], fm as u32);
                }
                for k in 0..4 {
                    *s.masters.entry(m.nodes[k]).or_insert(0.0) += o.m[a][k];
                }
            }
        }
    }
    sums.into_iter()
        .filter_map(|(j, s)| tie(j, s, &position))
        .collect()
}

/// Whether the overlap `(integral, face)` names the node's face rather than `best`: a larger
/// integral, or one equal to it within `SAME_SHARE` (a node on the edge between two faces
/// of its support, as on the mid-plane of a symmetric slice) and a lower face index, so
/// that the face named does not turn with the solution's error from one contact update to
/// the next.
fn outweighs((d, face): (f64, u32), (best, best_face): (f64, u32)) -> bool {
    d > best + SAME_SHARE * best.abs() || (d >= best - SAME_SHARE * best.abs() && face < best_face)
}

/// Two faces' shares of a node's support that differ by less than this fraction are
/// equal: the positions they are computed at carry the model problem's error (a node
/// on the edge of two faces of a symmetric slice comes out off the edge by 1e-9 of a
/// face, and the shares differ by about 1e-8).
const SAME_SHARE: f64 = 1e-6;

fn tie(slave: u32, s: Sums, position: &impl Fn(u32) -> Vec3) -> Option<Tie> {
    let l = norm(&s.normal);
    if !(s.area > COVERED * s.full) || !(l > 0.0) {
        return None;
    }
    let mut t = Tie {
        slave,
        normal: scale(&s.normal, 1.0 / l),
        area: s.area,
        masters: s
            .masters
            .into_iter()
            .map(|(k, m)| (k, m / s.area))
            .filter(|&(_, w)| w != 0.0)
            .collect(),
        gap: 0.0,
        face: s.best.1,
        offset: [0.0; 3],
    };
    t.offset = relative(&t, &position(slave), position);
    t.gap = dot(&t.normal, &t.offset);
    Some(t)
}

/// The slave node at `x` relative to its master point, x - sum_k w_k x_k, with master
/// positions from `master_position`.
pub fn relative(t: &Tie, x: &Vec3, master_position: &impl Fn(u32) -> Vec3) -> Vec3 {
    let mut d = *x;
    for &(k, w) in &t.masters {
        d = sub(&d, &scale(&master_position(k), w));
    }
    d
}

/// A uniform grid of the master faces' boxes, cells the size of the largest box: the
/// faces a box may overlap, without testing every face.
struct Grid {
    cell: f64,
    cells: std::collections::HashMap<[i64; 3], Vec<usize>>,
}

impl Grid {
    fn new(boxes: &[([f64; 3], [f64; 3])]) -> Grid {
        let cell = boxes
            .iter()
            .flat_map(|(lo, hi)| (0..3).map(move |i| hi[i] - lo[i]))
            .fold(0.0f64, f64::max);
        let mut grid = Grid {
            cell: if cell > 0.0 && cell.is_finite() {
                cell
            } else {
                1.0
            },
            cells: Default::default(),
        };
        for (k, (lo, hi)) in boxes.iter().enumerate() {
            for c in grid.range(lo, hi) {
                grid.cells.entry(c).or_default().push(k);
            }
        }
        grid
    }

    /// The cells a box covers.
    fn range(&self, lo: &[f64; 3], hi: &[f64; 3]) -> Vec<[i64; 3]> {
        let a: [i64; 3] = std::array::from_fn(|i| (lo[i] / self.cell).floor() as i64);
        let b: [i64; 3] = std::array::from_fn(|i| (hi[i] / self.cell).floor() as i64);
        let mut out = Vec::new();
        for x in a[0]..=b[0] {
            for y in a[1]..=b[1] {
                for z in a[2]..=b[2] {
                    out.push([x, y, z]);
                }
            }
        }
        out
    }

    /// The faces whose cells meet the box, ascending (the order the sums run in).
    fn candidates(&self, lo: &[f64; 3], hi: &[f64; 3]) -> Vec<usize> {
        let mut out: Vec<usize> = self
            .range(lo, hi)
            .iter()
            .filter_map(|c| self.cells.get(c))
            .flatten()
            .copied()
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }
}

fn bounds(x: &[Vec3; 4], pad: f64) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for c in x {
        for i in 0..3 {
            lo[i] = lo[i].min(c[i] - pad);
            hi[i] = hi[i].max(c[i] + pad);
        }
    }
    (lo, hi)
}

impl crate::comm::message::Message for Tie {
    fn write(&self, w: &mut crate::comm::message::Writer<'_>) {
        w.id(self.slave);
        w.reals(&self.normal);
        w.real(self.area);
        w.real(self.gap);
        w.id(self.face);
        w.reals(&self.offset);
        w.put(&self.masters);
    }

    fn read(r: &mut crate::comm::message::Reader) -> Option<Self> {
        Some(Tie {
            slave: r.id()?,
            normal: r.reals()?,
            area: r.real()?,
            gap: r.real()?,
            face: r.id()?,
            offset: r.reals()?,
            masters: r.get()?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two master faces side by side (x in [0, 1] and [1, 2], normal +z) under two slave
    /// faces whose shared nodes 12 and 13 lie on the masters' shared edge x = 1, shifted
    /// along x by `dx`.
    fn edge_ties(dx: f64) -> Vec<Tie> {
        let q = |x: [[f64; 2]; 4], z: f64| x.map(|p| [p[0], p[1], z]);
        let master = [
            Face::new(
                [0, 1, 2, 3],
                q([[0., 0.], [1., 0.], [1., 1.], [0., 1.]], 0.0),
                None,
            ),
            Face::new(
                [1, 4, 5, 2],
                q([[1., 0.], [2., 0.], [2., 1.], [1., 1.]], 0.0),
                None,
            ),
        ];
        let s = |x: f64| x + dx;
        let slave = [
            Face::new(
                [10, 11, 12, 13],
                q([[s(0.5), 0.], [s(0.5), 1.], [s(1.), 1.], [s(1.), 0.]], 1e-3),
                None,
            ),
            Face::new(
                [13, 12, 14, 15],
                q([[s(1.), 0.], [s(1.), 1.], [s(1.5), 1.], [s(1.5), 0.]], 1e-3),
                None,
            ),
        ];
        let at = |g: u32| {
            let f = slave.iter().chain(&master).find(|f| f.nodes.contains(&g));
            let f = f.expect("a node of the faces");
            f.x[f.nodes.iter().position(|&n| n == g).expect("its corner")]
        };
        ties(&slave, &master, &[12, 13], 0.01, at)
    }

    #[test]
    fn a_node_on_the_edge_of_two_faces_names_the_same_face_on_either_side_of_it() {
        // Off the edge by 1e-9 of a face either way (the model problem's error), the
        // shares of the two masters differ by about that much: the lower face is named
        // both times. By 1e-3, the face the node stands over.
        for dx in [-1e-9, 0.0, 1e-9] {
            let t = edge_ties(dx);
            assert_eq!(t.len(), 2);
            assert!(t.iter().all(|t| t.face == 0), "dx = {dx}: {t:?}");
        }
        assert!(edge_ties(1e-3).iter().all(|t| t.face == 1));
        assert!(edge_ties(-1e-3).iter().all(|t| t.face == 0));
    }

    #[test]
    fn a_share_outweighs_another_beyond_the_solutions_error() {
        assert!(outweighs((1.1, 1), (1.0, 0)));
        assert!(!outweighs((1.0 + 1e-9, 1), (1.0, 0)));
        assert!(outweighs((1.0 - 1e-9, 0), (1.0, 1)));
        assert!(!outweighs((0.9, 0), (1.0, 1)));
        // The first overlap against the empty start.
        assert!(outweighs((0.5, 3), (0.0, 0)));
    }
}
