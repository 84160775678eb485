//! Creating and appending the datasets of a result file; every dataset is chunked and
//! carries a Fletcher-32 checksum per chunk (see [`super::integrity`]).

use std::path::Path;

use hdf5::types::VarLenUnicode;
use hdf5::H5Type;

use super::data::{StepField, StepOutput, StepStats};
use super::error::{Hdf5Context, OutputError};
use super::layout;

/// Values per chunk along the node/element axis of the per-step datasets (one step per chunk):
/// a field written in parts is best cut at multiples of it (each chunk written once). HDF5
/// holds a chunk twice while it writes it (the chunk and the checksum filter's output): at
/// 4096 rows that is 0.4 MB for a step of the stress, where 32768 rows held 3.1 MB on the
/// writing rank, beside the round being written.
pub const CHUNK_ROWS: usize = 1 << 12;

/// The per-step datasets, kept open while the run goes on.
pub(super) struct StepDatasets {
    pub(super) time: hdf5::Dataset,
    pub(super) displacement: hdf5::Dataset,
    pub(super) stress: hdf5::Dataset,
    pub(super) reaction: hdf5::Dataset,
    pub(super) contact_force: hdf5::Dataset,
    pub(super) contact_status: hdf5::Dataset,
    pub(super) contact_gap: hdf5::Dataset,
    pub(super) cg_iterations: hdf5::Dataset,
    pub(super) contact_updates: hdf5::Dataset,
    pub(super) residual: hdf5::Dataset,
    pub(super) wall_time: hdf5::Dataset,
    pub(super) cutbacks: hdf5::Dataset,
    pub(super) contact_active: hdf5::Dataset,
    pub(super) contact_stick: hdf5::Dataset,
    pub(super) contact_slip: hdf5::Dataset,
    pub(super) contact_released: hdf5::Dataset,
    pub(super) max_penetration: hdf5::Dataset,
    /// Created with the first step that has a plastic strain (scenes with plastic bodies).
    pub(super) plastic_strain: Option<hdf5::Dataset>,
    /// Created with the first row when its step has a contact pressure; a file whose first
    /// row has none (a run continued from a file written before the pressure was recorded)
    /// gets none for later rows either, so that every row of the dataset is a step's.
    pub(super) contact_pressure: Option<hdf5::Dataset>,
}

fn str_value(file: &Path, name: &str, value: &str) -> Result<VarLenUnicode, OutputError> {
    value.parse().map_err(|_| OutputError::Invalid {
        file: file.to_path_buf(),
        dataset: format!("attribute {name}"),
        message: "text contains a NUL character".into(),
    })
}

