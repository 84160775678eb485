//! The per-step records of the Exodus file: `time_whole`, the global, nodal and element
//! variables, each value the HDF5 file's bits (integers as the f64 of the same number).

use std::path::Path;

use netcdf::FileMut;

use super::names as n;
use super::shape::Shape;
use crate::output::error::{io_error, OutputError};
use crate::output::{ResultFile, StepStats};

/// The global variables of one step, in [`n::GLOBAL_VARIABLES`]'s order.
fn globals(s: &StepStats) -> [f64; 9] {
    [
        s.cg_iterations as f64,
        s.contact_updates as f64,
        s.residual,
        s.cutbacks as f64,
        s.contact_active as f64,
        s.contact_stick as f64,
        s.contact_slip as f64,
        s.contact_released as f64,
        s.max_penetration,
    ]
}

/// The nodal variable `name` of one step from the result file.
fn nodal(f: &ResultFile, step: usize, name: &str) -> Result<Vec<f64>, OutputError> {
    let comp = |v: Vec<[f64; 3]>, k: usize| v.into_iter().map(|x| x[k]).collect();
    Ok(match name {
        "displ_x" => comp(f.displacement(step)?, 0),
        "displ_y" => comp(f.displacement(step)?, 1),
        "displ_z" => comp(f.displacement(step)?, 2),
        "reaction_x" => comp(f.reaction(step)?, 0),
        "reaction_y" => comp(f.reaction(step)?, 1),
        "reaction_z" => comp(f.reaction(step)?, 2),
        "contact_force_x" => comp(f.contact_force(step)?, 0),
        "contact_force_y" => comp(f.contact_force(step)?, 1),
        "contact_force_z" => comp(f.contact_force(step)?, 2),
        "contact_status" => f.contact_status(step)?.into_iter().map(f64::from).collect(),
        "contact_gap" => f.gap(step)?,
        _ => f.contact_pressure(step)?.unwrap_or_default(),
    })
}

/// The element variable `name` of one step, in global element order.
fn element(f: &ResultFile, step: usize, name: &str) -> Result<Vec<f64>, OutputError> {
    let k = n::ELEMENT_VARIABLES.iter().position(|v| *v == name);
    match k {
        Some(k) if k < 6 => Ok(f.stress(step)?.into_iter().map(|s| s[k]).collect()),
        _ => Ok(f.plastic_strain(step)?.unwrap_or_default()),
    }
}

fn put_row(nc: &mut FileMut, name: &str, step: usize, values: &[f64]) -> Result<(), netcdf::Error> {
    let mut v = nc
        .variable_mut(name)
        .ok_or(netcdf::Error::NotFound(name.to_string()))?;
    if v.dimensions().len() == 1 {
        return v.put_values(values, step..step + 1);
    }
    v.put_values(values, [step..step + 1, 0..values.len()])
}

/// Writes every step of `f`; `blocks` are the element counts of the bodies in order.
pub(super) fn put_steps(
    nc: &mut FileMut,
    f: &ResultFile,
    shape: &Shape,
    blocks: &[usize],
    path: &Path,
) -> Result<(), OutputError> {
    let time = f.time()?;
    let stats = f.stats()?;
    let err = |what: String| {
        move |e: netcdf::Error| {
            io_error(
                path,
                &format!("writing Exodus {what}"),
                std::io::Error::other(e.to_string()),
            )
        }
    };
    for step in 0..shape.steps {
        put_row(nc, "time_whole", step, &time[step..step + 1])
            .map_err(err(format!("time_whole, step {step}")))?;
        put_row(nc, "vals_glo_var", step, &globals(&stats[step]))
            .map_err(err(format!("vals_glo_var, step {step}")))?;
        for (v, name) in shape.nodal.iter().enumerate() {
            let values = nodal(f, step, name)?;
            put_row(nc, &n::vals_nod_var(v), step, &values)
                .map_err(err(format!("{name}, step {step}")))?;
        }
        for (v, name) in shape.element.iter().enumerate() {
            let values = element(f, step, name)?;
            let mut first = 0;
            for (b, &count) in blocks.iter().enumerate() {
                if count > 0 {
                    put_row(
                        nc,
                        &n::vals_elem_var(v, b),
                        step,
                        &values[first..first + count],
                    )
                    .map_err(err(format!("{name}, block {}, step {step}", b + 1)))?;
                }
                first += count;
            }
        }
    }
    Ok(())
}
