//! Exodus II output (`solver run -o NAME.e`): every array of the .e read by an independent
//! reader (Python netCDF4, run/check_exodus.py) holds the HDF5 result's bits; the .e of a
//! 1-rank and a 3-rank run are the same bytes; ParaView's Exodus readers load it; a path
//! that cannot take it is refused before any work.
//!
//! The tools come from run/setup (python3-netcdf4, python3-h5py; ParaView with
//! `--paraview`, which run/tests passes).

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common;
use common::{repo, solver, stderr_text};

fn dir(name: &str) -> PathBuf {
    common::fresh_dir(&format!("exodus-tests/{name}"))
}

/// `solver run SCENE -o OUT` on `ranks` ranks (1: no mpirun); standard error on failure.
fn run_to(scene: &Path, out: &Path, ranks: usize) -> std::process::Output {
    let mut cmd = if ranks == 1 {
        solver()
    } else {
        let mut c = Command::new(repo("run/mpirun"));
        c.args(["-np", &ranks.to_string(), env!("CARGO_BIN_EXE_solver")]);
        c
    };
    cmd.arg("run")
        .arg(scene)
        .arg("-o")
        .arg(out)
        .arg("-q")
        .output()
        .expect("the solver starts")
}

/// The independent check of run/check_exodus.py: its last line and exit status.
fn check_exodus(e: &Path, h5: &Path) -> (bool, String) {
    let o = Command::new("/usr/bin/python3")
        .arg(repo("run/check_exodus.py"))
        .arg(e)
        .arg(h5)
        .output()
        .expect("/usr/bin/python3 starts (run/setup installs python3-netcdf4)");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    (o.status.success(), text)
}

/// Contact with friction over three blocks with side sets (stick_slip) and a plastic body
/// (plastic_indent, eqps): the .e and the .h5 of the same run, every array compared as
/// 64-bit patterns (tolerance 0: the .e is written from the .h5's values).
#[test]
fn every_exodus_array_holds_the_hdf5_results_bits() {
    let d = dir("bits");
    for (scene, arrays) in [
        (repo("run/scenes/paper/stick_slip.toml"), 62),
        (repo("mpi-tests/plastic_indent.toml"), 39),
    ] {
        let e = d.join(format!(
            "{}.e",
            scene.file_stem().unwrap().to_string_lossy()
        ));
        let o = run_to(&scene, &e, 1);
        assert!(o.status.success(), "{}", stderr_text(&o));
        let (ok, text) = check_exodus(&e, &e.with_extension("h5"));
        assert!(ok, "{text}");
        let want = format!("exodus check: {arrays} of {arrays} arrays bitwise equal");
        assert!(text.contains(&want), "expected '{want}':\n{text}");
    }
}

/// The Exodus file holds nothing that depends on the rank count: 1 and 3 ranks write the
/// same bytes (tolerance 0), here with contact captured and released.
#[test]
fn one_and_three_ranks_write_the_same_exodus_bytes() {
    let d = dir("ranks");
    let scene = repo("run/scenes/paper/capture_release.toml");
    let (a, b) = (d.join("np1.e"), d.join("np3.e"));
    for (out, ranks) in [(&a, 1), (&b, 3)] {
        let o = run_to(&scene, out, ranks);
        assert!(o.status.success(), "{ranks} ranks: {}", stderr_text(&o));
    }
    let (x, y) = (std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    assert!(x.len() > 10_000, "{} bytes", x.len());
    assert!(x == y, "{} and {} differ", a.display(), b.display());
}

/// pvpython: ParaView's ExodusIIReader and IOSSReader open the file and list its time
/// steps (the HDF5 file's, to the bit through repr) and variables.
const PARAVIEW_PY: &str = r#"
import json, sys
from paraview.simple import ExodusIIReader, IOSSReader
r = ExodusIIReader(FileName=[sys.argv[1]])
r.UpdatePipelineInformation()
r.UpdatePipeline(float(r.TimestepValues[-1]))
info = r.GetDataInformation()
i = IOSSReader(FileName=[sys.argv[1]])
i.UpdatePipelineInformation()
print(json.dumps({"times": [repr(float(t)) for t in r.TimestepValues],
    "point": list(r.PointVariables), "cell": list(r.ElementVariables),
    "global": list(r.GlobalVariables), "points": info.GetNumberOfPoints(),
    "cells": info.GetNumberOfCells(),
    "ioss_times": [repr(float(t)) for t in i.TimestepValues],
    "ioss_point": list(i.NodeBlockFields), "ioss_cell": list(i.ElementBlockFields)}))
"#;

#[test]
fn paraview_loads_the_exodus_file() {
    let d = dir("paraview");
    let e = d.join("bar.e");
    let o = run_to(&repo("run/examples/bar.toml"), &e, 1);
    assert!(o.status.success(), "{}", stderr_text(&o));
    let o = Command::new("pvpython")
        .args(["-c", PARAVIEW_PY])
        .arg(&e)
        .output()
        .expect("pvpython starts (run/setup --paraview)");
    let out = String::from_utf8_lossy(&o.stdout);
    let line = out.lines().rev().find(|l| l.starts_with('{'));
    let v: serde_json::Value = serde_json::from_str(
        line.unwrap_or_else(|| panic!("pvpython printed no JSON:\n{out}\n{}", stderr_text(&o))),
    )
    .unwrap();
    // bar: 4 steps up to t = 1 (the scene's [time]).
    let h5 = solver::output::ResultFile::open(&e.with_extension("h5")).unwrap();
    let times: Vec<String> = h5.time().unwrap().iter().map(|t| py_repr(*t)).collect();
    assert_eq!(times.len(), 4);
    assert_eq!(v["times"], serde_json::json!(times));
    assert_eq!(v["ioss_times"], serde_json::json!(times));
    assert_eq!(v["points"], h5.num_nodes());
    assert_eq!(v["cells"], h5.num_elements());
    let list = |k: &str| {
        v[k].as_array()
            .unwrap()
            .iter()
            .map(|s| s.as_str().unwrap().to_string())
            .collect::<Vec<_>>()
    };
    for name in ["contact_status", "contact_gap", "contact_pressure"] {
        assert!(list("point").iter().any(|p| p == name), "{v}");
    }
    assert!(list("point").iter().any(|p| p.starts_with("displ")), "{v}");
    assert!(list("ioss_point").iter().any(|p| p == "displ"), "{v}");
    assert_eq!(list("cell").len(), 6, "{v}");
    assert_eq!(list("global").len(), 9, "{v}");
}

/// Python's repr of a float: the shortest digits that read back to the same bits, which
/// Rust's `{:?}` also prints (with `e` exponents written alike for these times).
fn py_repr(t: f64) -> String {
    format!("{t:?}")
}

/// A file in the way that is not an Exodus file is refused before any work: exit 2, one
/// line naming it, neither the .e nor the .h5 written.
#[test]
fn an_existing_file_that_is_not_exodus_is_refused() {
    let d = dir("refused");
    let e = d.join("bar.e");
    std::fs::write(&e, "notes\n").unwrap();
    let o = run_to(&repo("run/examples/bar.toml"), &e, 1);
    assert_eq!(o.status.code(), Some(2), "{}", stderr_text(&o));
    let err = stderr_text(&o);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("bar.e") && err.contains("not an Exodus"),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(&e).unwrap(), "notes\n");
    assert!(!d.join("bar.h5").exists());
}
