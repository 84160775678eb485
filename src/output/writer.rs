//! [`ResultWriter`]: writes one result file per run, step by step, on rank 0.

use std::path::{Path, PathBuf};

use hdf5::types::VarLenUnicode;
use hdf5::H5Type;

use super::data::{check_finite, OutputMesh, RestartState, RunInfo, StepOutput};
use super::error::{Hdf5Context, OutputError};
use super::layout::{self, ResultPaths};
use super::xdmf::XdmfDescription;

/// Values per chunk along the node/element axis of the per-step datasets (one step per chunk).
const CHUNK_ROWS: usize = 1 << 15;

/// The per-step datasets, kept open while the run goes on.
struct StepDatasets {
    time: hdf5::Dataset,
    displacement: hdf5::Dataset,
    stress: hdf5::Dataset,
    reaction: hdf5::Dataset,
    contact_force: hdf5::Dataset,
    contact_status: hdf5::Dataset,
    contact_gap: hdf5::Dataset,
    cg_iterations: hdf5::Dataset,
    contact_updates: hdf5::Dataset,
    residual: hdf5::Dataset,
    wall_time: hdf5::Dataset,
    cutbacks: hdf5::Dataset,
    contact_active: hdf5::Dataset,
    contact_stick: hdf5::Dataset,
    contact_slip: hdf5::Dataset,
    contact_released: hdf5::Dataset,
    max_penetration: hdf5::Dataset,
}

/// Writes a result file: created with the mesh and run metadata, one [`StepOutput`] appended
/// per finished step (flushed each time), then [`finish`](Self::finish)ed or
/// [`finish_failed`](Self::finish_failed).
///
/// While the run goes on the file is `<path>.tmp`; `finish` renames it to `<path>`,
/// `finish_failed` to `<stem>.failed.h5`. A run that dies without either leaves the `.tmp`
/// file with every finished step readable.
pub struct ResultWriter {
    paths: ResultPaths,
    file: hdf5::File,
    datasets: StepDatasets,
    node_ids: Vec<u64>,
    elements: usize,
    times: Vec<f64>,
    /// The restart datasets once written: displacement, previous displacement, contact,
    /// released, state.
    restart: Option<[hdf5::Dataset; 5]>,
}

fn str_value(file: &Path, name: &str, value: &str) -> Result<VarLenUnicode, OutputError> {
    value.parse().map_err(|_| OutputError::Invalid {
        file: file.to_path_buf(),
        dataset: format!("attribute {name}"),
        message: "text contains a NUL character".into(),
    })
}

/// Creates or overwrites a string attribute.
fn set_str_attr(
    file: &Path,
    loc: &hdf5::Location,
    name: &str,
    value: &str,
) -> Result<(), OutputError> {
    let v = str_value(file, name, value)?;
    let what = format!("attribute {name}");
    let attr = match loc.attr(name) {
        Ok(a) => a,
        Err(_) => loc
            .new_attr::<VarLenUnicode>()
            .shape(())
            .create(name)
            .at(file, &what)?,
    };
    attr.write_scalar(&v).at(file, &what)
}

/// Creates or overwrites a numeric scalar attribute.
fn set_attr<T: H5Type>(
    file: &Path,
    loc: &hdf5::Location,
    name: &str,
    value: T,
) -> Result<(), OutputError> {
    let what = format!("attribute {name}");
    let attr = match loc.attr(name) {
        Ok(a) => a,
        Err(_) => loc.new_attr::<T>().shape(()).create(name).at(file, &what)?,
    };
    attr.write_scalar(&value).at(file, &what)
}

fn remove_if_present(path: &Path) -> Result<(), OutputError> {
    match std::fs::remove_file(path) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(source) => Err(OutputError::Io {
            file: path.to_path_buf(),
            action: "removing a stale file of an earlier run".into(),
            source,
        }),
    }
}

/// A fixed-size dataset holding `rows` rows of `N` values.
fn write_rows<T: H5Type, const N: usize>(
    file: &hdf5::File,
    path: &Path,
    name: &str,
    rows: &[[T; N]],
) -> Result<hdf5::Dataset, OutputError> {
    file.new_dataset_builder()
        .with_data::<_, T, _>(rows)
        .create(name)
        .at(path, name)
}

/// A fixed-size one-dimensional dataset.
fn write_vec<T: H5Type>(
    file: &hdf5::File,
    path: &Path,
    name: &str,
    values: &[T],
) -> Result<hdf5::Dataset, OutputError> {
    file.new_dataset_builder()
        .with_data(values)
        .create(name)
        .at(path, name)
}

