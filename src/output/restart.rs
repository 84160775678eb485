//! The restart state in a result file: written after every written step into one of two
//! slots, read back (checked) by `solver run --restart`.
//!
//! The state after `rows` written steps goes to slot `rows % 2`: the slot of the step before
//! is never touched while a new state is written, and a slot's small `state` dataset is
//! written last, after the rest of the slot has been flushed. A run killed at any moment
//! therefore leaves one complete slot at least (once a first one was written), and the reader
//! takes the slot whose `state` records more rows.

use std::path::Path;

/// Values of a slot's `state`: step, time, last step length, reference force floor, rows,
/// whether the preconditioner had switched to multilevel (files of an earlier version have
/// the first five only).
const STATE_LEN: usize = 6;

use super::data::{check_finite, RestartState, StepOutput, StepStats};
use super::error::{Hdf5Context, OutputError};
use super::layout;
use super::reader::{to_rows, ResultFile};

/// Rows per chunk of the restart arrays (each chunk has its own checksum): the per-node
/// ones as the result file's fields (a round of the gather writes whole chunks), the plastic
/// history in 32768 values.
const CHUNK: usize = super::CHUNK_ROWS;
const HISTORY_CHUNK: usize = 1 << 15;

/// The open datasets of one slot, in [`layout::SLOT_DATASETS`] order.
struct Slot([hdf5::Dataset; 5]);

/// The two slots of the file being written.
#[derive(Default)]
pub(super) struct RestartSlots {
    slots: [Option<Slot>; 2],
    /// The state (by its rows) whose displacements `write_part` is writing, and the entries
    /// of each (the displacement, the previous one) written so far.
    parts: Option<(u64, [usize; 2])>,
    /// The state (by its rows) whose plastic history `write_history_part` is writing: the
    /// values written so far and in all.
    history: Option<(u64, usize, usize)>,
}

fn create_slot(file: &hdf5::File, p: &Path, k: usize, nodes: usize) -> Result<Slot, OutputError> {
    let group = layout::restart_slot(k);
    if file.group(layout::RESTART).is_err() {
        file.create_group(layout::RESTART).at(p, layout::RESTART)?;
    }
    file.create_group(&group).at(p, &group)?;
    let name = |d: &str| format!("{group}/{d}");
    let grow = |d: &str| {
        file.new_dataset::<f64>()
            .chunk((1024,))
            .fletcher32()
            .shape((0..,))
            .create(name(d).as_str())
            .at(p, &name(d))
    };
    let fixed = |d: &str| {
        file.new_dataset::<f64>()
            .chunk((nodes.clamp(1, CHUNK), 3))
            .fletcher32()
            .shape((nodes, 3))
            .create(name(d).as_str())
            .at(p, &name(d))
    };
    let state = file
        .new_dataset::<f64>()
        .chunk((STATE_LEN,))
        .fletcher32()
        .shape((STATE_LEN,))
        .create(name(layout::SLOT_STATE).as_str())
        .at(p, &name(layout::SLOT_STATE))?;
    let contact = grow(layout::SLOT_CONTACT)?;
    super::datasets::set_attr(
        p,
        &contact,
        layout::ATTR_CONTACT_LAYOUT,
        layout::CONTACT_LAYOUT,
    )?;
    Ok(Slot([
        contact,
        grow(layout::SLOT_RELEASED)?,
        fixed(layout::SLOT_DISPLACEMENT)?,
        fixed(layout::SLOT_PREVIOUS_DISPLACEMENT)?,
        state,
    ]))
}

impl RestartSlots {
    /// The slot of the state after `rows` written steps, created on its first use.
    fn slot(
        &mut self,
        file: &hdf5::File,
        p: &Path,
        rows: u64,
        nodes: usize,
    ) -> Result<&Slot, OutputError> {
        let k = (rows % 2) as usize;
        if self.slots[k].is_none() {
            self.slots[k] = Some(create_slot(file, p, k, nodes)?);
        }
        Ok(self.slots[k].as_ref().expect("created"))
    }

