//! The scene file's structure as serde reads it. Unknown keys are rejected everywhere.

use serde::Deserialize;

use crate::material::{J2Params, LinearElasticParams, Material, NeoHookeanParams, Parameters};
use crate::problem::Kinematics;

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    pub name: Option<String>,
    #[serde(default)]
    pub kinematics: Kinematics,
    /// The Gmsh mesh file that bodies with `gmsh_volume` come from.
    pub gmsh: Option<GmshDef>,
    /// The Exodus II mesh file that bodies with `exodus_block` come from (read as a Gmsh
    /// mesh is: `mesh::exodus`).
    pub exodus: Option<GmshDef>,
    #[serde(default)]
    pub body: Vec<BodyDef>,
    #[serde(default)]
    pub node_set: Vec<SetDef>,
    #[serde(default)]
    pub side_set: Vec<SetDef>,
    #[serde(default)]
    pub displacement: Vec<DisplacementDef>,
    #[serde(default)]
    pub pressure: Vec<PressureDef>,
    #[serde(default)]
    pub traction: Vec<TractionDef>,
    #[serde(default)]
    pub body_force: Vec<BodyForceDef>,
    #[serde(default)]
    pub contact: Vec<ContactDef>,
    /// Contact between the exterior faces of every pair of bodies (`scene::validate::general`).
    pub general_contact: Option<GeneralContactDef>,
    pub time: TimeDef,
    #[serde(default)]
    pub solver: SolverDef,
    #[serde(default)]
    pub output: OutputDef,
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct GmshDef {
    /// Path of the `.msh` file (format 4.1, ASCII or binary), relative to the scene file.
    pub file: String,
}

/// A body: a structured block (`box` or `corners`, with `divisions`) or the hexahedra of a
/// physical volume of the scene's Gmsh mesh (`gmsh_volume`).
#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct BodyDef {
    pub name: String,
    /// Element divisions along the block's three parametric directions (x, y, z for a box).
    pub divisions: Option<[i64; 3]>,
    #[serde(rename = "box")]
    pub box_: Option<BoxDef>,
    /// Eight corner points in the hexahedron node order (see the README).
    pub corners: Option<Vec<[f64; 3]>>,
    /// Name of a physical volume of the `[gmsh]` mesh (`exodus_block`: an element block of
    /// the `[exodus]` mesh).
    #[serde(alias = "exodus_block")]
    pub gmsh_volume: Option<String>,
    pub material: MaterialDef,
    #[serde(default)]
    pub integration: Integration,
    #[serde(default)]
    pub volumetric: Volumetric,
    /// Hourglass control, `mean` integration only: a Flanagan-Belytschko stiffness
    /// coefficient, "assumed_strain" or "assumed_strain_mu"; unset: "assumed_strain_mu"
    /// for linear elastic bodies, 0.1 for the others (`scene::validate`).
    pub hourglass: Option<HourglassDef>,
}

/// A body's `hourglass`: a number or a name.
#[derive(Deserialize, Debug, Clone)]
#[serde(untagged)]
pub enum HourglassDef {
    Coefficient(f64),
    Named(String),
}

#[derive(Deserialize, Debug, Clone, Copy)]
#[serde(deny_unknown_fields)]
pub struct BoxDef {
    pub min: [f64; 3],
    pub max: [f64; 3],
}

/// The `material` table: `model` names the model, whose own keys and checks live in its
/// file under `material/` (`Parameters`).
#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(tag = "model", rename_all = "snake_case")]
pub enum MaterialDef {
    LinearElastic(LinearElasticParams),
    NeoHookean(NeoHookeanParams),
    /// Von Mises plasticity with linear isotropic and kinematic hardening.
    J2Plastic(J2Params),
}

impl MaterialDef {
    /// The model's parameters as given.
    pub fn params(&self) -> &dyn Parameters<Material> {
        match self {
            MaterialDef::LinearElastic(p) => p,
            MaterialDef::NeoHookean(p) => p,
            MaterialDef::J2Plastic(p) => p,
        }
    }
}

#[derive(Deserialize, Debug, Clone, Copy, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum Integration {
    #[default]
    Full,
    Mean,
}

#[derive(Deserialize, Debug, Clone, Copy, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum Volumetric {
    #[default]
    Standard,
    MeanDilatation,
}

/// A node set or side set selection: exactly one of plane, box, ids, faces (side sets),
/// gmsh_group (node sets), gmsh_surface (side sets).
#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct SetDef {
    pub name: String,
    pub body: Option<String>,
    pub plane: Option<PlaneDef>,
    #[serde(rename = "box")]
    pub box_: Option<BoxDef>,
    /// Node ids (node sets only), 1-based as in the paper numbering.
    pub ids: Option<Vec<i64>>,
    /// [element id, local face 0..5] pairs (side sets only).
    pub faces: Option<Vec<[i64; 2]>>,
    /// The nodes of the Gmsh physical groups of this name, any dimension (node sets only).
    #[serde(alias = "exodus_node_set")]
    pub gmsh_group: Option<String>,
    /// The hexahedron faces under the quadrangles of a Gmsh physical surface (side sets only).
    #[serde(alias = "exodus_side_set")]
    pub gmsh_surface: Option<String>,
    /// Geometric tolerance, absolute; default 1e-6 times the mesh's bounding-box diagonal.
    pub tolerance: Option<f64>,
}

