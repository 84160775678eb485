//! A new result file's header: the mesh, the partition and the run's attributes, checked
//! ([`check`]) and then written ([`write`]) from a [`MeshSource`] a round of rows at a
//! time (`CHUNK_ROWS` nodes or elements: one chunk of each dataset written at once), so
//! that what rank 0 holds for it is a round, not a copy of the mesh.

use std::collections::HashSet;
use std::ops::Range;
use std::path::Path;

use hdf5::H5Type;

use super::cells::{xdmf_code, xdmf_topology};
use super::data::{check_finite, invalid, RunInfo};
use super::datasets::{set_attr, set_str_attr, write_rows, write_vec, CHUNK_ROWS};
use super::error::{Hdf5Context, OutputError};
use super::layout;
use super::source::{topology, MeshSource};
use super::xdmf::Topology;

/// The ranges of `CHUNK_ROWS` rows that cover `0..rows`.
fn rounds(rows: usize) -> impl Iterator<Item = Range<usize>> {
    (0..rows)
        .step_by(CHUNK_ROWS)
        .map(move |a| a..(a + CHUNK_ROWS).min(rows))
}

/// Checks the mesh is consistent enough to be written and read back: one id per node,
/// finite coordinates, distinct allowed body names, one id per element, known element
/// node counts, node indices in range, distinct allowed set names, local faces 0..5.
pub(super) fn check(source: &impl MeshSource, file: &Path) -> Result<(), OutputError> {
    let nodes = source.num_nodes();
    if source.num_node_ids() != nodes {
        return Err(invalid(
            file,
            layout::NODE_IDS,
            format!("{} node ids for {} nodes", source.num_node_ids(), nodes),
        ));
    }
    for r in rounds(nodes) {
        let ids = source.node_ids(r.clone());
        for (k, c) in source.coordinates(r.clone()).iter().enumerate() {
            check_finite(file, layout::COORDINATES, c, |j| {
                format!("node {} (id {}), component {j}", r.start + k, ids[k])
            })?;
        }
    }
    check_bodies(source, file)?;
    check_sets(source, file)
}

fn check_bodies(source: &impl MeshSource, file: &Path) -> Result<(), OutputError> {
    let nodes = source.num_nodes();
    let mut seen = HashSet::new();
    for (b, body) in source.bodies().iter().enumerate() {
        let ds = format!("/mesh/{}", body.name);
        layout::check_name(&body.name).map_err(|m| invalid(file, &ds, m))?;
        if layout::RESERVED_MESH_NAMES.contains(&body.name.as_str()) {
            return Err(invalid(
                file,
                &ds,
                format!("body name '{}' is reserved in /mesh", body.name),
            ));
        }
        if !seen.insert(body.name.clone()) {
            return Err(invalid(file, &ds, "two bodies have this name".into()));
        }
        let conn = layout::body_connectivity(&body.name);
        if source.num_element_ids(b) != body.elements {
            return Err(invalid(
                file,
                &layout::body_element_ids(&body.name),
                format!(
                    "{} element ids for {} elements",
                    source.num_element_ids(b),
                    body.elements
                ),
            ));
        }
        let per = body.nodes_per_element;
        if xdmf_topology(per).is_none() {
            return Err(invalid(
                file,
                &conn,
                format!(
                    "{per} nodes per element; expected 8 (hexahedra) or 10 (10-node tetrahedra)"
                ),
            ));
        }
        for r in rounds(body.elements) {
            let flat = source.connectivity(b, r.clone());
            if let Some(i) = flat.iter().position(|&n| n as usize >= nodes) {
                return Err(invalid(
                    file,
                    &conn,
                    format!(
                        "element {} refers to node index {}, but there are {nodes} nodes",
                        r.start + i / per,
                        flat[i]
                    ),
                ));
            }
        }
    }
    Ok(())
}

