//! The nodal 3 x 3 diagonal blocks of the tangent (the Jacobi blocks, the smoothers'
//! diagonals), element by element into the nodes.

use super::{Assembly, ElementError};
use crate::fem::{element, tet10, ElementKind};
use crate::math::{Mat3, Vec3, ZERO33};

impl Assembly<'_> {
    /// Nodal 3x3 diagonal blocks of the tangent at u.
    pub fn diagonal(&self, u: &[Vec3], d: &mut [Mat3]) -> Result<(), ElementError> {
        d.iter_mut().for_each(|v| *v = ZERO33);
        let mut de = [ZERO33; 8];
        let mut dt = [ZERO33; 10];
        for e in 0..self.mesh.elements.len() {
            let m = &self.models[self.mesh.element_body[e] as usize];
            if self.mesh.kind(e) == ElementKind::Tet10 {
                let geo = self.shapes.tet(e).map_err(|k| self.fail(e, k))?;
                let ue = self.gather(e, u);
                tet10::diagonal_blocks(geo, &ue, &m.material, m.formulation, self.hist(e), &mut dt)
                    .map_err(|k| self.fail(e, k))?;
                add_blocks(self.mesh.elements.fixed::<10>(e), &dt, d);
                continue;
            }
            let de = match self.shapes.diagonal(e) {
                Some(shared) => shared,
                None => {
                    let ue = self.gather(e, u);
                    let (geo, gauss) = self.shapes.get(e).map_err(|k| self.fail(e, k))?;
                    let hist = self.hist(e);
                    element::diagonal_blocks_with(
                        geo,
                        gauss,
                        &ue,
                        &m.material,
                        m.formulation,
                        hist,
                        &mut de,
                    )
                    .map_err(|k| self.fail(e, k))?;
                    &de
                }
            };
            add_blocks(self.mesh.elements.fixed::<8>(e), de, d);
        }
        Ok(())
    }
}

/// Adds an element's nodal diagonal blocks `de` into `d` at its nodes `el`.
#[inline]
fn add_blocks<const N: usize>(el: &[u32; N], de: &[Mat3; N], d: &mut [Mat3]) {
    for (a, &n) in el.iter().enumerate() {
        for i in 0..3 {
            for k in 0..3 {
                d[n as usize][i][k] += de[a][i][k];
            }
        }
    }
}
