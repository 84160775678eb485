//! From the scene file's text to a validated `Problem`: every error names the file, the
//! key and what was expected.

use super::types::*;
use super::PiecewiseLinear;
use crate::fem::hex8::min_jacobian_ratio;
use crate::fem::ElementKind;
use crate::fem::{Formulation, Stabilization};
use crate::math::{norm, scale, Vec3};
use crate::mesh::sets::{select_faces, select_nodes, Selector};
use crate::mesh::{block, Body, GlobalMesh};
use crate::problem::*;
use std::path::Path;

mod contacts;
mod error;
mod general;
mod gmsh;
mod kinds;
mod loads;
mod material;
mod prescribed;
mod self_contact;
mod sets;
use error::Builder;
pub use error::SceneError;
pub use gmsh::mesh_files;
use gmsh::{GmshImport, NEEDS_GMSH};

/// The Flanagan-Belytschko coefficient of a `mean` body that sets no `hourglass`.
pub const DEFAULT_HOURGLASS: f64 = 0.1;

pub fn load_scene(path: &Path) -> Result<Problem, SceneError> {
    load_scene_refined(path, 1)
}

/// Loads a scene with every body's divisions multiplied by `factor` (renamed
/// `<name>_r<factor>` when the factor is above 1).
pub fn load_scene_refined(path: &Path, factor: u32) -> Result<Problem, SceneError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| SceneError {
        file: file.clone(),
        key: String::new(),
        message: format!("cannot read the scene file: {e}"),
    })?;
    let text = super::text::utf8_text(bytes).map_err(|message| SceneError {
        file: file.clone(),
        key: String::new(),
        message,
    })?;
    let default_name = path
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| "scene".into());
    if factor == 1 {
        return parse_scene(&text, &file, &default_name);
    }
    let refined =
        super::refine::refine_scene_text(&text, factor, &default_name).map_err(|message| {
            SceneError {
                file: file.clone(),
                key: String::new(),
                message,
            }
        })?;
    parse_scene(&refined, &file, &default_name)
}

pub fn parse_scene(text: &str, file: &str, default_name: &str) -> Result<Problem, SceneError> {
    let raw: SceneFile = toml::from_str(text).map_err(|e| SceneError {
        file: file.to_string(),
        key: String::new(),
        message: e.to_string().trim_end().to_string(),
    })?;
    Builder {
        file: file.to_string(),
    }
    .build(raw, text, default_name)
}

