//! [`ResultWriter`]: writes one result file per run, step by step, on rank 0.

use std::path::{Path, PathBuf};

use super::data::{
    check_finite, check_stats, check_time, NodeIds, RestartState, RunInfo, StepField, StepOutput,
    StepStats,
};
use super::datasets::{set_attr, set_str_attr, StepDatasets};
use super::error::{Hdf5Context, OutputError};
use super::layout::{self, ResultPaths};
use super::lock::OutputLock;
use super::publish::Closed;
use super::restart::RestartSlots;
use super::source::MeshSource;
use super::xdmf::Topology;

/// Writes a result file: created with the mesh and run metadata, one [`StepOutput`] appended
/// per finished step (flushed each time), then [`finish`](Self::finish)ed or
/// [`finish_failed`](Self::finish_failed).
///
/// The output path is checked and locked first (see [`super::claim_output`]; a lock this
/// process holds already is shared). While the run goes on the file is a temporary file of a
/// name no other file has (`<path>.tmp`, or `<path>.2.tmp`, ... when that is taken); `finish`
/// closes it, checks it, and renames it to `<path>`, `finish_failed` to `<stem>.failed.h5`,
/// each with its XDMF file written under a temporary name first and renamed after it. A run
/// that dies without either leaves the temporary file with every finished step readable.
/// After a write fails (a full disk) nothing more is written and nothing is published.
pub struct ResultWriter {
    paths: ResultPaths,
    /// The temporary file this writer writes.
    tmp: PathBuf,
    file: hdf5::File,
    datasets: StepDatasets,
    /// Nodes of the mesh (their ids are the file's `/mesh/node_ids`, read for a message).
    nodes: usize,
    elements: usize,
    topology: Topology,
    times: Vec<f64>,
    restart: RestartSlots,
    /// The first write that failed: nothing is written or published after it.
    broken: Option<String>,
    /// The datasets written of the step begun by `write_field` and not yet ended.
    pending: Vec<&'static str>,
    /// The field `write_field_part` is writing, and the entry its next part starts at.
    part: Option<(&'static str, usize)>,
    _lock: OutputLock,
}

/// The node ids of a writer's mesh for its messages: read from the file it wrote them to,
/// one when a message names a node, instead of a copy held through the run (8 bytes per
/// node on rank 0). An id that cannot be read shows as 0 (ids are 1-based).
struct FileNodeIds<'a> {
    file: &'a hdf5::File,
    count: usize,
}

impl NodeIds for FileNodeIds<'_> {
    fn count(&self) -> usize {
        self.count
    }
    fn id(&self, i: usize) -> u64 {
        self.file
            .dataset(layout::NODE_IDS)
            .and_then(|d| d.read_slice_1d::<u64, _>(i..i + 1))
            .ok()
            .and_then(|v| v.first().copied())
            .unwrap_or(0)
    }
}

/// Whether an error means the file can no longer be trusted (a failed write), as opposed to
/// data refused before anything was written (non-finite values, wrong lengths).
fn breaks_the_file(e: &OutputError) -> bool {
    !matches!(
        e,
        OutputError::NonFinite { .. } | OutputError::Invalid { .. }
    )
}

