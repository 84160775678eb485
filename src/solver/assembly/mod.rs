//! The element loop: internal force, diagonal tangent blocks, body forces and stresses,
//! gathered from and scattered to rank-local nodal arrays. Elements are visited in
//! ascending global order (see `mesh::local`). Each loop dispatches per element on its
//! kind (`LocalMesh::kind`): a hexahedron takes `fem::element`'s kernels (or its shape's
//! or its elastic matrix), a composite tetrahedron `fem::tet10`'s, which have no matrix.

use crate::fem::{element, hex8, history, tet10, ElementFailure, ElementKind, Formulation};
use crate::material::PlasticState;
use crate::math::Vec3;
use crate::memory::{try_filled, AllocError};
use crate::mesh::local::LocalMesh;
use crate::problem::BodyModel;
use crate::solver::shapes::{Elements, Plan, Shapes};

mod diagonal;
mod elastic;
mod folded;
mod tangents;
pub use elastic::{Elastic, ElasticMatrices};
pub use tangents::Tangents;

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
    /// Reference geometry of every local element (mean gradients, volume, and the Gauss-point
    /// gradients when some body is fully integrated), computed once per distinct element
    /// shape: the kernels would otherwise spend a third of a run recomputing it.
    shapes: Shapes,
    /// Committed integration-point history of the plastic elements: element `e` owns
    /// `history[offset[e]..offset[e + 1]]`. Both empty when no body is plastic, so such a
    /// scene pays nothing. Only `commit` writes it, after a step converges; a step that is
    /// cut back never touches it.
    offset: Vec<u32>,
    history: Vec<PlasticState>,
    scratch: Vec<PlasticState>,
}

impl<'a> Assembly<'a> {
    /// `plan` says which bodies are evaluated by element matrices (`shapes::Plan` of the
    /// whole mesh; the default for none). Fails only when the memory for the element
    /// geometry or the history is refused.
    pub fn new(
        mesh: &'a LocalMesh,
        models: &'a [BodyModel],
        plan: &Plan,
    ) -> Result<Self, AllocError> {
        let linear = crate::problem::linear_models(models);
        let needs_gauss = models
            .iter()
            .any(|m| !matches!(m.formulation, Formulation::Mean { .. }));
        let shapes = Shapes::new(
            &Elements {
                count: mesh.elements.len(),
                kind: &|e| mesh.kind(e),
                coords: &|e| mesh.element_coords(e),
                tet_coords: &|e| mesh.element_coords(e),
                body: &|e| mesh.element_body[e] as usize,
            },
            models,
            needs_gauss,
            plan,
        )?;
        let mut offset = Vec::new();
        if models.iter().any(|m| m.material.is_plastic()) {
            offset.push(0u32);
            let mut n = 0u32;
            for &b in &mesh.element_body {
                let m = &models[b as usize];
                if m.material.is_plastic() {
                    n += history::points_of(mesh.body_kind[b as usize], m.formulation) as u32;
                }
                offset.push(n);
            }
        }
        let states = offset.last().copied().unwrap_or(0) as usize;
        Ok(Assembly {
            mesh,
            models,
            linear,
            shapes,
            offset,
            history: try_filled(PlasticState::default(), states, "the plastic history")?,
            scratch: Vec::new(),
        })
    }

    /// The committed history of local element `e` (empty for an elastic one).
    #[inline]
    fn hist(&self, e: usize) -> &[PlasticState] {
        match self.offset.get(e + 1) {
            Some(&end) => &self.history[self.offset[e] as usize..end as usize],
            None => &[],
        }
    }

    /// True when some body carries an integration-point history.
    pub fn has_history(&self) -> bool {
        !self.offset.is_empty()
    }

