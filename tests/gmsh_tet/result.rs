//! Result files of tet10 and mixed meshes, written through the output layer (the tet10
//! solve is another change's): each element's stress xx is its 0-based index and each
//! node's x displacement 1e-3 of its x, so that an element or node out of place shows.
//! Read back by the HDF5 reader, `solver post info`, `compare` and `exodus`, ParaView
//! (pvpython) and run/render.

use std::path::{Path, PathBuf};
use std::process::Command;

use solver::output::{ResultFile, ResultWriter, RunInfo, StepOutput, StepStats};
use solver::problem::Problem;
use solver::scene::parse_scene;

use super::common::{fresh_dir, repo, solver, stderr_text};

/// The problem's mesh with one step of the fields above, as `<dir>/<name>.h5`.
fn write(p: &Problem, dir: &Path, name: &str) -> PathBuf {
    let mesh = solver::run::output_mesh(p, &p.mesh);
    let (n, e) = (mesh.coordinates.len(), mesh.num_elements());
    let info = RunInfo {
        solver_version: "test".into(),
        ranks: 1,
        scene_text: p.text.clone(),
        scene_name: name.into(),
        start_time: "2026-01-01T00:00:00Z".into(),
        element_rank: vec![0; e],
    };
    let mut w = ResultWriter::create(&dir.join(format!("{name}.h5")), &info, &mesh).unwrap();
    w.append_step(&StepOutput {
        time: 1.0,
        displacement: mesh
            .coordinates
            .iter()
            .map(|x| [1e-3 * x[0], 0.0, 0.0])
            .collect(),
        stress: (0..e)
            .map(|k| [k as f64, 0.0, 0.0, 0.0, 0.0, 0.0])
            .collect(),
        reaction: vec![[0.0; 3]; n],
        contact_force: vec![[0.0; 3]; n],
        contact_status: vec![0; n],
        contact_gap: vec![0.0; n],
        contact_pressure: vec![0.0; n],
        plastic_strain: Vec::new(),
        stats: StepStats::default(),
    })
    .unwrap();
    w.finish(0.5).unwrap()
}

/// `text` with its mesh taken from the Exodus file `mesh`: every body its element block,
/// every Gmsh set the Exodus set of its name.
fn exodus_scene(text: &str, mesh: &Path) -> String {
    let mut v: toml::Table = text.parse().unwrap();
    v.remove("gmsh");
    let mut e = toml::Table::new();
    e.insert("file".into(), mesh.display().to_string().into());
    v.insert("exodus".into(), e.into());
    for (table, old, new) in [
        ("body", "gmsh_volume", "exodus_block"),
        ("node_set", "gmsh_group", "exodus_node_set"),
        ("side_set", "gmsh_surface", "exodus_side_set"),
    ] {
        let items = v.get_mut(table).and_then(|b| b.as_array_mut());
        for item in items.into_iter().flatten() {
            let t = item.as_table_mut().unwrap();
            if t.remove(old).is_some() {
                let name = t["name"].clone();
                t.insert(new.into(), name);
            }
        }
    }
    toml::to_string(&v).unwrap()
}

/// pvpython: the .xmf through ParaView's Xdmf3 reader: points, cells, VTK cell types, and
/// whether each cell's stress xx is its index.
const PARAVIEW_PY: &str = r#"
import json, sys
from paraview import servermanager
from paraview.simple import Xdmf3ReaderS
from vtkmodules.util.numpy_support import vtk_to_numpy
r = Xdmf3ReaderS(FileName=[sys.argv[1]])
r.UpdatePipeline(1.0)
d = servermanager.Fetch(r)
xx = vtk_to_numpy(d.GetCellData().GetArray("stress"))[:, 0]
print(json.dumps({"points": d.GetNumberOfPoints(), "cells": d.GetNumberOfCells(),
    "types": sorted({d.GetCellType(i) for i in range(d.GetNumberOfCells())}),
    "in_order": bool((xx == range(len(xx))).all())}))
"#;