impl ResultWriter {
    /// Checks and locks the output path, then creates a new temporary file with the mesh,
    /// the partition and the run's attributes.
    ///
    /// Files an earlier run left under this run's names stay as they are until this run
    /// publishes its own file under one of them, by renaming.
    ///
    /// The mesh is read from `mesh` a round of rows at a time (`super::header`).
    pub fn create(
        path: &Path,
        info: &RunInfo,
        mesh: &impl MeshSource,
    ) -> Result<Self, OutputError> {
        let first_tmp = ResultPaths::new(path).tmp;
        super::header::check(mesh, &first_tmp)?;
        let elements = mesh.num_elements();
        let nodes = mesh.num_nodes();
        let invalid = |dataset: &str, message: String| OutputError::Invalid {
            file: first_tmp.clone(),
            dataset: dataset.into(),
            message,
        };
        if nodes == 0 || elements == 0 {
            return Err(invalid(
                "/mesh",
                format!("a result needs nodes and elements ({nodes} nodes, {elements} elements)"),
            ));
        }
        if info.element_rank.len() != elements {
            return Err(invalid(
                layout::ELEMENT_RANK,
                format!("{} ranks for {elements} elements", info.element_rank.len()),
            ));
        }
        let (paths, lock) = super::paths::check_and_lock(path, &[], None)?;
        let (tmp, reserved) = super::paths::create_temp(&paths.result)?;
        drop(reserved);
        let created = (|| {
            let file = super::open::create(&tmp).at(&tmp, "/ (creating the file)")?;
            super::header::write(&file, &tmp, info, mesh)?;
            let datasets = StepDatasets::create(&file, &tmp, nodes, elements)?;
            file.flush().at(&tmp, "/ (flush)")?;
            Ok((file, datasets))
        })();
        let (file, datasets) = match created {
            Ok(x) => x,
            Err(e) => {
                let _ = std::fs::remove_file(&tmp);
                return Err(e);
            }
        };
        Ok(ResultWriter {
            paths,
            tmp,
            file,
            datasets,
            nodes,
            elements,
            topology: super::source::topology(&mesh.bodies()),
            times: Vec::new(),
            restart: RestartSlots::default(),
            broken: None,
            pending: Vec::new(),
            part: None,
            _lock: lock,
        })
    }

    /// The file being written (the temporary file).
    pub fn tmp_path(&self) -> &Path {
        &self.tmp
    }

    /// The names of this run's files.
    pub fn paths(&self) -> &ResultPaths {
        &self.paths
    }

    /// Number of steps appended so far.
    pub fn steps(&self) -> usize {
        self.times.len()
    }