    /// Commits the history of the converged displacements `u` (every local element, ghosts
    /// too: they see the same displacements as on their owner, so every rank holds the
    /// same states).
    pub fn commit(&mut self, u: &[Vec3]) -> Result<(), ElementError> {
        if self.offset.is_empty() {
            return Ok(());
        }
        let mut new = std::mem::take(&mut self.scratch);
        new.clone_from(&self.history);
        for e in 0..self.mesh.elements.len() {
            let (a, b) = (self.offset[e] as usize, self.offset[e + 1] as usize);
            if a == b {
                continue;
            }
            let m = &self.models[self.mesh.element_body[e] as usize];
            let (old, new) = (&self.history[a..b], &mut new[a..b]);
            match self.mesh.kind(e) {
                ElementKind::Hex8 => {
                    let (geo, gauss) = self.shapes.get(e).map_err(|k| self.fail(e, k))?;
                    let ue = self.gather(e, u);
                    history::update_with(geo, gauss, &ue, &m.material, m.formulation, old, new)
                }
                ElementKind::Tet10 => {
                    let geo = self.shapes.tet(e).map_err(|k| self.fail(e, k))?;
                    tet10::update_history(
                        geo,
                        &self.gather(e, u),
                        &m.material,
                        m.formulation,
                        old,
                        new,
                    )
                }
            }
            .map_err(|k| self.fail(e, k))?;
        }
        self.scratch = std::mem::replace(&mut self.history, new);
        Ok(())
    }

    /// Element-mean equivalent plastic strain of the owned elements, in local element order
    /// (zero in elastic bodies); `None` when no body is plastic.
    pub fn owned_eqps(&self) -> Option<Vec<f64>> {
        if self.offset.is_empty() {
            return None;
        }
        let mut out = Vec::new();
        for e in 0..self.mesh.elements.len() {
            if !self.mesh.element_owned[e] {
                continue;
            }
            let h = self.hist(e);
            out.push(if h.is_empty() {
                0.0
            } else {
                self.mean_eqps(e, h).unwrap_or(0.0)
            });
        }
        Some(out)
    }

    /// Per owned element of a plastic body, in local element order: the growth of its
    /// element-mean equivalent plastic strain from the committed state to the state `u`
    /// would commit (where the body flows in an attempted increment); `None` when no body
    /// is plastic or an element fails at `u`.
    pub fn owned_eqps_growth(&self, u: &[Vec3]) -> Option<Vec<(usize, f64)>> {
        if self.offset.is_empty() {
            return None;
        }
        let mut out = Vec::new();
        let mut new = Vec::new();
        for e in 0..self.mesh.elements.len() {
            let h = self.hist(e);
            if !self.mesh.element_owned[e] || h.is_empty() {
                continue;
            }
            let m = &self.models[self.mesh.element_body[e] as usize];
            new.clear();
            new.extend_from_slice(h);
            match self.mesh.kind(e) {
                ElementKind::Hex8 => {
                    let (geo, gauss) = self.shapes.get(e).ok()?;
                    let ue = self.gather(e, u);
                    history::update_with(geo, gauss, &ue, &m.material, m.formulation, h, &mut new)
                }
                ElementKind::Tet10 => {
                    let geo = self.shapes.tet(e).ok()?;
                    tet10::update_history(
                        geo,
                        &self.gather(e, u),
                        &m.material,
                        m.formulation,
                        h,
                        &mut new,
                    )
                }
            }
            .ok()?;
            let grown = self.mean_eqps(e, &new)? - self.mean_eqps(e, h)?;
            out.push((e, grown));
        }
        Some(out)
    }

    /// The number of values `owned_history_words` gives over all ids (without the words of
    /// id and count).
    pub fn owned_history_len(&self) -> usize {
        (0..self.mesh.elements.len())
            .filter(|&e| self.mesh.element_owned[e])
            .map(|e| self.hist(e).len() * crate::material::STATE_LEN)
            .sum()
    }

    /// The committed states of the owned plastic elements whose global ids are in `range`
    /// (what a restart file keeps), appended to `out` in local element order as words: the
    /// element's global id, the number of its values, its values.
    pub fn owned_history_words(&self, range: &std::ops::Range<u32>, out: &mut Vec<f64>) {
        for e in 0..self.mesh.elements.len() {
            let g = self.mesh.element_global[e];
            let h = self.hist(e);
            if self.mesh.element_owned[e] && !h.is_empty() && range.contains(&g) {
                out.push(f64::from(g));
                out.push((h.len() * crate::material::STATE_LEN) as f64);
                for state in h {
                    out.extend_from_slice(&state.to_array());
                }
            }
        }
    }

