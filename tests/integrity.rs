//! Integrity of result files: a bit flipped in any per-step dataset or in the restart state
//! is found by its checksum, and `post info`, `post compare` and `--restart` refuse the file
//! naming the dataset (and the step); a NaN in restart data is refused when it is loaded.

use std::path::{Path, PathBuf};

use crate::common;
use common::{fresh_dir, paper_scene, restart, solver, stderr_text};

fn dir(name: &str) -> PathBuf {
    fresh_dir(&format!("integrity-{name}"))
}

/// A finished result of `capture_release` (contact captured and released, 50 steps).
fn result(d: &Path) -> PathBuf {
    let path = d.join("good.h5");
    let s = solver()
        .args(["-q", "run", &paper_scene("capture_release"), "-o"])
        .arg(&path)
        .status()
        .unwrap();
    assert!(s.success());
    path
}

/// A chunk: its first row, its offset in the file, its size in bytes.
type Chunk = (usize, u64, u64);

/// Every dataset with data of the file, with its chunks.
fn chunks(path: &Path) -> Vec<(String, Vec<Chunk>)> {
    let f = hdf5::File::open(path).unwrap();
    let file = solver::output::ResultFile::open(path).unwrap();
    let mut out = Vec::new();
    for name in file.dataset_names() {
        let ds = f.dataset(&name).unwrap();
        let n = ds.num_chunks().unwrap_or(0);
        let c: Vec<_> = (0..n)
            .map(|i| {
                let info = ds.chunk_info(i).unwrap();
                (info.offset[0] as usize, info.addr, info.size)
            })
            .collect();
        if !c.is_empty() {
            out.push((name, c));
        }
    }
    out
}

fn run(args: &[&str], files: &[&Path]) -> (Option<i32>, String) {
    let mut cmd = solver();
    cmd.args(args);
    for f in files {
        cmd.arg(f);
    }
    let out = cmd.output().unwrap();
    (out.status.code(), stderr_text(&out))
}

#[test]
fn a_flipped_bit_in_any_per_step_or_restart_dataset_is_refused() {
    let d = dir("flips");
    let good = result(&d);
    let all = chunks(&good);
    let targets: Vec<_> = all
        .iter()
        .filter(|(n, _)| {
            n.starts_with("/results/") || n.starts_with("/stats/") || n.starts_with("/restart/")
        })
        .collect();
    // Every per-step dataset of the layout and the ten datasets of the two restart slots
    // (less those empty at the last step: no chunk to flip).
    let per_step = targets
        .iter()
        .filter(|(n, _)| !n.starts_with("/restart/"))
        .count();
    assert_eq!(
        per_step,
        18,
        "{:?}",
        targets.iter().map(|t| &t.0).collect::<Vec<_>>()
    );
    let restart = targets.len() - per_step;
    assert!(restart >= 6, "restart datasets with data: {restart}");
    let bytes = std::fs::read(&good).unwrap();
    let mut rng = common::Rng::new(7);
    let mut refused = [0usize; 3];
    for (k, (name, chunks)) in targets.iter().enumerate() {
        // A random chunk, a random bit of it (data or its four checksum bytes).
        let pick = |r: f64, n: u64| (((r + 1.0) * 0.5 * n as f64) as u64).min(n - 1);
        let (row, addr, size) = chunks[pick(rng.next(), chunks.len() as u64) as usize];
        let byte = addr + pick(rng.next(), size);
        let bit = pick(rng.next(), 8);
        let mut flipped = bytes.clone();
        flipped[byte as usize] ^= 1 << bit;
        let path = d.join(format!("flipped_{k}.h5"));
        std::fs::write(&path, &flipped).unwrap();
        let expected = if name.starts_with("/restart/") {
            format!("damaged: {name}:")
        } else {
            format!("damaged: {name}, step {row}:")
        };
        let out = d.join(format!("restarted_{k}.h5"));
        let attempts = [
            run(&["post", "info"], &[&path]),
            run(&["post", "compare"], &[&good, &path]),
            run(
                &["-q", "run", &paper_scene("capture_release"), "--restart"],
                &[&path, Path::new("-o"), &out],
            ),
        ];
        for (i, (code, err)) in attempts.iter().enumerate() {
            assert_eq!(*code, Some(2), "{name} (byte {byte}, bit {bit}): {err}");
            assert!(
                err.contains(&expected),
                "{name}: expected `{expected}` in: {err}"
            );
            assert_eq!(err.lines().count(), 1, "{err}");
            refused[i] += 1;
        }
        assert!(!out.exists(), "a refused restart publishes nothing");
        println!("{name}: byte {byte} bit {bit}: {}", attempts[0].1);
    }
    println!(
        "{} datasets flipped ({per_step} per-step, {restart} restart): refused by post info {}, post compare {}, --restart {}",
        targets.len(),
        refused[0],
        refused[1],
        refused[2]
    );
}

/// Writes `value` at index `at` of a dataset of a result file through HDF5 (so its checksum
/// is right).
fn poke(path: &Path, dataset: &str, at: usize, value: f64) {
    let f = hdf5::File::open_rw(path).unwrap();
    let ds = f.dataset(dataset).unwrap();
    let mut v: Vec<f64> = ds.read_raw().unwrap();
    v[at] = value;
    ds.write_raw(&v).unwrap();
}

