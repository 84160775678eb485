//! Writing the Exodus II file: the mesh (coordinates, one element block per body, node and
//! side sets, the number maps holding our global ids), then per step the time, the nodal,
//! element and global variables. Written to a temporary name beside the target and renamed
//! onto it once closed, as the HDF5 file is.

use std::path::Path;

use netcdf::{FileMut, Options};

use super::names::{self as n, LEN_LINE, LEN_NAME};
use super::shape::Shape;
use super::text::name_rows;
use crate::output::error::{io_error, OutputError};
use crate::output::{OutputMesh, ResultFile};

/// A netCDF error while writing `what` to `file`, as an I/O error (exit code 1).
fn nc_err<'a>(file: &'a Path, what: &str) -> impl Fn(netcdf::Error) -> OutputError + 'a {
    let action = format!("writing Exodus {what}");
    move |e| io_error(file, &action, std::io::Error::other(e.to_string()))
}

/// Checks that `target` can take an Exodus file: a new path or a regular file that is
/// already an Exodus file (netCDF signature `CDF`), under a directory, not one of `inputs`.
pub fn check_exodus_output(target: &Path, inputs: &[(&Path, &str)]) -> Result<(), OutputError> {
    let bad = |m: String| OutputError::BadOutput {
        file: target.to_path_buf(),
        message: m,
    };
    crate::output::paths::check_parent(target)?;
    let meta = match std::fs::symlink_metadata(target) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(bad(e.to_string())),
    };
    if !meta.file_type().is_file() {
        return Err(bad(format!(
            "it is {}; the Exodus file must be a regular file or a new path",
            crate::output::paths::kind(&meta)
        )));
    }
    for (p, what) in inputs {
        if let Ok(m) = std::fs::metadata(p) {
            if crate::output::paths::same_file(&meta, &m) {
                return Err(bad(format!(
                    "it is {what} of this run ({}); choose another output path",
                    p.display()
                )));
            }
        }
    }
    let head = crate::output::paths::head(target).map_err(|e| bad(e.to_string()))?;
    if !head.starts_with(b"CDF") {
        return Err(bad(
            "it exists and is not an Exodus (netCDF) file; remove it or choose another output path"
                .into(),
        ));
    }
    Ok(())
}

/// Writes the HDF5 result `result` as the Exodus II file `target` (replacing it).
pub fn write_exodus(result: &Path, target: &Path) -> Result<(), OutputError> {
    let f = ResultFile::open(result)?;
    let (tmp, handle) = crate::output::paths::create_temp(target)?;
    drop(handle);
    let written = write_to(&f, &tmp);
    let renamed = written.and_then(|()| {
        std::fs::rename(&tmp, target).map_err(|e| io_error(target, "renaming the Exodus file", e))
    });
    if renamed.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    renamed
}

/// The whole file at `path`: definitions, mesh, steps.
fn write_to(f: &ResultFile, path: &Path) -> Result<(), OutputError> {
    let mesh = f.mesh()?;
    let title = f.attributes()?.scene_name;
    let shape = Shape::of(f, &mesh)?;
    let mut nc = netcdf::create_with(path, Options::_64BIT_OFFSET)
        .map_err(nc_err(path, "(creating the file)"))?;
    define(&mut nc, &shape, &mesh, &title).map_err(nc_err(path, "definitions"))?;
    nc.enddef().map_err(nc_err(path, "definitions"))?;
    put_mesh(&mut nc, &shape, &mesh).map_err(nc_err(path, "mesh"))?;
    let blocks: Vec<usize> = mesh.bodies.iter().map(|b| b.connectivity.len()).collect();
    super::steps::put_steps(&mut nc, f, &shape, &blocks, path)?;
    nc.close().map_err(nc_err(path, "(closing the file)"))?;
    std::fs::File::open(path)
        .and_then(|h| h.sync_all())
        .map_err(|e| io_error(path, "flushing the file to the disk", e))
}

fn define(
    nc: &mut FileMut,
    shape: &Shape,
    mesh: &OutputMesh,
    title: &str,
) -> Result<(), netcdf::Error> {
    nc.add_attribute("api_version", 8.11f32)?;
    nc.add_attribute("version", 8.11f32)?;
    nc.add_attribute("floating_point_word_size", 8i32)?;
    nc.add_attribute("file_size", 1i32)?;
    nc.add_attribute("maximum_name_length", (LEN_NAME - 1) as i32)?;
    nc.add_attribute("int64_status", 0i32)?;
    nc.add_attribute("title", title)?;
    nc.add_dimension("len_string", LEN_NAME)?;
    nc.add_dimension("len_name", LEN_NAME)?;
    nc.add_dimension("len_line", LEN_LINE)?;
    nc.add_dimension("four", 4)?;
    nc.add_dimension("num_dim", 3)?;
    nc.add_dimension("num_nodes", mesh.coordinates.len())?;
    nc.add_dimension("num_elem", mesh.num_elements())?;
    nc.add_dimension("num_el_blk", mesh.bodies.len())?;
    nc.add_unlimited_dimension("time_step")?;
    nc.add_variable::<f64>("time_whole", &["time_step"])?;
    for c in ["coordx", "coordy", "coordz"] {
        nc.add_variable::<f64>(c, &["num_nodes"])?;
    }
    char_var(nc, "coor_names", "num_dim")?;
    nc.add_variable::<i32>("node_num_map", &["num_nodes"])?;
    nc.add_variable::<i32>("elem_num_map", &["num_elem"])?;
    define_blocks(nc, mesh)?;
    define_sets(nc, mesh)?;
    define_variables(nc, shape, mesh)
}

