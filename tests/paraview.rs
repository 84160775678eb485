//! Our results in ParaView: a result written by the solver is opened through ParaView's own
//! Xdmf3 readers (pvpython) and every array is checked against the HDF5 file read on its own
//! (python3-h5py); then run/render draws it and its pictures are checked.
//!
//! ParaView comes from `run/setup --paraview` (run/tests installs it); where it is missing
//! these tests fail with a message naming that option.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;

use crate::common;
/// A block pressed onto a wider base, then pushed sideways with Coulomb friction: at the
/// last step every result array is non-zero, nodes stick and slip, and all six stress
/// components differ (so a reordered tensor would show).
const SCENE: &str = r#"
name = "press"
kinematics = "small"

[[body]]
name = "base"
box = { min = [0.0, 0.0, 0.0], max = [2.0, 1.0, 2.0] }
divisions = [3, 2, 3]
material = { model = "linear_elastic", E = 1000.0, nu = 0.3 }

[[body]]
name = "block"
box = { min = [0.5, 1.0, 0.5], max = [1.5, 2.0, 1.5] }
divisions = [2, 2, 2]
material = { model = "linear_elastic", E = 1000.0, nu = 0.3 }

[[node_set]]
name = "bottom"
plane = { point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }

[[node_set]]
name = "top"
plane = { point = [0.0, 2.0, 0.0], normal = [0.0, 1.0, 0.0] }

[[side_set]]
name = "base_top"
body = "base"
plane = { point = [0.0, 1.0, 0.0], normal = [0.0, 1.0, 0.0] }

[[side_set]]
name = "block_bottom"
body = "block"
plane = { point = [0.0, 1.0, 0.0], normal = [0.0, 1.0, 0.0] }

[[displacement]]
node_set = "bottom"
components = ["x", "y", "z"]
value = 0.0

[[displacement]]
node_set = "top"
components = ["y"]
function = [[0.0, 0.0], [1.0, -0.02], [2.0, -0.02]]

[[displacement]]
node_set = "top"
components = ["x"]
function = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.01]]

[[displacement]]
node_set = "top"
components = ["z"]
function = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.004]]

[[contact]]
master = "base_top"
slave = "block_bottom"
friction = "coulomb"
mu = 0.3

[time]
segments = [{ end = 1.0, steps = 2 }, { end = 2.0, steps = 2 }]
"#;

/// Shared by both scripts below: one array as JSON (numbers as Python reprs, so that they
/// compare exactly as text; a SHA-256 of the values' bytes in row-major order).
const SUMMARY_PY: &str = r#"
import hashlib, json, sys
import numpy as np

def sha(v):
    return hashlib.sha256(np.ascontiguousarray(v).tobytes()).hexdigest()

def summary(v, association):
    flat = v.reshape(v.shape[0], -1)
    return {"association": association, "components": flat.shape[1], "tuples": flat.shape[0],
            "dtype": str(v.dtype), "min": [repr(float(x)) for x in flat.min(axis=0)],
            "max": [repr(float(x)) for x in flat.max(axis=0)], "sha256": sha(v)}
"#;

/// pvpython: every step of the .xmf through both of ParaView's Xdmf3 readers.
const PARAVIEW_PY: &str = r#"
from paraview import servermanager
from paraview.simple import Xdmf3ReaderS, Xdmf3ReaderT
from vtkmodules.util.numpy_support import vtk_to_numpy

out = {}
for label, Reader in (("Xdmf3ReaderS", Xdmf3ReaderS), ("Xdmf3ReaderT", Xdmf3ReaderT)):
    r = Reader(FileName=[sys.argv[1]])
    r.UpdatePipelineInformation()
    tv = r.TimestepValues
    times = [float(t) for t in tv] if hasattr(tv, "__len__") else [float(tv)]
    steps = []
    for t in times:
        r.UpdatePipeline(t)
        d = servermanager.Fetch(r)
        cells = d.GetCells()
        offsets = vtk_to_numpy(cells.GetOffsetsArray())
        arrays = {}
        for association, data in (("point", d.GetPointData()), ("cell", d.GetCellData())):
            for i in range(data.GetNumberOfArrays()):
                a = data.GetArray(i)
                arrays[a.GetName()] = summary(vtk_to_numpy(a), association)
        steps.append({
            "time": repr(t), "points": d.GetNumberOfPoints(), "cells": d.GetNumberOfCells(),
            "cell_types": sorted({d.GetCellType(i) for i in range(d.GetNumberOfCells())}),
            "nodes_per_cell": sorted({int(n) for n in np.diff(offsets)}),
            "points_sha256": sha(vtk_to_numpy(d.GetPoints().GetData()).astype(np.float64)),
            "connectivity_sha256": sha(vtk_to_numpy(cells.GetConnectivityArray()).astype(np.int64)),
            "arrays": arrays})
    out[label] = steps
