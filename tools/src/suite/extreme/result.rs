//! One result file of the extreme suite (completed, failed or a crashed run's `.tmp`) with
//! what the checks read: the mesh, the body of each node and element, the scene as written
//! into the file, and each step's fields.

use solver::output::{ResultFile, StepStats};
use solver::post::balance::{face_vector_area, Faces, SceneLoads, V3};
use std::path::{Path, PathBuf};

pub struct Res {
    pub path: PathBuf,
    pub file: ResultFile,
    pub scene: toml::Table,
    pub loads: SceneLoads,
    pub x: Vec<V3>,
    /// The eight nodes (0-based) of each element in global element order.
    pub conn: Vec<[usize; 8]>,
    pub element_body: Vec<usize>,
    pub node_body: Vec<usize>,
    pub bodies: Vec<String>,
    pub times: Vec<f64>,
    pub n: usize,
    pub large: bool,
    pub stats: Vec<StepStats>,
    side_sets: Vec<(String, Vec<(u64, u8)>)>,
    node_sets: Vec<(String, Vec<u64>)>,
}

impl Res {
    pub fn open(path: &Path) -> Result<Res, String> {
        let file = ResultFile::open(path).map_err(|e| e.to_string())?;
        let attrs = file.attributes().map_err(|e| e.to_string())?;
        let scene: toml::Table = attrs
            .scene_text
            .parse()
            .map_err(|e| format!("the scene in the file: {e}"))?;
        let loads =
            SceneLoads::from_scene(&scene).map_err(|k| format!("the scene in the file: {k}"))?;
        let mesh = file.mesh().map_err(|e| e.to_string())?;
        let mut conn = Vec::new();
        let mut element_body = Vec::new();
        let mut node_body = vec![0; mesh.coordinates.len()];
        for (i, b) in mesh.bodies.iter().enumerate() {
            if b.connectivity.nodes_per_element != 8 {
                return Err(format!(
                    "body '{}' has elements of {} nodes; the suite reads hexahedral meshes only",
                    b.name, b.connectivity.nodes_per_element
                ));
            }
            for c in &b.connectivity {
                let c: [usize; 8] = std::array::from_fn(|a| c[a] as usize);
                conn.push(c);
                element_body.push(i);
                for n in c {
                    node_body[n] = i;
                }
            }
        }
        let times = file.time().map_err(|e| e.to_string())?;
        let stats = file.stats().map_err(|e| e.to_string())?;
        Ok(Res {
            path: path.to_path_buf(),
            large: scene.get("kinematics").and_then(|k| k.as_str()) == Some("large"),
            loads,
            scene,
            x: mesh.coordinates.clone(),
            conn,
            element_body,
            node_body,
            bodies: mesh.bodies.iter().map(|b| b.name.clone()).collect(),
            n: times.len(),
            times,
            stats,
            side_sets: mesh.side_sets,
            node_sets: mesh.node_sets,
            file,
        })
    }

    pub fn body(&self, name: &str) -> Result<usize, String> {
        self.bodies
            .iter()
            .position(|b| b == name)
            .ok_or_else(|| format!("no body '{name}' in {}", self.path.display()))
    }

    /// The step at time `t`, if there is one.
    pub fn step(&self, t: f64) -> Option<usize> {
        self.times
            .iter()
            .position(|&x| (x - t).abs() <= 1e-9 * t.abs().max(1.0))
    }

    pub fn displacement(&self, k: usize) -> Result<Vec<V3>, String> {
        self.file.displacement(k).map_err(|e| e.to_string())
    }

    pub fn stress(&self, k: usize) -> Result<Vec<[f64; 6]>, String> {
        self.file.stress(k).map_err(|e| e.to_string())
    }

    pub fn reaction(&self, k: usize) -> Result<Vec<V3>, String> {
        self.file.reaction(k).map_err(|e| e.to_string())
    }

    pub fn contact_force(&self, k: usize) -> Result<Vec<V3>, String> {
        self.file.contact_force(k).map_err(|e| e.to_string())
    }

    pub fn status(&self, k: usize) -> Result<Vec<u8>, String> {
        self.file.contact_status(k).map_err(|e| e.to_string())
    }

