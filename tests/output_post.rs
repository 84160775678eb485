//! Reading result files back: `post compare`, `post info`, `post plot`, bad files, and the
//! independent Python check (run/check_h5.py). The files are the synthetic ones of
//! tests/output.rs (`common::synthetic`).

use std::path::Path;

use clap::Parser;
use solver::output::{layout, OutputError, ResultFile, ResultWriter, StepStats};
use solver::post::{self, PostCommand};

use crate::common;
use common::synthetic::{
    synthetic_info, synthetic_mesh, synthetic_step, test_dir, write_synthetic,
};

/// A file written before the contact pressure was recorded (its steps have none): read as
/// before, `post` says the pressure is not there, `compare` lists the dataset as one-sided.
#[test]
fn a_file_without_contact_pressure_is_read_as_before() {
    let dir = test_dir("no_pressure");
    let mesh = synthetic_mesh();
    let mut w = ResultWriter::create(&dir.join("old.h5"), &synthetic_info(), &mesh).unwrap();
    for s in 0..3 {
        let mut step = synthetic_step(s, &mesh);
        step.contact_pressure.clear();
        w.append_step(&step).unwrap();
    }
    let old = w.finish(1.0).unwrap();
    let f = ResultFile::open(&old).unwrap();
    assert!(!f.has_contact_pressure());
    assert!(!f
        .dataset_names()
        .contains(&layout::CONTACT_PRESSURE.to_string()));
    assert_eq!(f.contact_pressure(2).unwrap(), None);
    assert!(matches!(
        f.contact_pressure(3),
        Err(OutputError::StepOutOfRange { .. })
    ));
    assert_eq!(f.gap(1).unwrap(), synthetic_step(1, &mesh).contact_gap);
    let xmf = std::fs::read_to_string(dir.join("old.xmf")).unwrap();
    assert!(!xmf.contains("contact_pressure"), "{xmf}");
    assert!(xmf.contains("Name=\"contact_gap\""));

    let text = post::info_text(&old).unwrap();
    assert!(
        text.contains("contact pressure: not in this file"),
        "{text}"
    );
    let png = dir.join("p.png");
    let cmd = parse(&[
        "plot",
        old.to_str().unwrap(),
        "--quantity",
        "contact_pressure",
        "--node-set",
        "top",
        "--against",
        "x",
        "-o",
        png.to_str().unwrap(),
    ])
    .unwrap();
    let err = post::run_post(&cmd).unwrap_err().to_string();
    assert!(
        err.contains("old.h5") && err.contains("no /results/contact/pressure in this file"),
        "{err}"
    );
    assert!(!png.exists());

    // Against a file that has it: every common dataset compared, the pressure one-sided.
    let new = write_synthetic(&dir, "new", 3);
    let report = post::compare_files(&old, &new, 0.0).unwrap();
    assert_eq!(report.exit_code(), 0, "{}", report.render());
    assert_eq!(report.only_in_b, [layout::CONTACT_PRESSURE]);
    assert!(report.only_in_a.is_empty());

    // A file whose first step has no pressure (a run continued from such a file) gets none
    // for later steps either: no dataset with rows that belong to no step.
    let mut w = ResultWriter::create(&dir.join("cont.h5"), &synthetic_info(), &mesh).unwrap();
    for s in 0..3 {
        let mut step = synthetic_step(s, &mesh);
        if s == 0 {
            step.contact_pressure.clear();
        }
        w.append_step(&step).unwrap();
    }
    let cont = w.finish(1.0).unwrap();
    let f = ResultFile::open(&cont).unwrap();
    assert!(!f.has_contact_pressure());
    assert_eq!(f.num_steps(), 3);
}

#[test]
fn compare_identical_within_and_beyond_tolerance_and_mismatched_meshes() {
    let dir = test_dir("compare");
    let a = write_synthetic(&dir, "a", 3);
    compare_the_same_data(&dir, &a);
    compare_one_value_off(&dir, &a);
    compare_counted_statistics(&dir, &a);
    compare_mismatched_meshes_and_step_counts(&dir, &a);
}