    /// Writes entries `first..` of the displacement (or, `previous`, of the previous
    /// displacement) of the state after `rows` written steps into its slot, before `write`
    /// writes the rest of that state (whose displacements are then empty). Parts come in
    /// order from entry 0.
    pub(super) fn write_part(
        &mut self,
        file: &hdf5::File,
        p: &Path,
        (rows, nodes): (u64, usize),
        previous: bool,
        first: usize,
        part: &[[f64; 3]],
    ) -> Result<(), OutputError> {
        let mut done = match self.parts {
            Some((r, done)) if r == rows => done,
            _ => [0, 0],
        };
        let w = previous as usize;
        let d = [
            layout::SLOT_DISPLACEMENT,
            layout::SLOT_PREVIOUS_DISPLACEMENT,
        ][w];
        let name = format!("{}/{d}", layout::restart_slot((rows % 2) as usize));
        if first != done[w] || first + part.len() > nodes {
            return Err(OutputError::Invalid {
                file: p.to_path_buf(),
                dataset: name,
                message: format!(
                    "a part of entries {first}..{} of {nodes}, expected one starting at {}",
                    first + part.len(),
                    done[w]
                ),
            });
        }
        let Slot([_, _, u, up, _]) = self.slot(file, p, rows, nodes)?;
        let ds = if previous { up } else { u };
        ds.write_slice::<_, f64, _, _>(part, (first..first + part.len(), ..))
            .at(p, &name)?;
        done[w] = first + part.len();
        self.parts = Some((rows, done));
        Ok(())
    }

    /// Writes values `first..` of the plastic history (`total` values in all) of the state
    /// after `rows` written steps into its slot, before `write` writes the rest of that state
    /// (whose history is then empty). Parts come in order from value 0.
    pub(super) fn write_history_part(
        &mut self,
        file: &hdf5::File,
        p: &Path,
        (rows, nodes): (u64, usize),
        (total, first): (usize, usize),
        part: &[f64],
    ) -> Result<(), OutputError> {
        let done = match self.history {
            Some((r, done, t)) if r == rows && t == total => done,
            _ => 0,
        };
        let hname = format!(
            "{}/{}",
            layout::restart_slot((rows % 2) as usize),
            layout::SLOT_HISTORY
        );
        if first != done || first + part.len() > total {
            return Err(OutputError::Invalid {
                file: p.to_path_buf(),
                dataset: hname,
                message: format!(
                    "a part of values {first}..{} of {total}, expected one starting at {done}",
                    first + part.len()
                ),
            });
        }
        self.slot(file, p, rows, nodes)?;
        let ds = history_dataset(file, p, &hname, total)?;
        ds.write_slice::<_, f64, _, _>(part, first..first + part.len())
            .at(p, &hname)?;
        self.history = Some((rows, first + part.len(), total));
        Ok(())
    }

    /// Writes `r` into slot `r.rows % 2` (of a mesh of `nodes` nodes): the arrays, a
    /// flush, then the state, a flush. Displacements left empty must have been written by
    /// `write_part`, whole.
    pub(super) fn write(
        &mut self,
        file: &hdf5::File,
        p: &Path,
        r: &RestartState,
        nodes: usize,
    ) -> Result<(), OutputError> {
        let parts = self.parts.take().filter(|&(rows, _)| rows == r.rows);
        let streamed = r.displacement.is_empty() && r.previous_displacement.is_empty();
        let k = (r.rows % 2) as usize;
        let group = layout::restart_slot(k);
        let name = |d: &str| format!("{group}/{d}");
        if streamed && nodes > 0 && parts.is_none_or(|(_, done)| done != [nodes, nodes]) {
            return Err(OutputError::Invalid {
                file: p.to_path_buf(),
                dataset: name(layout::SLOT_DISPLACEMENT),
                message: format!(
                    "the restart state after {} rows was written without its displacements",
                    r.rows
                ),
            });
        }
        let history = self.history.take().filter(|&(rows, _, _)| rows == r.rows);
        if let Some((_, done, total)) = history.filter(|_| r.history.is_empty()) {
            if done != total {
                return Err(OutputError::Invalid {
                    file: p.to_path_buf(),
                    dataset: name(layout::SLOT_HISTORY),
                    message: format!(
                        "the restart state after {} rows was written with {done} of its {total} history values",
                        r.rows
                    ),
                });
            }
        }
        let Slot([contact, released, u, up, state]) = self.slot(file, p, r.rows, nodes)?;
        for (ds, d, v) in [
            (contact, layout::SLOT_CONTACT, &r.contact),
            (released, layout::SLOT_RELEASED, &r.released),
        ] {
            ds.resize((v.len(),)).at(p, &name(d))?;
            ds.write_raw(v).at(p, &name(d))?;
        }
        let whole = [
            (u, layout::SLOT_DISPLACEMENT, &r.displacement),
            (
                up,
                layout::SLOT_PREVIOUS_DISPLACEMENT,
                &r.previous_displacement,
            ),
        ];
        for (ds, d, v) in whole.into_iter().filter(|_| !streamed) {
            // Written from the rows as they lie, not from a flat copy (25 MB at 10^6
            // elements, on top of both gathered displacements).
            ds.write_raw(v.as_flattened()).at(p, &name(d))?;
        }
        if !r.history.is_empty() {
            let hname = name(layout::SLOT_HISTORY);
            let ds = history_dataset(file, p, &hname, r.history.len())?;
            ds.write_raw(&r.history).at(p, &hname)?;
        }
        for (d, words) in [
            (layout::SLOT_TIES, &r.ties),
            (layout::SLOT_HIERARCHY, &r.hierarchy),
        ] {
            let tname = name(d);
            let exists = file.link_exists(&tname);
            if exists || !words.is_empty() {
                let ds = if exists {
                    file.dataset(&tname).at(p, &tname)?
                } else {
                    file.new_dataset::<f64>()
                        .chunk((1024,))
                        .fletcher32()
                        .shape((0..,))
                        .create(tname.as_str())
                        .at(p, &tname)?
                };
                ds.resize((words.len(),)).at(p, &tname)?;
                ds.write_raw(words).at(p, &tname)?;
            }
        }
        file.flush().at(p, "/ (flush)")?;
        let head = [
            r.step as f64,
            r.time,
            r.dt_prev,
            r.reference_floor,
            r.rows as f64,
            r.multilevel_switched as u8 as f64,
        ];
        state.write_raw(&head).at(p, &name(layout::SLOT_STATE))?;
        file.flush().at(p, "/ (flush)")
    }
}

