//! The cases of the tetrahedra section: Cook's membrane (`run/tet/cook.geo`) and the flat
//! punch in an elastic-perfectly plastic block (`run/tet/punch.geo`), their Gmsh meshes and
//! the scenes that load them, written into each case's directory.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Which problem.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Problem {
    /// Cook's membrane, E = 250, nu = 0.4999, plane strain, shear traction 6.25 on x = 48:
    /// the mean u_y of the nodes at the corner (48, 60).
    Cook,
    /// The punch of `run/scenes/plasticity/punch_40.toml` (E = 200e3, nu = 0.3, sigma_y =
    /// 100, punch 0.1 deep in 50 increments): the punch's mean pressure at the end.
    Punch,
}

/// One mesh of a problem.
#[derive(Clone, Copy, Debug)]
pub struct Case {
    pub problem: Problem,
    /// Tetrahedra (Gmsh's 4-node ones completed to tet10 by the solver) or hexahedra.
    pub tet: bool,
    /// Cook: elements per side; punch: element size 6/n away from the punch's edge.
    pub n: usize,
    /// A tet10 body with the mean dilatation (`volumetric = "mean_dilatation"`); the
    /// hexahedra always have it.
    pub bar: bool,
}

/// The punch meshes' refinement towards the punch's edge (`punch.geo`'s r).
pub const PUNCH_REFINEMENT: usize = 4;

impl Case {
    pub fn name(&self) -> String {
        let p = match self.problem {
            Problem::Cook => "cook",
            Problem::Punch => "punch",
        };
        let bar = if self.bar && self.tet { "_bar" } else { "" };
        format!(
            "{p}_{}{}{bar}",
            if self.tet { "tet" } else { "hex" },
            self.n
        )
    }

    /// Meshes the case with Gmsh into `dir/mesh.msh` and writes `dir/scene.toml`; returns
    /// the scene's path.
    pub fn write(&self, root: &Path, dir: &Path) -> Result<PathBuf, String> {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
        let (geo, mut args) = match self.problem {
            Problem::Cook => ("run/tet/cook.geo", vec!["-setnumber", "tet"]),
            Problem::Punch => ("run/tet/punch.geo", vec!["-setnumber", "r"]),
        };
        let tet_or_r = match self.problem {
            Problem::Cook => (self.tet as usize).to_string(),
            Problem::Punch => PUNCH_REFINEMENT.to_string(),
        };
        let n = self.n.to_string();
        args.push(&tet_or_r);
        args.extend(["-setnumber", "n", &n, "-3", "-v", "2", "-o"]);
        let msh = dir.join("mesh.msh");
        let out = Command::new("gmsh")
            .arg(root.join(geo))
            .args(&args)
            .arg(&msh)
            .output()
            .map_err(|e| format!("cannot run gmsh (run/setup --gmsh installs it): {e}"))?;
        if !out.status.success() || !msh.is_file() {
            return Err(format!(
                "gmsh on {geo} failed: {}",
                String::from_utf8_lossy(&out.stderr).trim()
            ));
        }
        let scene = dir.join("scene.toml");
        let text = match self.problem {
            Problem::Cook => self.cook_scene(),
            Problem::Punch => self.punch_scene(),
        };
        std::fs::write(&scene, text)
            .map_err(|e| format!("cannot write {}: {e}", scene.display()))?;
        Ok(scene)
    }

    /// The body's volumetric key.
    fn volumetric(&self) -> &'static str {
        if self.tet && !self.bar {
            ""
        } else {
            "volumetric = \"mean_dilatation\"\n"
        }
    }

    fn cook_scene(&self) -> String {
        let volumetric = self.volumetric();
        format!(
            r#"# Cook's membrane ({}), written by the bench.
name = "{}"
kinematics = "small"
[gmsh]
file = "mesh.msh"
[[body]]
name = "panel"
gmsh_volume = "panel"
material = {{ model = "linear_elastic", E = 250.0, nu = 0.4999 }}
{volumetric}[[node_set]]
name = "clamp"
plane = {{ point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}
[[node_set]]
name = "front"
plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }}
[[node_set]]
name = "back"
plane = {{ point = [0.0, 0.0, {t}], normal = [0.0, 0.0, 1.0] }}
[[node_set]]
name = "tip"
box = {{ min = [47.99, 59.99, -1.0], max = [48.01, 60.01, 100.0] }}
[[side_set]]
name = "load"
gmsh_surface = "load"
[[displacement]]
node_set = "clamp"
components = ["x", "y", "z"]
value = 0.0
[[displacement]]
node_set = "front"
components = ["z"]
value = 0.0
[[displacement]]
node_set = "back"
components = ["z"]
value = 0.0
[[traction]]
side_set = "load"
vector = [0.0, 6.25, 0.0]
[time]
segments = [{{ end = 1.0, steps = 1 }}]
[solver]
tolerance = 1e-10
"#,
            if self.tet {
                "tet10 composite"
            } else {
                "hex8 with mean dilatation"
            },
            self.name(),
            // The slab's thickness (run/tet/cook.geo's T).
            t = if self.tet { 16.0 / self.n as f64 } else { 1.0 },
        )
    }

    fn punch_scene(&self) -> String {
        format!(
            r#"# The flat punch on tetrahedra, written by the bench.
name = "{}"
kinematics = "small"
[gmsh]
file = "mesh.msh"
[[body]]
name = "block"
gmsh_volume = "block"
material = {{ model = "j2_plastic", E = 200e3, nu = 0.3, yield_stress = 100.0 }}
{}[[node_set]]
name = "all"
box = {{ min = [-1.0, -1.0, -1.0], max = [7.0, 7.0, 7.0] }}
[[node_set]]
name = "x0"
plane = {{ point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}
[[node_set]]
name = "bottom"
plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}
[[node_set]]
name = "right"
plane = {{ point = [6.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}
[[node_set]]
name = "punch"
box = {{ min = [0.0, 5.999999, -1.0], max = [1.000001, 6.000001, 7.0] }}
[[displacement]]
node_set = "all"
components = ["z"]
value = 0.0
[[displacement]]
node_set = "x0"
components = ["x"]
value = 0.0
[[displacement]]
node_set = "bottom"
components = ["x", "y"]
value = 0.0
[[displacement]]
node_set = "right"
components = ["x"]
value = 0.0
[[displacement]]
node_set = "punch"
components = ["y"]
function = [[0.0, 0.0], [1.0, -0.1]]
[time]
segments = [{{ end = 1.0, steps = 50 }}]
"#,
            self.name(),
            self.volumetric()
        )
    }
}