    /// Sets the committed states of every local plastic element from `lookup` (by global
    /// element id), as read from a restart file.
    pub fn set_history(&mut self, lookup: impl Fn(u64) -> Option<Vec<PlasticState>>) {
        for e in 0..self.mesh.elements.len() {
            let (a, b) = match self.offset.get(e + 1) {
                Some(&end) => (self.offset[e] as usize, end as usize),
                None => return,
            };
            if a == b {
                continue;
            }
            if let Some(states) = lookup(self.mesh.element_global[e] as u64) {
                if states.len() == b - a {
                    self.history[a..b].copy_from_slice(&states);
                }
            }
        }
    }

    /// The element-mean equivalent plastic strain of local element `e` in the states `h`
    /// (`None` when its reference geometry failed).
    fn mean_eqps(&self, e: usize, h: &[PlasticState]) -> Option<f64> {
        let m = &self.models[self.mesh.element_body[e] as usize];
        Some(match self.mesh.kind(e) {
            ElementKind::Hex8 => {
                let (geo, gauss) = self.shapes.get(e).ok()?;
                history::mean_eqps(geo, gauss, m.formulation, h)
            }
            ElementKind::Tet10 => tet10::mean_eqps(self.shapes.tet(e).ok()?, h),
        })
    }

    /// The values of `u` at element `e`'s `N` nodes (its kind's count).
    #[inline]
    fn gather<const N: usize>(&self, e: usize, u: &[Vec3]) -> [Vec3; N] {
        let mut out = [[0.0; 3]; N];
        self.gather_into(e, u, &mut out);
        out
    }

    /// `gather` into a buffer the element loop keeps: a returned array is built aside and
    /// copied by a call to `memcpy` (3 to 4% of a large run's samples in the operator's
    /// loop).
    #[inline(always)]
    fn gather_into<const N: usize>(&self, e: usize, u: &[Vec3], out: &mut [Vec3; N]) {
        for (o, &n) in out.iter_mut().zip(self.mesh.elements.fixed::<N>(e)) {
            *o = u[n as usize];
        }
    }

    fn fail(&self, e: usize, failure: ElementFailure) -> ElementError {
        ElementError {
            element: self.mesh.element_global[e] as u64 + 1,
            failure,
        }
    }

    /// f = f_int(u) on every local node (complete on owned nodes).
    pub fn internal_force(&self, u: &[Vec3], f: &mut [Vec3]) -> Result<(), ElementError> {
        self.element_forces(u, f, None)
    }

    /// `internal_force` for a field that vanishes on most elements (the coarse space's
    /// probes): an element whose eight displacements are all zero contributes exactly zero
    /// (no elastic material carries an initial stress; it is used only when every body is
    /// linear, so never with a plastic body's residual stresses) and is skipped, told by
    /// `nonzero` (one flag per local node, set here: whether the node's displacement is
    /// not zero) before its displacements or geometry are read (an element whose
    /// reference geometry failed is reported by the step's forces, computed before any
    /// probe). Adding a zero never changes a sum, so the result is bitwise that of
    /// `internal_force`.
    pub fn internal_force_sparse(
        &self,
        u: &[Vec3],
        f: &mut [Vec3],
        nonzero: &mut [bool],
    ) -> Result<(), ElementError> {
        for (z, v) in nonzero.iter_mut().zip(u) {
            *z = v[0] != 0.0 || v[1] != 0.0 || v[2] != 0.0;
        }
        self.element_forces(u, f, Some(nonzero))
    }

