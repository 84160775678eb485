//! Names of the datasets and attributes of a result file, and the file names beside it.
//!
//! The README's "Result files" and docs/output.md document the layout; keep them in step.

use std::path::{Path, PathBuf};

/// Version of the layout below, written as the root attribute `format_version`.
///
/// 2: every dataset carries a Fletcher-32 checksum, the metadata is in HDF5 1.10's
/// checksummed format, and the restart state is kept in two slots (`/restart/slot0`,
/// `/restart/slot1`). 1: no checksums, one restart block (`/restart/state` etc.), still read.
pub const FORMAT_VERSION: u64 = 2;

pub const COORDINATES: &str = "/mesh/coordinates";
pub const NODE_IDS: &str = "/mesh/node_ids";
pub const ALL_CONNECTIVITY: &str = "/mesh/all_connectivity";
pub const NODE_SETS: &str = "/mesh/node_sets";
pub const SIDE_SETS: &str = "/mesh/side_sets";
/// Names that cannot be body names because they are taken in `/mesh`.
pub const RESERVED_MESH_NAMES: [&str; 5] = [
    "coordinates",
    "node_ids",
    "all_connectivity",
    "node_sets",
    "side_sets",
];

pub const TIME: &str = "/results/time";
pub const DISPLACEMENT: &str = "/results/displacement";
pub const STRESS: &str = "/results/stress";
pub const REACTION: &str = "/results/reaction";
pub const CONTACT_FORCE: &str = "/results/contact/force";
pub const CONTACT_STATUS: &str = "/results/contact/status";
pub const CONTACT_GAP: &str = "/results/contact/gap";
/// Nodal contact pressure, `[steps, nodes]`, created with the first step written; absent
/// from files written before it was recorded (and from a run continued from one), which
/// are read as before.
pub const CONTACT_PRESSURE: &str = "/results/contact/pressure";
/// Element-mean equivalent plastic strain, `[steps, elements]`; present only when a body of
/// the scene is plastic (zero in the elastic bodies' elements).
pub const PLASTIC_STRAIN: &str = "/results/plastic_strain";

pub const STATS_CG_ITERATIONS: &str = "/stats/cg_iterations";
pub const STATS_CONTACT_UPDATES: &str = "/stats/contact_updates";
pub const STATS_RESIDUAL: &str = "/stats/residual";
pub const STATS_WALL_TIME: &str = "/stats/wall_time";
pub const STATS_CUTBACKS: &str = "/stats/cutbacks";
pub const STATS_CONTACT_ACTIVE: &str = "/stats/contact_active";
pub const STATS_CONTACT_STICK: &str = "/stats/contact_stick";
pub const STATS_CONTACT_SLIP: &str = "/stats/contact_slip";
pub const STATS_CONTACT_RELEASED: &str = "/stats/contact_released";
pub const STATS_MAX_PENETRATION: &str = "/stats/max_penetration";

pub const ELEMENT_RANK: &str = "/partition/element_rank";

/// Attribute of each `/mesh/<body>` group: the body's position in the body order.
pub const BODY_INDEX_ATTR: &str = "body_index";
/// Attribute of each `/mesh/<body>` group: index of its first element in global element order.
pub const FIRST_ELEMENT_ATTR: &str = "first_element";
/// Attribute of each node/side set dataset: its position in the set order.
pub const SET_INDEX_ATTR: &str = "index";

pub const ATTR_FORMAT_VERSION: &str = "format_version";
pub const ATTR_SOLVER_VERSION: &str = "solver_version";
pub const ATTR_RANKS: &str = "ranks";
pub const ATTR_SCENE: &str = "scene";
pub const ATTR_SCENE_NAME: &str = "scene_name";
pub const ATTR_UNITS: &str = "units";
pub const ATTR_START_TIME: &str = "start_time";
pub const ATTR_WALL_TIME: &str = "wall_time";
pub const ATTR_EXIT_STATUS: &str = "exit_status";

/// The group of the state a run resumes from (`solver run --restart`).
pub const RESTART: &str = "/restart";
/// The restart state after a written step goes to slot `rows % 2` (rows of `/results`
/// written), so the slot holding the previous one is never touched while it is written.
pub fn restart_slot(slot: usize) -> String {
    format!("{RESTART}/slot{slot}")
}
/// Datasets of a slot: `state` = `[load step, time, previous step length, reference force
/// floor, rows of /results]`, written last; the displacement at that step and at the step
/// before it, per node; the active contact constraints and the released (slave, pair)
/// entries, encoded.
pub const SLOT_STATE: &str = "state";
pub const SLOT_DISPLACEMENT: &str = "displacement";
pub const SLOT_PREVIOUS_DISPLACEMENT: &str = "previous_displacement";
pub const SLOT_CONTACT: &str = "contact";
pub const SLOT_RELEASED: &str = "released";
/// Optional dataset of a slot, present when the scene has plastic bodies: the committed
/// integration-point history (see `RestartState::history`), written before `state`.
pub const SLOT_HISTORY: &str = "history";
/// The mortar ties of the active constraints (words of the contact module; present once a
/// mortar tie was written).
pub const SLOT_TIES: &str = "ties";
/// The constraint rows the multilevel hierarchy in use was built from (words of the
/// solver; present once a hierarchy of linear bodies was kept: a continued run builds the
/// same one).
pub const SLOT_HIERARCHY: &str = "hierarchy";
/// The datasets of a slot, the state last (the order they are written in).
/// Layout of the words of the restart slots' `contact` dataset (the contact module's
/// encoding of an active constraint: how many words, in which order), written as the
/// attribute `contact_layout` of that dataset. Raise it with every change of that encoding:
/// `--restart` refuses a file of another layout by name instead of misreading its words.
/// Files written before the attribute existed have layout 1.
pub const CONTACT_LAYOUT: u64 = 1;
pub const ATTR_CONTACT_LAYOUT: &str = "contact_layout";