print(json.dumps(out))
"#;

/// /usr/bin/python3 with h5py: the same per step, straight from the HDF5 datasets, plus the
/// last step's von Mises stress and contact force magnitudes (for run/render's numbers).
const HDF5_PY: &str = r#"
import h5py

DATASETS = {"displacement": ("point", "/results/displacement"),
            "reaction": ("point", "/results/reaction"),
            "contact_force": ("point", "/results/contact/force"),
            "contact_status": ("point", "/results/contact/status"),
            "contact_gap": ("point", "/results/contact/gap"),
            "stress": ("cell", "/results/stress")}
f = h5py.File(sys.argv[1], "r")
# Optional: files written before the contact pressure was recorded lack it.
if "/results/contact/pressure" in f:
    DATASETS["contact_pressure"] = ("point", "/results/contact/pressure")
times = f["/results/time"][:]
coords = f["/mesh/coordinates"][:]
conn = f["/mesh/all_connectivity"][:]
steps = []
for s, t in enumerate(times):
    steps.append({
        "time": repr(float(t)), "points": coords.shape[0], "cells": conn.shape[0],
        "cell_types": [12], "nodes_per_cell": [conn.shape[1]],
        "points_sha256": sha(coords.astype(np.float64)),
        "connectivity_sha256": sha(conn.astype(np.int64)),
        "arrays": {name: summary(f[path][s], association)
                   for name, (association, path) in DATASETS.items()}})
st = f["/results/stress"][-1]
vm = np.sqrt(0.5 * ((st[:, 0] - st[:, 1])**2 + (st[:, 1] - st[:, 2])**2
                    + (st[:, 2] - st[:, 0])**2)
             + 3.0 * (st[:, 3]**2 + st[:, 4]**2 + st[:, 5]**2))
status = f["/results/contact/status"][-1]
force = f["/results/contact/force"][-1]
touching = (status == 1) | (status == 2)
fmag = np.sqrt((force * force).sum(axis=1))[touching]
print(json.dumps({"steps": steps, "last": {
    "time": float(times[-1]), "von_mises": [float(vm.min()), float(vm.max())],
    "nodes_in_contact": int(touching.sum()),
    "contact_force_magnitude": [float(fmag.min()), float(fmag.max())] if len(fmag) else None,
    "contact_force_total": [float(v) for v in force[touching].sum(axis=0)]}}))
"#;

/// pvpython: size, share of pixels that are not the white background, and distinct colours
/// of a PNG.
const PNG_PY: &str = r#"
import sys
import numpy as np
from vtkmodules.vtkIOImage import vtkPNGReader
from vtkmodules.util.numpy_support import vtk_to_numpy
r = vtkPNGReader()
r.SetFileName(sys.argv[1])
r.Update()
img = r.GetOutput()
w, h, _ = img.GetDimensions()
px = vtk_to_numpy(img.GetPointData().GetScalars())[:, :3]
drawn = np.any(px < 250, axis=1).mean()
colours = len(np.unique(px.astype(np.uint32) @ np.array([65536, 256, 1], dtype=np.uint32)))
print(w, h, drawn, colours)
"#;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A fresh, empty directory for one test.
fn test_dir(name: &str) -> PathBuf {
    common::fresh_dir(&format!("paraview-tests/{name}"))
}

fn succeeds(cmd: &mut Command) -> bool {
    cmd.output().map(|o| o.status.success()).unwrap_or(false)
}

/// The tools are here, or the test fails naming what is missing and the `run/setup` option
/// that installs it (never a silent pass).
fn require_tools(test: &str, need_xvfb: bool) {
    let mut missing = Vec::new();
    if !succeeds(Command::new("pvpython").args(["-c", "import paraview.simple"])) {
        missing.push("pvpython with paraview.simple (Debian: paraview, python3-paraview)");
    }
    if need_xvfb && !succeeds(Command::new("Xvfb").arg("-help")) {
        missing.push("Xvfb (Debian: xvfb)");
    }
    if !succeeds(Command::new("/usr/bin/python3").args(["-c", "import h5py"])) {
        missing.push("/usr/bin/python3 with h5py (Debian: python3-h5py)");
    }
    assert!(
        missing.is_empty(),
        "{test}: missing {}; `run/setup --paraview` installs them",
        missing.join(", ")
    );
}