    /// The element loop of both: each element's force summed into its nodes in element
    /// order; with `nonzero`, elements none of whose nodes is flagged are skipped.
    #[inline]
    fn element_forces(
        &self,
        u: &[Vec3],
        f: &mut [Vec3],
        nonzero: Option<&[bool]>,
    ) -> Result<(), ElementError> {
        f.iter_mut().for_each(|v| *v = [0.0; 3]);
        let (mut ue, mut fe) = ([[0.0; 3]; 8], [[0.0; 3]; 8]);
        let (mut ut, mut ft) = ([[0.0; 3]; 10], [[0.0; 3]; 10]);
        for e in 0..self.mesh.elements.len() {
            if let Some(nz) = nonzero {
                if self
                    .mesh
                    .elements
                    .element(e)
                    .iter()
                    .all(|&n| !nz[n as usize])
                {
                    continue;
                }
            }
            match self.mesh.kind(e) {
                ElementKind::Hex8 => {
                    self.gather_into(e, u, &mut ue);
                    self.element_force(e, &ue, &mut fe)?;
                    self.scatter(e, &fe, f);
                }
                ElementKind::Tet10 => {
                    self.gather_into(e, u, &mut ut);
                    self.tet_force(e, &ut, &mut ft)?;
                    self.scatter(e, &ft, f);
                }
            }
        }
        Ok(())
    }

    /// y = (f_int(u + h x) - f_int(u - h x)) / (2 h) on every local node (complete on owned
    /// nodes): the central difference of the internal force along x, the history held at
    /// its committed state. Only the elements with a node where x is not zero are
    /// evaluated (`nonzero`, one flag per local node, set here): any other element
    /// contributes f_e(u) - f_e(u) = 0, so leaving it out changes only the rounding of the
    /// sums. An element with a stored matrix contributes K_e x_e.
    ///
    /// An element `elastic` marks (`mark_elastic`, every stress point elastic at u) gives
    /// its elastic matrix's K_e x_e instead: the same derivative, for a 24 x 24 product in
    /// place of two evaluations of its stress points; an element with a consistent
    /// tangent in `tangents` (`consistent_tangents` at u) gives that matrix's product.
    #[allow(clippy::too_many_arguments)]
    pub fn internal_force_difference(
        &self,
        u: &[Vec3],
        x: &[Vec3],
        h: f64,
        y: &mut [Vec3],
        nonzero: &mut [bool],
        elastic: Option<Elastic>,
        tangents: Option<&Tangents>,
    ) -> Result<(), ElementError> {
        for (z, v) in nonzero.iter_mut().zip(x) {
            *z = v[0] != 0.0 || v[1] != 0.0 || v[2] != 0.0;
        }
        y.iter_mut().for_each(|v| *v = [0.0; 3]);
        let (mut plus, mut minus) = ([[0.0; 3]; 8], [[0.0; 3]; 8]);
        for e in 0..self.mesh.elements.len() {
            if self
                .mesh
                .elements
                .element(e)
                .iter()
                .all(|&n| !nonzero[n as usize])
            {
                continue;
            }
            let consistent = tangents.and_then(|t| t.get(e));
            if self.mesh.kind(e) == ElementKind::Tet10 {
                match consistent {
                    Some(k) => {
                        let mut ft = [[0.0; 3]; 10];
                        tangents::product(k, &self.gather::<10>(e, x), &mut ft);
                        self.scatter(e, &ft, y);
                    }
                    None => self.tet_difference(e, u, x, h, y)?,
                }
                continue;
            }
            let xe = self.gather(e, x);
            let stored = self.shapes.matrix(e);
            let matrix = stored
                .or_else(|| elastic.and_then(|m| m.get(e)))
                .or_else(|| consistent.and_then(|k| k.try_into().ok()));
            if let Some(k) = matrix {
                element::matrix_force(k, &xe, &mut plus);
                self.scatter(e, &plus, y);
                continue;
            }
            let ue = self.gather::<8>(e, u);
            let shifted = |s: f64| -> [Vec3; 8] {
                std::array::from_fn(|a| std::array::from_fn(|i| ue[a][i] + s * xe[a][i]))
            };
            self.element_force(e, &shifted(h), &mut plus)?;
            self.element_force(e, &shifted(-h), &mut minus)?;
            for a in 0..8 {
                for i in 0..3 {
                    plus[a][i] = (plus[a][i] - minus[a][i]) / (2.0 * h);
                }
            }
            self.scatter(e, &plus, y);
        }
        Ok(())
    }