/// Same data as `a`; wall times and partition differ, which never counts.
fn compare_the_same_data(dir: &Path, a: &Path) {
    let a = a.to_path_buf();
    let mesh = synthetic_mesh();
    let mut info = synthetic_info();
    info.element_rank = vec![0, 0, 0];
    info.ranks = 1;
    let mut w = ResultWriter::create(&dir.join("b.h5"), &info, &mesh).unwrap();
    for s in 0..3 {
        let mut step = synthetic_step(s, &mesh);
        step.stats.wall_time *= 3.0;
        w.append_step(&step).unwrap();
    }
    let b = w.finish(99.0).unwrap();
    let report = post::compare_files(&a, &b, 0.0).unwrap();
    let text = report.render();
    assert_eq!(report.exit_code(), 0, "{text}");
    assert!(report.bitwise_identical());
    assert!(text.contains("bitwise identical"), "{text}");
    assert!(text.contains("/stats/wall_time"), "{text}");
    assert!(text.contains("not counted"), "{text}");
    let cmd = PostCommand::Compare {
        a: a.clone(),
        b: b.clone(),
        tol: 0.0,
        only: Vec::new(),
    };
    assert_eq!(post::run_post(&cmd).unwrap(), 0);
}

/// One displacement value off by a relative 1e-6 of the dataset's largest value.
fn compare_one_value_off(dir: &Path, a: &Path) {
    let a = a.to_path_buf();
    let mesh = synthetic_mesh();
    let mut w = ResultWriter::create(&dir.join("c.h5"), &synthetic_info(), &mesh).unwrap();
    for s in 0..3 {
        let mut step = synthetic_step(s, &mesh);
        if s == 2 {
            step.displacement[7][2] += 3.0 * 1e-6;
        }
        w.append_step(&step).unwrap();
    }
    let c = w.finish(1.0).unwrap();
    let report = post::compare_files(&a, &c, 0.0).unwrap();
    let text = report.render();
    assert_eq!(report.exit_code(), 1, "{text}");
    assert!(text.contains("EXCEEDS"), "{text}");
    assert!(
        text.contains("DIFFERENT") && text.contains("/results/displacement"),
        "{text}"
    );
    let d = report
        .datasets
        .iter()
        .find(|d| d.name == "/results/displacement")
        .unwrap();
    assert_eq!(d.differing, 1);
    assert!((d.max_rel_diff - 1e-6).abs() < 1e-9, "{}", d.max_rel_diff);
    let cmd = PostCommand::Compare {
        a: a.clone(),
        b: c.clone(),
        tol: 1e-8,
        only: Vec::new(),
    };
    assert_eq!(post::run_post(&cmd).unwrap(), 1);
    let report = post::compare_files(&a, &c, 1e-5).unwrap();
    assert_eq!(report.exit_code(), 0, "{}", report.render());
    assert!(!report.bitwise_identical());
    assert!(report.render().contains("within tolerance"));
}

/// A counted statistic differing fails; so do the contact statistics, a released count and
/// a penetration, each off in one step.
fn compare_counted_statistics(dir: &Path, a: &Path) {
    let mesh = synthetic_mesh();
    let mut w = ResultWriter::create(&dir.join("d.h5"), &synthetic_info(), &mesh).unwrap();
    for s in 0..3 {
        let mut step = synthetic_step(s, &mesh);
        step.stats.cg_iterations += 1;
        w.append_step(&step).unwrap();
    }
    let d = w.finish(1.0).unwrap();
    let report = post::compare_files(a, &d, 0.0).unwrap();
    assert_eq!(report.exit_code(), 1);
    assert!(report.render().contains("/stats/cg_iterations"));

    for (name, change) in [
        (
            "/stats/contact_released",
            (|st: &mut StepStats| st.contact_released += 1) as fn(&mut StepStats),
        ),
        ("/stats/max_penetration", |st| st.max_penetration += 1e-9),
    ] {
        let file = dir.join(format!("d{}.h5", name.len()));
        let mut w = ResultWriter::create(&file, &synthetic_info(), &mesh).unwrap();
        for s in 0..3 {
            let mut step = synthetic_step(s, &mesh);
            if s == 1 {
                change(&mut step.stats);
            }
            w.append_step(&step).unwrap();
        }
        let d = w.finish(1.0).unwrap();
        let report = post::compare_files(a, &d, 0.0).unwrap();
        let text = report.render();
        assert_eq!(report.exit_code(), 1, "{text}");
        let failing: Vec<&str> = report
            .datasets
            .iter()
            .filter(|d| d.counted && !d.within_tol)
            .map(|d| d.name.as_str())
            .collect();
        assert_eq!(failing, [name], "{text}");
    }
}