/// An empty dataset of shape `[0, inner...]`, resizable along the first (step) axis.
fn step_dataset<T: H5Type>(
    file: &hdf5::File,
    path: &Path,
    name: &str,
    inner: &[usize],
) -> Result<hdf5::Dataset, OutputError> {
    let b = file.new_dataset::<T>();
    let ds = match *inner {
        [] => b.chunk((64,)).shape((0..,)).create(name),
        [n] => b
            .chunk((1, n.clamp(1, CHUNK_ROWS)))
            .shape((0.., n))
            .create(name),
        [n, c] => b
            .chunk((1, n.clamp(1, CHUNK_ROWS), c))
            .shape((0.., n, c))
            .create(name),
        _ => unreachable!("per-step datasets have at most two inner axes"),
    };
    ds.at(path, name)
}

impl StepDatasets {
    fn create(
        file: &hdf5::File,
        path: &Path,
        nodes: usize,
        elements: usize,
    ) -> Result<Self, OutputError> {
        Ok(StepDatasets {
            time: step_dataset::<f64>(file, path, layout::TIME, &[])?,
            displacement: step_dataset::<f64>(file, path, layout::DISPLACEMENT, &[nodes, 3])?,
            stress: step_dataset::<f64>(file, path, layout::STRESS, &[elements, 6])?,
            reaction: step_dataset::<f64>(file, path, layout::REACTION, &[nodes, 3])?,
            contact_force: step_dataset::<f64>(file, path, layout::CONTACT_FORCE, &[nodes, 3])?,
            contact_status: step_dataset::<u8>(file, path, layout::CONTACT_STATUS, &[nodes])?,
            contact_gap: step_dataset::<f64>(file, path, layout::CONTACT_GAP, &[nodes])?,
            cg_iterations: step_dataset::<u64>(file, path, layout::STATS_CG_ITERATIONS, &[])?,
            contact_updates: step_dataset::<u64>(file, path, layout::STATS_CONTACT_UPDATES, &[])?,
            residual: step_dataset::<f64>(file, path, layout::STATS_RESIDUAL, &[])?,
            wall_time: step_dataset::<f64>(file, path, layout::STATS_WALL_TIME, &[])?,
            cutbacks: step_dataset::<u64>(file, path, layout::STATS_CUTBACKS, &[])?,
            contact_active: step_dataset::<u64>(file, path, layout::STATS_CONTACT_ACTIVE, &[])?,
            contact_stick: step_dataset::<u64>(file, path, layout::STATS_CONTACT_STICK, &[])?,
            contact_slip: step_dataset::<u64>(file, path, layout::STATS_CONTACT_SLIP, &[])?,
            contact_released: step_dataset::<u64>(file, path, layout::STATS_CONTACT_RELEASED, &[])?,
            max_penetration: step_dataset::<f64>(file, path, layout::STATS_MAX_PENETRATION, &[])?,
        })
    }
}

fn append_scalar<T: H5Type>(
    ds: &hdf5::Dataset,
    path: &Path,
    name: &str,
    step: usize,
    value: T,
) -> Result<(), OutputError> {
    ds.resize((step + 1,)).at(path, name)?;
    ds.write_slice(&[value][..], step..step + 1).at(path, name)
}

fn append_per_item<T: H5Type>(
    ds: &hdf5::Dataset,
    path: &Path,
    name: &str,
    step: usize,
    values: &[T],
) -> Result<(), OutputError> {
    ds.resize((step + 1, values.len())).at(path, name)?;
    ds.write_slice(values, (step, ..)).at(path, name)
}

fn append_rows<const N: usize>(
    ds: &hdf5::Dataset,
    path: &Path,
    name: &str,
    step: usize,
    rows: &[[f64; N]],
) -> Result<(), OutputError> {
    ds.resize((step + 1, rows.len(), N)).at(path, name)?;
    ds.write_slice::<_, f64, _, _>(rows, (step, .., ..))
        .at(path, name)
}

