//! The element loop: internal force, diagonal tangent blocks, body forces and stresses,
//! gathered from and scattered to rank-local nodal arrays. Elements are visited in
//! ascending global order (see `mesh::local`).

use crate::fem::{element, hex8, ElementFailure, Formulation};
use crate::math::{Mat3, Vec3, ZERO33};
use crate::memory::{try_with_capacity, AllocError};
use crate::mesh::local::LocalMesh;
use crate::problem::BodyModel;

/// A failure inside one element, with its global (1-based) id.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ElementError {
    pub element: u64,
    pub failure: ElementFailure,
}

impl std::fmt::Display for ElementError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "element {}: {}", self.element, self.failure)
    }
}

pub struct Assembly<'a> {
    pub mesh: &'a LocalMesh,
    pub models: &'a [BodyModel],
    /// True when every body is linear (small kinematics): then f_int(u) = K u.
    pub linear: bool,
    /// Reference geometry of every local element (mean gradients, volume), computed once:
    /// the kernels would otherwise spend a third of a run recomputing it. 216 bytes each.
    geometry: Vec<Result<element::Geometry, ElementFailure>>,
    /// Gradients at the Gauss points of every local element (1600 bytes each), kept only
    /// when some body is fully integrated (empty when every body uses `Mean`).
    gauss: Vec<element::GaussGeometry>,
}

impl<'a> Assembly<'a> {
    /// Fails only when the memory for the element geometry is refused.
    pub fn new(mesh: &'a LocalMesh, models: &'a [BodyModel]) -> Result<Self, AllocError> {
        let linear = models.iter().all(|m| !m.material.is_large());
        let needs_gauss = models
            .iter()
            .any(|m| !matches!(m.formulation, Formulation::Mean { .. }));
        let ne = mesh.elements.len();
        let mut geometry = try_with_capacity(ne, "the element geometry")?;
        let mut gauss = try_with_capacity(
            if needs_gauss { ne } else { 0 },
            "the Gauss-point gradients",
        )?;
        for e in 0..ne {
            match element::geometry(&mesh.element_coords(e)) {
                Ok((g, gg)) => {
                    geometry.push(Ok(g));
                    if needs_gauss {
                        gauss.push(gg);
                    }
                }
                Err(k) => {
                    geometry.push(Err(k));
                    if needs_gauss {
                        gauss.push(element::GaussGeometry::default());
                    }
                }
            }
        }
        Ok(Assembly {
            mesh,
            models,
            linear,
            geometry,
            gauss,
        })
    }

    #[inline]
    fn gather(&self, e: usize, u: &[Vec3]) -> [Vec3; 8] {
        let el = &self.mesh.elements[e];
        std::array::from_fn(|a| u[el[a] as usize])
    }

    fn fail(&self, e: usize, failure: ElementFailure) -> ElementError {
        ElementError {
            element: self.mesh.element_global[e] as u64 + 1,
            failure,
        }
    }

    /// f = f_int(u) on every local node (complete on owned nodes).
    pub fn internal_force(&self, u: &[Vec3], f: &mut [Vec3]) -> Result<(), ElementError> {
        self.element_forces(u, f, false)
    }

    /// `internal_force` for a field that vanishes on most elements (the coarse space's
    /// probes): an element whose eight displacements are all zero contributes exactly zero
    /// (no material here carries an initial stress) and is skipped. Adding a zero never
    /// changes a sum, so the result is bitwise that of `internal_force`.
    pub fn internal_force_sparse(&self, u: &[Vec3], f: &mut [Vec3]) -> Result<(), ElementError> {
        self.element_forces(u, f, true)
    }

    /// The element loop of both: each element's force summed into its nodes in element
    /// order; `skip_zero` skips elements whose displacements are all zero.
    #[inline]
    fn element_forces(
        &self,
        u: &[Vec3],
        f: &mut [Vec3],
        skip_zero: bool,
    ) -> Result<(), ElementError> {
        f.iter_mut().for_each(|v| *v = [0.0; 3]);
        let mut fe = [[0.0; 3]; 8];
        for e in 0..self.mesh.elements.len() {
            let geo = self.geometry[e].as_ref().map_err(|&k| self.fail(e, k))?;
            let ue = self.gather(e, u);
            if skip_zero && ue.iter().all(|v| v[0] == 0.0 && v[1] == 0.0 && v[2] == 0.0) {
                continue;
            }
            let m = &self.models[self.mesh.element_body[e] as usize];
            let gauss = self.gauss.get(e);
            element::internal_force_with(geo, gauss, &ue, &m.material, m.formulation, &mut fe)
                .map_err(|k| self.fail(e, k))?;
            for (a, &n) in self.mesh.elements[e].iter().enumerate() {
                let fa = &mut f[n as usize];
                fa[0] += fe[a][0];
                fa[1] += fe[a][1];
                fa[2] += fe[a][2];
            }
        }
        Ok(())
    }

    /// Nodal 3x3 diagonal blocks of the tangent at u.
    pub fn diagonal(&self, u: &[Vec3], d: &mut [Mat3]) -> Result<(), ElementError> {
        d.iter_mut().for_each(|v| *v = ZERO33);
        let mut de = [ZERO33; 8];
        for e in 0..self.mesh.elements.len() {
            let m = &self.models[self.mesh.element_body[e] as usize];
            let ue = self.gather(e, u);
            let geo = self.geometry[e].as_ref().map_err(|&k| self.fail(e, k))?;
            let gauss = self.gauss.get(e);
            element::diagonal_blocks_with(geo, gauss, &ue, &m.material, m.formulation, &mut de)
                .map_err(|k| self.fail(e, k))?;
            for (a, &n) in self.mesh.elements[e].iter().enumerate() {
                for i in 0..3 {
                    for k in 0..3 {
                        d[n as usize][i][k] += de[a][i][k];
                    }
                }
            }
        }
        Ok(())
    }

    /// Adds the consistent nodal body force `scale * force_density` of every element of
    /// `body` to `f`.
    pub fn add_body_force(
        &self,
        body: usize,
        force_density: &Vec3,
        scale: f64,
        f: &mut [Vec3],
    ) -> Result<(), ElementError> {
        for e in 0..self.mesh.elements.len() {
            if self.mesh.element_body[e] as usize != body {
                continue;
            }
            let x = self.mesh.element_coords(e);
            for xi in hex8::GAUSS.iter() {
                let (_, det) = hex8::gradients(&x, xi)
                    .ok_or_else(|| self.fail(e, ElementFailure::InvertedReference))?;
                let n = hex8::shape(xi);
                for (a, &node) in self.mesh.elements[e].iter().enumerate() {
                    for i in 0..3 {
                        f[node as usize][i] += scale * n[a] * det * force_density[i];
                    }
                }
            }
        }
        Ok(())
    }

    /// Element-average Cauchy stress of the owned elements, in local element order.
    pub fn owned_stresses(&self, u: &[Vec3]) -> Result<Vec<[f64; 6]>, ElementError> {
        let mut out = Vec::new();
        for e in 0..self.mesh.elements.len() {
            if !self.mesh.element_owned[e] {
                continue;
            }
            let m = &self.models[self.mesh.element_body[e] as usize];
            let ue = self.gather(e, u);
            let geo = self.geometry[e].as_ref().map_err(|&k| self.fail(e, k))?;
            out.push(
                element::average_cauchy_with(
                    geo,
                    self.gauss.get(e),
                    &ue,
                    &m.material,
                    m.formulation,
                )
                .map_err(|k| self.fail(e, k))?,
            );
        }
        Ok(out)
    }
}