fn paraview(xmf: &Path) -> serde_json::Value {
    let out = Command::new("pvpython")
        .args(["--force-offscreen-rendering", "-c", PARAVIEW_PY])
        .arg(xmf)
        .output()
        .expect("pvpython (ParaView) is installed by run/setup --paraview");
    assert!(out.status.success(), "pvpython: {}", stderr_text(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    let line = text.lines().rev().find(|l| l.starts_with('{')).unwrap();
    serde_json::from_str(line).unwrap()
}

/// `solver post ARGS`, which must succeed; its standard output.
fn post(args: &[&str]) -> String {
    let out = solver().arg("post").args(args).output().unwrap();
    assert!(out.status.success(), "post {args:?}: {}", stderr_text(&out));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Everything a file of `p`'s mesh is read by; `types` its VTK cell types.
fn reads_everywhere(p: &Problem, name: &str, types: &[u64]) -> PathBuf {
    let dir = fresh_dir(&format!("gmsh-tet/{name}"));
    let h5 = write(p, &dir, name);
    let f = ResultFile::open(&h5).unwrap();
    f.verify().unwrap();
    let mesh = f.mesh().unwrap();
    assert_eq!(mesh, solver::run::output_mesh(p, &p.mesh));
    let h5s = h5.display().to_string();
    let info = post(&["info", &h5s]);
    println!("{info}");
    let elements = format!(" {} in ", p.mesh.num_elements());
    assert!(
        info.lines()
            .any(|l| l.starts_with("elements:") && l.contains(&elements)),
        "{info}"
    );
    post(&["compare", &h5s, &h5s]);
    let exo = dir.join(format!("{name}.e"));
    post(&["exodus", &h5s, "-o", &exo.display().to_string()]);
    let again = parse_scene(&exodus_scene(&p.text, &exo), "exodus.toml", "exodus")
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(again.mesh.coords, p.mesh.coords);
    assert_eq!(again.mesh.elements, p.mesh.elements);
    assert_eq!(again.mesh.element_body, p.mesh.element_body);
    let kinds = |q: &Problem| q.mesh.bodies.iter().map(|b| b.kind).collect::<Vec<_>>();
    assert_eq!(kinds(&again), kinds(p));
    for (a, b) in again.side_sets.iter().zip(&p.side_sets) {
        assert_eq!(a.faces, b.faces, "side set {}", a.name);
    }
    for (a, b) in again.node_sets.iter().zip(&p.node_sets) {
        assert_eq!(a.nodes, b.nodes, "node set {}", a.name);
    }
    let v = paraview(&h5.with_extension("xmf"));
    println!("ParaView: {v}");
    assert_eq!(v["points"], p.mesh.num_nodes() as u64);
    assert_eq!(v["cells"], p.mesh.num_elements() as u64);
    assert_eq!(v["types"], serde_json::json!(types));
    assert_eq!(v["in_order"], true);
    let pictures = dir.join("render");
    let out = Command::new(repo("run/render"))
        .arg(h5.with_extension("xmf"))
        .arg("-o")
        .arg(&pictures)
        .output()
        .unwrap();
    assert!(out.status.success(), "run/render: {}", stderr_text(&out));
    assert!(pictures.join(format!("{name}.von_mises.png")).is_file());
    h5
}

/// VTK's cell types: 12 the hexahedron, 24 the quadratic tetrahedron.
const VTK_HEXAHEDRON: u64 = 12;
const VTK_QUADRATIC_TETRA: u64 = 24;

pub fn tet_result_file_reads_everywhere(p: &Problem) {
    let h5 = reads_everywhere(p, "tet", &[VTK_QUADRATIC_TETRA]);
    let f = ResultFile::open(&h5).unwrap();
    assert_eq!(f.shape("/mesh/all_connectivity").unwrap(), vec![184, 10]);
}

pub fn mixed_result_file_reads_everywhere(p: &Problem) {
    let h5 = reads_everywhere(p, "mixed", &[VTK_HEXAHEDRON, VTK_QUADRATIC_TETRA]);
    let f = ResultFile::open(&h5).unwrap();
    // XDMF's Mixed array: a type code before each element's nodes.
    assert_eq!(
        f.shape("/mesh/all_connectivity").unwrap(),
        vec![8 * 9 + 100 * 11]
    );
}
