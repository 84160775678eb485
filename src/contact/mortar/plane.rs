//! The auxiliary plane of a slave face, on which a slave face and a master face are
//! overlapped: projection along the plane's normal, the inverse of a projected bilinear
//! face, convex clipping and a triangle rule.

use crate::fem::face::{shape, shape_derivatives};
use crate::math::{cross, dot, norm, scale, sub, Vec3};

pub type P2 = [f64; 2];

/// The plane through a slave face's centre, normal to its diagonals' cross product
/// (outward from the slave body).
#[derive(Clone, Copy, Debug)]
pub struct Plane {
    pub origin: Vec3,
    pub normal: Vec3,
    e1: Vec3,
    e2: Vec3,
}

impl Plane {
    /// The plane of the face with corners `x` (ordered with an outward normal); None for a
    /// degenerate face.
    pub fn of_face(x: &[Vec3; 4]) -> Option<Plane> {
        let mut origin = [0.0; 3];
        for c in x {
            for i in 0..3 {
                origin[i] += 0.25 * c[i];
            }
        }
        let n = cross(&sub(&x[2], &x[0]), &sub(&x[3], &x[1]));
        let l = norm(&n);
        if !(l > 0.0 && l.is_finite()) {
            return None;
        }
        let normal = scale(&n, 1.0 / l);
        let (e1, e2) = crate::contact::project::tangents(&normal);
        Some(Plane {
            origin,
            normal,
            e1,
            e2,
        })
    }

    /// In-plane coordinates of the projection of `x` along the normal.
    pub fn project(&self, x: &Vec3) -> P2 {
        let d = sub(x, &self.origin);
        [dot(&d, &self.e1), dot(&d, &self.e2)]
    }

    /// Signed distance of `x` from the plane along the normal.
    pub fn height(&self, x: &Vec3) -> f64 {
        dot(&sub(x, &self.origin), &self.normal)
    }
}

/// Twice the signed area of the triangle (a, b, c): positive when counter-clockwise.
pub fn orient(a: &P2, b: &P2, c: &P2) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Signed area of a polygon (positive when counter-clockwise).
pub fn polygon_area(p: &[P2]) -> f64 {
    let mut a = 0.0;
    for i in 0..p.len() {
        let (u, v) = (p[i], p[(i + 1) % p.len()]);
        a += u[0] * v[1] - u[1] * v[0];
    }
    0.5 * a
}

/// The part of polygon `subject` inside the convex counter-clockwise polygon `clip`
/// (Sutherland-Hodgman). Points on an edge count as inside.
pub fn clip(subject: &[P2], clip: &[P2]) -> Vec<P2> {
    let mut out: Vec<P2> = subject.to_vec();
    for i in 0..clip.len() {
        if out.is_empty() {
            break;
        }
        let (a, b) = (clip[i], clip[(i + 1) % clip.len()]);
        let input = std::mem::take(&mut out);
        for j in 0..input.len() {
            let (p, q) = (input[j], input[(j + 1) % input.len()]);
            let (sp, sq) = (orient(&a, &b, &p), orient(&a, &b, &q));
            if sp >= 0.0 {
                out.push(p);
            }
            if (sp >= 0.0) != (sq >= 0.0) {
                let t = sp / (sp - sq);
                out.push([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]);
            }
        }
    }
    out
}

/// The local coordinates of the point `p` of the bilinear quadrilateral with (in-plane)
/// corners `c`, by Newton's method; None when it does not converge (a degenerate map).
pub fn inverse_bilinear(c: &[P2; 4], p: &P2) -> Option<P2> {
    let mut s = [0.0, 0.0];
    let size = (c[2][0] - c[0][0]).abs() + (c[2][1] - c[0][1]).abs();
    for _ in 0..30 {
        let n = shape(s[0], s[1]);
        let d = shape_derivatives(s[0], s[1]);
        let mut r = [-p[0], -p[1]];
        let mut j = [[0.0; 2]; 2];
        for a in 0..4 {
            for i in 0..2 {
                r[i] += n[a] * c[a][i];
                for k in 0..2 {
                    j[i][k] += d[a][k] * c[a][i];
                }
            }
        }
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        if det.abs() <= 1e-300 || !det.is_finite() {
            return None;
        }
        let ds = [
            (j[1][1] * r[0] - j[0][1] * r[1]) / det,
            (-j[1][0] * r[0] + j[0][0] * r[1]) / det,
        ];
        s = [s[0] - ds[0], s[1] - ds[1]];
        if r[0].abs() + r[1].abs() <= 1e-15 * size {
            return Some(s);
        }
    }
    None
}

