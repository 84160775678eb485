//! A contact facet: what contact searches, projects on and integrates over. A hexahedron's
//! face is one facet, a bilinear quadrilateral; a tet10's 6-node face is four facets, its
//! linear sub-triangles (`FaceKind::contact_facets`). A facet is stored as four node ids
//! (and its positions as four corners); a triangle's fourth repeats its third, so ghosts,
//! messages and the node lists of either shape are the same size, and a quadrilateral is
//! never taken for a triangle (its corners are distinct, or it is degenerate).
//!
//! On a triangle the local coordinates s = (s, t) are the barycentric coordinates of its
//! second and third corners: shape functions (1 - s - t, s, t, 0).

use super::project;
use crate::fem::face;
use crate::math::{cross, dot, norm, sub, Vec3};

/// Whether the facet with these nodes (or corners) is a triangle.
#[inline]
pub fn is_triangle<T: PartialEq>(c: &[T; 4]) -> bool {
    c[3] == c[2]
}

/// The facet's shape functions at local coordinates `s`.
#[inline]
pub fn shape(triangle: bool, s: &[f64; 2]) -> [f64; 4] {
    if triangle {
        [1.0 - s[0] - s[1], s[0], s[1], 0.0]
    } else {
        face::shape(s[0], s[1])
    }
}

/// The facet's nodes' weights at `s`, with the nodes `c` telling its shape.
#[inline]
pub fn shape_of<T: PartialEq>(c: &[T; 4], s: &[f64; 2]) -> [f64; 4] {
    shape(is_triangle(c), s)
}

/// Local coordinates moved onto the facet (each coordinate into [-1, 1] on a
/// quadrilateral; onto the reference triangle s, t >= 0, s + t <= 1 on a triangle).
pub fn clamp(triangle: bool, s: &[f64; 2]) -> [f64; 2] {
    if !triangle {
        return [s[0].clamp(-1.0, 1.0), s[1].clamp(-1.0, 1.0)];
    }
    let mut c = [s[0].max(0.0), s[1].max(0.0)];
    let over = c[0] + c[1] - 1.0;
    if over > 0.0 {
        c = [(c[0] - 0.5 * over).max(0.0), (c[1] - 0.5 * over).max(0.0)];
        let over = c[0] + c[1] - 1.0;
        if over > 0.0 {
            // One coordinate was cut at zero: the other takes the rest.
            c = if c[0] > c[1] {
                [1.0 - c[1], c[1]]
            } else {
                [c[0], 1.0 - c[0]]
            };
        }
    }
    c
}

/// Local coordinates of corner `k` of the facet.
pub fn corner(triangle: bool, k: usize) -> [f64; 2] {
    match (triangle, k) {
        (true, 0) => [0.0, 0.0],
        (true, 1) => [1.0, 0.0],
        (true, _) => [0.0, 1.0],
        (false, k) => face::corner(k),
    }
}

/// Whether `s` lies beyond the facet's edge by more than `margin`, a fraction of the
/// facet's extent in local coordinates (which span 2 on a quadrilateral, 1 on a triangle).
pub fn beyond(triangle: bool, s: &[f64; 2], margin: f64) -> bool {
    if triangle {
        let m = 0.5 * margin;
        s[0] < -m || s[1] < -m || s[0] + s[1] > 1.0 + m
    } else {
        s.iter().any(|v| v.abs() > 1.0 + margin)
    }
}

/// Local coordinates of the closest point of the (extended) facet to `p`, and whether they
/// were found (Newton on a quadrilateral; the exact solve on a flat triangle).
pub fn closest_point(x: &[Vec3; 4], p: &Vec3) -> ([f64; 2], bool) {
    if !is_triangle(x) {
        return project::closest_point(x, p);
    }
    let (e1, e2) = (sub(&x[1], &x[0]), sub(&x[2], &x[0]));
    let d = sub(p, &x[0]);
    let (a, b, c) = (dot(&e1, &e1), dot(&e1, &e2), dot(&e2, &e2));
    let det = a * c - b * b;
    if !(det.abs() > 0.0) {
        return ([0.0; 2], false);
    }
    let (g1, g2) = (dot(&d, &e1), dot(&d, &e2));
    ([(c * g1 - b * g2) / det, (a * g2 - b * g1) / det], true)
}

/// Unit outward normal of the facet at `s` (a triangle's is constant).
pub fn normal(x: &[Vec3; 4], s: &[f64; 2]) -> Vec3 {
    if !is_triangle(x) {
        return project::normal(x, s);
    }
    let n = cross(&sub(&x[1], &x[0]), &sub(&x[2], &x[0]));
    let l = norm(&n);
    [n[0] / l, n[1] / l, n[2] / l]
}

/// The number of edges (edge k runs from corner k to corner k + 1, cyclically).
pub fn edges(triangle: bool) -> usize {
    if triangle {
        3
    } else {
        4
    }
}

/// Integral of each corner's shape function over the facet (a triangle's fourth is 0).
pub fn nodal_areas(x: &[Vec3; 4]) -> [f64; 4] {
    if !is_triangle(x) {
        return face::nodal_areas(x);
    }
    let a = face::triangle_area(&[x[0], x[1], x[2]]) / 3.0;
    [a, a, a, 0.0]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_projection_interpolates_and_clamps() {
        let x = [
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [0.0, 1.0, 0.5],
            [0.0, 1.0, 0.5],
        ];
        assert!(is_triangle(&x));
        // A point above (s, t) = (0.25, 0.5) along the normal projects back onto it.
        let n = normal(&x, &[0.0; 2]);
        let on = project::interpolate(&x, &shape(true, &[0.25, 0.5]));
        let p = [on[0] + 0.3 * n[0], on[1] + 0.3 * n[1], on[2] + 0.3 * n[2]];
        let (s, ok) = closest_point(&x, &p);
        assert!(ok && (s[0] - 0.25).abs() < 1e-15 && (s[1] - 0.5).abs() < 1e-15);
        // The normal is the corners' right-handed one: (0, -0.5, 1) normalised.
        assert!((n[1] + 0.5 / 1.25f64.sqrt()).abs() < 1e-15);
        assert_eq!(clamp(true, &[-0.2, 0.5]), [0.0, 0.5]);
        // Beyond the hypotenuse by 0.4: each coordinate gives 0.2 (to round-off).
        let c = clamp(true, &[0.8, 0.6]);
        assert!(
            (c[0] - 0.6).abs() < 1e-15 && (c[1] - 0.4).abs() < 1e-15,
            "{c:?}"
        );
        assert_eq!(clamp(true, &[1.5, -0.2]), [1.0, 0.0]);
        assert!(!beyond(true, &[0.5, 0.5], 0.0) && beyond(true, &[0.7, 0.5], 0.1));
        let a = nodal_areas(&x);
        // Area |e1 x e2| / 2 = 1.25^0.5, a third at each corner.
        assert!((a.iter().sum::<f64>() - 1.25f64.sqrt()).abs() < 1e-15 && a[3] == 0.0);
    }
}
