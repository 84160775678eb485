//! Bilinear quadrilateral faces: geometry, consistent nodal loads of pressure and traction;
//! and the same loads on the linear triangles a 6-node triangular face is made of.

use crate::math::{cross, Vec3};

const G: f64 = 0.577_350_269_189_625_8;
const GAUSS2: [[f64; 2]; 4] = [[-G, -G], [G, -G], [G, G], [-G, G]];
const CORNERS: [[f64; 2]; 4] = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];

/// Local coordinates of corner `a`.
#[inline]
pub fn corner(a: usize) -> [f64; 2] {
    CORNERS[a]
}

#[inline]
pub fn shape(s: f64, t: f64) -> [f64; 4] {
    let mut n = [0.0; 4];
    for (a, na) in n.iter_mut().enumerate() {
        *na = 0.25 * (1.0 + s * CORNERS[a][0]) * (1.0 + t * CORNERS[a][1]);
    }
    n
}

#[inline]
pub fn shape_derivatives(s: f64, t: f64) -> [[f64; 2]; 4] {
    let mut d = [[0.0; 2]; 4];
    for (a, da) in d.iter_mut().enumerate() {
        let (ps, pt) = (CORNERS[a][0], CORNERS[a][1]);
        *da = [0.25 * ps * (1.0 + t * pt), 0.25 * pt * (1.0 + s * ps)];
    }
    d
}

/// Tangent vectors dx/ds and dx/dt.
#[inline]
pub fn tangents(x: &[Vec3; 4], s: f64, t: f64) -> (Vec3, Vec3) {
    let d = shape_derivatives(s, t);
    let mut ts = [0.0; 3];
    let mut tt = [0.0; 3];
    for a in 0..4 {
        for i in 0..3 {
            ts[i] += d[a][0] * x[a][i];
            tt[i] += d[a][1] * x[a][i];
        }
    }
    (ts, tt)
}

/// Consistent nodal forces of a uniform pressure `p` (positive pushes against the outward
/// normal) on the face with corner positions `x` (ordered with an outward normal).
pub fn pressure_forces(x: &[Vec3; 4], p: f64) -> [Vec3; 4] {
    let mut f = [[0.0; 3]; 4];
    for gp in GAUSS2.iter() {
        let (ts, tt) = tangents(x, gp[0], gp[1]);
        // |ts x tt| ds dt is the area element; ts x tt is outward.
        let an = cross(&ts, &tt);
        let n = shape(gp[0], gp[1]);
        for a in 0..4 {
            for i in 0..3 {
                f[a][i] -= p * n[a] * an[i];
            }
        }
    }
    f
}

/// Consistent nodal forces of a uniform traction vector (force per unit area).
pub fn traction_forces(x: &[Vec3; 4], traction: &Vec3) -> [Vec3; 4] {
    let mut f = [[0.0; 3]; 4];
    for gp in GAUSS2.iter() {
        let (ts, tt) = tangents(x, gp[0], gp[1]);
        let area = crate::math::norm(&cross(&ts, &tt));
        let n = shape(gp[0], gp[1]);
        for a in 0..4 {
            for i in 0..3 {
                f[a][i] += n[a] * area * traction[i];
            }
        }
    }
    f
}

/// Area of the face.
pub fn area(x: &[Vec3; 4]) -> f64 {
    GAUSS2
        .iter()
        .map(|gp| {
            let (ts, tt) = tangents(x, gp[0], gp[1]);
            crate::math::norm(&cross(&ts, &tt))
        })
        .sum()
}

/// Integral of each corner's shape function over the face (2x2 Gauss, exact for a
/// parallelogram): the corner's share of the area, the four summing to [`area`].
pub fn nodal_areas(x: &[Vec3; 4]) -> [f64; 4] {
    let mut a = [0.0; 4];
    for gp in GAUSS2.iter() {
        let (ts, tt) = tangents(x, gp[0], gp[1]);
        let da = crate::math::norm(&cross(&ts, &tt));
        let n = shape(gp[0], gp[1]);
        for (k, ak) in a.iter_mut().enumerate() {
            *ak += n[k] * da;
        }
    }
    a
}

/// Nodal forces of a uniform pressure `p` on the flat triangle `x` (ordered with an
/// outward normal): a third of the area vector's load at each corner, exact for the
/// linear triangle.
pub fn triangle_pressure_forces(x: &[Vec3; 3], p: f64) -> [Vec3; 3] {
    let an = triangle_area_vector(x);
    let fa = [-p * an[0] / 3.0, -p * an[1] / 3.0, -p * an[2] / 3.0];
    [fa; 3]
}

/// Nodal forces of a uniform traction (force per area) on the triangle `x`: a third of
/// the total at each corner.
pub fn triangle_traction_forces(x: &[Vec3; 3], traction: &Vec3) -> [Vec3; 3] {
    let a = crate::math::norm(&triangle_area_vector(x));
    let fa = [
        traction[0] * a / 3.0,
        traction[1] * a / 3.0,
        traction[2] * a / 3.0,
    ];
    [fa; 3]
}

/// Area of the flat triangle `x`.
pub fn triangle_area(x: &[Vec3; 3]) -> f64 {
    crate::math::norm(&triangle_area_vector(x))
}

/// The triangle's area times its unit normal (right-hand rule on the corner order).
#[inline]
fn triangle_area_vector(x: &[Vec3; 3]) -> Vec3 {
    let n = cross(
        &crate::math::sub(&x[1], &x[0]),
        &crate::math::sub(&x[2], &x[0]),
    );
    [0.5 * n[0], 0.5 * n[1], 0.5 * n[2]]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-15 * b.abs().max(1.0)
    }

    #[test]
    fn nodal_areas_of_a_unit_square_are_a_quarter_each() {
        let x = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        for a in nodal_areas(&x) {
            assert!(close(a, 0.25), "{a}");
        }
    }

    #[test]
    fn nodal_areas_of_a_tilted_2x1_rectangle_are_a_half_each() {
        // In the plane x = z, so the area element is not axis-aligned.
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let x = [
            [0.0, 0.0, 0.0],
            [2.0 * s, 0.0, 2.0 * s],
            [2.0 * s, 1.0, 2.0 * s],
            [0.0, 1.0, 0.0],
        ];
        let a = nodal_areas(&x);
        for ak in a {
            assert!(close(ak, 0.5), "{a:?}");
        }
        assert!(close(a.iter().sum(), area(&x)));
    }

    #[test]
    fn nodal_areas_of_a_trapezoid_match_the_hand_integral() {
        // Corners (0,0), (4,0), (3,2), (1,2): parallel sides 4 (y = 0) and 2 (y = 2), area 6.
        // With x = sum N_a x_a: dx/ds = (3 - t)/2, dy/ds = 0, dx/dt = -s/2, dy/dt = 1, so the
        // area element is J = (3 - t)/2. Corner a (local (s_a, t_a)) gets
        // int int (1 + s s_a)(1 + t t_a)/4 (3 - t)/2 ds dt = 1/4 int (1 + t t_a)(3 - t) dt
        // = (6 - 2 t_a / 3)/4: 5/3 at the bottom corners (t_a = -1), 4/3 at the top ones.
        let x = [
            [0.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [3.0, 2.0, 0.0],
            [1.0, 2.0, 0.0],
        ];
        let a = nodal_areas(&x);
        let exact = [5.0 / 3.0, 5.0 / 3.0, 4.0 / 3.0, 4.0 / 3.0];
        for k in 0..4 {
            assert!(close(a[k], exact[k]), "{a:?} vs {exact:?}");
        }
        assert!(close(a.iter().sum(), 6.0));
    }
}