/// The local coordinates of the point `p` of the facet with in-plane corners `c`: the
/// inverse bilinear map of a quadrilateral, the barycentric coordinates (of the second
/// and third corners) of a triangle (`contact::facet`). None for a degenerate facet.
pub fn local(c: &[P2; 4], triangle: bool, p: &P2) -> Option<P2> {
    if !triangle {
        return inverse_bilinear(c, p);
    }
    let (e1, e2) = (
        [c[1][0] - c[0][0], c[1][1] - c[0][1]],
        [c[2][0] - c[0][0], c[2][1] - c[0][1]],
    );
    let det = e1[0] * e2[1] - e1[1] * e2[0];
    if det.abs() <= 1e-300 || !det.is_finite() {
        return None;
    }
    let d = [p[0] - c[0][0], p[1] - c[0][1]];
    Some([
        (d[0] * e2[1] - d[1] * e2[0]) / det,
        (e1[0] * d[1] - e1[1] * d[0]) / det,
    ])
}

/// The Jacobian determinant of the in-plane bilinear map at `s`.
pub fn jacobian(c: &[P2; 4], s: &P2) -> f64 {
    let d = shape_derivatives(s[0], s[1]);
    let mut j = [[0.0; 2]; 2];
    for a in 0..4 {
        for i in 0..2 {
            for k in 0..2 {
                j[i][k] += d[a][k] * c[a][i];
            }
        }
    }
    j[0][0] * j[1][1] - j[0][1] * j[1][0]
}

const B1: f64 = 0.470_142_064_105_115_1;
const A1: f64 = 0.059_715_871_789_769_82;
const W1: f64 = 0.132_394_152_788_506_16;
const B2: f64 = 0.101_286_507_323_456_34;
const A2: f64 = 0.797_426_985_353_087_3;
const W2: f64 = 0.125_939_180_544_827_15;

/// The 7-point rule of degree 5 on a triangle: (barycentric coordinates, weight), the
/// weights summing to 1 (multiply by the area).
pub const TRIANGLE_RULE: [([f64; 3], f64); 7] = [
    ([1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0], 0.225),
    ([A1, B1, B1], W1),
    ([B1, A1, B1], W1),
    ([B1, B1, A1], W1),
    ([A2, B2, B2], W2),
    ([B2, A2, B2], W2),
    ([B2, B2, A2], W2),
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_rule_integrates_quartics_exactly() {
        // On the triangle (0,0), (1,0), (0,1): integral of x^a y^b = a! b! / (a + b + 2)!.
        let fact = |n: u32| (1..=n).map(f64::from).product::<f64>();
        let sum: f64 = TRIANGLE_RULE.iter().map(|r| r.1).sum();
        assert!((sum - 1.0).abs() < 1e-15);
        for a in 0..=5u32 {
            for b in 0..=(5 - a) {
                let q: f64 = TRIANGLE_RULE
                    .iter()
                    .map(|(l, w)| 0.5 * w * l[1].powi(a as i32) * l[2].powi(b as i32))
                    .sum();
                let exact = fact(a) * fact(b) / fact(a + b + 2);
                // Degree 5: exact to round-off for every monomial up to x^a y^b, a + b <= 5.
                assert!((q - exact).abs() < 1e-15, "x^{a} y^{b}: {q} vs {exact}");
            }
        }
    }

    #[test]
    fn clipping_two_squares_leaves_their_overlap() {
        let sq =
            |x0: f64, y0: f64, h: f64| vec![[x0, y0], [x0 + h, y0], [x0 + h, y0 + h], [x0, y0 + h]];
        let c = clip(&sq(0.5, 0.25, 1.0), &sq(0.0, 0.0, 1.0));
        // The overlap is [0.5, 1] x [0.25, 1]: area 0.375 (round-off only).
        assert!((polygon_area(&c) - 0.375).abs() < 1e-15);
        assert!(clip(&sq(2.0, 0.0, 1.0), &sq(0.0, 0.0, 1.0)).len() < 3);
    }

    #[test]
    fn inverse_bilinear_recovers_local_coordinates() {
        let c = [[0.0, 0.0], [2.0, 0.1], [2.3, 1.7], [-0.2, 1.2]];
        for s in [[-0.3, 0.8], [0.9, -0.95], [0.0, 0.0]] {
            let n = shape(s[0], s[1]);
            let p = [0, 1].map(|i| (0..4).map(|a| n[a] * c[a][i]).sum::<f64>());
            let r = inverse_bilinear(&c, &p).unwrap();
            // Newton converges quadratically to round-off.
            assert!((r[0] - s[0]).abs() < 1e-13 && (r[1] - s[1]).abs() < 1e-13);
        }
    }
}