impl Builder {
    fn finite(&self, key: &str, v: f64) -> Result<f64, SceneError> {
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.err(key, format!("expected a finite number, got {v}")))
        }
    }

    fn finite3(&self, key: &str, v: &Vec3) -> Result<Vec3, SceneError> {
        for x in v {
            self.finite(key, *x)?;
        }
        Ok(*v)
    }

    fn function(
        &self,
        key: &str,
        value: Option<f64>,
        function: &Option<Vec<[f64; 2]>>,
    ) -> Result<PiecewiseLinear, SceneError> {
        match (value, function) {
            (Some(v), None) => Ok(PiecewiseLinear::constant(
                self.finite(&format!("{key}.value"), v)?,
            )),
            (None, Some(points)) => self.points(&format!("{key}.function"), points),
            (Some(_), Some(_)) => Err(self.err(key, "give either `value` or `function`, not both")),
            (None, None) => Err(self.err(
                key,
                "expected `value = <number>` or `function = [[t, v], ...]`",
            )),
        }
    }

    fn points(&self, key: &str, points: &[[f64; 2]]) -> Result<PiecewiseLinear, SceneError> {
        if points.is_empty() {
            return Err(self.err(key, "expected at least one [t, v] point"));
        }
        for (i, p) in points.iter().enumerate() {
            self.finite(&format!("{key}[{i}]"), p[0])?;
            self.finite(&format!("{key}[{i}]"), p[1])?;
            if i > 0 && p[0] <= points[i - 1][0] {
                return Err(self.err(format!("{key}[{i}]"), "times must increase strictly"));
            }
        }
        Ok(PiecewiseLinear::new(
            points.iter().map(|p| (p[0], p[1])).collect(),
        ))
    }

    fn build(&self, raw: SceneFile, text: &str, default_name: &str) -> Result<Problem, SceneError> {
        let name = raw.name.clone().unwrap_or_else(|| default_name.to_string());
        if name.is_empty() || name.contains(['/', '\\']) {
            return Err(self.err("name", "expected a non-empty name without path separators"));
        }
        if raw.body.is_empty() {
            return Err(self.err("body", "expected at least one [[body]]"));
        }
        let (mesh, body_models, gmsh) = self.bodies(&raw)?;
        let diag = mesh.bounding_diagonal();
        let boundary = mesh.boundary_faces();
        let node_sets = self.node_sets(&raw, &mesh, gmsh.as_ref(), diag)?;
        let side_sets = self.side_sets(&raw, &mesh, gmsh.as_ref(), &boundary, diag)?;

        let dirichlet = self.displacements(&raw, &node_sets)?;
        let pressures = self.pressures(&raw, &side_sets)?;
        let tractions = self.tractions(&raw, &side_sets)?;
        let body_forces = self.body_forces(&raw, &mesh, &body_models)?;
        let contacts = self.contacts(&raw, &mesh, &side_sets, &node_sets, &dirichlet)?;
        let (start_time, step_times) = self.time(&raw.time)?;
        let solver = self.solver(&raw.solver)?;
        let output_every = match raw.output.every {
            None => 1,
            Some(n) if n >= 1 => n as usize,
            Some(n) => {
                return Err(self.err("output.every", format!("expected an integer >= 1, got {n}")))
            }
        };

        Ok(Problem {
            name,
            text: text.to_string(),
            file: self.file.clone(),
            kinematics: raw.kinematics,
            mesh,
            body_models,
            node_sets,
            side_sets,
            dirichlet,
            pressures,
            tractions,
            body_forces,
            contacts,
            start_time,
            step_times,
            solver,
            output_every,
            retained: None,
        })
    }

    fn bodies(
        &self,
        raw: &SceneFile,
    ) -> Result<(GlobalMesh, Vec<BodyModel>, Option<GmshImport>), SceneError> {
        let mut mesh = GlobalMesh::default();
        let mut models = Vec::new();
        let mut gmsh = match (&raw.gmsh, &raw.exodus) {
            (Some(_), Some(_)) => {
                return Err(self.err(
                    "exodus",
                    "a scene takes one mesh file: `[gmsh]` or `[exodus]`, not both",
                ))
            }
            (Some(g), None) => Some(self.gmsh_file(g)?),
            (None, Some(e)) => Some(self.exodus_file(e)?),
            (None, None) => None,
        };
        for (bi, b) in raw.body.iter().enumerate() {
            let key = format!("body[{bi}]");
            self.body_name(raw, bi, &key)?;
            let first_node = mesh.coords.len();
            let first_element = mesh.elements.len();
            let offset = first_node as u32;
            let (coords, kind) = match &b.gmsh_volume {
                Some(volume) => {
                    if b.box_.is_some() || b.corners.is_some() || b.divisions.is_some() {
                        return Err(self.err(&key, "a body takes either `gmsh_volume` or `box`/`corners` with `divisions`, not both"));
                    }
                    let Some(g) = gmsh.as_mut() else {
                        return Err(self.err(format!("{key}.gmsh_volume"), NEEDS_GMSH));
                    };
                    let (coords, kind, elements) =
                        g.add_body(self, &key, volume, bi, first_node)?;
                    mesh.elements.extend_mapped(&elements, |n| n + offset);
                    (coords, kind)
                }
                None => {
                    let (coords, elements) = self.block_geometry(&key, b, first_element)?;
                    for el in &elements {
                        mesh.elements.push(&el.map(|n| n + offset));
                    }
                    (coords, ElementKind::Hex8)
                }
            };
            let num_elements = mesh.elements.len() - first_element;
            let (material, density) =
                self.material(&format!("{key}.material"), &b.material, raw.kinematics)?;
            let formulation = self.formulation(&key, b)?;
            let large = raw.kinematics == Kinematics::Large;
            self.kind_formulation(&key, kind, b, large)?;
            mesh.coords.extend_from_slice(&coords);
            mesh.element_body
                .extend(std::iter::repeat_n(bi as u32, num_elements));
            mesh.bodies.push(Body {
                name: b.name.clone(),
                kind,
                first_node,
                num_nodes: coords.len(),
                first_element,
                num_elements,
            });
            models.push(BodyModel {
                material,
                formulation,
                density,
            });
        }
        if mesh.coords.len() > u32::MAX as usize / 2 {
            return Err(self.err("body", "mesh too large"));
        }
        Ok((mesh, models, gmsh))
    }

    /// Body `bi`'s name: not empty, without '/', not reserved, not used before.
    fn body_name(&self, raw: &SceneFile, bi: usize, key: &str) -> Result<(), SceneError> {
        let b = &raw.body[bi];
        if b.name.is_empty() || b.name.contains('/') {
            return Err(self.err(
                format!("{key}.name"),
                "expected a non-empty name without '/'",
            ));
        }
        if crate::output::layout::RESERVED_MESH_NAMES.contains(&b.name.as_str()) {
            return Err(self.err(
                format!("{key}.name"),
                format!(
                    "'{}' is reserved in the result file; choose another body name",
                    b.name
                ),
            ));
        }
        if raw.body[..bi].iter().any(|o| o.name == b.name) {
            return Err(self.err(
                format!("{key}.name"),
                format!("body name '{}' used twice", b.name),
            ));
        }
        Ok(())
    }

    /// The element formulation from a body's integration, volumetric treatment and
    /// hourglass control. A `mean` body without `hourglass` takes the assumed-strain
    /// stabilisation with the shear modulus only if it is linear elastic, and
    /// Flanagan-Belytschko at `DEFAULT_HOURGLASS` otherwise: plastic bodies (the
    /// incremental control of `fem::element::hourglass`) and neo-Hookean ones (with the
    /// assumed strain two ironing scenes of `tests/penetration_audit.rs` stopped);
    /// "assumed_strain" (with lambda) and "assumed_strain_mu" are asked for by name
    /// (docs/elements.md).
    fn formulation(&self, key: &str, b: &BodyDef) -> Result<Formulation, SceneError> {
        let mean = |h| Ok(Formulation::Mean { hourglass: h });
        let default = match b.material {
            MaterialDef::LinearElastic { .. } => Stabilization::AssumedStrainMu,
            MaterialDef::NeoHookean { .. } | MaterialDef::J2Plastic { .. } => {
                Stabilization::Coefficient(DEFAULT_HOURGLASS)
            }
        };
        match (b.integration, b.volumetric, &b.hourglass) {
            (Integration::Full, Volumetric::Standard, None) => Ok(Formulation::Full),
            (Integration::Full, Volumetric::MeanDilatation, None) => Ok(Formulation::FullBar),
            (Integration::Full, _, Some(_)) => {
                Err(self.err(format!("{key}.hourglass"), "hourglass stiffness applies to integration = \"mean\" only"))
            }
            (Integration::Mean, Volumetric::MeanDilatation, _) => {
                Err(self.err(format!("{key}.volumetric"), "mean_dilatation applies to integration = \"full\" only (\"mean\" is already one-point)"))
            }
            (Integration::Mean, Volumetric::Standard, None) => mean(default),
            (Integration::Mean, Volumetric::Standard, Some(HourglassDef::Named(n))) => match n.as_str() {
                "assumed_strain" => mean(Stabilization::AssumedStrain),
                "assumed_strain_mu" => mean(Stabilization::AssumedStrainMu),
                _ => Err(self.err(format!("{key}.hourglass"), format!("expected a number >= 0, \"assumed_strain\" or \"assumed_strain_mu\", got \"{n}\""))),
            },
            (Integration::Mean, Volumetric::Standard, Some(HourglassDef::Coefficient(h))) => {
                let h = *h;
                if !(h.is_finite() && h >= 0.0) {
                    return Err(self.err(format!("{key}.hourglass"), format!("expected a number >= 0, got {h}")));
                }
                mean(Stabilization::Coefficient(h))
            }
        }
    }

    /// A structured block's nodes and elements (0-based, local to the block), checked for
    /// inverted elements.
    fn block_geometry(
        &self,
        key: &str,
        b: &BodyDef,
        first_element: usize,
    ) -> Result<(Vec<Vec3>, Vec<[u32; 8]>), SceneError> {
        let Some(divisions) = b.divisions else {
            return Err(self.err(
                key,
                "expected `divisions = [nx, ny, nz]` with `box` or `corners` (or a `gmsh_volume`)",
            ));
        };
        let mut div = [0usize; 3];
        for i in 0..3 {
            if divisions[i] < 1 || divisions[i] > 10_000 {
                return Err(self.err(
                    format!("{key}.divisions"),
                    format!("expected integers from 1 to 10000, got {:?}", divisions),
                ));
            }
            div[i] = divisions[i] as usize;
        }
        let corners: [Vec3; 8] = match (&b.box_, &b.corners) {
            (Some(bx), None) => {
                let min = self.finite3(&format!("{key}.box.min"), &bx.min)?;
                let max = self.finite3(&format!("{key}.box.max"), &bx.max)?;
                if (0..3).any(|i| !(max[i] > min[i])) {
                    return Err(self.err(format!("{key}.box"), format!("expected max > min in every direction, got min {min:?} max {max:?}")));
                }
                block::box_corners(&min, &max)
            }
            (None, Some(c)) => {
                if c.len() != 8 {
                    return Err(self.err(format!("{key}.corners"), format!("expected 8 corner points, got {}", c.len())));
                }
                let mut out = [[0.0; 3]; 8];
                for (i, p) in c.iter().enumerate() {
                    out[i] = self.finite3(&format!("{key}.corners[{i}]"), p)?;
                }
                out
            }
            (Some(_), Some(_)) => return Err(self.err(key, "give either `box` or `corners`, not both")),
            (None, None) => return Err(self.err(key, "expected `box = { min = [..], max = [..] }`, `corners = [[x, y, z], ... 8 points]` or `gmsh_volume = \"<physical volume>\"`")),
        };
        let blk = block::generate(&corners, div[0], div[1], div[2])
            .map_err(|e| self.err(format!("{key}.divisions"), e.to_string()))?;
        for (e, el) in blk.elements.iter().enumerate() {
            let x: [Vec3; 8] = std::array::from_fn(|a| blk.coords[el[a] as usize]);
            let r = min_jacobian_ratio(&x);
            if !(r > 1e-8) {
                return Err(self.err(
                    key,
                    format!(
                        "element {} (global id {}) is inverted or degenerate (min Jacobian ratio {r:.3e}); check the corner order (see README: x-,y-,z- first, counter-clockwise seen from +z, bottom then top)",
                        e + 1,
                        first_element + e + 1
                    ),
                ));
            }
        }
        Ok((blk.coords, blk.elements))
    }

    fn time(&self, t: &TimeDef) -> Result<(f64, Vec<f64>), SceneError> {
        let start = self.finite("time.start", t.start)?;
        if t.segments.is_empty() {
            return Err(self.err(
                "time.segments",
                "expected at least one { end = <time>, steps = <n> }",
            ));
        }
        let mut times = Vec::new();
        let mut t0 = start;
        for (i, s) in t.segments.iter().enumerate() {
            let key = format!("time.segments[{i}]");
            let end = self.finite(&format!("{key}.end"), s.end)?;
            if !(end > t0) {
                return Err(self.err(
                    format!("{key}.end"),
                    format!("expected an end time after {t0}, got {end}"),
                ));
            }
            if s.steps < 1 || s.steps > 1_000_000 {
                return Err(self.err(
                    format!("{key}.steps"),
                    format!("expected an integer from 1 to 1000000, got {}", s.steps),
                ));
            }
            let n = s.steps as usize;
            for k in 1..=n {
                times.push(if k == n {
                    end
                } else {
                    t0 + (end - t0) * k as f64 / n as f64
                });
            }
            t0 = end;
        }
        Ok((start, times))
    }

    fn solver(&self, s: &SolverDef) -> Result<SolverSettings, SceneError> {
        let mut out = SolverSettings::default();
        if let Some(t) = s.tolerance {
            if !(t.is_finite() && t > 0.0 && t < 1.0) {
                return Err(self.err(
                    "solver.tolerance",
                    format!("expected a number in (0, 1), got {t}"),
                ));
            }
            out.tolerance = t;
        }
        if let Some(n) = s.max_iterations {
            if n < 1 {
                return Err(self.err(
                    "solver.max_iterations",
                    format!("expected an integer >= 1, got {n}"),
                ));
            }
            out.max_iterations = n as usize;
        }
        if let Some(p) = s.predictor {
            out.predictor = p;
        }
        if let Some(n) = s.max_contact_updates {
            if !(1..=100_000).contains(&n) {
                return Err(self.err(
                    "solver.max_contact_updates",
                    format!("expected an integer from 1 to 100000, got {n}"),
                ));
            }
            out.max_contact_updates = n as usize;
        }
        if let Some(n) = s.max_cutbacks {
            if !(0..=30).contains(&n) {
                return Err(self.err(
                    "solver.max_cutbacks",
                    format!("expected an integer from 0 to 30, got {n}"),
                ));
            }
            out.max_cutbacks = n as usize;
        }
        if let Some(name) = &s.preconditioner {
            use crate::problem::Preconditioner;
            out.preconditioner = Preconditioner::from_name(name).ok_or_else(|| {
                self.err(
                    "solver.preconditioner",
                    format!(
                        "expected \"auto\", \"jacobi\", \"two_level\", \"multilevel\" or \"tangent\", got \"{name}\""
                    ),
                )
            })?;
        }
        if let Some(name) = &s.nonlinear {
            use crate::problem::NonlinearSolver;
            out.nonlinear = NonlinearSolver::from_name(name).ok_or_else(|| {
                self.err(
                    "solver.nonlinear",
                    format!("expected \"auto\", \"cg\" or \"newton\", got \"{name}\""),
                )
            })?;
        }
        Ok(out)
    }
}

fn list<'a>(names: impl Iterator<Item = &'a String>) -> String {
    let v: Vec<&str> = names.map(|s| s.as_str()).collect();
    if v.is_empty() {
        "none".into()
    } else {
        v.join(", ")
    }
}