/// Different meshes or step counts cannot be compared, nor with a negative tolerance.
fn compare_mismatched_meshes_and_step_counts(dir: &Path, a: &Path) {
    let a = a.to_path_buf();
    let mut m = synthetic_mesh();
    m.coordinates.pop();
    m.node_ids.pop();
    for set in &mut m.node_sets {
        set.1.retain(|&id| id != 39);
    }
    m.bodies[1].connectivity[1][6] = 0;
    let mut w = ResultWriter::create(&dir.join("e.h5"), &synthetic_info(), &m).unwrap();
    for s in 0..3 {
        w.append_step(&synthetic_step(s, &m)).unwrap();
    }
    let e = w.finish(1.0).unwrap();
    let err = post::compare_files(&a, &e, 0.0).unwrap_err();
    assert!(matches!(err, OutputError::Mismatch { .. }), "{err}");
    assert!(err.to_string().contains("/mesh/coordinates"), "{err}");
    assert!(post::run_post(&PostCommand::Compare {
        a: a.clone(),
        b: e,
        tol: 0.0,
        only: Vec::new(),
    })
    .is_err());

    let mut m = synthetic_mesh();
    m.bodies[1].connectivity[1].swap(0, 1);
    let mut w = ResultWriter::create(&dir.join("f.h5"), &synthetic_info(), &m).unwrap();
    for s in 0..3 {
        w.append_step(&synthetic_step(s, &m)).unwrap();
    }
    let f = w.finish(1.0).unwrap();
    let err = post::compare_files(&a, &f, 0.0).unwrap_err().to_string();
    assert!(
        err.contains("meshes differ") && err.contains("connectivity"),
        "{err}"
    );

    let short = write_synthetic(dir, "short", 2);
    let err = post::compare_files(&a, &short, 0.0)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("/results/displacement has shape [3, 20, 3] in a, [2, 20, 3] in b"),
        "{err}"
    );

    assert!(post::compare_files(&a, &a, -1.0).is_err());
}

#[test]
fn bad_files_give_clear_errors() {
    let dir = test_dir("bad_files");
    let missing = dir.join("missing.h5");
    let err = ResultFile::open(&missing).err().unwrap();
    assert!(matches!(err, OutputError::NotFound { .. }), "{err}");
    assert!(
        err.to_string().contains("missing.h5: no such file"),
        "{err}"
    );

    let text = dir.join("text.h5");
    std::fs::write(&text, "this is not an HDF5 file\n".repeat(40)).unwrap();
    let err = ResultFile::open(&text).err().unwrap();
    assert!(matches!(err, OutputError::NotHdf5 { .. }), "{err}");
    assert!(err.to_string().contains("not an HDF5 file"), "{err}");

    let empty = dir.join("empty.h5");
    std::fs::write(&empty, "").unwrap();
    let err = ResultFile::open(&empty).err().unwrap();
    assert!(err.to_string().contains("empty"), "{err}");

    let good = write_synthetic(&dir, "good", 3);
    let bytes = std::fs::read(&good).unwrap();
    for keep in [bytes.len() / 2, bytes.len() - 100, 600, 40] {
        let truncated = dir.join(format!("truncated_{keep}.h5"));
        std::fs::write(&truncated, &bytes[..keep]).unwrap();
        let err = ResultFile::open(&truncated).err().unwrap();
        assert!(
            matches!(err, OutputError::Corrupt { .. }),
            "truncated to {keep} bytes: {err}"
        );
        assert!(err.to_string().contains("truncated"), "{err}");
        assert!(post::info_text(&truncated).is_err());
    }

    // An HDF5 file that is not a result file.
    let other = dir.join("other.h5");
    {
        let f = hdf5::File::create(&other).unwrap();
        f.new_dataset_builder()
            .with_data(&[1.0f64, 2.0][..])
            .create("x")
            .unwrap();
    }
    let err = ResultFile::open(&other).err().unwrap();
    assert!(matches!(err, OutputError::Missing { .. }), "{err}");
    assert!(
        err.to_string()
            .contains("missing dataset /mesh/coordinates"),
        "{err}"
    );

    // A result file with one dataset removed.
    let holed = dir.join("holed.h5");
    std::fs::copy(&good, &holed).unwrap();
    {
        let f = hdf5::File::open_rw(&holed).unwrap();
        f.unlink("/results/contact/gap").unwrap();
    }
    let err = ResultFile::open(&holed).err().unwrap().to_string();
    assert!(
        err.contains("holed.h5: missing dataset /results/contact/gap"),
        "{err}"
    );

    let err = post::run_post(&PostCommand::Info { file: missing }).unwrap_err();
    assert!(matches!(err, OutputError::NotFound { .. }));
}