/// A `char` variable of one name per entry of `dim`.
fn char_var(nc: &mut FileMut, name: &str, dim: &str) -> Result<(), netcdf::Error> {
    nc.add_variable::<super::NcChar>(name, &[dim, "len_name"])?;
    Ok(())
}

/// `<prefix>_status`, `<prefix>_prop1` (the ids, 1..) and `<prefix>_names` of blocks or sets.
fn define_entity_list(nc: &mut FileMut, prefix: &str, dim: &str) -> Result<(), netcdf::Error> {
    nc.add_variable::<i32>(&format!("{prefix}_status"), &[dim])?;
    let mut prop = nc.add_variable::<i32>(&format!("{prefix}_prop1"), &[dim])?;
    prop.put_attribute("name", "ID")?;
    char_var(nc, &format!("{prefix}_names"), dim)
}

fn define_blocks(nc: &mut FileMut, mesh: &OutputMesh) -> Result<(), netcdf::Error> {
    define_entity_list(nc, "eb", "num_el_blk")?;
    for (b, body) in mesh.bodies.iter().enumerate() {
        nc.add_dimension(&n::num_el_in_blk(b), body.connectivity.len())?;
        let per = body.connectivity.nodes_per_element;
        nc.add_dimension(&n::num_nod_per_el(b), per)?;
        let mut v = nc.add_variable::<i32>(
            &n::connect(b),
            &[&n::num_el_in_blk(b), &n::num_nod_per_el(b)],
        )?;
        // The mesh was checked when the result was read: 8 or 10 nodes per element.
        let kind = crate::output::cells::exodus_type(per).expect("a known cell type");
        v.put_attribute("elem_type", kind)?;
    }
    Ok(())
}

fn define_sets(nc: &mut FileMut, mesh: &OutputMesh) -> Result<(), netcdf::Error> {
    if !mesh.node_sets.is_empty() {
        nc.add_dimension("num_node_sets", mesh.node_sets.len())?;
        define_entity_list(nc, "ns", "num_node_sets")?;
        for (s, (_, nodes)) in mesh.node_sets.iter().enumerate() {
            nc.add_dimension(&n::num_nod_ns(s), nodes.len())?;
            nc.add_variable::<i32>(&n::node_ns(s), &[&n::num_nod_ns(s)])?;
        }
    }
    if !mesh.side_sets.is_empty() {
        nc.add_dimension("num_side_sets", mesh.side_sets.len())?;
        define_entity_list(nc, "ss", "num_side_sets")?;
        for (s, (_, faces)) in mesh.side_sets.iter().enumerate() {
            nc.add_dimension(&n::num_side_ss(s), faces.len())?;
            nc.add_variable::<i32>(&n::elem_ss(s), &[&n::num_side_ss(s)])?;
            nc.add_variable::<i32>(&n::side_ss(s), &[&n::num_side_ss(s)])?;
        }
    }
    Ok(())
}

fn define_variables(
    nc: &mut FileMut,
    shape: &Shape,
    mesh: &OutputMesh,
) -> Result<(), netcdf::Error> {
    nc.add_dimension("num_glo_var", n::GLOBAL_VARIABLES.len())?;
    char_var(nc, "name_glo_var", "num_glo_var")?;
    nc.add_variable::<f64>("vals_glo_var", &["time_step", "num_glo_var"])?;
    nc.add_dimension("num_nod_var", shape.nodal.len())?;
    char_var(nc, "name_nod_var", "num_nod_var")?;
    for v in 0..shape.nodal.len() {
        nc.add_variable::<f64>(&n::vals_nod_var(v), &["time_step", "num_nodes"])?;
    }
    nc.add_dimension("num_elem_var", shape.element.len())?;
    char_var(nc, "name_elem_var", "num_elem_var")?;
    nc.add_variable::<i32>("elem_var_tab", &["num_el_blk", "num_elem_var"])?;
    for v in 0..shape.element.len() {
        for b in 0..mesh.bodies.len() {
            nc.add_variable::<f64>(
                &n::vals_elem_var(v, b),
                &["time_step", &n::num_el_in_blk(b)],
            )?;
        }
    }
    Ok(())
}

fn put_i32(nc: &mut FileMut, name: &str, values: &[i32]) -> Result<(), netcdf::Error> {
    if values.is_empty() {
        return Ok(());
    }
    let mut v = nc
        .variable_mut(name)
        .ok_or(netcdf::Error::NotFound(name.to_string()))?;
    v.put_values(values, ..)
}