#[derive(Deserialize, Debug, Clone, Copy)]
#[serde(deny_unknown_fields)]
pub struct PlaneDef {
    pub point: [f64; 3],
    pub normal: [f64; 3],
}

/// A value: a constant or a piecewise-linear function of time as [[t, v], ...].
#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct DisplacementDef {
    pub node_set: String,
    /// Components "x", "y", "z"; or give `direction`.
    pub components: Option<Vec<String>>,
    pub direction: Option<[f64; 3]>,
    pub value: Option<f64>,
    pub function: Option<Vec<[f64; 2]>>,
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct PressureDef {
    pub side_set: String,
    pub value: Option<f64>,
    pub function: Option<Vec<[f64; 2]>>,
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct TractionDef {
    pub side_set: String,
    /// Force per unit area.
    pub vector: [f64; 3],
    /// Scale factor through time (default 1).
    pub function: Option<Vec<[f64; 2]>>,
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct BodyForceDef {
    pub body: String,
    /// Acceleration (for gravity, g); the force density is the material density times it.
    pub acceleration: [f64; 3],
    pub function: Option<Vec<[f64; 2]>>,
}

/// A master/slave contact pair.
#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct ContactDef {
    pub name: Option<String>,
    /// Side set of master faces.
    pub master: String,
    /// Side set whose nodes are the slave nodes.
    pub slave: String,
    /// "frictionless" (default) or "coulomb" (then `mu`).
    pub friction: Option<String>,
    pub mu: Option<f64>,
    /// Search tolerances (absolute lengths); defaults scale with the master face size.
    pub normal_tolerance: Option<f64>,
    pub tangential_tolerance: Option<f64>,
    /// A node within this distance outside the master surface is pulled onto it.
    pub capture_tolerance: Option<f64>,
    /// Slave nodes within this distance of the master surface (inside or outside it) in
    /// the reference configuration are moved onto it before the run, strain-free.
    pub adjust: Option<f64>,
    /// Normal smoothing width as a fraction of the face size; absent: no smoothing.
    pub smoothing_width: Option<f64>,
    /// "node_face" (default: each slave node tied to one master point) or "mortar"
    /// (each slave node's gap weighted over the slave surface against the master faces).
    pub discretization: Option<String>,
}

/// `[general_contact]`: every body's exterior faces against every other body's, with one
/// default interaction; `[[general_contact.pair]]` overrides it for two bodies, `exclude`
/// leaves out a body (`["a"]`) or a pair of bodies (`["a", "b"]`).
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct GeneralContactDef {
    pub friction: Option<String>,
    pub mu: Option<f64>,
    pub normal_tolerance: Option<f64>,
    pub tangential_tolerance: Option<f64>,
    pub capture_tolerance: Option<f64>,
    pub smoothing_width: Option<f64>,
    /// "node_face" (default) or "mortar": the discretisation of the primary pass.
    #[serde(alias = "method")]
    pub discretization: Option<String>,
    /// The second pass of every body pair (the master body's nodes audited against the
    /// slave body, tied back when found inside): on by default.
    pub symmetric: Option<bool>,
    #[serde(default)]
    pub exclude: Vec<Vec<String>>,
    #[serde(default)]
    pub pair: Vec<GeneralPairDef>,
    /// Self contact: `true` (every body), `false` (none, the default) or a list of body
    /// names (`scene::validate::self_contact` reads it).
    #[serde(rename = "self")]
    pub self_contact: Option<toml::Value>,
}

/// `[[general_contact.pair]]`: the interaction of two bodies, each key unset taking the
/// general default; `slave` chooses the body whose nodes the primary pass ties.
#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct GeneralPairDef {
    pub bodies: [String; 2],
    pub slave: Option<String>,
    pub friction: Option<String>,
    pub mu: Option<f64>,
    pub normal_tolerance: Option<f64>,
    pub tangential_tolerance: Option<f64>,
    pub capture_tolerance: Option<f64>,
    pub smoothing_width: Option<f64>,
    /// "node_face" (default) or "mortar": the discretisation of the primary pass.
    #[serde(alias = "method")]
    pub discretization: Option<String>,
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct TimeDef {
    #[serde(default)]
    pub start: f64,
    pub segments: Vec<SegmentDef>,
}

#[derive(Deserialize, Debug, Clone, Copy)]
#[serde(deny_unknown_fields)]
pub struct SegmentDef {
    pub end: f64,
    pub steps: i64,
}

#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct SolverDef {
    pub tolerance: Option<f64>,
    pub max_iterations: Option<i64>,
    pub predictor: Option<bool>,
    pub max_cutbacks: Option<i64>,
    /// Contact updates allowed in one load step.
    pub max_contact_updates: Option<i64>,
    /// "auto" (default), "jacobi" or "two_level".
    pub preconditioner: Option<String>,
    /// "auto" (default), "cg" or "newton".
    pub nonlinear: Option<String>,
}

#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct OutputDef {
    /// Write every n-th step (the last step is always written).
    pub every: Option<i64>,
}