impl ResultWriter {
    /// Creates `<path>.tmp` with the mesh, the partition and the run's attributes.
    ///
    /// Files an earlier run left under this run's names (`<path>`, `<stem>.xmf`,
    /// `<stem>.failed.h5`, `<stem>.failed.xmf`) are removed first, so that none of them can
    /// be mistaken for this run's result.
    pub fn create(path: &Path, info: &RunInfo, mesh: &OutputMesh) -> Result<Self, OutputError> {
        let paths = ResultPaths::new(path);
        let tmp = paths.tmp.clone();
        mesh.validate(&tmp)?;
        let elements = mesh.num_elements();
        let invalid = |dataset: &str, message: String| OutputError::Invalid {
            file: tmp.clone(),
            dataset: dataset.into(),
            message,
        };
        if mesh.coordinates.is_empty() || elements == 0 {
            return Err(invalid(
                "/mesh",
                format!(
                    "a result needs nodes and elements ({} nodes, {elements} elements)",
                    mesh.coordinates.len()
                ),
            ));
        }
        if info.element_rank.len() != elements {
            return Err(invalid(
                layout::ELEMENT_RANK,
                format!("{} ranks for {elements} elements", info.element_rank.len()),
            ));
        }
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            if !dir.is_dir() {
                return Err(OutputError::Io {
                    file: path.to_path_buf(),
                    action: "creating the result file".into(),
                    source: std::io::Error::new(
                        std::io::ErrorKind::NotFound,
                        format!("directory {} does not exist", dir.display()),
                    ),
                });
            }
        }
        for stale in [
            &paths.result,
            &paths.xdmf,
            &paths.failed,
            &paths.failed_xdmf,
        ] {
            remove_if_present(stale)?;
        }

        let file = super::open::create(&tmp).at(&tmp, "/ (creating the file)")?;
        let root: &hdf5::Location = &file;
        set_attr(
            &tmp,
            root,
            layout::ATTR_FORMAT_VERSION,
            layout::FORMAT_VERSION,
        )?;
        set_str_attr(
            &tmp,
            root,
            layout::ATTR_SOLVER_VERSION,
            &info.solver_version,
        )?;
        set_attr(&tmp, root, layout::ATTR_RANKS, info.ranks)?;
        set_str_attr(&tmp, root, layout::ATTR_SCENE, &info.scene_text)?;
        set_str_attr(&tmp, root, layout::ATTR_SCENE_NAME, &info.scene_name)?;
        set_str_attr(&tmp, root, layout::ATTR_UNITS, layout::UNITS_NOTE)?;
        set_str_attr(&tmp, root, layout::ATTR_START_TIME, &info.start_time)?;
        set_str_attr(&tmp, root, layout::ATTR_EXIT_STATUS, layout::STATUS_RUNNING)?;

        write_rows(&file, &tmp, layout::COORDINATES, &mesh.coordinates)?;
        write_vec(&file, &tmp, layout::NODE_IDS, &mesh.node_ids)?;
        let mut first = 0u64;
        for (i, body) in mesh.bodies.iter().enumerate() {
            write_rows(
                &file,
                &tmp,
                &layout::body_connectivity(&body.name),
                &body.connectivity,
            )?;
            write_vec(
                &file,
                &tmp,
                &layout::body_element_ids(&body.name),
                &body.element_ids,
            )?;
            let gname = layout::body_group(&body.name);
            let group = file.group(&gname).at(&tmp, &gname)?;
            set_attr(&tmp, &group, layout::BODY_INDEX_ATTR, i as u64)?;
            set_attr(&tmp, &group, layout::FIRST_ELEMENT_ATTR, first)?;
            first += body.connectivity.len() as u64;
        }
        write_rows(
            &file,
            &tmp,
            layout::ALL_CONNECTIVITY,
            &mesh.all_connectivity(),
        )?;
        for name in [layout::NODE_SETS, layout::SIDE_SETS] {
            file.create_group(name).at(&tmp, name)?;
        }
        for (i, (name, ids)) in mesh.node_sets.iter().enumerate() {
            let ds = write_vec(&file, &tmp, &layout::node_set(name), ids)?;
            set_attr(&tmp, &ds, layout::SET_INDEX_ATTR, i as u64)?;
        }
        for (i, (name, faces)) in mesh.side_sets.iter().enumerate() {
            let rows: Vec<[u64; 2]> = faces.iter().map(|&(e, f)| [e, u64::from(f)]).collect();
            let ds = write_rows(&file, &tmp, &layout::side_set(name), &rows)?;
            set_attr(&tmp, &ds, layout::SET_INDEX_ATTR, i as u64)?;
        }
        write_vec(&file, &tmp, layout::ELEMENT_RANK, &info.element_rank)?;