/// A slot's history dataset of `len` values: the one the slot has (its plastic elements do
/// not change within a run), or a new one.
fn history_dataset(
    file: &hdf5::File,
    p: &Path,
    hname: &str,
    len: usize,
) -> Result<hdf5::Dataset, OutputError> {
    match file.dataset(hname) {
        Ok(ds) => Ok(ds),
        Err(_) => file
            .new_dataset::<f64>()
            .chunk((len.clamp(1, HISTORY_CHUNK),))
            .fletcher32()
            .shape((len,))
            .create(hname)
            .at(p, hname),
    }
}

/// A restart value that is not finite: never written, so the file was changed.
fn non_finite(file: &Path, dataset: &str, values: &[f64]) -> Result<(), OutputError> {
    check_finite(file, dataset, values, |k| format!("value {k}")).map_err(|e| match e {
        OutputError::NonFinite {
            file,
            dataset,
            location,
            value,
        } => OutputError::Damaged {
            file,
            dataset,
            step: None,
            message: format!(
                "{location} is {value}; the solver never writes a non-finite value, so the file was changed"
            ),
        },
        e => e,
    })
}

/// A restart block: its group and the values of its datasets in [`layout::SLOT_DATASETS`]
/// order.
type Block = (String, Vec<Vec<f64>>);

impl ResultFile {
    fn read_f64(&self, name: &str) -> Result<Vec<f64>, OutputError> {
        self.dataset(name)?.read_raw::<f64>().at(self.path(), name)
    }

    /// The restart blocks of the file, each read whole (so every checksum is checked): the
    /// two slots of format 2, or `/restart` of format 1.
    fn restart_blocks(&self) -> Result<Vec<Block>, OutputError> {
        let mut groups: Vec<String> = (0..2).map(layout::restart_slot).collect();
        groups.push(layout::RESTART.to_string());
        let mut blocks = Vec::new();
        for group in groups {
            let state = format!("{group}/{}", layout::SLOT_STATE);
            if !self.hdf5().link_exists(&state) {
                continue;
            }
            let mut values = Vec::new();
            for d in layout::SLOT_DATASETS {
                values.push(self.read_f64(&format!("{group}/{d}"))?);
            }
            blocks.push((group, values));
            if blocks.len() == 2 {
                break;
            }
        }
        Ok(blocks)
    }