    /// Marks (`marks`, one flag per local element) the elements of small-kinematics
    /// plastic bodies whose every stress point responds elastically at u from the committed
    /// history, computing each one's elastic matrix into `m` the first time (a function of
    /// its geometry and material only, so the same on any number of ranks and after a
    /// restart); returns how many are marked.
    pub fn mark_elastic(
        &self,
        u: &[Vec3],
        m: &mut ElasticMatrices,
        marks: &mut Vec<bool>,
    ) -> usize {
        marks.clear();
        let small_plastic = |b: &BodyModel| b.material.is_plastic() && !b.material.is_large();
        if !self.models.iter().any(small_plastic) {
            return 0;
        }
        let n = self.mesh.elements.len();
        m.matrix.resize_with(n, || None);
        marks.resize(n, false);
        let mut marked = 0;
        for e in 0..n {
            // A composite tetrahedron has no elastic matrix: it keeps its kernel.
            if self.mesh.kind(e) != ElementKind::Hex8 {
                continue;
            }
            let model = &self.models[self.mesh.element_body[e] as usize];
            let (hist, form) = (self.hist(e), model.formulation);
            let Ok((geo, gauss)) = self.shapes.get(e) else {
                continue;
            };
            if hist.is_empty()
                || !element::responds_elastically(
                    geo,
                    gauss,
                    &self.gather(e, u),
                    &model.material,
                    form,
                    hist,
                )
            {
                continue;
            }
            if m.matrix[e].is_none() {
                m.matrix[e] = element::elastic_matrix(geo, gauss, &model.material, form);
            }
            marks[e] = m.matrix[e].is_some();
            marked += marks[e] as usize;
        }
        marked
    }

    /// The consistent tangents at u (from the committed history) of the local elements of
    /// small-kinematics J2 bodies that `elastic` does not mark, into `t` (overwritten);
    /// returns how many elements have one.
    pub fn consistent_tangents(
        &self,
        u: &[Vec3],
        elastic: Option<Elastic>,
        t: &mut Tangents,
    ) -> usize {
        t.clear();
        let mut count = 0;
        for e in 0..self.mesh.elements.len() {
            let m = &self.models[self.mesh.element_body[e] as usize];
            let model = (&m.material, m.formulation);
            if m.material.is_plastic()
                && !m.material.is_large()
                && elastic.and_then(|s| s.get(e)).is_none()
            {
                let added = match self.mesh.kind(e) {
                    ElementKind::Hex8 => self.shapes.get(e).is_ok_and(|shape| {
                        t.add_hex(shape, &self.gather(e, u), model, self.hist(e))
                    }),
                    ElementKind::Tet10 => self
                        .shapes
                        .tet(e)
                        .is_ok_and(|geo| t.add_tet(geo, &self.gather(e, u), model, self.hist(e))),
                };
                count += added as usize;
            }
            t.end_element();
        }
        count
    }

    /// The internal force at `u` of the elements evaluated by their kernel: all but those
    /// with a stored matrix and those `elastic` marks, into `f` (overwritten).
    pub fn kernel_force(
        &self,
        u: &[Vec3],
        elastic: Elastic,
        f: &mut [Vec3],
    ) -> Result<(), ElementError> {
        f.iter_mut().for_each(|v| *v = [0.0; 3]);
        let (mut ue, mut fe) = ([[0.0; 3]; 8], [[0.0; 3]; 8]);
        let (mut ut, mut ft) = ([[0.0; 3]; 10], [[0.0; 3]; 10]);
        for e in 0..self.mesh.elements.len() {
            if self.mesh.kind(e) == ElementKind::Tet10 {
                self.gather_into(e, u, &mut ut);
                self.tet_force(e, &ut, &mut ft)?;
                self.scatter(e, &ft, f);
                continue;
            }
            if self.shapes.matrix(e).is_some() || elastic.get(e).is_some() {
                continue;
            }
            self.gather_into(e, u, &mut ue);
            self.element_force(e, &ue, &mut fe)?;
            self.scatter(e, &fe, f);
        }
        Ok(())
    }