#[test]
fn info_summarises_the_run() {
    let dir = test_dir("info");
    let path = write_synthetic(&dir, "r", 3);
    let text = post::info_text(&path).unwrap();
    for want in [
        "scene:        two blocks",
        "ranks:        2",
        "steps:        3",
        "wall time:    12.500 s",
        "exit status:  completed",
        "base (1 elements), lid (2 elements)",
        "node sets:    top, bottom",
        "CG its",
        "max penetration",
        "max pressure",
    ] {
        assert!(text.contains(want), "missing '{want}' in\n{text}");
    }
    // One table row per step plus the header and total.
    assert_eq!(
        text.lines().filter(|l| l.contains("e-1")).count(),
        3,
        "{text}"
    );
    // The largest contact pressure of step 2 is 2.5 * 3 * 2 = 15, first at node index 2
    // (id 5); it is the largest of all steps too.
    let rows: Vec<&str> = text.lines().filter(|l| l.contains("1.5000e1")).collect();
    assert_eq!(rows.len(), 2, "{text}");
    assert!(rows[0].trim_start().starts_with("2 ") && rows[0].ends_with(" 5"));
    assert!(rows[1].trim_start().starts_with("max ") && rows[1].ends_with(" 5"));
    assert!(!text.contains("not in this file"), "{text}");
    assert_eq!(
        post::run_post(&PostCommand::Info { file: path }).unwrap(),
        0
    );
}

/// `solver post ...` as the lead's main would parse it.
#[derive(Parser, Debug)]
struct Cli {
    #[command(subcommand)]
    cmd: PostCommand,
}

fn parse(args: &[&str]) -> Result<PostCommand, clap::Error> {
    Cli::try_parse_from(std::iter::once("post").chain(args.iter().copied())).map(|c| c.cmd)
}

/// The data of a `post plot` command.
fn plot_data(cmd: &PostCommand) -> post::PlotData {
    let PostCommand::Plot(args) = cmd else {
        panic!("{cmd:?}")
    };
    post::plot_data(args).unwrap()
}

#[test]
fn plot_along_a_node_set_and_through_time() {
    let dir = test_dir("plot");
    let path = write_synthetic(&dir, "r", 3);
    let file = path.to_str().unwrap();
    let out = dir.join("along.png");
    plot_along_x_at_every_step(file, &out);
    plot_along_the_arc_length_without_fonts(file, &dir.join("arc.png"));
    let out3 = dir.join("history.png");
    plot_the_summed_force_through_time(file, &out3);
    plot_the_pressure_and_the_status_per_node(file, &out3);
    plot_argument_errors(file, out.to_str().unwrap());
}