fn put_names(nc: &mut FileMut, name: &str, names: &[&str]) -> Result<(), netcdf::Error> {
    if names.is_empty() {
        return Ok(());
    }
    let mut v = nc
        .variable_mut(name)
        .ok_or(netcdf::Error::NotFound(name.to_string()))?;
    v.put_values(&name_rows(names, LEN_NAME), ..)
}

/// 1..=n as the ids of blocks or sets, and every one present (status 1).
fn put_entity_list(nc: &mut FileMut, prefix: &str, names: &[&str]) -> Result<(), netcdf::Error> {
    let count = names.len() as i32;
    put_i32(nc, &format!("{prefix}_status"), &vec![1; names.len()])?;
    put_i32(
        nc,
        &format!("{prefix}_prop1"),
        &(1..=count).collect::<Vec<_>>(),
    )?;
    put_names(nc, &format!("{prefix}_names"), names)
}

fn put_mesh(nc: &mut FileMut, shape: &Shape, mesh: &OutputMesh) -> Result<(), netcdf::Error> {
    for (k, c) in ["coordx", "coordy", "coordz"].into_iter().enumerate() {
        let values: Vec<f64> = mesh.coordinates.iter().map(|x| x[k]).collect();
        if !values.is_empty() {
            let mut v = nc
                .variable_mut(c)
                .ok_or(netcdf::Error::NotFound(c.into()))?;
            v.put_values(&values, ..)?;
        }
    }
    put_names(nc, "coor_names", &["x", "y", "z"])?;
    let ids = |v: &[u64]| v.iter().map(|&i| i as i32).collect::<Vec<_>>();
    put_i32(nc, "node_num_map", &ids(&mesh.node_ids))?;
    let elem_ids: Vec<u64> = mesh
        .bodies
        .iter()
        .flat_map(|b| b.element_ids.iter().copied())
        .collect();
    put_i32(nc, "elem_num_map", &ids(&elem_ids))?;
    let body_names: Vec<&str> = mesh.bodies.iter().map(|b| b.name.as_str()).collect();
    put_entity_list(nc, "eb", &body_names)?;
    for (b, body) in mesh.bodies.iter().enumerate() {
        // Exodus connectivity is 1-based positions in the node order.
        let conn: Vec<i32> = body
            .connectivity
            .iter()
            .flatten()
            .map(|&i| i as i32 + 1)
            .collect();
        put_i32(nc, &n::connect(b), &conn)?;
    }
    put_sets(nc, mesh)?;
    put_names(nc, "name_glo_var", &n::GLOBAL_VARIABLES)?;
    put_names(nc, "name_nod_var", &shape.nodal)?;
    put_names(nc, "name_elem_var", &shape.element)?;
    put_i32(
        nc,
        "elem_var_tab",
        &vec![1; shape.element.len() * mesh.bodies.len()],
    )
}

/// Node sets as 1-based node positions, side sets as 1-based element positions and
/// Exodus side numbers (our local faces follow Exodus's side order, 0-based).
fn put_sets(nc: &mut FileMut, mesh: &OutputMesh) -> Result<(), netcdf::Error> {
    let node_pos: std::collections::HashMap<u64, i32> = mesh
        .node_ids
        .iter()
        .enumerate()
        .map(|(i, &id)| (id, i as i32 + 1))
        .collect();
    let elem_pos: std::collections::HashMap<u64, i32> = mesh
        .bodies
        .iter()
        .flat_map(|b| b.element_ids.iter().copied())
        .enumerate()
        .map(|(i, id)| (id, i as i32 + 1))
        .collect();
    let missing = |what: &str, id: u64| {
        netcdf::Error::Str(format!(
            "a set names {what} id {id}, which the mesh has not"
        ))
    };
    let names: Vec<&str> = mesh.node_sets.iter().map(|s| s.0.as_str()).collect();
    if !names.is_empty() {
        put_entity_list(nc, "ns", &names)?;
    }
    for (s, (_, nodes)) in mesh.node_sets.iter().enumerate() {
        let pos = nodes
            .iter()
            .map(|id| {
                node_pos
                    .get(id)
                    .copied()
                    .ok_or_else(|| missing("node", *id))
            })
            .collect::<Result<Vec<_>, _>>()?;
        put_i32(nc, &n::node_ns(s), &pos)?;
    }
    let names: Vec<&str> = mesh.side_sets.iter().map(|s| s.0.as_str()).collect();
    if !names.is_empty() {
        put_entity_list(nc, "ss", &names)?;
    }
    for (s, (_, faces)) in mesh.side_sets.iter().enumerate() {
        let elems = faces
            .iter()
            .map(|(id, _)| {
                elem_pos
                    .get(id)
                    .copied()
                    .ok_or_else(|| missing("element", *id))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let sides: Vec<i32> = faces.iter().map(|&(_, f)| i32::from(f) + 1).collect();
        put_i32(nc, &n::elem_ss(s), &elems)?;
        put_i32(nc, &n::side_ss(s), &sides)?;
    }
    Ok(())
}