pub const SLOT_DATASETS: [&str; 5] = [
    SLOT_CONTACT,
    SLOT_RELEASED,
    SLOT_DISPLACEMENT,
    SLOT_PREVIOUS_DISPLACEMENT,
    SLOT_STATE,
];

/// The one restart block of a format 1 file (read, never written): its datasets are
/// `/restart/<name>` with the slot dataset names.
pub const RESTART_V1_STATE: &str = "/restart/state";

/// The text of the `units` attribute.
pub const UNITS_NOTE: &str = "consistent units; the scene's";
/// `exit_status` while the run is under way (only ever seen in a `.tmp` file).
pub const STATUS_RUNNING: &str = "running";
/// `exit_status` of a run that finished.
pub const STATUS_COMPLETED: &str = "completed";
/// Prefix of `exit_status` of a run that failed.
pub const STATUS_FAILED_PREFIX: &str = "failed: ";

/// The per-step node datasets with three components.
pub const NODE_VECTOR_DATASETS: [&str; 3] = [DISPLACEMENT, REACTION, CONTACT_FORCE];

/// Every dataset a result file has whatever its mesh (body and set datasets come on top).
pub const REQUIRED_DATASETS: [&str; 21] = [
    COORDINATES,
    NODE_IDS,
    ALL_CONNECTIVITY,
    TIME,
    DISPLACEMENT,
    STRESS,
    REACTION,
    CONTACT_FORCE,
    CONTACT_STATUS,
    CONTACT_GAP,
    STATS_CG_ITERATIONS,
    STATS_CONTACT_UPDATES,
    STATS_RESIDUAL,
    STATS_WALL_TIME,
    STATS_CUTBACKS,
    STATS_CONTACT_ACTIVE,
    STATS_CONTACT_STICK,
    STATS_CONTACT_SLIP,
    STATS_CONTACT_RELEASED,
    STATS_MAX_PENETRATION,
    ELEMENT_RANK,
];

/// Every root attribute a finished result file has.
pub const REQUIRED_ATTRIBUTES: [&str; 9] = [
    ATTR_FORMAT_VERSION,
    ATTR_SOLVER_VERSION,
    ATTR_RANKS,
    ATTR_SCENE,
    ATTR_SCENE_NAME,
    ATTR_UNITS,
    ATTR_START_TIME,
    ATTR_WALL_TIME,
    ATTR_EXIT_STATUS,
];

pub fn body_group(body: &str) -> String {
    format!("/mesh/{body}")
}

pub fn body_connectivity(body: &str) -> String {
    format!("/mesh/{body}/connectivity")
}

pub fn body_element_ids(body: &str) -> String {
    format!("/mesh/{body}/element_ids")
}

pub fn node_set(name: &str) -> String {
    format!("{NODE_SETS}/{name}")
}

pub fn side_set(name: &str) -> String {
    format!("{SIDE_SETS}/{name}")
}

/// A body or set name must be usable as one HDF5 link name.
pub(crate) fn check_name(name: &str) -> Result<(), String> {
    if name.is_empty() {
        Err("empty name".into())
    } else if name == "." || name == ".." {
        Err(format!("'{name}' cannot be a name"))
    } else if name.contains('/') || name.contains('\0') {
        Err(format!("name '{name}' contains '/' or a NUL byte"))
    } else {
        Ok(())
    }
}

/// The file names a run writes for the result path `<dir>/<stem>.h5`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ResultPaths {
    /// `<dir>/<stem>.h5`: the complete result, present only after `finish()`.
    pub result: PathBuf,
    /// `<dir>/<stem>.h5.tmp`: the file while the run writes it (`<dir>/<stem>.h5.2.tmp`,
    /// ... when that name is taken, see [`super::paths`]).
    pub tmp: PathBuf,
    /// `<dir>/<stem>.failed.h5`: the partial result of a failed run.
    pub failed: PathBuf,
    /// `<dir>/<stem>.xmf`: XDMF for `result`.
    pub xdmf: PathBuf,
    /// `<dir>/<stem>.failed.xmf`: XDMF for `failed`.
    pub failed_xdmf: PathBuf,
    /// `<dir>/<stem>.h5.lock`: held by the run writing `result`.
    pub lock: PathBuf,
}

impl ResultPaths {
    pub fn new(result: &Path) -> Self {
        let dir = result.parent().unwrap_or(Path::new(""));
        let stem = result
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "result".into());
        ResultPaths {
            result: result.to_path_buf(),
            tmp: temp_name(result, 1),
            lock: super::lock::lock_path(result),
            failed: dir.join(format!("{stem}.failed.h5")),
            xdmf: dir.join(format!("{stem}.xmf")),
            failed_xdmf: dir.join(format!("{stem}.failed.xmf")),
        }
    }
}

/// The `k`-th candidate name of a temporary file for `target`: `<target>.tmp`, then
/// `<target>.2.tmp`, `<target>.3.tmp`, ...
pub(crate) fn temp_name(target: &Path, k: usize) -> PathBuf {
    let mut s = target.as_os_str().to_owned();
    if k > 1 {
        s.push(format!(".{k}"));
    }
    s.push(".tmp");
    PathBuf::from(s)
}
