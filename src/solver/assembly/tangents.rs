//! The consistent tangent matrices of the local elements of small-kinematics J2 bodies at
//! one state (`fem::consistent`), for the full tangent preconditioner's probes: with them
//! a probe costs a matrix product per element where it cost two evaluations of the
//! element's stress points (return maps included), and the assembled tangent is symmetric
//! and positive semi-definite element by element, a point on its yield surface taking
//! the mean of its branches, where a central difference of the forces mixes them column
//! by column (docs/plasticity-solve.md).

use super::{Assembly, Elastic};
use crate::fem::{element, tet10, ElementKind};
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

impl Assembly<'_> {
    /// The consistent tangents at u (from the committed history) of the local elements of
    /// small-kinematics J2 bodies that `elastic` does not mark, into `t` (overwritten);
    /// returns how many elements have one.
    pub fn consistent_tangents(
        &self,
        u: &[Vec3],
        elastic: Option<Elastic>,
        t: &mut Tangents,
    ) -> usize {
        t.offset.clear();
        t.k.clear();
        t.offset.push(0);
        let mut count = 0;
        for e in 0..self.mesh.elements.len() {
            let m = &self.models[self.mesh.element_body[e] as usize];
            let wanted = m.material.is_plastic()
                && !m.material.is_large()
                && elastic.and_then(|s| s.get(e)).is_none();
            if wanted && self.add_tangent(e, u, t) {
                count += 1;
            }
            t.offset.push(t.k.len());
        }
        count
    }

    /// Appends element `e`'s consistent tangent to `t.k`; false (nothing appended) when
    /// the element has none.
    fn add_tangent(&self, e: usize, u: &[Vec3], t: &mut Tangents) -> bool {
        let m = &self.models[self.mesh.element_body[e] as usize];
        let (mat, form, hist) = (&m.material, m.formulation, self.hist(e));
        match self.mesh.kind(e) {
            ElementKind::Hex8 => {
                let Ok((geo, gauss)) = self.shapes.get(e) else {
                    return false;
                };
                let ue = self.gather::<8>(e, u);
                match element::consistent_matrix(geo, gauss, &ue, mat, form, hist) {
                    Some(k) => {
                        t.k.extend_from_slice(&k[..]);
                        true
                    }
                    None => false,
                }
            }
            ElementKind::Tet10 => {
                let Ok(geo) = self.shapes.tet(e) else {
                    return false;
                };
                let ue = self.gather::<10>(e, u);
                let start = t.k.len();
                t.k.resize(start + 900, 0.0);
                let done = tet10::consistent_matrix(geo, &ue, mat, form, hist, &mut t.k[start..]);
                if !done {
                    t.k.truncate(start);
                }
                done
            }
        }
    }
}
