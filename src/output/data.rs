//! The in-memory form of what a result file holds: the mesh, the run's metadata and one step.
//!
//! Everything here is in *global* order (rank 0 has gathered it): nodes in the order of
//! [`OutputMesh::coordinates`], elements in the order of the bodies of [`OutputMesh::bodies`]
//! concatenated.

use std::path::Path;

use super::cells::ElementNodes;
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

/// One body's elements (of one kind).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OutputBody {
    pub name: String,
    /// 0-based indices into the global node order: 8 per hexahedron, 10 per 10-node
    /// tetrahedron.
    pub connectivity: ElementNodes,
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

    /// The connectivity of all bodies concatenated (global element order): a table while
    /// every element has the same node count, else (`Err`) XDMF's "Mixed" array
    /// (`super::cells`).
    pub fn all_connectivity(&self) -> Result<ElementNodes, Vec<u64>> {
        super::cells::concatenate(self.bodies.iter().map(|b| &b.connectivity))
    }
}

/// A dataset of `file` that cannot be written or read as it is.
pub(super) fn invalid(file: &Path, dataset: &str, message: String) -> OutputError {
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

/// The scene's node ids by global node index, as the messages naming a node give them.
pub(crate) trait NodeIds {
    /// Nodes of the mesh.
    fn count(&self) -> usize;
    /// The id of node i (asked only for a message).
    fn id(&self, i: usize) -> u64;
}

/// Node ids 1, 2, ...: node i is node i + 1.
pub(crate) struct Sequential(pub(crate) usize);

impl NodeIds for Sequential {
    fn count(&self) -> usize {
        self.0
    }
    fn id(&self, i: usize) -> u64 {
        i as u64 + 1
    }
}

/// One per-node or per-element field of a step: what [`super::ResultWriter::write_field`]
/// writes, one at a time, so that a large run's rank 0 holds one gathered field and not the
/// whole step.
#[derive(Clone, Copy, Debug)]
pub enum StepField<'a> {
    Displacement(&'a [[f64; 3]]),
    Stress(&'a [[f64; 6]]),
    Reaction(&'a [[f64; 3]]),
    ContactForce(&'a [[f64; 3]]),
    ContactStatus(&'a [u8]),
    ContactGap(&'a [f64]),
    ContactPressure(&'a [f64]),
    PlasticStrain(&'a [f64]),
}

impl StepField<'_> {
    /// Every field a step has (contact pressure and plastic strain only where given).
    pub const REQUIRED: [&'static str; 6] = [
        layout::DISPLACEMENT,
        layout::STRESS,
        layout::REACTION,
        layout::CONTACT_FORCE,
        layout::CONTACT_STATUS,
        layout::CONTACT_GAP,
    ];

    /// The dataset the field is written to.
    pub fn dataset(&self) -> &'static str {
        match self {
            StepField::Displacement(_) => layout::DISPLACEMENT,
            StepField::Stress(_) => layout::STRESS,
            StepField::Reaction(_) => layout::REACTION,
            StepField::ContactForce(_) => layout::CONTACT_FORCE,
            StepField::ContactStatus(_) => layout::CONTACT_STATUS,
            StepField::ContactGap(_) => layout::CONTACT_GAP,
            StepField::ContactPressure(_) => layout::CONTACT_PRESSURE,
            StepField::PlasticStrain(_) => layout::PLASTIC_STRAIN,
        }
    }

    /// (values, whether per element).
    pub(crate) fn len_per(&self) -> (usize, bool) {
        match self {
            StepField::Displacement(v) | StepField::Reaction(v) | StepField::ContactForce(v) => {
                (v.len(), false)
            }
            StepField::Stress(v) => (v.len(), true),
            StepField::ContactStatus(v) => (v.len(), false),
            StepField::ContactGap(v) | StepField::ContactPressure(v) => (v.len(), false),
            StepField::PlasticStrain(v) => (v.len(), true),
        }
    }

    /// A value per node or per element, every value finite, every contact status one of
    /// 0..3 (named by node and its id, or by element), as [`StepOutput`]'s own check says.
    pub(crate) fn validate(
        &self,
        file: &Path,
        nodes: &dyn NodeIds,
        elements: usize,
    ) -> Result<(), OutputError> {
        self.check_length(file, nodes.count(), elements)?;
        self.check_values(file, nodes, 0)
    }

    /// The values of the field's entries from `first` on (`ResultWriter::write_field_part`):
    /// named as `validate` names them.
    pub(crate) fn validate_from(
        &self,
        file: &Path,
        nodes: &dyn NodeIds,
        first: usize,
    ) -> Result<(), OutputError> {
        self.check_values(file, nodes, first)
    }

    fn check_length(&self, file: &Path, nodes: usize, elements: usize) -> Result<(), OutputError> {
        let (found, per_element) = self.len_per();
        let (expected, what) = if per_element {
            (elements, "elements")
        } else {
            (nodes, "nodes")
        };
        if found == expected {
            return Ok(());
        }
        Err(OutputError::Invalid {
            file: file.to_path_buf(),
            dataset: self.dataset().to_string(),
            message: format!("{found} values for {expected} {what}"),
        })
    }

    /// The values checked as the entries `first..` of the field.
    fn check_values(
        &self,
        file: &Path,
        nodes: &dyn NodeIds,
        first: usize,
    ) -> Result<(), OutputError> {
        let dataset = self.dataset();
        let node = |i: usize| format!("node {} (id {})", first + i, nodes.id(first + i));
        match *self {
            StepField::Displacement(v) | StepField::Reaction(v) | StepField::ContactForce(v) => {
                for (i, x) in v.iter().enumerate() {
                    check_finite(file, dataset, x, |k| format!("{}, component {k}", node(i)))?;
                }
                Ok(())
            }
            StepField::Stress(v) => {
                for (e, x) in v.iter().enumerate() {
                    check_finite(file, dataset, x, |k| {
                        format!("element {}, component {k}", first + e)
                    })?;
                }
                Ok(())
            }
            StepField::ContactGap(v) | StepField::ContactPressure(v) => {
                check_finite(file, dataset, v, node)
            }
            StepField::PlasticStrain(v) => {
                check_finite(file, dataset, v, |e| format!("element {}", first + e))
            }
            StepField::ContactStatus(v) => match v.iter().position(|&s| s > 3) {
                None => Ok(()),
                Some(i) => Err(OutputError::Invalid {
                    file: file.to_path_buf(),
                    dataset: dataset.into(),
                    message: format!("{} has status {}, expected 0..3", node(i), v[i]),
                }),
            },
        }
    }
}

impl StepOutput {
    /// Checks lengths against the mesh and that every value is finite.
    pub(crate) fn validate(
        &self,
        file: &Path,
        nodes: &dyn NodeIds,
        elements: usize,
    ) -> Result<(), OutputError> {
        let fields = self.fields();
        for f in &fields {
            f.check_length(file, nodes.count(), elements)?;
        }
        check_time(file, self.time)?;
        for f in &fields {
            f.check_values(file, nodes, 0)?;
        }
        check_stats(file, &self.stats)
    }

    /// The step's fields, the contact pressure and the plastic strain where it has them.
    pub fn fields(&self) -> Vec<StepField<'_>> {
        let mut f = vec![
            StepField::Displacement(&self.displacement),
            StepField::Stress(&self.stress),
            StepField::Reaction(&self.reaction),
            StepField::ContactForce(&self.contact_force),
            StepField::ContactStatus(&self.contact_status),
            StepField::ContactGap(&self.contact_gap),
        ];
        if !self.contact_pressure.is_empty() {
            f.push(StepField::ContactPressure(&self.contact_pressure));
        }
        if !self.plastic_strain.is_empty() {
            f.push(StepField::PlasticStrain(&self.plastic_strain));
        }
        f
    }
}

impl StepStats {
    /// Whether a step at `time` with these statistics passes the writer's checks of them
    /// (`ResultWriter::end_step`, `append_step`).
    pub fn writable(&self, time: f64) -> bool {
        let nowhere = Path::new("");
        check_time(nowhere, time).is_ok() && check_stats(nowhere, self).is_ok()
    }
}

/// The step's time finite.
pub(crate) fn check_time(file: &Path, time: f64) -> Result<(), OutputError> {
    check_finite(file, layout::TIME, &[time], |_| "the step's time".into())
}

/// The step's statistics finite, the penetration not negative.
pub(crate) fn check_stats(file: &Path, stats: &StepStats) -> Result<(), OutputError> {
    check_finite(file, layout::STATS_RESIDUAL, &[stats.residual], |_| {
        "the step's residual".into()
    })?;
    check_finite(file, layout::STATS_WALL_TIME, &[stats.wall_time], |_| {
        "the step's wall time".into()
    })?;
    check_finite(
        file,
        layout::STATS_MAX_PENETRATION,
        &[stats.max_penetration],
        |_| "the step's largest penetration".into(),
    )?;
    if stats.max_penetration < 0.0 {
        return Err(OutputError::Invalid {
            file: file.to_path_buf(),
            dataset: layout::STATS_MAX_PENETRATION.into(),
            message: format!(
                "the step's largest penetration is {}, expected >= 0",
                stats.max_penetration
            ),
        });
    }
    Ok(())
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
    /// The constraint rows and slip springs the multilevel hierarchy in use was built
    /// from, encoded by the solver (`Stepper::hierarchy_words`); empty when no hierarchy
    /// of linear bodies is kept (and then not written).
    pub hierarchy: Vec<f64>,
    /// Committed integration-point history of the plastic elements in global element order
    /// (`STATE_LEN` values per point); empty when no body is plastic.
    pub history: Vec<f64>,
}
