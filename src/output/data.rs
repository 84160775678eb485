//! The in-memory form of what a result file holds: the mesh, the run's metadata and one step.
//!
//! Everything here is in *global* order (rank 0 has gathered it): nodes in the order of
//! [`OutputMesh::coordinates`], elements in the order of the bodies of [`OutputMesh::bodies`]
//! concatenated.

use std::path::Path;

use super::error::OutputError;
use super::layout;

/// The mesh as written under `/mesh`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OutputMesh {
    /// Undeformed node coordinates, one per node, in global node order.
    pub coordinates: Vec<[f64; 3]>,
    /// The scene's 1-based node id of each node.
    pub node_ids: Vec<u64>,
    /// The bodies in order; their elements concatenated give the global element order.
    pub bodies: Vec<OutputBody>,
    /// Node sets: name and 1-based node ids.
    pub node_sets: Vec<(String, Vec<u64>)>,
    /// Side sets: name and (1-based element id, local face 0..5).
    pub side_sets: Vec<(String, Vec<(u64, u8)>)>,
}

/// One body's hexahedra.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OutputBody {
    pub name: String,
    /// Eight 0-based indices into the global node order per element.
    pub connectivity: Vec<[u64; 8]>,
    /// The 1-based global element id of each element.
    pub element_ids: Vec<u64>,
}

/// Metadata of the run, written as root attributes (and `/partition/element_rank`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RunInfo {
    pub solver_version: String,
    pub ranks: u64,
    /// The scene file's full text.
    pub scene_text: String,
    pub scene_name: String,
    /// RFC 3339 time stamp of the run's start (see [`super::rfc3339_now`]).
    pub start_time: String,
    /// The rank owning each element, in global element order.
    pub element_rank: Vec<u32>,
}

/// Solver statistics of one step, written under `/stats`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepStats {
    pub cg_iterations: u64,
    pub contact_updates: u64,
    pub residual: f64,
    /// Wall-clock seconds the step took.
    pub wall_time: f64,
    pub cutbacks: u64,
    /// Slave constraints in contact at the end of the step.
    pub contact_active: u64,
    /// Of those, sticking.
    pub contact_stick: u64,
    /// Of those, slipping.
    pub contact_slip: u64,
    /// Slave constraints released during the step.
    pub contact_released: u64,
    /// Largest penetration of any slave node after enforcement (>= 0; 0 when none
    /// penetrates).
    pub max_penetration: f64,
}

/// Contact status codes of `/results/contact/status`.
pub mod contact_status {
    pub const FREE: u8 = 0;
    pub const STICK: u8 = 1;
    pub const SLIP: u8 = 2;
    pub const RELEASED: u8 = 3;
}

/// The results of one finished step, in global order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StepOutput {
    pub time: f64,
    /// Per node.
    pub displacement: Vec<[f64; 3]>,
    /// Per element: element-averaged Cauchy stress, order xx yy zz xy yz zx.
    pub stress: Vec<[f64; 6]>,
    /// Per node.
    pub reaction: Vec<[f64; 3]>,
    /// Per node.
    pub contact_force: Vec<[f64; 3]>,
    /// Per node, see [`contact_status`].
    pub contact_status: Vec<u8>,
    /// Per node.
    pub contact_gap: Vec<f64>,
    /// Per node: the contact pressure (normal force per slave area, compressive > 0; see
    /// `crate::contact::area`). Empty for a step copied from a file written before the
    /// pressure was recorded (then the file has no such dataset).
    pub contact_pressure: Vec<f64>,
    /// Per element: the element-mean equivalent plastic strain; empty when no body is
    /// plastic (then the file has no such dataset).
    pub plastic_strain: Vec<f64>,
    pub stats: StepStats,
}

impl OutputMesh {
    /// Number of elements of all bodies.
    pub fn num_elements(&self) -> usize {
        self.bodies.iter().map(|b| b.connectivity.len()).sum()
    }

    /// The connectivity of all bodies concatenated (global element order).
    pub fn all_connectivity(&self) -> Vec<[u64; 8]> {
        self.bodies
            .iter()
            .flat_map(|b| b.connectivity.iter().copied())
            .collect()
    }

    /// Checks the mesh is consistent enough to be written and read back.
    pub(crate) fn validate(&self, file: &Path) -> Result<(), OutputError> {
        self.validate_nodes(file)?;
        self.validate_bodies(file)?;
        self.validate_sets(file)
    }