/// The x displacement along the set `top` against x, at every step, drawn to `out`.
fn plot_along_x_at_every_step(file: &str, out: &Path) {
    let cmd = parse(&[
        "plot",
        file,
        "--quantity",
        "displacement",
        "--component",
        "x",
        "--node-set",
        "top",
        "--against",
        "x",
        "--steps",
        "all",
        "-o",
        out.to_str().unwrap(),
    ])
    .unwrap();
    let data = plot_data(&cmd);
    assert_eq!(data.series.len(), 3);
    let mesh = synthetic_mesh();
    for (s, series) in data.series.iter().enumerate() {
        assert_eq!(series.points.len(), 6);
        let step = synthetic_step(s, &mesh);
        // Sorted by x; values are the nodes' x displacement.
        assert!(series.points.windows(2).all(|w| w[0].0 <= w[1].0));
        for &(x, v) in &series.points {
            // Both nodes at this x have the same x displacement.
            let i = mesh
                .coordinates
                .iter()
                .position(|c| c[2] == 2.25 && c[0] == x)
                .unwrap();
            assert_eq!(v, step.displacement[i][0]);
        }
    }
    assert_eq!(post::run_post(&cmd).unwrap(), 0);
    let png = std::fs::read(out).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
}

/// The gap along the set `bottom` against its arc length at the last step, drawn to `out2`
/// without fonts.
fn plot_along_the_arc_length_without_fonts(file: &str, out2: &Path) {
    let cmd = parse(&[
        "plot",
        file,
        "--quantity",
        "gap",
        "--node-set",
        "bottom",
        "--against",
        "s",
        "-o",
        out2.to_str().unwrap(),
    ])
    .unwrap();
    let data = plot_data(&cmd);
    assert_eq!(data.series.len(), 1);
    let xs: Vec<f64> = data.series[0].points.iter().map(|p| p.0).collect();
    assert_eq!(xs.first(), Some(&0.0));
    assert!(xs.windows(2).all(|w| w[0] <= w[1]));
    post::render_plot(&data, out2, false).unwrap();
    assert_eq!(&std::fs::read(out2).unwrap()[..4], b"\x89PNG");
}

/// The contact force summed over the set `top` through time, drawn to `out3`.
fn plot_the_summed_force_through_time(file: &str, out3: &Path) {
    let mesh = synthetic_mesh();
    let cmd = parse(&[
        "plot",
        file,
        "--history",
        "--quantity",
        "contact_force",
        "--component",
        "y",
        "--node-set",
        "top",
        "--sum",
        "-o",
        out3.to_str().unwrap(),
    ])
    .unwrap();
    let data = plot_data(&cmd);
    assert_eq!(data.series.len(), 1);
    let top: Vec<usize> = (0..20)
        .filter(|&i| mesh.coordinates[i][2] == 2.25)
        .collect();
    for (s, &(t, v)) in data.series[0].points.iter().enumerate() {
        let step = synthetic_step(s, &mesh);
        assert_eq!(t, step.time);
        let want: f64 = top.iter().map(|&i| step.contact_force[i][1]).sum();
        assert!((v - want).abs() < 1e-12, "{v} vs {want}");
    }
    assert_eq!(post::run_post(&cmd).unwrap(), 0);
    assert!(out3.exists());
}

/// The contact pressure, a scalar, along the set `bottom` at the last step; the status per
/// node through time, one line per node of the set.
fn plot_the_pressure_and_the_status_per_node(file: &str, out3: &Path) {
    let mesh = synthetic_mesh();
    let cmd = parse(&[
        "plot",
        file,
        "--quantity",
        "contact_pressure",
        "--node-set",
        "bottom",
        "--against",
        "x",
        "-o",
        out3.to_str().unwrap(),
    ])
    .unwrap();
    let data = plot_data(&cmd);
    let last = synthetic_step(2, &mesh);
    let bottom: Vec<usize> = (0..20).filter(|&i| mesh.coordinates[i][2] == 0.0).collect();
    let mut want: Vec<(f64, f64)> = bottom
        .iter()
        .map(|&i| (mesh.coordinates[i][0], last.contact_pressure[i]))
        .collect();
    want.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let mut got = data.series[0].points.clone();
    got.sort_by(|a, b| a.partial_cmp(b).unwrap());
    assert_eq!(got, want);

    // Per node through time: one line per node of the set.
    let cmd = parse(&[
        "plot",
        file,
        "--history",
        "--quantity",
        "status",
        "--node-set",
        "bottom",
        "-o",
        out3.to_str().unwrap(),
    ])
    .unwrap();
    assert_eq!(plot_data(&cmd).series.len(), 4);
}