    fn node_ids(&self) -> FileNodeIds<'_> {
        FileNodeIds {
            file: &self.file,
            count: self.nodes,
        }
    }

    /// Remembers a failed write: the file is not written to or published after it.
    fn check<T>(&mut self, r: Result<T, OutputError>) -> Result<T, OutputError> {
        if let Some(first) = &self.broken {
            return Err(OutputError::NotPublished {
                first: first.clone(),
                kept: None,
            });
        }
        if let Err(e) = &r {
            if breaks_the_file(e) {
                self.broken = Some(e.to_string());
            }
        }
        r
    }

    /// Appends one finished step and flushes the file.
    ///
    /// Refuses (and writes nothing of the step) when a length does not match the mesh or a
    /// value is NaN or infinite; the error names the dataset and the node or element.
    pub fn append_step(&mut self, step: &StepOutput) -> Result<(), OutputError> {
        let r = self.check(Ok(()));
        r?;
        let p = self.tmp.clone();
        step.validate(&p, &self.node_ids(), self.elements)?;
        let i = self.times.len();
        let r = self
            .datasets
            .append(&self.file, &p, i, step)
            .and_then(|()| self.file.flush().at(&p, "/ (flush)"));
        self.check(r)?;
        self.times.push(step.time);
        self.pending.clear();
        self.part = None;
        Ok(())
    }

    /// Writes one field of the next step (the step is complete once [`end_step`] wrote its
    /// time): rank 0 of a large run need not hold the whole step at once. Refuses a field
    /// of the wrong length or with a value that is not finite, as [`append_step`] does;
    /// fields written before a refused one stay as rows past the last complete step, which
    /// readers do not count.
    ///
    /// [`end_step`]: Self::end_step
    /// [`append_step`]: Self::append_step
    pub fn write_field(&mut self, field: StepField<'_>) -> Result<(), OutputError> {
        let r = self.check(Ok(()));
        r?;
        let p = self.tmp.clone();
        field.validate(&p, &self.node_ids(), self.elements)?;
        let i = self.times.len();
        let r = self.datasets.append_field(&self.file, &p, i, field);
        self.check(r)?;
        if self.part.is_some_and(|(d, _)| d == field.dataset()) {
            self.part = None;
        }
        self.pending.push(field.dataset());
        Ok(())
    }

    /// Writes entries `first..first + n` of one field of the next step (n the part's
    /// length), so that rank 0 need not hold even one whole field: the parts of a field come
    /// in order, from entry 0, and the field counts as written (for [`end_step`]) with its
    /// last entry. Each part's values are checked as [`write_field`] checks the whole
    /// field's, named by their entries in the whole; a part that does not start where the
    /// last one ended, or runs past the mesh, is refused.
    ///
    /// [`end_step`]: Self::end_step
    /// [`write_field`]: Self::write_field
    pub fn write_field_part(
        &mut self,
        field: StepField<'_>,
        first: usize,
    ) -> Result<(), OutputError> {
        let r = self.check(Ok(()));
        r?;
        let p = self.tmp.clone();
        let name = field.dataset();
        let (n, per_element) = field.len_per();
        let total = if per_element {
            self.elements
        } else {
            self.nodes
        };
        let next = match self.part {
            Some((d, next)) if d == name => next,
            _ => 0,
        };
        if first != next || first + n > total {
            return Err(OutputError::Invalid {
                file: p,
                dataset: name.to_string(),
                message: format!(
                    "a part of entries {first}..{} of {total}, expected one starting at {next}",
                    first + n
                ),
            });
        }
        field.validate_from(&p, &self.node_ids(), first)?;
        let i = self.times.len();
        let r = self
            .datasets
            .append_field_part(&self.file, &p, (i, first, total), field);
        self.check(r)?;
        if first + n == total {
            self.part = None;
            self.pending.push(name);
        } else {
            self.part = Some((name, first + n));
        }
        Ok(())
    }

    /// Completes the step whose fields [`write_field`](Self::write_field) wrote: its
    /// statistics, then its time, then a flush. Refused when a field is missing.
    pub fn end_step(&mut self, time: f64, stats: &StepStats) -> Result<(), OutputError> {
        let r = self.check(Ok(()));
        r?;
        let p = self.tmp.clone();
        let i = self.times.len();
        let written = std::mem::take(&mut self.pending);
        self.part = None;
        let mut required = StepField::REQUIRED.to_vec();
        if self.datasets.contact_pressure.is_some() {
            required.push(super::layout::CONTACT_PRESSURE);
        }
        if let Some(missing) = required.iter().find(|d| !written.contains(d)) {
            return Err(OutputError::Invalid {
                file: p,
                dataset: missing.to_string(),
                message: format!("step {i} was ended without this field"),
            });
        }
        check_time(&p, time)?;
        check_stats(&p, stats)?;
        let r = self
            .datasets
            .append_stats(&p, i, stats)
            .and_then(|()| {
                super::datasets::append_scalar(
                    &self.datasets.time,
                    &p,
                    super::layout::TIME,
                    i,
                    time,
                )
            })
            .and_then(|()| self.file.flush().at(&p, "/ (flush)"));
        self.check(r)?;
        self.times.push(time);
        Ok(())
    }

    /// Records the state the run can resume from after the step just appended (flushed), in
    /// the restart slot of `r.rows` (see [`super::restart`]).
    pub fn write_restart(&mut self, r: &RestartState) -> Result<(), OutputError> {
        let ok = self.check(Ok(()));
        ok?;
        let nodes = self.nodes;
        let res = self.restart.write(&self.file, &self.tmp, r, nodes);
        self.check(res)
    }

    /// Writes entries `first..` of the displacement (or, `previous`, the previous
    /// displacement) of the restart state after `rows` written steps, so that rank 0 need
    /// not hold them whole: parts in order from entry 0, then [`write_restart`] with both
    /// displacements left empty writes the rest of the state (and refuses it unless both
    /// were written whole).
    ///
    /// [`write_restart`]: Self::write_restart
    pub fn write_restart_part(
        &mut self,
        rows: u64,
        previous: bool,
        first: usize,
        part: &[[f64; 3]],
    ) -> Result<(), OutputError> {
        let ok = self.check(Ok(()));
        ok?;
        let nodes = self.nodes;
        let res =
            self.restart
                .write_part(&self.file, &self.tmp, (rows, nodes), previous, first, part);
        self.check(res)
    }

    /// Writes values `first..` of the plastic history (`total` values in all) of the restart
    /// state after `rows` written steps, so that rank 0 need not hold it whole: parts in
    /// order from value 0, then [`write_restart`] with the history left empty writes the
    /// rest of the state (and refuses it unless the history was written whole).
    ///
    /// [`write_restart`]: Self::write_restart
    pub fn write_restart_history_part(
        &mut self,
        rows: u64,
        (total, first): (usize, usize),
        part: &[f64],
    ) -> Result<(), OutputError> {
        let ok = self.check(Ok(()));
        ok?;
        let nodes = self.nodes;
        let res = self.restart.write_history_part(
            &self.file,
            &self.tmp,
            (rows, nodes),
            (total, first),
            part,
        );
        self.check(res)
    }

    /// Writes the closing attributes and closes the file.
    fn close(self, wall_time: f64, status: &str) -> Result<Closed, OutputError> {
        let p = self.tmp.clone();
        if let Some(first) = self.broken {
            drop(self.datasets);
            drop(self.file);
            return Err(super::publish::abandon(&p, first));
        }
        let written = (|| {
            check_finite(
                &p,
                &format!("attribute {}", layout::ATTR_WALL_TIME),
                &[wall_time],
                |_| "the run's wall time".into(),
            )?;
            let root: &hdf5::Location = &self.file;
            set_attr(&p, root, layout::ATTR_WALL_TIME, wall_time)?;
            set_str_attr(&p, root, layout::ATTR_EXIT_STATUS, status)?;
            self.file.flush().at(&p, "/ (flush)")
        })();
        let ResultWriter {
            paths,
            file,
            datasets,
            times,
            elements,
            topology,
            nodes,
            restart,
            _lock,
            ..
        } = self;
        let plastic = datasets.plastic_strain.is_some();
        let pressure = datasets.contact_pressure.is_some();
        drop(datasets);
        drop(restart);
        let closed = written.and_then(|()| file.close().at(&p, "/ (closing the file)"));
        if let Err(e) = closed {
            return Err(super::publish::abandon(&p, e.to_string()));
        }
        Ok(Closed {
            paths,
            tmp: p,
            times,
            nodes,
            elements,
            topology,
            plastic,
            pressure,
            _lock,
        })
    }

    /// Completes the run: writes `wall_time` and `exit_status = "completed"`, closes and
    /// checks the file, renames it to `<path>` and its XDMF file to `<stem>.xmf`; returns
    /// `<path>`.
    pub fn finish(self, wall_time: f64) -> Result<PathBuf, OutputError> {
        let c = self.close(wall_time, layout::STATUS_COMPLETED)?;
        c.publish(false)
    }

    /// Ends a failed run: writes `wall_time` and `exit_status = "failed: <message>"`, renames
    /// the file to `<stem>.failed.h5` (never to `<path>`) and its XDMF file to
    /// `<stem>.failed.xmf`; returns the `.failed.h5` path. The steps that finished stay
    /// readable.
    pub fn finish_failed(self, wall_time: f64, message: &str) -> Result<PathBuf, OutputError> {
        let status = format!("{}{message}", layout::STATUS_FAILED_PREFIX).replace('\0', " ");
        let c = self.close(wall_time, &status)?;
        c.publish(true)
    }
}