fn check_sets(source: &impl MeshSource, file: &Path) -> Result<(), OutputError> {
    let node_sets: Vec<String> = (0..source.node_sets())
        .map(|i| source.node_set(i).0)
        .collect();
    let side_sets: Vec<(String, Vec<(u64, u8)>)> = (0..source.side_sets())
        .map(|i| source.side_set(i))
        .collect();
    for (kind, names) in [
        (layout::NODE_SETS, node_sets.iter().collect::<Vec<_>>()),
        (
            layout::SIDE_SETS,
            side_sets.iter().map(|s| &s.0).collect::<Vec<_>>(),
        ),
    ] {
        let mut seen = HashSet::new();
        for name in names {
            let ds = format!("{kind}/{name}");
            layout::check_name(name).map_err(|m| invalid(file, &ds, m))?;
            if !seen.insert(name) {
                return Err(invalid(file, &ds, "two sets have this name".into()));
            }
        }
    }
    for (name, faces) in &side_sets {
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

/// A new dataset of `rows` rows of `width` values (one value when `None`), chunked by
/// `CHUNK_ROWS` rows with checksums (an empty one stays contiguous: HDF5 refuses a chunk
/// larger than it), for the rounds to fill.
fn fixed<T: H5Type>(
    file: &hdf5::File,
    path: &Path,
    name: &str,
    rows: usize,
    width: Option<usize>,
) -> Result<hdf5::Dataset, OutputError> {
    let chunk = rows.min(CHUNK_ROWS);
    let b = file.new_dataset::<T>();
    let b = match width {
        None if rows == 0 => b.shape((0,)),
        None => b.shape((rows,)).chunk((chunk,)).fletcher32(),
        Some(k) if rows == 0 => b.shape((0, k)),
        Some(k) => b.shape((rows, k)).chunk((chunk, k)).fletcher32(),
    };
    b.create(name).at(path, name)
}

/// Writes `flat` (rows of `width` values) as rows `first..` of the two-dimensional `ds`.
fn write_flat_rows<T: H5Type>(
    ds: &hdf5::Dataset,
    path: &Path,
    name: &str,
    (first, width): (usize, usize),
    flat: &[T],
) -> Result<(), OutputError> {
    let rows = flat.len() / width;
    let view =
        ndarray::ArrayView2::from_shape((rows, width), flat).expect("a round holds whole rows");
    ds.write_slice(view, (first..first + rows, ..))
        .at(path, name)
}

/// Writes the mesh, the partition and the run's attributes into a new file (checked by
/// [`check`] first).
pub(super) fn write(
    file: &hdf5::File,
    tmp: &Path,
    info: &RunInfo,
    source: &impl MeshSource,
) -> Result<(), OutputError> {
    let root: &hdf5::Location = file;
    set_attr(
        tmp,
        root,
        layout::ATTR_FORMAT_VERSION,
        layout::FORMAT_VERSION,
    )?;
    set_str_attr(tmp, root, layout::ATTR_SOLVER_VERSION, &info.solver_version)?;
    set_attr(tmp, root, layout::ATTR_RANKS, info.ranks)?;
    set_str_attr(tmp, root, layout::ATTR_SCENE, &info.scene_text)?;
    set_str_attr(tmp, root, layout::ATTR_SCENE_NAME, &info.scene_name)?;
    set_str_attr(tmp, root, layout::ATTR_UNITS, layout::UNITS_NOTE)?;
    set_str_attr(tmp, root, layout::ATTR_START_TIME, &info.start_time)?;
    set_str_attr(tmp, root, layout::ATTR_EXIT_STATUS, layout::STATUS_RUNNING)?;

    write_nodes(file, tmp, source)?;
    write_bodies(file, tmp, source)?;
    write_all_connectivity(file, tmp, source)?;
    for name in [layout::NODE_SETS, layout::SIDE_SETS] {
        file.create_group(name).at(tmp, name)?;
    }
    for i in 0..source.node_sets() {
        let (name, ids) = source.node_set(i);
        let ds = write_vec(file, tmp, &layout::node_set(&name), &ids)?;
        set_attr(tmp, &ds, layout::SET_INDEX_ATTR, i as u64)?;
    }
    for i in 0..source.side_sets() {
        let (name, faces) = source.side_set(i);
        let rows: Vec<[u64; 2]> = faces.iter().map(|&(e, f)| [e, u64::from(f)]).collect();
        let ds = write_rows(file, tmp, &layout::side_set(&name), &rows)?;
        set_attr(tmp, &ds, layout::SET_INDEX_ATTR, i as u64)?;
    }
    write_vec(file, tmp, layout::ELEMENT_RANK, &info.element_rank)?;
    Ok(())
}

/// The coordinates and node ids.
fn write_nodes(file: &hdf5::File, tmp: &Path, source: &impl MeshSource) -> Result<(), OutputError> {
    let nodes = source.num_nodes();
    let xyz = fixed::<f64>(file, tmp, layout::COORDINATES, nodes, Some(3))?;
    let ids = fixed::<u64>(file, tmp, layout::NODE_IDS, nodes, None)?;
    for r in rounds(nodes) {
        let c = source.coordinates(r.clone());
        xyz.write_slice::<_, f64, _, _>(&c[..], (r.clone(), ..))
            .at(tmp, layout::COORDINATES)?;
        ids.write_slice(&source.node_ids(r.clone())[..], r)
            .at(tmp, layout::NODE_IDS)?;
    }
    Ok(())
}

/// Each body's connectivity and element ids, and its group's attributes.
fn write_bodies(
    file: &hdf5::File,
    tmp: &Path,
    source: &impl MeshSource,
) -> Result<(), OutputError> {
    let mut first = 0u64;
    for (i, body) in source.bodies().iter().enumerate() {
        let conn = layout::body_connectivity(&body.name);
        let width = body.nodes_per_element;
        let table = fixed::<u64>(file, tmp, &conn, body.elements, Some(width))?;
        let id_name = layout::body_element_ids(&body.name);
        let ids = fixed::<u64>(file, tmp, &id_name, body.elements, None)?;
        for r in rounds(body.elements) {
            let flat = source.connectivity(i, r.clone());
            write_flat_rows(&table, tmp, &conn, (r.start, width), &flat)?;
            ids.write_slice(&source.element_ids(i, r.clone())[..], r)
                .at(tmp, &id_name)?;
        }
        let gname = layout::body_group(&body.name);
        let group = file.group(&gname).at(tmp, &gname)?;
        set_attr(tmp, &group, layout::BODY_INDEX_ATTR, i as u64)?;
        set_attr(tmp, &group, layout::FIRST_ELEMENT_ATTR, first)?;
        first += body.elements as u64;
    }
    Ok(())
}

/// `/mesh/all_connectivity`: the bodies' rows concatenated, written a round of global
/// elements at a time; with several node counts, XDMF's "Mixed" array (each element's type
/// code before its nodes), a body's round at a time.
fn write_all_connectivity(
    file: &hdf5::File,
    tmp: &Path,
    source: &impl MeshSource,
) -> Result<(), OutputError> {
    let name = layout::ALL_CONNECTIVITY;
    let bodies = source.bodies();
    let total: usize = bodies.iter().map(|b| b.elements).sum();
    match topology(&bodies) {
        Topology::Uniform { nodes_per_element } => {
            let ds = fixed::<u64>(file, tmp, name, total, Some(nodes_per_element))?;
            let starts: Vec<usize> = bodies
                .iter()
                .scan(0, |at, b| {
                    *at += b.elements;
                    Some(*at - b.elements)
                })
                .collect();
            for r in rounds(total) {
                let mut flat = Vec::with_capacity(r.len() * nodes_per_element);
                for (i, b) in bodies.iter().enumerate() {
                    let (a, z) = (r.start.max(starts[i]), r.end.min(starts[i] + b.elements));
                    if a < z {
                        flat.extend(source.connectivity(i, a - starts[i]..z - starts[i]));
                    }
                }
                write_flat_rows(&ds, tmp, name, (r.start, nodes_per_element), &flat)?;
            }
        }
        Topology::Mixed { length } => {
            let ds = fixed::<u64>(file, tmp, name, length, None)?;
            let mut at = 0;
            for (i, b) in bodies.iter().enumerate() {
                let per = b.nodes_per_element;
                let code = xdmf_code(per).expect("a known cell type (checked)");
                for r in rounds(b.elements) {
                    let flat = source.connectivity(i, r);
                    let mut mixed = Vec::with_capacity(flat.len() / per * (per + 1));
                    for el in flat.chunks_exact(per) {
                        mixed.push(code);
                        mixed.extend_from_slice(el);
                    }
                    ds.write_slice(&mixed[..], at..at + mixed.len())
                        .at(tmp, name)?;
                    at += mixed.len();
                }
            }
        }
    }
    Ok(())
}