    /// The state to resume the run from, if the file has one: the slot whose state records
    /// more rows. Both slots are read whole, so a checksum that fails in either refuses the
    /// file; the chosen one must have the right sizes and finite values only.
    pub fn restart_state(&self) -> Result<Option<RestartState>, OutputError> {
        let blocks = self.restart_blocks()?;
        let rows = |b: &Block| b.1[4].get(4).copied().unwrap_or(f64::NAN);
        let Some((group, v)) = blocks
            .into_iter()
            .reduce(|a, b| if rows(&b) > rows(&a) { b } else { a })
        else {
            return Ok(None);
        };
        let p = self.path();
        self.check_contact_layout(&group)?;
        for (d, values) in layout::SLOT_DATASETS.iter().zip(&v) {
            non_finite(p, &format!("{group}/{d}"), values)?;
        }
        let [contact, released, u, up, head]: [Vec<f64>; 5] = v.try_into().expect("five datasets");
        let nodes = self.num_nodes();
        if !(head.len() == STATE_LEN || head.len() == STATE_LEN - 1)
            || u.len() != 3 * nodes
            || up.len() != 3 * nodes
        {
            return Err(OutputError::Invalid {
                file: p.to_path_buf(),
                dataset: group,
                message: format!(
                    "the restart state has {} header values and {} / {} displacement values for {nodes} nodes",
                    head.len(),
                    u.len(),
                    up.len(),
                ),
            });
        }
        let hname = format!("{group}/{}", layout::SLOT_HISTORY);
        let history = if self.hdf5().link_exists(&hname) {
            let h = self.read_f64(&hname)?;
            non_finite(p, &hname, &h)?;
            h
        } else {
            Vec::new()
        };
        let optional = |d: &str| -> Result<Vec<f64>, OutputError> {
            let tname = format!("{group}/{d}");
            if self.hdf5().link_exists(&tname) {
                let t = self.read_f64(&tname)?;
                non_finite(p, &tname, &t)?;
                Ok(t)
            } else {
                Ok(Vec::new())
            }
        };
        let ties = optional(layout::SLOT_TIES)?;
        let hierarchy = optional(layout::SLOT_HIERARCHY)?;
        Ok(Some(RestartState {
            history,
            ties,
            hierarchy,
            step: head[0] as u64,
            time: head[1],
            dt_prev: head[2],
            reference_floor: head[3],
            rows: head[4] as u64,
            multilevel_switched: head.get(5).is_some_and(|&v| v != 0.0),
            displacement: to_rows(&u),
            previous_displacement: to_rows(&up),
            contact,
            released,
        }))
    }

    /// Refuses a restart block whose contact words are of another layout than this
    /// solver's ([`layout::CONTACT_LAYOUT`]; no attribute is layout 1).
    fn check_contact_layout(&self, group: &str) -> Result<(), OutputError> {
        let name = format!("{group}/{}", layout::SLOT_CONTACT);
        let found = match self.dataset(&name)?.attr(layout::ATTR_CONTACT_LAYOUT) {
            Ok(a) => a.read_scalar::<u64>().at(self.path(), &name)?,
            Err(_) => 1,
        };
        if found == layout::CONTACT_LAYOUT {
            return Ok(());
        }
        Err(OutputError::Invalid {
            file: self.path().to_path_buf(),
            dataset: name,
            message: format!(
                "the restart state's contact constraints are in layout {found}, this solver reads layout {} \
                 (the words per contact constraint changed): it cannot continue this run; start it again",
                layout::CONTACT_LAYOUT
            ),
        })
    }

    /// Step `i`'s results, checked as a restart input: every checksum and every value finite
    /// (a non-finite value is never written, so one is damage).
    pub fn step_output(
        &self,
        i: usize,
        time: f64,
        stats: StepStats,
    ) -> Result<StepOutput, OutputError> {
        let s = StepOutput {
            time,
            displacement: self.displacement(i)?,
            stress: self.stress(i)?,
            reaction: self.reaction(i)?,
            contact_force: self.contact_force(i)?,
            contact_status: self.contact_status(i)?,
            contact_gap: self.gap(i)?,
            contact_pressure: self.contact_pressure(i)?.unwrap_or_default(),
            plastic_strain: self.plastic_strain(i)?.unwrap_or_default(),
            stats,
        };
        let nodes = super::data::Sequential(self.num_nodes());
        s.validate(self.path(), &nodes, self.num_elements())
            .map_err(|e| match e {
                OutputError::NonFinite {
                    file,
                    dataset,
                    location,
                    value,
                } => OutputError::Damaged {
                    file,
                    dataset,
                    step: Some(i),
                    message: format!(
                        "{location} is {value}; the solver never writes a non-finite value, so the file was changed"
                    ),
                },
                e => e,
            })?;
        Ok(s)
    }
}