    /// The derivative of the internal force at `base` along x by a forward difference,
    /// y = (f(base + h x) - f(base)) / h, with `f_base` the kernel's part of f(base)
    /// (`kernel_force`): an element with a stored or a marked elastic matrix gives
    /// K_e x_e, every other its kernel's force at base + h x.
    pub fn forward_difference(
        &self,
        base: &[Vec3],
        x: &[Vec3],
        h: f64,
        f_base: &[Vec3],
        elastic: Elastic,
        y: &mut [Vec3],
    ) -> Result<(), ElementError> {
        y.iter_mut().for_each(|v| *v = [0.0; 3]);
        let mut fe = [[0.0; 3]; 8];
        let mut ft = [[0.0; 3]; 10];
        for e in 0..self.mesh.elements.len() {
            if self.mesh.kind(e) == ElementKind::Tet10 {
                let (ue, xe) = (self.gather::<10>(e, base), self.gather::<10>(e, x));
                let shifted =
                    std::array::from_fn(|a| std::array::from_fn(|i| ue[a][i] + h * xe[a][i]));
                self.tet_force(e, &shifted, &mut ft)?;
                self.scatter(e, &ft, y);
                continue;
            }
            if self.shapes.matrix(e).is_some() || elastic.get(e).is_some() {
                continue;
            }
            let (ue, xe) = (self.gather::<8>(e, base), self.gather::<8>(e, x));
            let shifted = std::array::from_fn(|a| std::array::from_fn(|i| ue[a][i] + h * xe[a][i]));
            self.element_force(e, &shifted, &mut fe)?;
            self.scatter(e, &fe, y);
        }
        for (v, b) in y.iter_mut().zip(f_base) {
            for i in 0..3 {
                v[i] = (v[i] - b[i]) / h;
            }
        }
        for e in 0..self.mesh.elements.len() {
            if self.mesh.kind(e) != ElementKind::Hex8 {
                continue;
            }
            if let Some(k) = self.shapes.matrix(e).or_else(|| elastic.get(e)) {
                element::matrix_force(k, &self.gather(e, x), &mut fe);
                self.scatter(e, &fe, y);
            }
        }
        Ok(())
    }

    /// Element `e`'s nodal internal forces at its displacements `ue`, into `fe`.
    #[inline(always)]
    fn element_force(
        &self,
        e: usize,
        ue: &[Vec3; 8],
        fe: &mut [Vec3; 8],
    ) -> Result<(), ElementError> {
        if let Some(k) = self.shapes.matrix(e) {
            element::matrix_force(k, ue, fe);
            return Ok(());
        }
        let (geo, gauss) = self.shapes.get(e).map_err(|k| self.fail(e, k))?;
        let m = &self.models[self.mesh.element_body[e] as usize];
        element::internal_force_with(geo, gauss, ue, &m.material, m.formulation, self.hist(e), fe)
            .map_err(|k| self.fail(e, k))
    }

    /// Composite tetrahedron `e`'s nodal internal forces at its displacements `ue`, into
    /// `fe`.
    #[inline]
    fn tet_force(
        &self,
        e: usize,
        ue: &[Vec3; 10],
        fe: &mut [Vec3; 10],
    ) -> Result<(), ElementError> {
        let geo = self.shapes.tet(e).map_err(|k| self.fail(e, k))?;
        let m = &self.models[self.mesh.element_body[e] as usize];
        tet10::internal_force(geo, ue, &m.material, m.formulation, self.hist(e), fe)
            .map_err(|k| self.fail(e, k))
    }