/// Creates or overwrites a string attribute.
pub(super) fn set_str_attr(
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
pub(super) fn set_attr<T: H5Type>(
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

/// A fixed-size dataset holding `rows` rows of `N` values, chunked with checksums (an empty
/// one has no data to check and stays contiguous: HDF5 refuses a chunk larger than it).
pub(super) fn write_rows<T: H5Type, const N: usize>(
    file: &hdf5::File,
    path: &Path,
    name: &str,
    rows: &[[T; N]],
) -> Result<hdf5::Dataset, OutputError> {
    let b = file.new_dataset_builder();
    let b = if rows.is_empty() {
        b
    } else {
        b.chunk((rows.len().min(CHUNK_ROWS), N)).fletcher32()
    };
    b.with_data::<_, T, _>(rows).create(name).at(path, name)
}

/// A fixed-size one-dimensional dataset, chunked with checksums unless empty.
pub(super) fn write_vec<T: H5Type>(
    file: &hdf5::File,
    path: &Path,
    name: &str,
    values: &[T],
) -> Result<hdf5::Dataset, OutputError> {
    let b = file.new_dataset_builder();
    let b = if values.is_empty() {
        b
    } else {
        b.chunk((values.len().min(CHUNK_ROWS),)).fletcher32()
    };
    b.with_data(values).create(name).at(path, name)
}

/// An empty dataset of shape `[0, inner...]`, resizable along the first (step) axis; a chunk
/// holds one step (a step's values may span several chunks), so a checksum names its step.
pub(super) fn step_dataset<T: H5Type>(
    file: &hdf5::File,
    path: &Path,
    name: &str,
    inner: &[usize],
) -> Result<hdf5::Dataset, OutputError> {
    let b = file.new_dataset::<T>().fletcher32();
    let ds = match *inner {
        [] => b.chunk((1,)).shape((0..,)).create(name),
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
    pub(super) fn create(
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
            plastic_strain: None,
            contact_pressure: None,
        })
    }
}

pub(super) fn append_scalar<T: H5Type>(
    ds: &hdf5::Dataset,
    path: &Path,
    name: &str,
    step: usize,
    value: T,
) -> Result<(), OutputError> {
    ds.resize((step + 1,)).at(path, name)?;
    ds.write_slice(&[value][..], step..step + 1).at(path, name)
}

/// Writes `values` as entries `first..` of row `step` (of `total` entries) of a per-step
/// dataset of one value per entry; the row's first part makes the dataset that long.
pub(super) fn append_per_item<T: H5Type>(
    ds: &hdf5::Dataset,
    path: &Path,
    name: &str,
    (step, first, total): (usize, usize, usize),
    values: &[T],
) -> Result<(), OutputError> {
    if first == 0 {
        ds.resize((step + 1, total)).at(path, name)?;
    }
    ds.write_slice(values, (step, first..first + values.len()))
        .at(path, name)
}

/// `append_per_item` for datasets of `N` values per entry.
pub(super) fn append_rows<const N: usize>(
    ds: &hdf5::Dataset,
    path: &Path,
    name: &str,
    (step, first, total): (usize, usize, usize),
    rows: &[[f64; N]],
) -> Result<(), OutputError> {
    if first == 0 {
        ds.resize((step + 1, total, N)).at(path, name)?;
    }
    ds.write_slice::<_, f64, _, _>(rows, (step, first..first + rows.len(), ..))
        .at(path, name)
}

impl StepDatasets {
    /// Writes `step` as row `i` of every per-step dataset, the time last (its length is the
    /// number of complete steps).
    pub(super) fn append(
        &mut self,
        file: &hdf5::File,
        p: &Path,
        i: usize,
        step: &StepOutput,
    ) -> Result<(), OutputError> {
        if self.contact_pressure.is_some() && step.contact_pressure.is_empty() {
            return Err(self.no_pressure(p, i));
        }
        for f in step.fields() {
            self.append_field(file, p, i, f)?;
        }
        self.append_stats(p, i, &step.stats)?;
        append_scalar(&self.time, p, layout::TIME, i, step.time)
    }

    /// The error for row `i` without a contact pressure when the rows before have one.
    pub(super) fn no_pressure(&self, p: &Path, i: usize) -> OutputError {
        OutputError::Invalid {
            file: p.to_path_buf(),
            dataset: layout::CONTACT_PRESSURE.into(),
            message: format!("step {i} has no contact pressure, the steps before it have"),
        }
    }

    /// Writes one field as row `i` of its dataset.
    pub(super) fn append_field(
        &mut self,
        file: &hdf5::File,
        p: &Path,
        i: usize,
        field: StepField<'_>,
    ) -> Result<(), OutputError> {
        let total = field.len_per().0;
        self.append_field_part(file, p, (i, 0, total), field)
    }

    /// Writes the entries `first..` of row `i` (of `total` entries) of one field's dataset.
    /// The plastic strain's dataset is created with the first step that has one; the
    /// contact pressure's with row 0 when that step has one (see
    /// [`StepDatasets::contact_pressure`]), and later rows are dropped without it.
    pub(super) fn append_field_part(
        &mut self,
        file: &hdf5::File,
        p: &Path,
        (i, first, total): (usize, usize, usize),
        field: StepField<'_>,
    ) -> Result<(), OutputError> {
        let name = field.dataset();
        let at = (i, first, total);
        match field {
            StepField::Displacement(v) => append_rows(&self.displacement, p, name, at, v),
            StepField::Stress(v) => append_rows(&self.stress, p, name, at, v),
            StepField::Reaction(v) => append_rows(&self.reaction, p, name, at, v),
            StepField::ContactForce(v) => append_rows(&self.contact_force, p, name, at, v),
            StepField::ContactStatus(v) => append_per_item(&self.contact_status, p, name, at, v),
            StepField::ContactGap(v) => append_per_item(&self.contact_gap, p, name, at, v),
            StepField::PlasticStrain(v) => {
                if self.plastic_strain.is_none() {
                    self.plastic_strain = Some(step_dataset::<f64>(file, p, name, &[total])?);
                }
                let ds = self.plastic_strain.as_ref().expect("created");
                append_per_item(ds, p, name, at, v)
            }
            StepField::ContactPressure(v) => {
                if i == 0 && self.contact_pressure.is_none() {
                    self.contact_pressure = Some(step_dataset::<f64>(file, p, name, &[total])?);
                }
                match &self.contact_pressure {
                    Some(ds) => append_per_item(ds, p, name, at, v),
                    None => Ok(()),
                }
            }
        }
    }

    /// Writes the solver statistics of row `i`: the counts, then the real numbers.
    pub(super) fn append_stats(
        &self,
        p: &Path,
        i: usize,
        s: &StepStats,
    ) -> Result<(), OutputError> {
        let d = self;
        let counts = [
            (
                &d.cg_iterations,
                layout::STATS_CG_ITERATIONS,
                s.cg_iterations,
            ),
            (
                &d.contact_updates,
                layout::STATS_CONTACT_UPDATES,
                s.contact_updates,
            ),
            (&d.cutbacks, layout::STATS_CUTBACKS, s.cutbacks),
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
        for (ds, name, value) in counts {
            append_scalar(ds, p, name, i, value)?;
        }
        let reals = [
            (&d.residual, layout::STATS_RESIDUAL, s.residual),
            (&d.wall_time, layout::STATS_WALL_TIME, s.wall_time),
            (
                &d.max_penetration,
                layout::STATS_MAX_PENETRATION,
                s.max_penetration,
            ),
        ];
        for (ds, name, value) in reals {
            append_scalar(ds, p, name, i, value)?;
        }
        Ok(())
    }
}
