//! [`ResultFile`]: reads a result file back (for `solver post`, tests and tools).

use std::io::Read;
use std::ops::Range;
use std::path::{Path, PathBuf};

use hdf5::types::{TypeDescriptor, VarLenUnicode};
use hdf5::H5Type;

use super::cells::ElementNodes;
use super::data::{OutputBody, OutputMesh, StepStats};
use super::error::{Hdf5Context, OutputError};
use super::integrity::{at_step, locate};
use super::layout;

/// The root attributes of a result file.
#[derive(Clone, Debug, PartialEq)]
pub struct FileAttributes {
    pub format_version: u64,
    pub solver_version: String,
    pub ranks: u64,
    pub scene_text: String,
    pub scene_name: String,
    pub units: String,
    pub start_time: String,
    /// Absent in a `.tmp` file of a run that has not finished (or died).
    pub wall_time: Option<f64>,
    /// "completed", "failed: <message>", or "running" in a `.tmp` file.
    pub exit_status: String,
}

/// The values of a numeric dataset, in the dataset's own number kind.
#[derive(Clone, Debug, PartialEq)]
pub enum NumericData {
    Float(Vec<f64>),
    Unsigned(Vec<u64>),
    Signed(Vec<i64>),
}

impl NumericData {
    pub fn len(&self) -> usize {
        match self {
            NumericData::Float(v) => v.len(),
            NumericData::Unsigned(v) => v.len(),
            NumericData::Signed(v) => v.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The kind of number a dataset holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NumericKind {
    Float,
    Unsigned,
    Signed,
}

/// An open result file (a finished one, a `.failed.h5`, or the `.tmp` of a run under way).
pub struct ResultFile {
    path: PathBuf,
    file: hdf5::File,
    steps: usize,
    nodes: usize,
    elements: usize,
}

const HDF5_SIGNATURE: [u8; 8] = [0x89, b'H', b'D', b'F', b'\r', b'\n', 0x1a, b'\n'];

/// Whether the file carries the HDF5 signature at one of the offsets HDF5 allows.
fn has_hdf5_signature(path: &Path) -> std::io::Result<bool> {
    let mut f = std::fs::File::open(path)?;
    let mut buf = Vec::new();
    f.by_ref().take(8192 + 8).read_to_end(&mut buf)?;
    let mut offset = 0usize;
    while offset + 8 <= buf.len() {
        if buf[offset..offset + 8] == HDF5_SIGNATURE {
            return Ok(true);
        }
        offset = if offset == 0 { 512 } else { offset * 2 };
    }
    Ok(false)
}

impl ResultFile {
    /// Opens a result file, checking that every dataset of the format is there with a
    /// consistent shape. Errors say whether the file is missing, not HDF5, truncated or
    /// corrupt, or lacks a dataset.
    pub fn open(path: &Path) -> Result<Self, OutputError> {
        let file = open_hdf5(path)?;
        let mut r = ResultFile {
            path: path.to_path_buf(),
            file,
            steps: 0,
            nodes: 0,
            elements: 0,
        };
        r.check_layout()?;
        Ok(r)
    }

    /// Every dataset of the format is there with a consistent shape; sets the counts of
    /// nodes, elements and steps.
    fn check_layout(&mut self) -> Result<(), OutputError> {
        let r = self;
        for name in layout::REQUIRED_DATASETS {
            r.dataset(name)?;
        }
        let coords = r.shape(layout::COORDINATES)?;
        r.expect_shape(
            layout::COORDINATES,
            &coords,
            2,
            &[None, Some(3)],
            "[nodes, 3]",
        )?;
        r.nodes = coords[0];
        r.elements = r.all_connectivity_elements()?;
        let time = r.shape(layout::TIME)?;
        r.expect_shape(layout::TIME, &time, 1, &[None], "[steps]")?;
        r.steps = time[0];
        r.check_dataset_shapes()?;
        r.check_optional_shapes()?;
        r.check_stats_lengths()
    }

    /// The contact pressure, where the file has it: `[steps, nodes]`, at least the steps that
    /// have a time.
    fn check_optional_shapes(&self) -> Result<(), OutputError> {
        let r = self;
        let name = layout::CONTACT_PRESSURE;
        if !r.file.link_exists(name) {
            return Ok(());
        }
        let shape = r.shape(name)?;
        r.expect_shape(name, &shape, 2, &[None, Some(r.nodes)], "[steps, nodes]")?;
        if shape[0] < r.steps {
            return Err(r.shape_error(
                name,
                &shape,
                &format!("[steps, nodes] with {} steps", r.steps),
            ));
        }
        Ok(())
    }

    /// The node, element and per-step datasets have their shapes; the per-step ones at least
    /// the steps that have a time.
    fn check_dataset_shapes(&self) -> Result<(), OutputError> {
        let r = self;
        let (n, e) = (Some(r.nodes), Some(r.elements));
        let checks: [(&str, Vec<Option<usize>>, &str); 11] = [
            (layout::NODE_IDS, vec![n], "[nodes]"),
            (layout::ELEMENT_RANK, vec![e], "[elements]"),
            (
                layout::DISPLACEMENT,
                vec![None, n, Some(3)],
                "[steps, nodes, 3]",
            ),
            (
                layout::STRESS,
                vec![None, e, Some(6)],
                "[steps, elements, 6]",
            ),
            (
                layout::REACTION,
                vec![None, n, Some(3)],
                "[steps, nodes, 3]",
            ),
            (
                layout::CONTACT_FORCE,
                vec![None, n, Some(3)],
                "[steps, nodes, 3]",
            ),
            (layout::CONTACT_STATUS, vec![None, n], "[steps, nodes]"),
            (layout::CONTACT_GAP, vec![None, n], "[steps, nodes]"),
            (layout::STATS_CG_ITERATIONS, vec![None], "[steps]"),
            (layout::STATS_RESIDUAL, vec![None], "[steps]"),
            (layout::STATS_WALL_TIME, vec![None], "[steps]"),
        ];
        for (name, dims, text) in checks.iter() {
            let shape = r.shape(name)?;
            r.expect_shape(name, &shape, dims.len(), dims, text)?;
            // A run that died inside a step may have written part of it: only the steps
            // that have a time count, so every step dataset needs at least that many.
            if dims[0].is_none() && shape[0] < r.steps {
                return Err(r.shape_error(name, &shape, &format!("{text} with {} steps", r.steps)));
            }
        }
        Ok(())
    }

    /// The other statistics datasets: one value per step, at least the steps that have a time.
    fn check_stats_lengths(&self) -> Result<(), OutputError> {
        let r = self;
        for name in [
            layout::STATS_CONTACT_UPDATES,
            layout::STATS_CUTBACKS,
            layout::STATS_CONTACT_ACTIVE,
            layout::STATS_CONTACT_STICK,
            layout::STATS_CONTACT_SLIP,
            layout::STATS_CONTACT_RELEASED,
            layout::STATS_MAX_PENETRATION,
        ] {
            let shape = r.shape(name)?;
            if shape.len() != 1 || shape[0] < r.steps {
                return Err(r.shape_error(
                    name,
                    &shape,
                    &format!("[steps] with {} steps", r.steps),
                ));
            }
        }
        Ok(())
    }

    /// The number of elements `/mesh/all_connectivity` holds: `[elements, 8 or 10]`, or
    /// XDMF's "Mixed" array (bodies of several node counts; `super::cells`).
    fn all_connectivity_elements(&self) -> Result<usize, OutputError> {
        let name = layout::ALL_CONNECTIVITY;
        let shape = self.shape(name)?;
        let expected = "[elements, 8 or 10] (or a 1-D XDMF Mixed array)";
        match shape[..] {
            [e, k] if super::cells::xdmf_topology(k).is_some() => Ok(e),
            [_] => {
                let mixed = self.read_all::<u64>(name)?;
                super::cells::count_mixed(&mixed).map_err(|message| OutputError::Invalid {
                    file: self.path.clone(),
                    dataset: name.into(),
                    message,
                })
            }
            _ => Err(self.shape_error(name, &shape, expected)),
        }
    }

    fn shape_error(&self, name: &str, found: &[usize], expected: &str) -> OutputError {
        OutputError::Shape {
            file: self.path.clone(),
            dataset: name.to_string(),
            expected: expected.to_string(),
            found: found.to_vec(),
        }
    }

    fn expect_shape(
        &self,
        name: &str,
        shape: &[usize],
        ndim: usize,
        dims: &[Option<usize>],
        text: &str,
    ) -> Result<(), OutputError> {
        let ok = shape.len() == ndim
            && dims
                .iter()
                .zip(shape)
                .all(|(d, s)| d.is_none_or(|d| d == *s));
        if ok {
            Ok(())
        } else {
            Err(self.shape_error(name, shape, text))
        }
    }

    pub(super) fn dataset(&self, name: &str) -> Result<hdf5::Dataset, OutputError> {
        self.file
            .dataset(name)
            .map_err(|e| match super::error::classify(&self.path, name, e) {
                d @ OutputError::Damaged { .. } => d,
                _ => OutputError::Missing {
                    file: self.path.clone(),
                    what: "dataset",
                    name: name.to_string(),
                },
            })
    }

    /// The open HDF5 file.
    pub(super) fn hdf5(&self) -> &hdf5::File {
        &self.file
    }

    fn check_step(&self, step: usize) -> Result<(), OutputError> {
        if step < self.steps {
            Ok(())
        } else {
            Err(OutputError::StepOutOfRange {
                file: self.path.clone(),
                step,
                steps: self.steps,
            })
        }
    }

    fn read_all<T: H5Type>(&self, name: &str) -> Result<Vec<T>, OutputError> {
        self.dataset(name)?.read_raw::<T>().at(&self.path, name)
    }

    /// The first `steps` entries of a per-step scalar dataset.
    fn read_steps<T: H5Type + Clone>(&self, name: &str) -> Result<Vec<T>, OutputError> {
        let ds = self.dataset(name)?;
        locate(name, 0..self.steps, |rows| {
            let a = ds.read_slice_1d::<T, _>(rows).at(&self.path, name)?;
            Ok(a.iter().cloned().collect())
        })
    }

    fn read_step_rows<const N: usize>(
        &self,
        name: &str,
        step: usize,
    ) -> Result<Vec<[f64; N]>, OutputError> {
        self.check_step(step)?;
        let ds = self.dataset(name)?;
        let a = at_step(
            ds.read_slice_2d::<f64, _>((step, .., ..))
                .at(&self.path, name),
            step,
        )?;
        Ok(to_rows(&a.iter().copied().collect::<Vec<_>>()))
    }

    fn read_step_values<T: H5Type + Clone>(
        &self,
        name: &str,
        step: usize,
    ) -> Result<Vec<T>, OutputError> {
        self.check_step(step)?;
        let ds = self.dataset(name)?;
        let a = at_step(
            ds.read_slice_1d::<T, _>((step, ..)).at(&self.path, name),
            step,
        )?;
        Ok(a.iter().cloned().collect())
    }

    fn str_attr(&self, loc: &hdf5::Location, name: &str) -> Result<String, OutputError> {
        let attr = loc.attr(name).map_err(|_| OutputError::Missing {
            file: self.path.clone(),
            what: "attribute",
            name: name.to_string(),
        })?;
        let v = attr
            .read_scalar::<VarLenUnicode>()
            .at(&self.path, &format!("attribute {name}"))?;
        Ok(v.as_str().to_string())
    }

    fn num_attr<T: H5Type>(&self, loc: &hdf5::Location, name: &str) -> Result<T, OutputError> {
        let attr = loc.attr(name).map_err(|_| OutputError::Missing {
            file: self.path.clone(),
            what: "attribute",
            name: name.to_string(),
        })?;
        attr.read_scalar::<T>()
            .at(&self.path, &format!("attribute {name}"))
    }

    /// The file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Number of complete steps (the length of `/results/time`).
    pub fn num_steps(&self) -> usize {
        self.steps
    }

    pub fn num_nodes(&self) -> usize {
        self.nodes
    }

    pub fn num_elements(&self) -> usize {
        self.elements
    }

    /// The time of each step.
    pub fn time(&self) -> Result<Vec<f64>, OutputError> {
        self.read_steps(layout::TIME)
    }

    pub fn displacement(&self, step: usize) -> Result<Vec<[f64; 3]>, OutputError> {
        self.read_step_rows(layout::DISPLACEMENT, step)
    }

    /// Element-averaged Cauchy stress, order xx yy zz xy yz zx, global element order.
    pub fn stress(&self, step: usize) -> Result<Vec<[f64; 6]>, OutputError> {
        self.read_step_rows(layout::STRESS, step)
    }

    pub fn reaction(&self, step: usize) -> Result<Vec<[f64; 3]>, OutputError> {
        self.read_step_rows(layout::REACTION, step)
    }

    pub fn contact_force(&self, step: usize) -> Result<Vec<[f64; 3]>, OutputError> {
        self.read_step_rows(layout::CONTACT_FORCE, step)
    }

    /// 0 free, 1 stick, 2 slip, 3 released this step.
    pub fn contact_status(&self, step: usize) -> Result<Vec<u8>, OutputError> {
        self.read_step_values(layout::CONTACT_STATUS, step)
    }

    pub fn gap(&self, step: usize) -> Result<Vec<f64>, OutputError> {
        self.read_step_values(layout::CONTACT_GAP, step)
    }

    /// Whether the file has the nodal contact pressure (files written before it was recorded
    /// have not).
    pub fn has_contact_pressure(&self) -> bool {
        self.hdf5().link_exists(layout::CONTACT_PRESSURE)
    }

    /// Nodal contact pressure at `step` (compressive > 0, zero where not in contact);
    /// `None` for a file written before the pressure was recorded (no such dataset).
    pub fn contact_pressure(&self, step: usize) -> Result<Option<Vec<f64>>, OutputError> {
        if !self.has_contact_pressure() {
            self.check_step(step)?;
            return Ok(None);
        }
        self.read_step_values(layout::CONTACT_PRESSURE, step)
            .map(Some)
    }

    /// Element-mean equivalent plastic strain at `step`, global element order; `None` when
    /// the scene has no plastic body (the file has no such dataset).
    pub fn plastic_strain(&self, step: usize) -> Result<Option<Vec<f64>>, OutputError> {
        if !self.hdf5().link_exists(layout::PLASTIC_STRAIN) {
            return Ok(None);
        }
        self.read_step_values(layout::PLASTIC_STRAIN, step)
            .map(Some)
    }

    /// The solver statistics of every step.
    pub fn stats(&self) -> Result<Vec<StepStats>, OutputError> {
        let cg = self.read_steps::<u64>(layout::STATS_CG_ITERATIONS)?;
        let cu = self.read_steps::<u64>(layout::STATS_CONTACT_UPDATES)?;
        let res = self.read_steps::<f64>(layout::STATS_RESIDUAL)?;
        let wall = self.read_steps::<f64>(layout::STATS_WALL_TIME)?;
        let cut = self.read_steps::<u64>(layout::STATS_CUTBACKS)?;
        let active = self.read_steps::<u64>(layout::STATS_CONTACT_ACTIVE)?;
        let stick = self.read_steps::<u64>(layout::STATS_CONTACT_STICK)?;
        let slip = self.read_steps::<u64>(layout::STATS_CONTACT_SLIP)?;
        let released = self.read_steps::<u64>(layout::STATS_CONTACT_RELEASED)?;
        let pen = self.read_steps::<f64>(layout::STATS_MAX_PENETRATION)?;
        Ok((0..self.steps)
            .map(|i| StepStats {
                cg_iterations: cg[i],
                contact_updates: cu[i],
                residual: res[i],
                wall_time: wall[i],
                cutbacks: cut[i],
                contact_active: active[i],
                contact_stick: stick[i],
                contact_slip: slip[i],
                contact_released: released[i],
                max_penetration: pen[i],
            })
            .collect())
    }

    /// The owning rank of each element.
    pub fn element_rank(&self) -> Result<Vec<u32>, OutputError> {
        self.read_all(layout::ELEMENT_RANK)
    }

    /// The mesh, bodies and sets in the order they were written.
    pub fn mesh(&self) -> Result<OutputMesh, OutputError> {
        let coordinates = to_rows(&self.read_all::<f64>(layout::COORDINATES)?);
        let node_ids = self.read_all::<u64>(layout::NODE_IDS)?;
        let mesh_group = self.file.group("/mesh").at(&self.path, "/mesh")?;
        let mut bodies = Vec::new();
        for g in mesh_group.groups().at(&self.path, "/mesh")? {
            let gname = g.name();
            let name = gname.rsplit('/').next().unwrap_or_default().to_string();
            if layout::RESERVED_MESH_NAMES.contains(&name.as_str()) {
                continue;
            }
            let index = self.num_attr::<u64>(&g, layout::BODY_INDEX_ATTR)?;
            let conn = layout::body_connectivity(&name);
            let shape = self.shape(&conn)?;
            let nodes_per_element = match shape[..] {
                [_, k] if super::cells::xdmf_topology(k).is_some() => k,
                _ => return Err(self.shape_error(&conn, &shape, "[elements, 8 or 10]")),
            };
            let connectivity = ElementNodes {
                nodes_per_element,
                flat: self.read_all::<u64>(&conn)?,
            };
            let element_ids = self.read_all::<u64>(&layout::body_element_ids(&name))?;
            bodies.push((
                index,
                OutputBody {
                    name,
                    connectivity,
                    element_ids,
                },
            ));
        }
        bodies.sort_by_key(|(i, _)| *i);
        let node_sets = self
            .sets(layout::NODE_SETS)?
            .into_iter()
            .map(|(name, ds)| {
                Ok((
                    name,
                    ds.read_raw::<u64>().at(&self.path, layout::NODE_SETS)?,
                ))
            })
            .collect::<Result<Vec<_>, OutputError>>()?;
        let side_sets = self
            .sets(layout::SIDE_SETS)?
            .into_iter()
            .map(|(name, ds)| {
                let raw = ds.read_raw::<u64>().at(&self.path, layout::SIDE_SETS)?;
                let faces = to_rows::<u64, 2>(&raw)
                    .into_iter()
                    .map(|[e, f]| (e, f as u8))
                    .collect();
                Ok((name, faces))
            })
            .collect::<Result<Vec<_>, OutputError>>()?;
        Ok(OutputMesh {
            coordinates,
            node_ids,
            bodies: bodies.into_iter().map(|(_, b)| b).collect(),
            node_sets,
            side_sets,
        })
    }

    /// The datasets of a set group, in their written order.
    fn sets(&self, group: &str) -> Result<Vec<(String, hdf5::Dataset)>, OutputError> {
        let Ok(g) = self.file.group(group) else {
            return Ok(Vec::new());
        };
        let mut sets = Vec::new();
        for ds in g.datasets().at(&self.path, group)? {
            let full = ds.name();
            let name = full.rsplit('/').next().unwrap_or_default().to_string();
            let index = self
                .num_attr::<u64>(&ds, layout::SET_INDEX_ATTR)
                .unwrap_or(u64::MAX);
            sets.push((index, name, ds));
        }
        sets.sort_by(|a, b| (a.0, &a.1).cmp(&(b.0, &b.1)));
        Ok(sets.into_iter().map(|(_, n, d)| (n, d)).collect())
    }

    /// The 1-based node ids of a node set, `None` if the file has no such set.
    pub fn node_set(&self, name: &str) -> Result<Option<Vec<u64>>, OutputError> {
        let path = layout::node_set(name);
        match self.file.dataset(&path) {
            Ok(ds) => Ok(Some(ds.read_raw::<u64>().at(&self.path, &path)?)),
            Err(_) => Ok(None),
        }
    }

    /// The names of the node sets.
    pub fn node_set_names(&self) -> Result<Vec<String>, OutputError> {
        Ok(self
            .sets(layout::NODE_SETS)?
            .into_iter()
            .map(|(n, _)| n)
            .collect())
    }

    /// The root attributes.
    pub fn attributes(&self) -> Result<FileAttributes, OutputError> {
        let root: &hdf5::Location = &self.file;
        Ok(FileAttributes {
            format_version: self.num_attr(root, layout::ATTR_FORMAT_VERSION)?,
            solver_version: self.str_attr(root, layout::ATTR_SOLVER_VERSION)?,
            ranks: self.num_attr(root, layout::ATTR_RANKS)?,
            scene_text: self.str_attr(root, layout::ATTR_SCENE)?,
            scene_name: self.str_attr(root, layout::ATTR_SCENE_NAME)?,
            units: self.str_attr(root, layout::ATTR_UNITS)?,
            start_time: self.str_attr(root, layout::ATTR_START_TIME)?,
            wall_time: match root.attr(layout::ATTR_WALL_TIME) {
                Ok(_) => Some(self.num_attr(root, layout::ATTR_WALL_TIME)?),
                Err(_) => None,
            },
            exit_status: self.str_attr(root, layout::ATTR_EXIT_STATUS)?,
        })
    }

    /// The names of the root attributes.
    pub fn attribute_names(&self) -> Vec<String> {
        let mut names = self.file.attr_names().unwrap_or_default();
        names.sort();
        names
    }

    /// The full path of every dataset in the file, sorted.
    pub fn dataset_names(&self) -> Vec<String> {
        fn visit(g: &hdf5::Group, out: &mut Vec<String>) {
            for ds in g.datasets().unwrap_or_default() {
                out.push(ds.name());
            }
            for sub in g.groups().unwrap_or_default() {
                visit(&sub, out);
            }
        }
        let mut out = Vec::new();
        visit(&self.file, &mut out);
        out.sort();
        out
    }

    /// The shape of any dataset.
    pub fn shape(&self, name: &str) -> Result<Vec<usize>, OutputError> {
        Ok(self.dataset(name)?.shape())
    }

    /// The number kind of a dataset, `None` if it does not hold plain numbers.
    pub fn numeric_kind(&self, name: &str) -> Result<Option<NumericKind>, OutputError> {
        let ds = self.dataset(name)?;
        let desc = ds
            .dtype()
            .and_then(|t| t.to_descriptor())
            .at(&self.path, name)?;
        Ok(match desc {
            TypeDescriptor::Float(_) => Some(NumericKind::Float),
            TypeDescriptor::Unsigned(_) | TypeDescriptor::Boolean => Some(NumericKind::Unsigned),
            TypeDescriptor::Integer(_) => Some(NumericKind::Signed),
            _ => None,
        })
    }

    /// Rows `rows` along the first axis of a numeric dataset of one to three dimensions, as a
    /// flat vector in row-major order (a scalar dataset is one row).
    pub fn read_numeric_rows(
        &self,
        name: &str,
        rows: Range<usize>,
    ) -> Result<NumericData, OutputError> {
        let kind = self
            .numeric_kind(name)?
            .ok_or_else(|| OutputError::Invalid {
                file: self.path.clone(),
                dataset: name.to_string(),
                message: "not a numeric dataset".into(),
            })?;
        Ok(match kind {
            NumericKind::Float => NumericData::Float(self.rows::<f64>(name, rows)?),
            NumericKind::Unsigned => NumericData::Unsigned(self.rows::<u64>(name, rows)?),
            NumericKind::Signed => NumericData::Signed(self.rows::<i64>(name, rows)?),
        })
    }

    fn rows<T: H5Type + Clone>(
        &self,
        name: &str,
        rows: Range<usize>,
    ) -> Result<Vec<T>, OutputError> {
        let ds = self.dataset(name)?;
        let p = &self.path;
        match ds.ndim() {
            0 => Ok(vec![ds.read_scalar::<T>().at(p, name)?]),
            1 => locate(name, rows, |r| {
                Ok(ds
                    .read_slice_1d::<T, _>(r)
                    .at(p, name)?
                    .iter()
                    .cloned()
                    .collect())
            }),
            2 => locate(name, rows, |r| {
                Ok(ds
                    .read_slice_2d::<T, _>((r, ..))
                    .at(p, name)?
                    .iter()
                    .cloned()
                    .collect())
            }),
            3 => {
                let mut out = Vec::new();
                for i in rows {
                    let a = ds.read_slice_2d::<T, _>((i, .., ..)).at(p, name);
                    let a = if super::integrity::is_per_step(name) {
                        at_step(a, i)?
                    } else {
                        a?
                    };
                    out.extend(a.iter().cloned());
                }
                Ok(out)
            }
            n => Err(OutputError::Invalid {
                file: p.clone(),
                dataset: name.to_string(),
                message: format!("{n}-dimensional datasets are not supported"),
            }),
        }
    }
}

/// Groups a flat row-major vector into rows of `N`.
pub(super) fn to_rows<T: Copy + Default, const N: usize>(flat: &[T]) -> Vec<[T; N]> {
    flat.chunks_exact(N)
        .map(|c| {
            let mut row = [T::default(); N];
            row.copy_from_slice(c);
            row
        })
        .collect()
}

/// Opens `path` as an HDF5 file, telling a missing file, a directory, an empty file, a file
/// that is not HDF5 and a truncated or corrupt one apart.
fn open_hdf5(path: &Path) -> Result<hdf5::File, OutputError> {
    let file_err = |reason: String| OutputError::NotHdf5 {
        file: path.to_path_buf(),
        reason,
    };
    let meta = match std::fs::metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(OutputError::NotFound {
                file: path.to_path_buf(),
            })
        }
        Err(source) => {
            return Err(OutputError::Io {
                file: path.to_path_buf(),
                action: "reading the file".into(),
                source,
            })
        }
    };
    if meta.is_dir() {
        return Err(file_err("it is a directory".into()));
    }
    if meta.len() == 0 {
        return Err(file_err("the file is empty".into()));
    }
    match super::open::open(path) {
        Ok(f) => Ok(f),
        Err(e) => {
            let e = e.to_string();
            Err(match has_hdf5_signature(path) {
                Ok(true) => OutputError::Corrupt {
                    file: path.to_path_buf(),
                    message: e,
                },
                Ok(false) => file_err("no HDF5 signature".into()),
                Err(source) => OutputError::Io {
                    file: path.to_path_buf(),
                    action: "reading the file".into(),
                    source,
                },
            })
        }
    }
}
