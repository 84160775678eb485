//! Hexahedra of mean-integrated bodies folded at a corner. A mean element samples its
//! deformation at its centre only (with hourglass control), so a corner can turn inside
//! out while the centre's Jacobian stays positive and nothing fails: the element's
//! stress and the contact it carries are then not to be trusted. Measured on the general
//! block die (`run/scenes/general/sliding/ironing_block.toml`): 4 to 8 slab elements
//! under the die folded from its second drag step, corner Jacobians down to -1.18 times
//! the centre's, which the run went on with for 8 steps.

use super::Assembly;
use crate::fem::{hex8, ElementKind, Formulation};
use crate::math::{add, Vec3};

impl Assembly<'_> {
    /// The owned hexahedra of mean-integrated bodies whose Jacobian at a corner (or at a
    /// Gauss point) is not positive at `u`, each as (global id, the smallest Jacobian over
    /// those points relative to the element's mean), in local order; empty when no body is
    /// mean-integrated.
    pub fn folded_mean_elements(&self, u: &[Vec3]) -> Vec<(u32, f64)> {
        let mean = |b: u32| {
            matches!(
                self.models[b as usize].formulation,
                Formulation::Mean { .. }
            )
        };
        if !self.models.iter().enumerate().any(|(b, _)| mean(b as u32)) {
            return Vec::new();
        }
        let mesh = self.mesh;
        let mut out = Vec::new();
        for e in 0..mesh.elements.len() {
            if !mesh.element_owned[e]
                || mesh.kind(e) != ElementKind::Hex8
                || !mean(mesh.element_body[e])
            {
                continue;
            }
            let nodes = mesh.elements.fixed::<8>(e);
            let x: [Vec3; 8] = std::array::from_fn(|a| {
                let n = nodes[a] as usize;
                add(&mesh.coords[n], &u[n])
            });
            let ratio = hex8::min_jacobian_ratio(&x);
            if !(ratio > 0.0) {
                out.push((mesh.element_global[e], ratio));
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use crate::fem::hex8;

    /// A unit cube whose corner (1, 1, 1) is pushed in to (0.2, 0.2, 0.2): the Jacobian at
    /// that corner turns negative while the centre's (the mean element's one point) stays
    /// positive; pushed in to (0.8, 0.8, 0.8) the element is only dented.
    #[test]
    fn a_corner_pushed_through_folds_the_element_with_its_centre_whole() {
        let cube = |c: f64| {
            [
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
                [1.0, 0.0, 1.0],
                [c, c, c],
                [0.0, 1.0, 1.0],
            ]
        };
        let centre = |x: &[[f64; 3]; 8]| hex8::gradients(x, &[0.0; 3]).map(|g| g.1);
        let folded = cube(0.2);
        assert!(centre(&folded).is_some_and(|j| j > 0.0));
        assert!(hex8::min_jacobian_ratio(&folded) < 0.0);
        let dented = cube(0.8);
        assert!(hex8::min_jacobian_ratio(&dented) > 0.0);
    }
}