/// A missing component, an unknown node set, a step out of range and bad arguments are
/// refused (`o` the picture's path).
fn plot_argument_errors(file: &str, o: &str) {
    let bad = |args: &[&str]| {
        let cmd = parse(args).unwrap();
        post::run_post(&cmd).unwrap_err().to_string()
    };
    let e = bad(&[
        "plot",
        file,
        "--quantity",
        "displacement",
        "--node-set",
        "top",
        "--against",
        "x",
        "-o",
        o,
    ]);
    assert!(e.contains("--component"), "{e}");
    let e = bad(&[
        "plot",
        file,
        "--quantity",
        "reaction",
        "--component",
        "z",
        "--node-set",
        "nope",
        "--against",
        "x",
        "-o",
        o,
    ]);
    assert!(
        e.contains("no node set 'nope'") && e.contains("top, bottom"),
        "{e}"
    );
    let e = bad(&[
        "plot",
        file,
        "--quantity",
        "reaction",
        "--component",
        "z",
        "--node-set",
        "top",
        "--against",
        "x",
        "--steps",
        "0,7",
        "-o",
        o,
    ]);
    assert!(e.contains("step 7 out of range"), "{e}");
    assert!(parse(&[
        "plot",
        file,
        "--quantity",
        "reaction",
        "--node-set",
        "top",
        "-o",
        o
    ])
    .is_err());
    assert!(parse(&[
        "plot",
        file,
        "--quantity",
        "strain",
        "--node-set",
        "top",
        "--history",
        "-o",
        o
    ])
    .is_err());
}

#[test]
fn python_check_accepts_a_result_and_rejects_a_broken_one() {
    let python = Path::new("/usr/bin/python3");
    let has_h5py = python.exists()
        && std::process::Command::new(python)
            .args(["-c", "import h5py"])
            .status()
            .map(|s| s.success())
            .unwrap_or(false);
    assert!(
        has_h5py,
        "/usr/bin/python3 lacks h5py: `run/setup` installs it (Debian's python3-h5py)"
    );
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("run/check_h5.py");
    let dir = test_dir("python");
    let good = write_synthetic(&dir, "good", 3);
    let out = std::process::Command::new(python)
        .arg(&script)
        .arg(&good)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("/results/displacement"), "{stdout}");
    assert!(
        stdout.contains("shape=(3, 20, 3) dtype=float64"),
        "{stdout}"
    );
    assert!(stdout.contains("check_h5: ok"), "{stdout}");

    // Replace /mesh/node_ids by one of the wrong length: the check must fail.
    let broken = dir.join("broken.h5");
    std::fs::copy(&good, &broken).unwrap();
    {
        let f = hdf5::File::open_rw(&broken).unwrap();
        f.unlink("/mesh/node_ids").unwrap();
        f.new_dataset_builder()
            .with_data(&[1u64, 2, 3][..])
            .create("/mesh/node_ids")
            .unwrap();
    }
    let out = std::process::Command::new(python)
        .arg(&script)
        .arg(&broken)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    assert!(stdout.contains("MISMATCH: /mesh/node_ids"), "{stdout}");

    // The optional contact pressure: checked when there, of the wrong shape refused.
    let broken = dir.join("broken_pressure.h5");
    std::fs::copy(&good, &broken).unwrap();
    {
        let f = hdf5::File::open_rw(&broken).unwrap();
        f.unlink(layout::CONTACT_PRESSURE).unwrap();
        f.new_dataset_builder()
            .with_data(&[0.0f64; 20][..])
            .create(layout::CONTACT_PRESSURE)
            .unwrap();
    }
    let out = std::process::Command::new(python)
        .arg(&script)
        .arg(&broken)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    assert!(
        stdout.contains("MISMATCH: /results/contact/pressure"),
        "{stdout}"
    );
}
