//! The consistent tangent matrices of the local elements of small-kinematics J2 bodies at
//! one state (`fem::consistent`), for the full tangent preconditioner's probes: with them
//! a probe costs a matrix product per element where it cost two evaluations of the
//! element's stress points (return maps included), and the assembled tangent is symmetric
//! and positive semi-definite element by element, a point on its yield surface taking
//! the mean of its branches, where a central difference of the forces mixes them column
//! by column (docs/plasticity-solve.md).

use crate::fem::{element, tet10, Formulation};
use crate::material::{Material, PlasticState};
use crate::math::Vec3;

/// Element e's n x n matrix (column j at `j * n`) is `k[offset[e]..offset[e + 1]]`, empty
/// when the element has none (other materials, the one-point element, large kinematics,
/// an element marked elastic: its elastic matrix serves).
#[derive(Default)]
pub struct Tangents {
    offset: Vec<usize>,
    k: Vec<f64>,
}

impl Tangents {
    /// Element `e`'s matrix, if it has one.
    #[inline]
    pub fn get(&self, e: usize) -> Option<&[f64]> {
        let (a, b) = (*self.offset.get(e)?, *self.offset.get(e + 1)?);
        (b > a).then(|| &self.k[a..b])
    }
}

/// y_e = K_e (x_e - x_1) for an element of `N` nodes (K annihilates translations: as
/// `element::matrix_force`, the rounding follows the deformation, not the rigid motion).
pub fn product<const N: usize>(k: &[f64], x: &[Vec3; N], y: &mut [Vec3; N]) {
    let n = 3 * N;
    let mut acc = [0.0; 30];
    for (a, xa) in x.iter().enumerate() {
        for i in 0..3 {
            let d = xa[i] - x[0][i];
            for (r, c) in acc.iter_mut().zip(&k[(3 * a + i) * n..(3 * a + i + 1) * n]) {
                *r += c * d;
            }
        }
    }
    for (a, ya) in y.iter_mut().enumerate() {
        *ya = [acc[3 * a], acc[3 * a + 1], acc[3 * a + 2]];
    }
}

impl Tangents {
    /// Empties the matrices before a state's elements are added, in order.
    pub(super) fn clear(&mut self) {
        self.offset.clear();
        self.k.clear();
        self.offset.push(0);
    }

    /// Closes the next element's range (empty if nothing was added for it).
    pub(super) fn end_element(&mut self) {
        self.offset.push(self.k.len());
    }

    /// Adds a hexahedron's consistent tangent at `u` (`element::consistent_matrix`); false
    /// (nothing added) when it has none.
    pub(super) fn add_hex(
        &mut self,
        (geo, gauss): (&element::Geometry, Option<&element::GaussGeometry>),
        u: &[Vec3; 8],
        (mat, form): (&Material, Formulation),
        hist: &[PlasticState],
    ) -> bool {
        match element::consistent_matrix(geo, gauss, u, mat, form, hist) {
            Some(k) => {
                self.k.extend_from_slice(&k[..]);
                true
            }
            None => false,
        }
    }

    /// Adds a composite tetrahedron's consistent tangent at `u` (`tet10::consistent_matrix`);
    /// false (nothing added) when it has none.
    pub(super) fn add_tet(
        &mut self,
        geo: &tet10::Geometry,
        u: &[Vec3; 10],
        (mat, form): (&Material, Formulation),
        hist: &[PlasticState],
    ) -> bool {
        let start = self.k.len();
        self.k.resize(start + 900, 0.0);
        let done = tet10::consistent_matrix(geo, u, mat, form, hist, &mut self.k[start..]);
        if !done {
            self.k.truncate(start);
        }
        done
    }
}