#[test]
fn a_nan_in_restart_data_is_refused_when_loaded() {
    let d = dir("nan");
    let good = result(&d);
    let f = solver::output::ResultFile::open(&good).unwrap();
    let steps = f.num_steps();
    drop(f);
    // The newest slot is the one of the last row (rows % 2); both are checked.
    let newest = format!("/restart/slot{}", steps % 2);
    let cases = [
        (
            format!("{newest}/displacement"),
            7,
            f64::NAN,
            "value 7 is NaN",
        ),
        (
            format!("{newest}/previous_displacement"),
            0,
            f64::INFINITY,
            "value 0 is inf",
        ),
        (format!("{newest}/state"), 3, f64::NAN, "value 3 is NaN"),
    ];
    for (k, (dataset, at, value, what)) in cases.iter().enumerate() {
        let path = d.join(format!("nan_{k}.h5"));
        std::fs::copy(&good, &path).unwrap();
        poke(&path, dataset, *at, *value);
        let out = d.join(format!("out_{k}.h5"));
        let (code, err) = run(
            &["-q", "run", &paper_scene("capture_release"), "--restart"],
            &[&path, Path::new("-o"), &out],
        );
        println!("{dataset}: {err}");
        assert_eq!(code, Some(2), "{err}");
        assert!(
            err.contains(&format!("damaged: {dataset}: {what}")),
            "{err}"
        );
        assert!(!out.exists());
    }
    // A NaN in a step the restart copies: named with the dataset, the step and the node.
    let path = d.join("nan_step.h5");
    std::fs::copy(&good, &path).unwrap();
    {
        let f = hdf5::File::open_rw(&path).unwrap();
        let ds = f.dataset("/results/reaction").unwrap();
        let mut v: Vec<f64> = ds.read_raw().unwrap();
        let per_step = v.len() / steps;
        v[5 * per_step + 3 * 2 + 1] = f64::NAN; // step 5, node 2, component 1
        ds.write_raw(&v).unwrap();
    }
    let (code, err) = run(
        &["-q", "run", &paper_scene("capture_release"), "--restart"],
        &[&path, Path::new("-o"), &d.join("out_step.h5")],
    );
    println!("/results/reaction: {err}");
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("damaged: /results/reaction, step 5: node 2 (id 3), component 1 is NaN"),
        "{err}"
    );
    // Likewise in the contact pressure, a scalar per node.
    let path = d.join("nan_pressure.h5");
    std::fs::copy(&good, &path).unwrap();
    poke(
        &path,
        "/results/contact/pressure",
        7 * (per_node(&path)) + 4,
        f64::INFINITY,
    );
    let (code, err) = run(
        &["-q", "run", &paper_scene("capture_release"), "--restart"],
        &[&path, Path::new("-o"), &d.join("out_pressure.h5")],
    );
    println!("/results/contact/pressure: {err}");
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("damaged: /results/contact/pressure, step 7: node 4 (id 5) is inf"),
        "{err}"
    );
}

/// Number of nodes of a result file.
fn per_node(path: &Path) -> usize {
    solver::output::ResultFile::open(path).unwrap().num_nodes()
}

/// Turns a format 2 file into the layout of format 1: one restart block `/restart/<name>`
/// (the newest slot's datasets, hard-linked there), `format_version` 1, and no contact
/// pressure (recorded only since a later version of format 2).
fn to_format_1(path: &Path) {
    let f = hdf5::File::open_rw(path).unwrap();
    let rows = |k: usize| -> f64 {
        let name = format!("/restart/slot{k}/state");
        f.dataset(&name)
            .map_or(-1.0, |d| d.read_raw::<f64>().unwrap()[4])
    };
    let newest = if rows(1) > rows(0) { 1 } else { 0 };
    for name in [
        "state",
        "displacement",
        "previous_displacement",
        "contact",
        "released",
    ] {
        f.link_hard(
            &format!("/restart/slot{newest}/{name}"),
            &format!("/restart/{name}"),
        )
        .unwrap();
    }
    for k in 0..2 {
        if f.link_exists(&format!("/restart/slot{k}")) {
            f.unlink(&format!("/restart/slot{k}")).unwrap();
        }
    }
    f.unlink("/results/contact/pressure").unwrap();
    f.delete_attr("format_version").unwrap();
    f.new_attr::<u64>()
        .shape(())
        .create("format_version")
        .unwrap()
        .write_scalar(&1u64)
        .unwrap();
}

#[test]
fn a_format_1_file_is_still_read_and_restarted_from() {
    let d = dir("format1");
    let full = result(&d);
    // A run killed after step 23 (of 50), in the layout of format 1.
    let cut = d.join("cut.h5");
    let s = solver()
        .args(["-q", "run", &paper_scene("capture_release"), "-o"])
        .arg(&cut)
        .env("SOLVER_TEST_ABORT_AFTER_STEP", "23")
        .status()
        .unwrap();
    assert!(!s.success());
    let old = d.join("old.h5");
    std::fs::rename(d.join("cut.h5.tmp"), &old).unwrap();
    to_format_1(&old);
    let info = solver().args(["post", "info"]).arg(&old).output().unwrap();
    let text = String::from_utf8_lossy(&info.stdout);
    assert!(
        info.status.success(),
        "{}",
        String::from_utf8_lossy(&info.stderr)
    );
    assert!(
        text.contains("checksums:    none (format version 1)"),
        "{text}"
    );
    let o = solver()
        .args(["run", &paper_scene("capture_release"), "--restart"])
        .arg(&old)
        .arg("-o")
        .arg(&cut)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("continuing from step 23 "), "{err}");
    let (_, report) = restart::post_compare(&full, &cut);
    println!("{}", report.lines().last().unwrap_or_default());
    assert!(report.contains("result: bitwise identical"), "{report}");
    assert!(
        report.contains("only in a: /results/contact/pressure"),
        "{report}"
    );
}