        let datasets = StepDatasets::create(&file, &tmp, mesh.coordinates.len(), elements)?;
        file.flush().at(&tmp, "/ (flush)")?;
        Ok(ResultWriter {
            paths,
            file,
            datasets,
            node_ids: mesh.node_ids.clone(),
            elements,
            times: Vec::new(),
            restart: None,
        })
    }

    /// The file being written (`<path>.tmp`).
    pub fn tmp_path(&self) -> &Path {
        &self.paths.tmp
    }

    /// Number of steps appended so far.
    pub fn steps(&self) -> usize {
        self.times.len()
    }

    /// Appends one finished step and flushes the file.
    ///
    /// Refuses (and writes nothing of the step) when a length does not match the mesh or a
    /// value is NaN or infinite; the error names the dataset and the node or element.
    pub fn append_step(&mut self, step: &StepOutput) -> Result<(), OutputError> {
        let p = self.paths.tmp.as_path();
        step.validate(p, &self.node_ids, self.elements)?;
        let i = self.times.len();
        let d = &self.datasets;
        append_rows(
            &d.displacement,
            p,
            layout::DISPLACEMENT,
            i,
            &step.displacement,
        )?;
        append_rows(&d.stress, p, layout::STRESS, i, &step.stress)?;
        append_rows(&d.reaction, p, layout::REACTION, i, &step.reaction)?;
        append_rows(
            &d.contact_force,
            p,
            layout::CONTACT_FORCE,
            i,
            &step.contact_force,
        )?;
        append_per_item(
            &d.contact_status,
            p,
            layout::CONTACT_STATUS,
            i,
            &step.contact_status,
        )?;
        append_per_item(&d.contact_gap, p, layout::CONTACT_GAP, i, &step.contact_gap)?;
        let s = &step.stats;
        append_scalar(
            &d.cg_iterations,
            p,
            layout::STATS_CG_ITERATIONS,
            i,
            s.cg_iterations,
        )?;
        append_scalar(
            &d.contact_updates,
            p,
            layout::STATS_CONTACT_UPDATES,
            i,
            s.contact_updates,
        )?;
        append_scalar(&d.residual, p, layout::STATS_RESIDUAL, i, s.residual)?;
        append_scalar(&d.wall_time, p, layout::STATS_WALL_TIME, i, s.wall_time)?;
        append_scalar(&d.cutbacks, p, layout::STATS_CUTBACKS, i, s.cutbacks)?;
        let contact_counts = [
            (
                &d.contact_active,
                layout::STATS_CONTACT_ACTIVE,
                s.contact_active,
            ),
            (
                &d.contact_stick,
                layout::STATS_CONTACT_STICK,
                s.contact_stick,
            ),
            (&d.contact_slip, layout::STATS_CONTACT_SLIP, s.contact_slip),
            (
                &d.contact_released,
                layout::STATS_CONTACT_RELEASED,
                s.contact_released,
            ),
        ];
        for (ds, name, value) in contact_counts {
            append_scalar(ds, p, name, i, value)?;
        }
        append_scalar(
            &d.max_penetration,
            p,
            layout::STATS_MAX_PENETRATION,
            i,
            s.max_penetration,
        )?;
        // The time goes last: its length is the number of complete steps.
        append_scalar(&d.time, p, layout::TIME, i, step.time)?;
        self.file.flush().at(p, "/ (flush)")?;
        self.times.push(step.time);
        Ok(())
    }

    /// Records the state the run can resume from after the step just appended (flushed).
    /// The small `state` dataset is written last, so it always describes complete arrays.
    pub fn write_restart(&mut self, r: &RestartState) -> Result<(), OutputError> {
        let p = self.paths.tmp.clone();
        let p = &p;
        let n = r.displacement.len();
        if self.restart.is_none() {
            let f = &self.file;
            f.create_group("/restart").at(p, "/restart")?;
            let fixed = |name: &str| {
                f.new_dataset::<f64>()
                    .shape((n, 3))
                    .create(name)
                    .at(p, name)
            };
            let grow = |name: &str| {
                f.new_dataset::<f64>()
                    .chunk((1024,))
                    .shape((0..,))
                    .create(name)
                    .at(p, name)
            };
            self.restart = Some([
                fixed(layout::RESTART_DISPLACEMENT)?,
                fixed(layout::RESTART_PREVIOUS_DISPLACEMENT)?,
                grow(layout::RESTART_CONTACT)?,
                grow(layout::RESTART_RELEASED)?,
                f.new_dataset::<f64>()
                    .shape((5,))
                    .create(layout::RESTART_STATE)
                    .at(p, layout::RESTART_STATE)?,
            ]);
        }
        let [u, up, contact, released, state] = self.restart.as_ref().expect("created above");
        for (ds, name, v) in [
            (contact, layout::RESTART_CONTACT, &r.contact),
            (released, layout::RESTART_RELEASED, &r.released),
        ] {
            ds.resize((v.len(),)).at(p, name)?;
            ds.write_raw(v).at(p, name)?;
        }
        for (ds, name, v) in [
            (u, layout::RESTART_DISPLACEMENT, &r.displacement),
            (
                up,
                layout::RESTART_PREVIOUS_DISPLACEMENT,
                &r.previous_displacement,
            ),
        ] {
            let flat: Vec<f64> = v.iter().flatten().copied().collect();
            ds.write_raw(&flat).at(p, name)?;
        }
        let head = [
            r.step as f64,
            r.time,
            r.dt_prev,
            r.reference_floor,
            r.rows as f64,
        ];
        state.write_raw(&head).at(p, layout::RESTART_STATE)?;
        self.file.flush().at(p, "/ (flush)")
    }

    /// Writes the closing attributes and closes the file.
    fn close(
        self,
        wall_time: f64,
        status: &str,
    ) -> Result<(ResultPaths, Vec<f64>, usize, usize), OutputError> {
        let p = self.paths.tmp.clone();
        check_finite(
            &p,
            &format!("attribute {}", layout::ATTR_WALL_TIME),
            &[wall_time],
            |_| "the run's wall time".into(),
        )?;
        let root: &hdf5::Location = &self.file;
        set_attr(&p, root, layout::ATTR_WALL_TIME, wall_time)?;
        set_str_attr(&p, root, layout::ATTR_EXIT_STATUS, status)?;
        self.file.flush().at(&p, "/ (flush)")?;
        let nodes = self.node_ids.len();
        let ResultWriter {
            paths,
            file,
            datasets,
            times,
            elements,
            restart,
            ..
        } = self;
        drop(datasets);
        drop(restart);
        file.close().at(&p, "/ (closing the file)")?;
        Ok((paths, times, nodes, elements))
    }

    fn publish(
        tmp: &Path,
        target: &Path,
        xdmf: &Path,
        times: &[f64],
        nodes: usize,
        elements: usize,
    ) -> Result<(), OutputError> {
        std::fs::rename(tmp, target).map_err(|source| OutputError::Io {
            file: tmp.to_path_buf(),
            action: format!("renaming to {}", target.display()),
            source,
        })?;
        let h5_name = target
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let text = XdmfDescription {
            h5_name: &h5_name,
            nodes,
            elements,
            times,
        }
        .render();
        std::fs::write(xdmf, text).map_err(|source| OutputError::Io {
            file: xdmf.to_path_buf(),
            action: "writing the XDMF file".into(),
            source,
        })
    }

    /// Completes the run: writes `wall_time` and `exit_status = "completed"`, renames
    /// `<path>.tmp` to `<path>`, writes `<stem>.xmf` and returns `<path>`.
    pub fn finish(self, wall_time: f64) -> Result<PathBuf, OutputError> {
        let (paths, times, nodes, elements) = self.close(wall_time, layout::STATUS_COMPLETED)?;
        Self::publish(
            &paths.tmp,
            &paths.result,
            &paths.xdmf,
            &times,
            nodes,
            elements,
        )?;
        Ok(paths.result)
    }

    /// Ends a failed run: writes `wall_time` and `exit_status = "failed: <message>"`, renames
    /// `<path>.tmp` to `<stem>.failed.h5` (never to `<path>`), writes `<stem>.failed.xmf` and
    /// returns the `.failed.h5` path. The steps that finished stay readable.
    pub fn finish_failed(self, wall_time: f64, message: &str) -> Result<PathBuf, OutputError> {
        let status = format!("{}{message}", layout::STATUS_FAILED_PREFIX).replace('\0', " ");
        let (paths, times, nodes, elements) = self.close(wall_time, &status)?;
        Self::publish(
            &paths.tmp,
            &paths.failed,
            &paths.failed_xdmf,
            &times,
            nodes,
            elements,
        )?;
        Ok(paths.failed)
    }
}