    pub fn gap(&self, k: usize) -> Result<Vec<f64>, String> {
        self.file.gap(k).map_err(|e| e.to_string())
    }

    /// (1-based element id, local face) of a side set.
    pub fn side_set(&self, name: &str) -> Result<&[(u64, u8)], String> {
        self.side_sets
            .iter()
            .find(|s| s.0 == name)
            .map(|s| s.1.as_slice())
            .ok_or_else(|| format!("no side set '{name}' in {}", self.path.display()))
    }

    /// 0-based nodes of a node set.
    pub fn node_set(&self, name: &str) -> Result<Vec<usize>, String> {
        self.node_sets
            .iter()
            .find(|s| s.0 == name)
            .map(|s| s.1.iter().map(|&i| i as usize - 1).collect())
            .ok_or_else(|| format!("no node set '{name}' in {}", self.path.display()))
    }

    /// The corners of element `e` (1-based) at positions `x`.
    pub fn corners(&self, x: &[V3], e: u64) -> [V3; 8] {
        self.conn[e as usize - 1].map(|n| x[n])
    }

    /// Outward vector areas of a side set's faces (deformed under large kinematics) at
    /// step `k`, with the body of each face.
    pub fn faces(&self, side: &str, k: usize) -> Result<Faces, String> {
        let x: Vec<V3> = if self.large {
            let u = self.displacement(k)?;
            self.x
                .iter()
                .zip(&u)
                .map(|(a, b)| [a[0] + b[0], a[1] + b[1], a[2] + b[2]])
                .collect()
        } else {
            self.x.clone()
        };
        let mut f = Faces {
            areas: vec![],
            bodies: vec![],
        };
        for &(e, lf) in self.side_set(side)? {
            f.areas
                .push(face_vector_area(&self.corners(&x, e), lf as usize));
            f.bodies.push(self.element_body[e as usize - 1]);
        }
        Ok(f)
    }

    /// The resultant of the applied pressures and tractions at step `k` (on one body, or
    /// all); `None` when the scene has body forces.
    pub fn applied(&self, k: usize, body: Option<usize>) -> Result<Option<V3>, String> {
        solver::post::balance::applied_resultant(&self.loads, self.times[k], body, &|s| {
            self.faces(s, k)
        })
    }

    /// The datasets holding a NaN or an infinity (the completed steps of per-step ones).
    pub fn not_finite(&self) -> Vec<String> {
        use solver::output::NumericData;
        let mut bad = Vec::new();
        for name in self.file.dataset_names() {
            let per_step = name.starts_with("/results") || name.starts_with("/stats");
            let rows = if per_step {
                0..self.n
            } else {
                0..self
                    .file
                    .shape(&name)
                    .ok()
                    .and_then(|s| s.first().copied())
                    .unwrap_or(1)
            };
            if let Ok(NumericData::Float(v)) = self.file.read_numeric_rows(&name, rows) {
                if v.iter().any(|x| !x.is_finite()) {
                    bad.push(name);
                }
            }
        }
        bad
    }

    /// The scene's first contact pair's key, as a table value.
    pub fn contact(&self, key: &str) -> Option<&toml::Value> {
        self.scene.get("contact")?.as_array()?.first()?.get(key)
    }

    pub fn mu(&self) -> Result<f64, String> {
        self.contact("mu")
            .and_then(|v| v.as_float().or_else(|| v.as_integer().map(|i| i as f64)))
            .ok_or_else(|| "the scene's first contact pair has no mu".to_string())
    }

    /// The last value of the scene's first pressure function.
    pub fn pressure(&self) -> Result<f64, String> {
        self.loads
            .pressures
            .first()
            .and_then(|p| p.1.last())
            .map(|p| p.1)
            .ok_or_else(|| "the scene has no pressure".to_string())
    }

    /// The body of the first face of the first contact pair's slave side set.
    pub fn slave_body(&self) -> Result<String, String> {
        let slave = self
            .contact("slave")
            .and_then(|s| s.as_str())
            .ok_or("the scene's first contact pair has no slave")?;
        let first = self
            .side_set(slave)?
            .first()
            .ok_or(format!("side set '{slave}' is empty"))?;
        Ok(self.bodies[self.element_body[first.0 as usize - 1]].clone())
    }
}