    /// Adds composite tetrahedron `e`'s central difference of its force along `x` (at `u`,
    /// step `h`) into `y`.
    fn tet_difference(
        &self,
        e: usize,
        u: &[Vec3],
        x: &[Vec3],
        h: f64,
        y: &mut [Vec3],
    ) -> Result<(), ElementError> {
        let (ue, xe) = (self.gather::<10>(e, u), self.gather::<10>(e, x));
        let shifted = |s: f64| -> [Vec3; 10] {
            std::array::from_fn(|a| std::array::from_fn(|i| ue[a][i] + s * xe[a][i]))
        };
        let (mut plus, mut minus) = ([[0.0; 3]; 10], [[0.0; 3]; 10]);
        self.tet_force(e, &shifted(h), &mut plus)?;
        self.tet_force(e, &shifted(-h), &mut minus)?;
        for a in 0..10 {
            for i in 0..3 {
                plus[a][i] = (plus[a][i] - minus[a][i]) / (2.0 * h);
            }
        }
        self.scatter(e, &plus, y);
        Ok(())
    }

    /// Adds element `e`'s nodal forces (`N` nodes, its kind's) into `f`.
    #[inline(always)]
    fn scatter<const N: usize>(&self, e: usize, fe: &[Vec3; N], f: &mut [Vec3]) {
        for (a, &n) in self.mesh.elements.fixed::<N>(e).iter().enumerate() {
            let fa = &mut f[n as usize];
            fa[0] += fe[a][0];
            fa[1] += fe[a][1];
            fa[2] += fe[a][2];
        }
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
            match self.mesh.kind(e) {
                ElementKind::Hex8 => {
                    let x = self.mesh.element_coords::<8>(e);
                    for xi in hex8::GAUSS.iter() {
                        let (_, det) = hex8::gradients(&x, xi)
                            .ok_or_else(|| self.fail(e, ElementFailure::InvertedReference))?;
                        let n = hex8::shape(xi);
                        for (a, &node) in self.mesh.elements.fixed::<8>(e).iter().enumerate() {
                            for i in 0..3 {
                                f[node as usize][i] += scale * n[a] * det * force_density[i];
                            }
                        }
                    }
                }
                ElementKind::Tet10 => {
                    // The consistent force of a uniform density: each node's share is the
                    // integral of its (piecewise-linear, positive) shape function.
                    let geo = self.shapes.tet(e).map_err(|k| self.fail(e, k))?;
                    let v = tet10::nodal_volumes(geo);
                    for (a, &node) in self.mesh.elements.fixed::<10>(e).iter().enumerate() {
                        for i in 0..3 {
                            f[node as usize][i] += scale * v[a] * force_density[i];
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// Element-average Cauchy stress of the owned elements, in local element order.
    pub fn owned_stresses(&self, u: &[Vec3]) -> Result<Vec<[f64; 6]>, ElementError> {
        self.owned_stresses_of(u, |_| true)
    }

    /// `owned_stresses` of the owned elements whose global id `take` takes.
    pub fn owned_stresses_of(
        &self,
        u: &[Vec3],
        take: impl Fn(u32) -> bool,
    ) -> Result<Vec<[f64; 6]>, ElementError> {
        let mut out = Vec::new();
        for e in 0..self.mesh.elements.len() {
            if !self.mesh.element_owned[e] || !take(self.mesh.element_global[e]) {
                continue;
            }
            let m = &self.models[self.mesh.element_body[e] as usize];
            let s = match self.mesh.kind(e) {
                ElementKind::Hex8 => {
                    let ue = self.gather(e, u);
                    let (geo, gauss) = self.shapes.get(e).map_err(|k| self.fail(e, k))?;
                    element::average_cauchy_with(
                        geo,
                        gauss,
                        &ue,
                        &m.material,
                        m.formulation,
                        self.hist(e),
                    )
                }
                ElementKind::Tet10 => {
                    let geo = self.shapes.tet(e).map_err(|k| self.fail(e, k))?;
                    tet10::average_cauchy(
                        geo,
                        &self.gather(e, u),
                        &m.material,
                        m.formulation,
                        self.hist(e),
                    )
                }
            };
            out.push(s.map_err(|k| self.fail(e, k))?);
        }
        Ok(out)
    }
}
