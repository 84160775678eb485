//! Closest-point projection of a point onto a bilinear quadrilateral face (Newton in the
//! face's local coordinates), and the face normal.

use crate::fem::face;
use crate::math::{cross, dot, norm, scale, sub, Vec3};

/// Local coordinates of the closest point of the (extended) bilinear surface, and whether
/// Newton converged.
pub fn closest_point(x: &[Vec3; 4], p: &Vec3) -> ([f64; 2], bool) {
    let mut s = [0.0f64; 2];
    for _ in 0..30 {
        let n = face::shape(s[0], s[1]);
        let xs = interpolate(x, &n);
        let (ts, tt) = face::tangents(x, s[0], s[1]);
        let d = sub(&xs, p);
        // Gradient of |x(s) - p|^2 / 2 and its Hessian (with the bilinear twist term).
        let g = [dot(&d, &ts), dot(&d, &tt)];
        let mut twist = [0.0; 3];
        for a in 0..4 {
            let c = crate::fem::face::corner(a);
            for i in 0..3 {
                twist[i] += 0.25 * c[0] * c[1] * x[a][i];
            }
        }
        let h = [
            [dot(&ts, &ts), dot(&ts, &tt) + dot(&d, &twist)],
            [dot(&ts, &tt) + dot(&d, &twist), dot(&tt, &tt)],
        ];
        let det = h[0][0] * h[1][1] - h[0][1] * h[1][0];
        if !(det.abs() > 0.0) {
            return (s, false);
        }
        let ds = [
            (h[1][1] * g[0] - h[0][1] * g[1]) / det,
            (h[0][0] * g[1] - h[1][0] * g[0]) / det,
        ];
        s[0] -= ds[0];
        s[1] -= ds[1];
        // Keep far-away points from sending Newton to infinity.
        s[0] = s[0].clamp(-3.0, 3.0);
        s[1] = s[1].clamp(-3.0, 3.0);
        if ds[0].abs() + ds[1].abs() < 1e-14 {
            return (s, true);
        }
    }
    (s, true)
}

#[inline]
pub fn interpolate(x: &[Vec3; 4], n: &[f64; 4]) -> Vec3 {
    let mut out = [0.0; 3];
    for a in 0..4 {
        for i in 0..3 {
            out[i] += n[a] * x[a][i];
        }
    }
    out
}

/// Unit outward normal of the face at local coordinates s.
pub fn normal(x: &[Vec3; 4], s: &[f64; 2]) -> Vec3 {
    let (ts, tt) = face::tangents(x, s[0], s[1]);
    let n = cross(&ts, &tt);
    let l = norm(&n);
    [n[0] / l, n[1] / l, n[2] / l]
}

/// A tangent basis of the plane normal to n, chosen deterministically.
pub fn tangents(n: &Vec3) -> (Vec3, Vec3) {
    let a = if n[0].abs() <= n[1].abs() && n[0].abs() <= n[2].abs() {
        [1.0, 0.0, 0.0]
    } else if n[1].abs() <= n[2].abs() {
        [0.0, 1.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    let t1 = cross(&a, n);
    let t1 = scale(&t1, 1.0 / norm(&t1));
    let t2 = cross(n, &t1);
    (t1, t2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projects_onto_a_warped_face() {
        let x = [
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.1],
            [2.0, 1.0, -0.1],
            [0.0, 1.0, 0.05],
        ];
        let p = [1.3, 0.4, 0.7];
        let (s, ok) = closest_point(&x, &p);
        assert!(ok);
        let n = face::shape(s[0], s[1]);
        let xs = interpolate(&x, &n);
        let (ts, tt) = face::tangents(&x, s[0], s[1]);
        let d = sub(&p, &xs);
        // At the closest point the offset is orthogonal to both tangents.
        assert!(dot(&d, &ts).abs() < 1e-12 && dot(&d, &tt).abs() < 1e-12);
        assert!(dot(&d, &normal(&x, &s)) > 0.0);
    }
}
