//! The mortar integrals of one slave face against one master face: both projected onto
//! the slave face's auxiliary plane, the master's projection clipped to the slave's, the
//! overlap cut into triangles from its centre and integrated with a rule of degree 5
//! (exact for the degree-4 integrands of faces that are parallelograms).

use super::dual::dual_shape;
use super::plane::{clip, local, polygon_area, Plane, P2, TRIANGLE_RULE};
use crate::contact::facet::{self, shape};
use crate::math::{cross, dot, Vec3};

/// How far a master face takes part in a slave face's integrals, by the cosine c between
/// the slave face's normal and the opposite of the master's: wholly within 30 degrees
/// (c >= FULL), not at all beyond 60 (c <= NONE), and in between by a smooth step. Two
/// faces more than 45 degrees apart meet across a corner, not face to face (the angle at
/// which the search and the smoothing call an edge sharp): the overlap of a steep face,
/// projected along the slave's normal, is a strip whose "gap" is a distance across the
/// corner. A hard cut (78 degrees) turned a slab face behind a block die's back edge,
/// sloping about 12 degrees, into the back face's partner and out again as the slope
/// crossed the cut, in every other contact update; the step makes the tie's weights and
/// normal continuous in the angle.
const FULL: f64 = 0.866_025_403_784_438_6;
const NONE: f64 = 0.5;

/// The share of a master face at cosine `c` (see `FULL`).
fn facing(c: f64) -> f64 {
    let x = ((c - NONE) / (FULL - NONE)).clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// Overlaps smaller than this fraction of the slave face's projected area are round-off
/// of faces that only touch along an edge.
const SLIVER: f64 = 1e-12;

/// A slave face prepared for integration: its plane, in-plane corners and dual basis. A
/// face is a contact facet (`contact::facet`): a quadrilateral or a triangle, on either
/// side.
pub struct SlaveFace {
    pub triangle: bool,
    pub plane: Plane,
    pub corners: [P2; 4],
    pub dual: [[f64; 4]; 4],
    /// int N_a over the face (the nodes' areas).
    pub areas: [f64; 4],
    /// Heights of the corners above the plane (a warped face's are not all zero).
    heights: [f64; 4],
}

impl SlaveFace {
    pub fn new(x: &[Vec3; 4]) -> Option<SlaveFace> {
        let plane = Plane::of_face(x)?;
        let corners = x.map(|c| plane.project(&c));
        let triangle = facet::is_triangle(x);
        let (dual, areas) = if triangle {
            super::dual::triangle_coefficients(&corners)?
        } else {
            super::dual::coefficients(&corners)?
        };
        Some(SlaveFace {
            triangle,
            plane,
            corners,
            dual,
            areas,
            heights: x.map(|c| plane.height(&c)),
        })
    }
}

/// The integrals over the overlap: per slave corner a, int Phi_a (`d`), int N_a (`n`)
/// and int Phi_a N_k of each master corner k (`m`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Overlap {
    pub d: [f64; 4],
    pub n: [f64; 4],
    pub m: [[f64; 4]; 4],
}

/// Integrates the slave face against the master face with corners `xm` (ordered with
/// the master's outward normal). None when they do not overlap, do not face each other,
/// or the master face lies farther than `reach` from the slave face along the normal.
pub fn integrate(slave: &SlaveFace, xm: &[Vec3; 4], reach: f64) -> Option<Overlap> {
    let nm = cross(
        &crate::math::sub(&xm[2], &xm[0]),
        &crate::math::sub(&xm[3], &xm[1]),
    );
    let l = crate::math::norm(&nm);
    if !(l > 0.0) {
        return None;
    }
    let share = facing(-dot(&nm, &slave.plane.normal) / l);
    if !(share > 0.0) {
        return None;
    }
    let cm: [P2; 4] = xm.map(|c| slave.plane.project(&c));
    let hm: [f64; 4] = xm.map(|c| slave.plane.height(&c));
    let triangle = facet::is_triangle(xm);
    let corners = |t: bool| facet::edges(t);
    let own = &slave.corners[..corners(slave.triangle)];
    let piece = clip(&cm[..corners(triangle)], own);
    let area = polygon_area(own);
    if piece.len() < 3 || polygon_area(&piece).abs() <= SLIVER * area {
        return None;
    }
    let n = piece.len() as f64;
    let centre = [0, 1].map(|i| piece.iter().map(|p| p[i]).sum::<f64>() / n);
    // The gap along the normal at the overlap's centre decides whether the faces are
    // within reach of each other.
    let sc = local(&slave.corners, slave.triangle, &centre)?;
    let mc = local(&cm, triangle, &centre)?;
    let gap = interpolate(&hm, triangle, &mc) - interpolate(&slave.heights, slave.triangle, &sc);
    if gap.abs() > reach {
        return None;
    }
    let mut out = Overlap::default();
    for k in 0..piece.len() {
        let (p, q) = (piece[k], piece[(k + 1) % piece.len()]);
        let tri = 0.5 * super::plane::orient(&centre, &p, &q).abs();
        for (l, w) in TRIANGLE_RULE {
            let x = [0, 1].map(|i| l[0] * centre[i] + l[1] * p[i] + l[2] * q[i]);
            let s = local(&slave.corners, slave.triangle, &x)?;
            let t = local(&cm, triangle, &x)?;
            let phi = dual_shape(&slave.dual, slave.triangle, &s);
            let ns = shape(slave.triangle, &s);
            let nm = shape(triangle, &t);
            for a in 0..4 {
                let f = share * tri * w * phi[a];
                out.d[a] += f;
                out.n[a] += share * tri * w * ns[a];
                for k in 0..4 {
                    out.m[a][k] += f * nm[k];
                }
            }
        }
    }
    Some(out)
}