fn run(cmd: &mut Command) -> Output {
    let out = cmd.output().unwrap_or_else(|e| panic!("{cmd:?}: {e}"));
    assert!(
        out.status.success(),
        "{cmd:?} exited with {}\nstdout:\n{}\nstderr:\n{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Runs a Python script (the shared summary code first) and parses the JSON it prints; also
/// returns its standard error.
fn python_json(
    interpreter: &str,
    dir: &Path,
    name: &str,
    body: &str,
    arg: &Path,
) -> (Value, String) {
    let script = dir.join(name);
    std::fs::write(&script, format!("{SUMMARY_PY}\n{body}")).unwrap();
    let out = run(Command::new(interpreter)
        .arg(&script)
        .arg(arg)
        // pvpython links Open MPI, which refuses to start as root without these.
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1"));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let last = stdout.lines().last().unwrap_or("");
    let value = serde_json::from_str(last).unwrap_or_else(|e| panic!("{name}: {e}\n{stdout}"));
    (value, String::from_utf8_lossy(&out.stderr).into_owned())
}

/// The scene solved by the solver binary: (result .h5, its .xmf), absolute paths.
fn solve_scene(dir: &Path) -> (PathBuf, PathBuf) {
    let scene = dir.join("press.toml");
    std::fs::write(&scene, SCENE).unwrap();
    let h5 = dir.join("press.h5");
    run(Command::new(env!("CARGO_BIN_EXE_solver"))
        .args(["-q", "run"])
        .arg(&scene)
        .arg("-o")
        .arg(&h5));
    let xmf = dir.join("press.xmf");
    assert!(xmf.exists(), "{} was not written", xmf.display());
    (
        std::fs::canonicalize(h5).unwrap(),
        std::fs::canonicalize(xmf).unwrap(),
    )
}

/// Differences between ParaView's view of one step and the HDF5 file's, one line each.
fn step_differences(reader: &str, step: usize, pv: &Value, h5: &Value) -> Vec<String> {
    let mut diffs = Vec::new();
    let at = format!("{reader}, step {step}");
    for key in [
        "time",
        "points",
        "cells",
        "cell_types",
        "nodes_per_cell",
        "points_sha256",
        "connectivity_sha256",
    ] {
        if pv[key] != h5[key] {
            diffs.push(format!(
                "{at}: {key}: ParaView {} , HDF5 {}",
                pv[key], h5[key]
            ));
        }
    }
    let names = |v: &Value| -> Vec<String> {
        v["arrays"]
            .as_object()
            .map(|m| m.keys().cloned().collect())
            .unwrap_or_default()
    };
    if names(pv) != names(h5) {
        diffs.push(format!(
            "{at}: arrays: ParaView {:?}, HDF5 {:?}",
            names(pv),
            names(h5)
        ));
    }
    for name in names(h5) {
        let (a, b) = (&pv["arrays"][&name], &h5["arrays"][&name]);
        if a.is_null() {
            continue;
        }
        for key in [
            "association",
            "components",
            "tuples",
            "dtype",
            "min",
            "max",
            "sha256",
        ] {
            if a[key] != b[key] {
                diffs.push(format!(
                    "{at}: {name}.{key}: ParaView {}, HDF5 {}",
                    a[key], b[key]
                ));
            }
        }
    }
    diffs
}

#[test]
fn paraview_reads_every_array_of_a_result_as_the_hdf5_file_holds_it() {
    require_tools(
        "paraview_reads_every_array_of_a_result_as_the_hdf5_file_holds_it",
        false,
    );
    let dir = test_dir("read");
    let (h5, xmf) = solve_scene(&dir);
    let (reference, _) = python_json("/usr/bin/python3", &dir, "hdf5.py", HDF5_PY, &h5);
    let (paraview, stderr) = python_json("pvpython", &dir, "read_xdmf.py", PARAVIEW_PY, &xmf);
    // What the readers say when they drop an attribute they cannot type.
    assert!(
        !stderr.contains("Skipping unrecognized array type"),
        "{stderr}"
    );

    let steps = reference["steps"].as_array().unwrap();
    assert_eq!(steps.len(), 4, "steps in the HDF5 file");
    // The check means something only if the arrays do: at the last step all six stress
    // components have different ranges and nodes are in contact.
    let last = &steps[3]["arrays"];
    let ranges: std::collections::BTreeSet<String> = (0..6)
        .map(|c| format!("{} {}", last["stress"]["min"][c], last["stress"]["max"][c]))
        .collect();
    assert_eq!(ranges.len(), 6, "stress components: {}", last["stress"]);
    assert!(
        last.get("contact_pressure").is_some(),
        "the solver's file has the contact pressure: {last}"
    );
    assert!(
        reference["last"]["nodes_in_contact"].as_u64().unwrap() > 0,
        "{}",
        reference["last"]
    );

    let mut diffs = Vec::new();
    let mut report = BTreeMap::new();
    for reader in ["Xdmf3ReaderS", "Xdmf3ReaderT"] {
        let got = paraview[reader].as_array().unwrap();
        if got.len() != steps.len() {
            diffs.push(format!(
                "{reader}: {} time steps, the HDF5 file has {}",
                got.len(),
                steps.len()
            ));
            continue;
        }
        for (s, (pv, h)) in got.iter().zip(steps).enumerate() {
            diffs.extend(step_differences(reader, s, pv, h));
        }
        report.insert(reader, got.len());
    }
    assert!(
        diffs.is_empty(),
        "ParaView and the HDF5 file differ:\n{}",
        diffs.join("\n")
    );
    // What was compared, shown with --nocapture.
    let arrays: Vec<String> = last
        .as_object()
        .unwrap()
        .iter()
        .map(|(k, v)| {
            format!(
                "{k} ({}, {} x {})",
                v["association"], v["tuples"], v["components"]
            )
        })
        .collect();
    println!(
        "ParaView's Xdmf3ReaderS and Xdmf3ReaderT read {} steps of {} points and {} cells; \
         per step every array, its range per component and its SHA-256 equal the HDF5 file's: {}",
        steps.len(),
        steps[0]["points"],
        steps[0]["cells"],
        arrays.join(", ")
    );
}

#[test]
fn run_render_draws_the_last_step_with_the_values_of_the_file() {
    require_tools(
        "run_render_draws_the_last_step_with_the_values_of_the_file",
        true,
    );
    let dir = test_dir("render");
    let (h5, xmf) = solve_scene(&dir);
    let (reference, _) = python_json("/usr/bin/python3", &dir, "hdf5.py", HDF5_PY, &h5);
    let pictures = dir.join("pictures");
    let out = run(Command::new(root().join("run/render"))
        .arg(&xmf)
        .arg("-o")
        .arg(&pictures));
    let stdout = String::from_utf8_lossy(&out.stdout);
    println!("{stdout}");

    let info: Value =
        serde_json::from_str(&std::fs::read_to_string(pictures.join("press.render.json")).unwrap())
            .unwrap();
    let last = &reference["last"];
    assert_eq!(info["time"], last["time"], "{info}");
    assert_eq!(info["steps"], 4, "{info}");
    let scale = info["warp_scale"].as_f64().unwrap();
    assert!(scale >= 1.0, "{info}");
    assert!(
        stdout.contains(&format!("displacement x {scale}")),
        "{stdout}"
    );
    let close = |a: &Value, b: &Value| {
        let (a, b) = (a.as_f64().unwrap(), b.as_f64().unwrap());
        (a - b).abs() <= 1e-12 * b.abs().max(1e-300)
    };
    let vm = &info["pictures"]["von_mises"];
    assert!(
        close(&vm["min"], &last["von_mises"][0]) && close(&vm["max"], &last["von_mises"][1]),
        "von Mises: run/render {vm}, from the HDF5 stress {}",
        last["von_mises"]
    );
    let contact = &info["pictures"]["contact"];
    assert_eq!(
        contact["nodes_in_contact"], last["nodes_in_contact"],
        "{contact}"
    );
    assert!(
        close(&contact["min"], &last["contact_force_magnitude"][0])
            && close(&contact["max"], &last["contact_force_magnitude"][1]),
        "contact force: run/render {contact}, from the HDF5 file {}",
        last["contact_force_magnitude"]
    );
    let scale_of_forces = last["contact_force_magnitude"][1].as_f64().unwrap();
    for c in 0..3 {
        let (a, b) = (
            contact["total"][c].as_f64().unwrap(),
            last["contact_force_total"][c].as_f64().unwrap(),
        );
        assert!(
            (a - b).abs() <= 1e-12 * scale_of_forces,
            "total contact force: run/render {}, from the HDF5 file {}",
            contact["total"],
            last["contact_force_total"]
        );
    }

    let png_check = dir.join("png.py");
    std::fs::write(&png_check, PNG_PY).unwrap();
    for picture in ["press.von_mises.png", "press.contact.png"] {
        let path = pictures.join(picture);
        let bytes = std::fs::read(&path).unwrap();
        assert!(
            bytes.starts_with(b"\x89PNG\r\n\x1a\n"),
            "{picture} is not a PNG"
        );
        let out = run(Command::new("pvpython").arg(&png_check).arg(&path));
        let stdout = String::from_utf8_lossy(&out.stdout);
        let w: Vec<f64> = stdout
            .split_whitespace()
            .map(|v| v.parse().unwrap())
            .collect();
        assert_eq!(w[0], 1200.0, "{picture}: width {stdout}");
        // Drawn on: a fifth of the pixels at least, in many colours (shading and colour map).
        assert!(w[2] > 0.2, "{picture}: {stdout}");
        assert!(w[3] > 100.0, "{picture}: {stdout}");
        println!(
            "{picture}: {} x {} pixels, {:.0}% drawn, {} colours",
            w[0],
            w[1],
            100.0 * w[2],
            w[3]
        );
    }
}
