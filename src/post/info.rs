//! `solver post info`: a summary of one result file.

use std::fmt::Write;
use std::path::Path;

use crate::output::{FileAttributes, OutputError, OutputMesh, ResultFile, StepStats};

/// The summary `solver post info` prints.
pub fn info_text(path: &Path) -> Result<String, OutputError> {
    let f = ResultFile::open(path)?;
    // Every dataset is read once, so that HDF5 checks every checksum of the file.
    let verified = f.verify()?;
    let checksums = if f.has_checksums() {
        format!("verified ({verified} datasets)")
    } else {
        format!("none (format version {})", f.format_version())
    };
    let attrs = f.attributes()?;
    let mesh = f.mesh()?;
    let time = f.time()?;
    let stats = f.stats()?;
    let mut s = String::new();
    header(&mut s, path, &f, &attrs, &mesh, &checksums);
    if !time.is_empty() {
        let _ = writeln!(s);
        step_table(&mut s, &time, &stats);
        let _ = writeln!(s);
        let pressure = max_pressures(&f, &mesh.node_ids)?;
        contact_table(&mut s, &stats, pressure.as_deref());
        plastic_table(&f, &mut s)?;
    }
    Ok(s)
}

/// The file, the run and the mesh. Writing to a String cannot fail.
fn header(
    s: &mut String,
    path: &Path,
    f: &ResultFile,
    attrs: &FileAttributes,
    mesh: &OutputMesh,
    checksums: &str,
) {
    let wall = attrs.wall_time.map_or_else(
        || "- (run not finished)".to_string(),
        |w| format!("{w:.3} s"),
    );
    let bodies = mesh
        .bodies
        .iter()
        .map(|b| format!("{} ({} elements)", b.name, b.connectivity.len()))
        .collect::<Vec<_>>()
        .join(", ");
    let sets = |names: Vec<&String>| {
        if names.is_empty() {
            "-".to_string()
        } else {
            names
                .iter()
                .map(|n| n.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        }
    };
    let _ = writeln!(s, "file:         {}", path.display());
    let _ = writeln!(s, "scene:        {}", attrs.scene_name);
    let _ = writeln!(s, "solver:       {}", attrs.solver_version);
    let _ = writeln!(s, "ranks:        {}", attrs.ranks);
    let _ = writeln!(s, "start time:   {}", attrs.start_time);
    let _ = writeln!(s, "wall time:    {wall}");
    let _ = writeln!(s, "exit status:  {}", attrs.exit_status);
    let _ = writeln!(s, "units:        {}", attrs.units);
    let _ = writeln!(s, "checksums:    {checksums}");
    let _ = writeln!(s, "nodes:        {}", f.num_nodes());
    let _ = writeln!(s, "elements:     {} in {}", f.num_elements(), bodies);
    let _ = writeln!(
        s,
        "node sets:    {}",
        sets(mesh.node_sets.iter().map(|x| &x.0).collect())
    );
    let _ = writeln!(
        s,
        "side sets:    {}",
        sets(mesh.side_sets.iter().map(|x| &x.0).collect())
    );
    let _ = writeln!(s, "steps:        {}", f.num_steps());
}

/// Per step: time, CG iterations, contact updates, cut-backs, residual, wall time; totals.
fn step_table(s: &mut String, time: &[f64], stats: &[StepStats]) {
    let _ = writeln!(
        s,
        "{:>5} {:>14} {:>8} {:>8} {:>8} {:>12} {:>10}",
        "step", "time", "CG its", "contact", "cutback", "residual", "wall [s]"
    );
    for (i, (t, st)) in time.iter().zip(stats).enumerate() {
        let _ = writeln!(
            s,
            "{:>5} {:>14.6e} {:>8} {:>8} {:>8} {:>12.4e} {:>10.3}",
            i, t, st.cg_iterations, st.contact_updates, st.cutbacks, st.residual, st.wall_time
        );
    }
    let cg: u64 = stats.iter().map(|st| st.cg_iterations).sum();
    let wall: f64 = stats.iter().map(|st| st.wall_time).sum();
    let _ = writeln!(
        s,
        "{:>5} {:>14} {:>8} {:>8} {:>8} {:>12} {:>10.3}",
        "total",
        "",
        cg,
        stats.iter().map(|st| st.contact_updates).sum::<u64>(),
        stats.iter().map(|st| st.cutbacks).sum::<u64>(),
        "",
        wall
    );
}

/// A step's largest nodal contact pressure and the node id that has it (None: no node has a
/// positive pressure).
type PeakPressure = (f64, Option<u64>);

/// Per step, the largest nodal contact pressure and the id (`/mesh/node_ids`) of the first
/// node that has it (`None` when no node has a positive pressure); `None` for a file
/// without pressures.
fn max_pressures(
    f: &ResultFile,
    node_ids: &[u64],
) -> Result<Option<Vec<PeakPressure>>, OutputError> {
    if !f.has_contact_pressure() {
        return Ok(None);
    }
    (0..f.num_steps())
        .map(|i| {
            let p = f.contact_pressure(i)?.unwrap_or_default();
            let (at, max) =
                p.iter()
                    .enumerate()
                    .fold((0, 0.0f64), |m, (k, &v)| if v > m.1 { (k, v) } else { m });
            Ok((max, (max > 0.0).then(|| node_ids[at])))
        })
        .collect::<Result<Vec<_>, _>>()
        .map(Some)
}

/// Per step: the contact counts, the largest penetration and the largest contact pressure
/// with its node; their maxima. A file written before the pressure was recorded says so.
fn contact_table(s: &mut String, stats: &[StepStats], pressure: Option<&[PeakPressure]>) {
    let _ = writeln!(
        s,
        "{:>5} {:>8} {:>8} {:>8} {:>8} {:>15} {:>13} {:>8}",
        "step", "active", "stick", "slip", "released", "max penetration", "max pressure", "at node"
    );
    let shown = |p: Option<PeakPressure>| match p {
        Some((v, at)) => (
            format!("{v:.4e}"),
            at.map_or_else(|| "-".to_string(), |n| n.to_string()),
        ),
        None => ("-".to_string(), "-".to_string()),
    };
    for (i, st) in stats.iter().enumerate() {
        let (p, at) = shown(pressure.map(|p| p[i]));
        let _ = writeln!(
            s,
            "{:>5} {:>8} {:>8} {:>8} {:>8} {:>15.4e} {:>13} {:>8}",
            i,
            st.contact_active,
            st.contact_stick,
            st.contact_slip,
            st.contact_released,
            st.max_penetration,
            p,
            at
        );
    }
    let peak = pressure.map(|p| {
        p.iter()
            .copied()
            .fold((0.0, None), |m, q| if q.0 > m.0 { q } else { m })
    });
    let (p, at) = shown(peak);
    let _ = writeln!(
        s,
        "{:>5} {:>8} {:>8} {:>8} {:>8} {:>15.4e} {:>13} {:>8}",
        "max",
        stats.iter().map(|st| st.contact_active).max().unwrap_or(0),
        stats.iter().map(|st| st.contact_stick).max().unwrap_or(0),
        stats.iter().map(|st| st.contact_slip).max().unwrap_or(0),
        stats
            .iter()
            .map(|st| st.contact_released)
            .max()
            .unwrap_or(0),
        stats
            .iter()
            .map(|st| st.max_penetration)
            .fold(0.0, f64::max),
        p,
        at
    );
    if pressure.is_none() {
        let _ = writeln!(
            s,
            "contact pressure: not in this file (written before the solver recorded it)"
        );
    }
}

/// Per step: the largest element-mean equivalent plastic strain and how many elements have
/// yielded (files of scenes with plastic bodies only).
fn plastic_table(f: &ResultFile, s: &mut String) -> Result<(), OutputError> {
    if f.plastic_strain(0)?.is_none() {
        return Ok(());
    }
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "{:>5} {:>16} {:>10} {:>16}",
        "step", "max plastic eps", "yielded", "at element"
    );
    for i in 0..f.num_steps() {
        let e = f.plastic_strain(i)?.unwrap_or_default();
        let (at, max) = e
            .iter()
            .enumerate()
            .fold((0, 0.0f64), |m, (k, &v)| if v > m.1 { (k, v) } else { m });
        let yielded = e.iter().filter(|&&v| v > 0.0).count();
        let id = if max > 0.0 {
            (at + 1).to_string()
        } else {
            "-".to_string()
        };
        let _ = writeln!(s, "{:>5} {:>16.6e} {:>10} {:>16}", i, max, yielded, id);
    }
    Ok(())
}