    /// One id per node, finite coordinates.
    fn validate_nodes(&self, file: &Path) -> Result<(), OutputError> {
        let nodes = self.coordinates.len();
        if self.node_ids.len() != nodes {
            return Err(invalid(
                file,
                layout::NODE_IDS,
                format!("{} node ids for {} nodes", self.node_ids.len(), nodes),
            ));
        }
        for (i, c) in self.coordinates.iter().enumerate() {
            check_finite(file, layout::COORDINATES, c, |k| {
                format!("node {i} (id {}), component {k}", self.node_ids[i])
            })?;
        }
        Ok(())
    }

    /// Distinct, allowed body names; one id per element; node indices in range.
    fn validate_bodies(&self, file: &Path) -> Result<(), OutputError> {
        let nodes = self.coordinates.len();
        let mut seen = std::collections::HashSet::new();
        for body in &self.bodies {
            let ds = format!("/mesh/{}", body.name);
            layout::check_name(&body.name).map_err(|m| invalid(file, &ds, m))?;
            if layout::RESERVED_MESH_NAMES.contains(&body.name.as_str()) {
                return Err(invalid(
                    file,
                    &ds,
                    format!("body name '{}' is reserved in /mesh", body.name),
                ));
            }
            if !seen.insert(body.name.as_str()) {
                return Err(invalid(file, &ds, "two bodies have this name".into()));
            }
            let conn = layout::body_connectivity(&body.name);
            if body.element_ids.len() != body.connectivity.len() {
                return Err(invalid(
                    file,
                    &layout::body_element_ids(&body.name),
                    format!(
                        "{} element ids for {} elements",
                        body.element_ids.len(),
                        body.connectivity.len()
                    ),
                ));
            }
            for (e, hex) in body.connectivity.iter().enumerate() {
                if let Some(&n) = hex.iter().find(|&&n| n as usize >= nodes) {
                    return Err(invalid(
                        file,
                        &conn,
                        format!(
                            "element {e} refers to node index {n}, but there are {nodes} nodes"
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Distinct, allowed set names; local faces 0..5.
    fn validate_sets(&self, file: &Path) -> Result<(), OutputError> {
        for (kind, names) in [
            (
                layout::NODE_SETS,
                self.node_sets.iter().map(|s| &s.0).collect::<Vec<_>>(),
            ),
            (
                layout::SIDE_SETS,
                self.side_sets.iter().map(|s| &s.0).collect::<Vec<_>>(),
            ),
        ] {
            let mut seen = std::collections::HashSet::new();
            for name in names {
                let ds = format!("{kind}/{name}");
                layout::check_name(name).map_err(|m| invalid(file, &ds, m))?;
                if !seen.insert(name) {
                    return Err(invalid(file, &ds, "two sets have this name".into()));
                }
            }
        }
        for (name, faces) in &self.side_sets {
            if let Some((e, f)) = faces.iter().find(|(_, f)| *f > 5) {
                return Err(invalid(
                    file,
                    &format!("{}/{name}", layout::SIDE_SETS),
                    format!("element {e} has local face {f}, expected 0..5"),
                ));
            }
        }
        Ok(())
    }
}

/// A dataset of `file` that cannot be written or read as it is.
fn invalid(file: &Path, dataset: &str, message: String) -> OutputError {
    OutputError::Invalid {
        file: file.to_path_buf(),
        dataset: dataset.to_string(),
        message,
    }
}

/// Refuses NaN and infinities, naming the dataset and the entry.
pub(crate) fn check_finite(
    file: &Path,
    dataset: &str,
    values: &[f64],
    location: impl Fn(usize) -> String,
) -> Result<(), OutputError> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(k) => Err(OutputError::NonFinite {
            file: file.to_path_buf(),
            dataset: dataset.to_string(),
            location: location(k),
            value: values[k],
        }),
    }
}

impl StepOutput {
    /// Checks lengths against the mesh and that every value is finite.
    pub(crate) fn validate(
        &self,
        file: &Path,
        node_ids: &[u64],
        elements: usize,
    ) -> Result<(), OutputError> {
        self.check_lengths(file, node_ids.len(), elements)?;
        self.check_values(file, node_ids)?;
        self.check_stats(file)
    }

    /// Every dataset has a value per node or per element.
    fn check_lengths(&self, file: &Path, nodes: usize, elements: usize) -> Result<(), OutputError> {
        let length = |dataset: &str, found: usize, expected: usize, what: &str| {
            if found == expected {
                Ok(())
            } else {
                Err(OutputError::Invalid {
                    file: file.to_path_buf(),
                    dataset: dataset.to_string(),
                    message: format!("{found} values for {expected} {what}"),
                })
            }
        };
        length(
            layout::DISPLACEMENT,
            self.displacement.len(),
            nodes,
            "nodes",
        )?;
        length(layout::STRESS, self.stress.len(), elements, "elements")?;
        length(layout::REACTION, self.reaction.len(), nodes, "nodes")?;
        length(
            layout::CONTACT_FORCE,
            self.contact_force.len(),
            nodes,
            "nodes",
        )?;
        length(
            layout::CONTACT_STATUS,
            self.contact_status.len(),
            nodes,
            "nodes",
        )?;
        length(layout::CONTACT_GAP, self.contact_gap.len(), nodes, "nodes")?;
        if !self.contact_pressure.is_empty() {
            length(
                layout::CONTACT_PRESSURE,
                self.contact_pressure.len(),
                nodes,
                "nodes",
            )?;
        }
        if !self.plastic_strain.is_empty() {
            length(
                layout::PLASTIC_STRAIN,
                self.plastic_strain.len(),
                elements,
                "elements",
            )?;
        }
        Ok(())
    }

    /// Every value finite, every contact status one of 0..3 (named by node and its id).
    fn check_values(&self, file: &Path, node_ids: &[u64]) -> Result<(), OutputError> {
        check_finite(file, layout::PLASTIC_STRAIN, &self.plastic_strain, |e| {
            format!("element {e}")
        })?;

        check_finite(file, layout::TIME, &[self.time], |_| {
            "the step's time".into()
        })?;
        let node_vectors = [
            (layout::DISPLACEMENT, &self.displacement),
            (layout::REACTION, &self.reaction),
            (layout::CONTACT_FORCE, &self.contact_force),
        ];
        for (dataset, values) in node_vectors {
            for (i, v) in values.iter().enumerate() {
                check_finite(file, dataset, v, |k| {
                    format!("node {i} (id {}), component {k}", node_ids[i])
                })?;
            }
        }
        for (e, s) in self.stress.iter().enumerate() {
            check_finite(file, layout::STRESS, s, |k| {
                format!("element {e}, component {k}")
            })?;
        }
        check_finite(file, layout::CONTACT_GAP, &self.contact_gap, |i| {
            format!("node {i} (id {})", node_ids[i])
        })?;
        check_finite(
            file,
            layout::CONTACT_PRESSURE,
            &self.contact_pressure,
            |i| format!("node {i} (id {})", node_ids[i]),
        )?;
        if let Some(i) = self.contact_status.iter().position(|&s| s > 3) {
            return Err(OutputError::Invalid {
                file: file.to_path_buf(),
                dataset: layout::CONTACT_STATUS.into(),
                message: format!(
                    "node {i} (id {}) has status {}, expected 0..3",
                    node_ids[i], self.contact_status[i]
                ),
            });
        }
        Ok(())
    }

    /// The step's statistics finite, the penetration not negative.
    fn check_stats(&self, file: &Path) -> Result<(), OutputError> {
        check_finite(file, layout::STATS_RESIDUAL, &[self.stats.residual], |_| {
            "the step's residual".into()
        })?;
        check_finite(
            file,
            layout::STATS_WALL_TIME,
            &[self.stats.wall_time],
            |_| "the step's wall time".into(),
        )?;
        check_finite(
            file,
            layout::STATS_MAX_PENETRATION,
            &[self.stats.max_penetration],
            |_| "the step's largest penetration".into(),
        )?;
        if self.stats.max_penetration < 0.0 {
            return Err(OutputError::Invalid {
                file: file.to_path_buf(),
                dataset: layout::STATS_MAX_PENETRATION.into(),
                message: format!(
                    "the step's largest penetration is {}, expected >= 0",
                    self.stats.max_penetration
                ),
            });
        }
        Ok(())
    }
}

/// Everything a run needs to continue after its last written step, in global node order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RestartState {
    /// The load step (1-based) the state is the end of.
    pub step: u64,
    pub time: f64,
    /// Length of that step (the predictor extrapolates with it).
    pub dt_prev: f64,
    /// The CG reference force floor carried from step to step.
    pub reference_floor: f64,
    /// Rows of the per-step result datasets written up to this step.
    pub rows: u64,
    /// The run had switched from its first preconditioner to the multilevel one (`auto`,
    /// a model problem that stalled); a continued run goes on with multilevel. Files
    /// written before this field existed read as false.
    pub multilevel_switched: bool,
    pub displacement: Vec<[f64; 3]>,
    pub previous_displacement: Vec<[f64; 3]>,
    /// Active contact constraints, encoded by the contact module.
    pub contact: Vec<f64>,
    /// Released (slave, pair) entries, encoded by the contact module.
    pub released: Vec<f64>,
    /// The mortar ties of the active constraints, encoded by the contact module; empty
    /// without mortar pairs (and then not written).
    pub ties: Vec<f64>,
    /// Committed integration-point history of the plastic elements in global element order
    /// (`STATE_LEN` values per point); empty when no body is plastic.
    pub history: Vec<f64>,
}