fn interpolate(v: &[f64; 4], triangle: bool, s: &P2) -> f64 {
    let n = shape(triangle, s);
    (0..4).map(|a| n[a] * v[a]).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad(x0: f64, y0: f64, h: f64, z: f64, up: bool) -> [Vec3; 4] {
        let c = [
            [x0, y0, z],
            [x0 + h, y0, z],
            [x0 + h, y0 + h, z],
            [x0, y0 + h, z],
        ];
        if up {
            c
        } else {
            [c[0], c[3], c[2], c[1]]
        }
    }

    #[test]
    fn a_face_fully_covered_reproduces_its_own_nodes() {
        // Slave face (outward normal down) under four master faces (outward up) that cover
        // it in pieces: sum_k m_ak x_k = d_a x_a for a linear field (the patch test).
        let s = SlaveFace::new(&quad(0.1, 0.2, 0.6, 0.0, false)).unwrap();
        let mut d = [0.0; 4];
        let mut mx = [[0.0; 2]; 4];
        for (x0, y0) in [(0.0, 0.0), (0.45, 0.0), (0.0, 0.45), (0.45, 0.45)] {
            let xm = quad(x0, y0, 0.45, 0.0, true);
            let o = integrate(&s, &xm, 1e-3).unwrap();
            for a in 0..4 {
                d[a] += o.d[a];
                for k in 0..4 {
                    for i in 0..2 {
                        mx[a][i] += o.m[a][k] * xm[k][i];
                    }
                }
            }
        }
        let xs = quad(0.1, 0.2, 0.6, 0.0, false);
        for a in 0..4 {
            // Biorthogonality: the overlap is the whole face, int Phi_a = int N_a.
            assert!((d[a] - s.areas[a]).abs() < 1e-15, "{d:?} {:?}", s.areas);
            for i in 0..2 {
                assert!((mx[a][i] / d[a] - xs[a][i]).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn faces_out_of_reach_or_not_facing_are_skipped() {
        let s = SlaveFace::new(&quad(0.0, 0.0, 1.0, 0.0, false)).unwrap();
        assert!(integrate(&s, &quad(0.0, 0.0, 1.0, -0.5, true), 0.1).is_none());
        assert!(integrate(&s, &quad(0.0, 0.0, 1.0, 0.0, false), 0.1).is_none());
        assert!(integrate(&s, &quad(2.0, 0.0, 1.0, 0.0, true), 0.1).is_none());
        assert!(integrate(&s, &quad(0.0, 0.0, 1.0, -0.05, true), 0.1).is_some());
    }

    /// A master face 3 wide through the slave face's centre (0.5, 0.5, 0), turned about
    /// the y axis by `deg` from facing it (outward normal up): up to 70 degrees its
    /// projection covers the unit slave face.
    fn tilted(deg: f64) -> [Vec3; 4] {
        let (c, s) = (deg.to_radians().cos(), deg.to_radians().sin());
        let p = |u: f64, y: f64| [0.5 + u * c, y, -u * s];
        [p(-1.5, -1.0), p(1.5, -1.0), p(1.5, 2.0), p(-1.5, 2.0)]
    }

    #[test]
    fn a_master_face_takes_part_by_a_smooth_step_of_the_angle() {
        assert_eq!(facing(1.0), 1.0);
        assert_eq!(facing(FULL), 1.0);
        assert_eq!(facing(NONE), 0.0);
        assert_eq!(facing(0.2), 0.0);
        // Continuous and increasing across the band.
        let mut last = 0.0;
        for k in 1..=100 {
            let c = NONE + (FULL - NONE) * k as f64 / 100.0;
            let f = facing(c);
            assert!(f > last && f - last < 0.03, "{c}: {f} after {last}");
            last = f;
        }
        // Within 30 degrees a face counts wholly; beyond 60 not at all (a hard cut at 78
        // degrees took it wholly up to there); between, by its share.
        let s = SlaveFace::new(&quad(0.0, 0.0, 1.0, 0.0, false)).unwrap();
        let total = |deg: f64| integrate(&s, &tilted(deg), 1.0).map(|o| o.d.iter().sum::<f64>());
        let flat = total(0.0).unwrap();
        assert!((total(20.0).unwrap() - flat).abs() < 1e-12 * flat);
        assert!(total(65.0).is_none());
        let half = total(45.0).unwrap() / flat;
        assert!(half > 0.3 && half < 0.7, "{half}");
    }
}
