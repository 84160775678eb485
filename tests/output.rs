//! The result file: writing, reading back, XDMF (`post compare/info/plot`, bad files, files
//! without the contact pressure and the Python check: tests/output_post.rs).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use solver::output::{
    layout, OutputError, OutputMesh, ResultFile, ResultWriter, RunInfo, StepField, StepOutput,
};
use solver::post;

use crate::common;
use common::synthetic::{
    synthetic_info, synthetic_mesh, synthetic_step, test_dir, write_synthetic,
};

#[test]
fn round_trip_of_every_dataset_and_attribute() {
    let dir = test_dir("round_trip");
    let path = dir.join("result.h5");
    let mesh = synthetic_mesh();
    let info = synthetic_info();
    let mut w = ResultWriter::create(&path, &info, &mesh).unwrap();
    let tmp = dir.join("result.h5.tmp");
    assert_eq!(w.tmp_path(), tmp);
    assert!(tmp.exists(), "the .tmp file exists while writing");
    assert!(!path.exists(), "no final file before finish");
    let steps: Vec<StepOutput> = (0..3).map(|s| synthetic_step(s, &mesh)).collect();
    for (i, s) in steps.iter().enumerate() {
        w.append_step(s).unwrap();
        assert_eq!(w.steps(), i + 1);
        // Every finished step is readable from the .tmp file while the run goes on.
        let partial = ResultFile::open(&tmp).unwrap();
        assert_eq!(partial.num_steps(), i + 1);
        assert_eq!(partial.displacement(i).unwrap(), s.displacement);
    }
    assert!(tmp.exists() && !path.exists());
    let finished = w.finish(12.5).unwrap();
    assert_eq!(finished, path);
    assert!(!tmp.exists(), "the .tmp file is gone after finish");
    assert!(path.exists());
    assert!(dir.join("result.xmf").exists());

    let f = ResultFile::open(&path).unwrap();
    check_the_data_read_back(&f, &mesh, &info, &steps);
    check_the_attributes_read_back(&f, &info);
    check_exactly_the_documented_datasets(&f);
    let all = mesh.all_connectivity().unwrap();
    assert_eq!(all.len(), 3);
    assert_eq!(all[0], mesh.bodies[0].connectivity[0]);
    assert_eq!(all[2], mesh.bodies[1].connectivity[1]);
}

/// The mesh, partition, times, statistics and every step's fields of `f` are the ones
/// written (`mesh`, `info`, `steps`).
fn check_the_data_read_back(
    f: &ResultFile,
    mesh: &OutputMesh,
    info: &RunInfo,
    steps: &[StepOutput],
) {
    assert_eq!(f.num_steps(), 3);
    assert_eq!(f.num_nodes(), 20);
    assert_eq!(f.num_elements(), 3);
    assert_eq!(&f.mesh().unwrap(), mesh);
    assert_eq!(f.element_rank().unwrap(), info.element_rank);
    assert_eq!(
        f.time().unwrap(),
        steps.iter().map(|s| s.time).collect::<Vec<_>>()
    );
    assert_eq!(
        f.stats().unwrap(),
        steps.iter().map(|s| s.stats).collect::<Vec<_>>()
    );
    // The contact statistics, field by field (the comparison above covers them too).
    let stats = f.stats().unwrap();
    assert_eq!(
        stats.iter().map(|s| s.contact_active).collect::<Vec<_>>(),
        [5, 7, 9]
    );
    assert_eq!(
        stats.iter().map(|s| s.contact_stick).collect::<Vec<_>>(),
        [3, 4, 5]
    );
    assert_eq!(
        stats.iter().map(|s| s.contact_slip).collect::<Vec<_>>(),
        [2, 3, 4]
    );
    assert_eq!(
        stats.iter().map(|s| s.contact_released).collect::<Vec<_>>(),
        [0, 1, 0]
    );
    assert_eq!(
        stats.iter().map(|s| s.max_penetration).collect::<Vec<_>>(),
        [0.0, 2.5e-4, 5e-4]
    );
    for (i, s) in steps.iter().enumerate() {
        assert_eq!(f.displacement(i).unwrap(), s.displacement);
        assert_eq!(f.stress(i).unwrap(), s.stress);
        assert_eq!(f.reaction(i).unwrap(), s.reaction);
        assert_eq!(f.contact_force(i).unwrap(), s.contact_force);
        assert_eq!(f.contact_status(i).unwrap(), s.contact_status);
        assert_eq!(f.gap(i).unwrap(), s.contact_gap);
        assert_eq!(
            f.contact_pressure(i).unwrap().as_ref(),
            Some(&s.contact_pressure)
        );
    }
    assert!(matches!(
        f.displacement(3),
        Err(OutputError::StepOutOfRange {
            step: 3,
            steps: 3,
            ..
        })
    ));
}

/// The root attributes of `f`: the documented ones, with the values `info` gave.
fn check_the_attributes_read_back(f: &ResultFile, info: &RunInfo) {
    let a = f.attributes().unwrap();
    assert_eq!(a.format_version, layout::FORMAT_VERSION);
    assert_eq!(a.solver_version, info.solver_version);
    assert_eq!(a.ranks, 2);
    assert_eq!(a.scene_text, info.scene_text);
    assert_eq!(a.scene_name, "two blocks");
    assert_eq!(a.units, "consistent units; the scene's");
    assert_eq!(a.start_time, info.start_time);
    assert_eq!(a.wall_time, Some(12.5));
    assert_eq!(a.exit_status, "completed");
    let attr_names: BTreeSet<String> = f.attribute_names().into_iter().collect();
    let required: BTreeSet<String> = layout::REQUIRED_ATTRIBUTES
        .iter()
        .map(|s| s.to_string())
        .collect();
    assert_eq!(attr_names, required);
}

/// Exactly the documented datasets, with the documented shapes.
fn check_exactly_the_documented_datasets(f: &ResultFile) {
    let (n, e, st) = (20, 3, 3);
    let expected: Vec<(&str, Vec<usize>)> = vec![
        ("/mesh/coordinates", vec![n, 3]),
        ("/mesh/node_ids", vec![n]),
        ("/mesh/all_connectivity", vec![e, 8]),
        ("/mesh/base/connectivity", vec![1, 8]),
        ("/mesh/base/element_ids", vec![1]),
        ("/mesh/lid/connectivity", vec![2, 8]),
        ("/mesh/lid/element_ids", vec![2]),
        ("/mesh/node_sets/top", vec![6]),
        ("/mesh/node_sets/bottom", vec![4]),
        ("/mesh/side_sets/contact_slave", vec![2, 2]),
        ("/mesh/side_sets/contact_master", vec![1, 2]),
        ("/results/time", vec![st]),
        ("/results/displacement", vec![st, n, 3]),
        ("/results/stress", vec![st, e, 6]),
        ("/results/reaction", vec![st, n, 3]),
        ("/results/contact/force", vec![st, n, 3]),
        ("/results/contact/status", vec![st, n]),
        ("/results/contact/gap", vec![st, n]),
        ("/results/contact/pressure", vec![st, n]),
        ("/stats/cg_iterations", vec![st]),
        ("/stats/contact_updates", vec![st]),
        ("/stats/residual", vec![st]),
        ("/stats/wall_time", vec![st]),
        ("/stats/cutbacks", vec![st]),
        ("/stats/contact_active", vec![st]),
        ("/stats/contact_stick", vec![st]),
        ("/stats/contact_slip", vec![st]),
        ("/stats/contact_released", vec![st]),
        ("/stats/max_penetration", vec![st]),
        ("/partition/element_rank", vec![e]),
    ];
    let names: BTreeSet<String> = f.dataset_names().into_iter().collect();
    let want: BTreeSet<String> = expected.iter().map(|(n, _)| n.to_string()).collect();
    assert_eq!(names, want);
    for (name, shape) in &expected {
        assert_eq!(&f.shape(name).unwrap(), shape, "{name}");
    }
}

#[test]
fn a_run_that_dies_leaves_only_the_tmp_file_with_its_finished_steps() {
    let dir = test_dir("crash");
    let path = dir.join("run.h5");
    let mesh = synthetic_mesh();
    let mut w = ResultWriter::create(&path, &synthetic_info(), &mesh).unwrap();
    w.append_step(&synthetic_step(0, &mesh)).unwrap();
    w.append_step(&synthetic_step(1, &mesh)).unwrap();
    drop(w); // no finish: as if the process died
    assert!(!path.exists());
    let f = ResultFile::open(&dir.join("run.h5.tmp")).unwrap();
    assert_eq!(f.num_steps(), 2);
    assert_eq!(
        f.displacement(1).unwrap(),
        synthetic_step(1, &mesh).displacement
    );
    let a = f.attributes().unwrap();
    assert_eq!(a.exit_status, "running");
    assert_eq!(a.wall_time, None);
}

/// A process started while a result file is open must not inherit its descriptor: HDF5's
/// `flock` belongs to the open file description, so an inherited descriptor would keep the
/// file locked after the writer closes it and the next open would fail with "unable to lock
/// file" (seen in CI when another test started a Python process at the wrong moment).
#[test]
fn a_process_started_while_the_file_is_open_does_not_keep_it_locked() {
    let dir = test_dir("child_lock");
    let path = dir.join("run.h5");
    let mesh = synthetic_mesh();
    let mut w = ResultWriter::create(&path, &synthetic_info(), &mesh).unwrap();
    w.append_step(&synthetic_step(0, &mesh)).unwrap();
    let mut child = std::process::Command::new("sleep")
        .arg("30")
        .spawn()
        .expect("starting `sleep`");
    let path = w.finish(1.0).unwrap();
    let opened = ResultFile::open(&path).map(|f| f.num_steps());
    // The reader too: its shared lock, kept by a child, would refuse a writer's exclusive one.
    let reader = ResultFile::open(&path).unwrap();
    let mut child2 = std::process::Command::new("sleep")
        .arg("30")
        .spawn()
        .expect("starting `sleep`");
    drop(reader);
    // Another test of this binary may start a process (Python) in the instant between an
    // open and its close-on-exec flag; that process holds the lock only until it exits, so
    // the open is retried for a second, as the solver's own opens are. The `sleep`s live
    // for 30 s: an inherited descriptor of theirs would still fail every retry.
    let mut read_write = hdf5::File::open_rw(&path).map(|_| ());
    for _ in 0..40 {
        if read_write.is_ok() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(25));
        read_write = hdf5::File::open_rw(&path).map(|_| ());
    }
    for c in [&mut child, &mut child2] {
        let _ = c.kill();
        let _ = c.wait();
    }
    assert_eq!(opened.unwrap(), 1);
    read_write.unwrap();
}

#[test]
fn finish_failed_names_the_file_as_failed() {
    let dir = test_dir("failed");
    let path = dir.join("run.h5");
    let mesh = synthetic_mesh();
    let mut w = ResultWriter::create(&path, &synthetic_info(), &mesh).unwrap();
    w.append_step(&synthetic_step(0, &mesh)).unwrap();
    let failed = w
        .finish_failed(3.0, "Newton iteration diverged at step 2")
        .unwrap();
    assert_eq!(failed, dir.join("run.failed.h5"));
    assert!(failed.exists());
    assert!(!path.exists(), "a failed run never leaves <path>");
    assert!(!dir.join("run.h5.tmp").exists());
    assert!(dir.join("run.failed.xmf").exists());
    assert!(!dir.join("run.xmf").exists());
    let f = ResultFile::open(&failed).unwrap();
    assert_eq!(f.num_steps(), 1);
    let a = f.attributes().unwrap();
    assert_eq!(a.exit_status, "failed: Newton iteration diverged at step 2");
    assert_eq!(a.wall_time, Some(3.0));
    let info = post::info_text(&failed).unwrap();
    assert!(info.contains("failed: Newton iteration diverged"), "{info}");
}

/// Writes the three synthetic steps into `<name>.h5` through `write` (given the writer, the
/// step's index and the step; it must complete the step), and asserts that the file is the
/// one `append_step` writes, bit for bit (post compare's default). Returns its path.
fn written_as_whole(
    dir: &Path,
    name: &str,
    mut write: impl FnMut(&mut ResultWriter, usize, &StepOutput),
) -> PathBuf {
    let mesh = synthetic_mesh();
    let whole = write_synthetic(dir, "whole", 3);
    let path = dir.join(format!("{name}.h5"));
    let mut w = ResultWriter::create(&path, &synthetic_info(), &mesh).unwrap();
    for s in 0..3 {
        write(&mut w, s, &synthetic_step(s, &mesh));
    }
    let done = w.finish(12.5).unwrap();
    let report = post::compare_files(&whole, &done, 0.0).unwrap();
    assert!(report.bitwise_identical(), "{report:?}");
    assert!(
        report.only_in_a.is_empty() && report.only_in_b.is_empty(),
        "{report:?}"
    );
    done
}

#[test]
fn a_step_written_field_by_field_is_the_step_written_whole() {
    // The run writes each field as it is gathered (`write_field`, `end_step`); the file must
    // be the one `append_step` writes, bit for bit (post compare's default), and a field
    // missing, not finite or of the wrong length must be refused.
    let dir = test_dir("field_by_field");
    let mesh = synthetic_mesh();
    let fields = written_as_whole(&dir, "fields", |w, s, step| {
        // In the order the run gathers them.
        let mut fields = step.fields();
        fields.reverse();
        for f in fields {
            w.write_field(f).unwrap();
        }
        w.end_step(step.time, &step.stats).unwrap();
        assert_eq!(w.steps(), s + 1);
    });
    assert_eq!(ResultFile::open(&fields).unwrap().num_steps(), 3);

    let path = dir.join("refused.h5");
    let mut w = ResultWriter::create(&path, &synthetic_info(), &mesh).unwrap();
    let mut step = synthetic_step(0, &mesh);
    w.write_field(StepField::Displacement(&step.displacement))
        .unwrap();
    let err = w.end_step(step.time, &step.stats).unwrap_err();
    assert!(err.to_string().contains(layout::STRESS), "{err}");
    step.reaction[4][1] = f64::NAN;
    let err = w
        .write_field(StepField::Reaction(&step.reaction))
        .unwrap_err();
    assert!(matches!(err, OutputError::NonFinite { .. }), "{err}");
    assert!(
        err.to_string().contains("node 4 (id 9), component 1"),
        "{err}"
    );
    let err = w
        .write_field(StepField::Stress(&step.stress[1..]))
        .unwrap_err();
    assert!(err.to_string().contains("2 values for 3 elements"), "{err}");
    assert_eq!(w.steps(), 0, "no step was completed");
}

/// `field`'s entries from `first` to `first + n` (n clipped to the field), as a part.
fn part_of<'a>(field: &StepField<'a>, first: usize, n: usize) -> StepField<'a> {
    let r = |len: usize| first..(first + n).min(len);
    match *field {
        StepField::Displacement(v) => StepField::Displacement(&v[r(v.len())]),
        StepField::Stress(v) => StepField::Stress(&v[r(v.len())]),
        StepField::Reaction(v) => StepField::Reaction(&v[r(v.len())]),
        StepField::ContactForce(v) => StepField::ContactForce(&v[r(v.len())]),
        StepField::ContactStatus(v) => StepField::ContactStatus(&v[r(v.len())]),
        StepField::ContactGap(v) => StepField::ContactGap(&v[r(v.len())]),
        StepField::ContactPressure(v) => StepField::ContactPressure(&v[r(v.len())]),
        StepField::PlasticStrain(v) => StepField::PlasticStrain(&v[r(v.len())]),
    }
}

fn field_len(field: &StepField<'_>) -> usize {
    match *field {
        StepField::Displacement(v) | StepField::Reaction(v) | StepField::ContactForce(v) => v.len(),
        StepField::Stress(v) => v.len(),
        StepField::ContactStatus(v) => v.len(),
        StepField::ContactGap(v) | StepField::ContactPressure(v) | StepField::PlasticStrain(v) => {
            v.len()
        }
    }
}

#[test]
fn a_field_written_in_parts_is_the_field_written_whole() {
    // A large run's rank 0 writes each field a range of entries at a time as it gathers it
    // (`write_field_part`); the file must be the one `append_step` writes, bit for bit, and
    // a part out of order, past the mesh or with a value that is not finite refused, the
    // value named by its entry in the whole field.
    let dir = test_dir("field_parts");
    let mesh = synthetic_mesh();
    written_as_whole(&dir, "parts", |w, s, step| {
        // Parts of 1, 2, 5, ... entries: some fields in one part, some in several, the
        // last part shorter than the others.
        let n = [1usize, 2, 5][s];
        for f in step.fields() {
            let mut first = 0;
            while first < field_len(&f) {
                w.write_field_part(part_of(&f, first, n), first).unwrap();
                first += n;
            }
        }
        w.end_step(step.time, &step.stats).unwrap();
    });

    let path = dir.join("refused.h5");
    let mut w = ResultWriter::create(&path, &synthetic_info(), &mesh).unwrap();
    let mut step = synthetic_step(0, &mesh);
    let d = StepField::Displacement(&step.displacement);
    // Not from entry 0, then a gap after entries 0..3.
    let err = w.write_field_part(part_of(&d, 2, 3), 2).unwrap_err();
    assert!(
        err.to_string().contains("expected one starting at 0"),
        "{err}"
    );
    w.write_field_part(part_of(&d, 0, 3), 0).unwrap();
    let err = w.write_field_part(part_of(&d, 4, 3), 4).unwrap_err();
    assert!(
        err.to_string().contains("expected one starting at 3"),
        "{err}"
    );
    // Past the last node (20 nodes).
    let err = w.write_field_part(part_of(&d, 0, 3), 18).unwrap_err();
    assert!(err.to_string().contains("18..21 of 20"), "{err}");
    // A field whose parts stop short is missing at the step's end.
    w.write_field_part(part_of(&d, 3, 10), 3).unwrap();
    for f in step.fields().into_iter().skip(1) {
        w.write_field(f).unwrap();
    }
    let err = w.end_step(step.time, &step.stats).unwrap_err();
    assert!(err.to_string().contains(layout::DISPLACEMENT), "{err}");
    // A value that is not finite in a later part: named by its node in the whole field.
    step.reaction[14][2] = f64::INFINITY;
    let r = StepField::Reaction(&step.reaction);
    w.write_field_part(part_of(&r, 0, 10), 0).unwrap();
    let err = w.write_field_part(part_of(&r, 10, 10), 10).unwrap_err();
    assert!(matches!(err, OutputError::NonFinite { .. }), "{err}");
    assert!(
        err.to_string().contains("node 14 (id 29), component 2"),
        "{err}"
    );
    assert_eq!(w.steps(), 0, "no step was completed");
}

#[test]
fn a_restart_state_written_in_parts_reads_back_as_written_whole() {
    // The run gives rank 0's writer the restart state's two displacements a range of nodes
    // at a time (`write_restart_part`) and then the rest of the state with both left empty;
    // likewise the plastic history (`write_restart_history_part`); the state read back must
    // be the one written whole, and a state whose displacements or history were not all
    // written refused.
    let dir = test_dir("restart_parts");
    let mesh = synthetic_mesh();
    let n = mesh.coordinates.len();
    let state = |rows: u64| solver::output::RestartState {
        step: rows + 1,
        time: 0.5 * rows as f64,
        dt_prev: 0.25,
        reference_floor: 3.5,
        rows,
        multilevel_switched: rows == 2,
        displacement: (0..n).map(|i| [i as f64, 0.5, -(rows as f64)]).collect(),
        previous_displacement: (0..n).map(|i| [0.1, i as f64 / 3.0, 1e-9]).collect(),
        contact: vec![1.0, 2.0, 3.0],
        released: vec![4.0],
        ties: Vec::new(),
        hierarchy: vec![1.0, 0.0, 0.0, 0.0 - rows as f64],
        history: (0..40).map(|i| i as f64 * 0.125 - rows as f64).collect(),
    };
    let mut read = Vec::new();
    for parts in [false, true] {
        let path = dir.join(format!("parts_{parts}.h5"));
        let mut w = ResultWriter::create(&path, &synthetic_info(), &mesh).unwrap();
        for rows in 1..=3u64 {
            w.append_step(&synthetic_step(rows as usize - 1, &mesh))
                .unwrap();
            let mut r = state(rows);
            if parts {
                for (previous, u) in [(false, &r.displacement), (true, &r.previous_displacement)] {
                    for first in (0..n).step_by(7) {
                        let part = &u[first..(first + 7).min(n)];
                        w.write_restart_part(rows, previous, first, part).unwrap();
                    }
                }
                r.displacement.clear();
                r.previous_displacement.clear();
                let h = std::mem::take(&mut r.history);
                for first in (0..h.len()).step_by(9) {
                    let part = &h[first..(first + 9).min(h.len())];
                    w.write_restart_history_part(rows, (h.len(), first), part)
                        .unwrap();
                }
            }
            w.write_restart(&r).unwrap();
        }
        let done = w.finish(1.0).unwrap();
        read.push(ResultFile::open(&done).unwrap().restart_state().unwrap());
    }
    assert_eq!(read[0], Some(state(3)));
    assert_eq!(read[1], read[0]);

    let path = dir.join("refused.h5");
    let mut w = ResultWriter::create(&path, &synthetic_info(), &mesh).unwrap();
    w.append_step(&synthetic_step(0, &mesh)).unwrap();
    let mut r = state(1);
    let u = std::mem::take(&mut r.displacement);
    r.previous_displacement.clear();
    w.write_restart_part(1, false, 0, &u).unwrap();
    let err = w.write_restart_part(1, true, 5, &u[5..]).unwrap_err();
    assert!(
        err.to_string().contains("expected one starting at 0"),
        "{err}"
    );
    let err = w.write_restart(&r).unwrap_err();
    assert!(
        err.to_string().contains("without its displacements"),
        "{err}"
    );
    // The displacements whole (again: the refused state's parts are gone), the history not.
    w.write_restart_part(1, false, 0, &u).unwrap();
    w.write_restart_part(1, true, 0, &u).unwrap();
    let h = std::mem::take(&mut r.history);
    let err = w
        .write_restart_history_part(1, (h.len(), 9), &h[9..])
        .unwrap_err();
    assert!(
        err.to_string().contains("expected one starting at 0"),
        "{err}"
    );
    w.write_restart_history_part(1, (h.len(), 0), &h[..30])
        .unwrap();
    let err = w.write_restart(&r).unwrap_err();
    assert!(
        err.to_string().contains("with 30 of its 40 history values"),
        "{err}"
    );
}

#[test]
fn non_finite_values_and_bad_lengths_are_refused() {
    let dir = test_dir("nan");
    let mesh = synthetic_mesh();
    let mut w = ResultWriter::create(&dir.join("r.h5"), &synthetic_info(), &mesh).unwrap();
    w.append_step(&synthetic_step(0, &mesh)).unwrap();
    refuse_bad_steps(&mut w, &mesh);

    // Nothing of a refused step reached the file; the writer goes on.
    assert_eq!(w.steps(), 1);
    w.append_step(&synthetic_step(1, &mesh)).unwrap();
    let path = w.finish(1.0).unwrap();
    let f = ResultFile::open(&path).unwrap();
    assert_eq!(f.num_steps(), 2);
    assert_eq!(f.shape("/results/displacement").unwrap(), vec![2, 20, 3]);

    refuse_bad_meshes(&dir);
}

/// Steps with a value that is not finite, a field of the wrong length, a missing pressure
/// after steps that had one, a negative penetration or an unknown status are refused by `w`,
/// naming the dataset (and the node or element).
fn refuse_bad_steps(w: &mut ResultWriter, mesh: &OutputMesh) {
    let mut bad = synthetic_step(1, mesh);
    bad.displacement[5][1] = f64::NAN;
    let err = w.append_step(&bad).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, OutputError::NonFinite { .. }), "{msg}");
    assert!(msg.contains("/results/displacement"), "{msg}");
    assert!(msg.contains("node 5 (id 11), component 1"), "{msg}");
    assert!(msg.contains("r.h5.tmp"), "{msg}");

    let mut bad = synthetic_step(1, mesh);
    bad.stress[2][4] = f64::INFINITY;
    let msg = w.append_step(&bad).unwrap_err().to_string();
    assert!(
        msg.contains("/results/stress") && msg.contains("element 2"),
        "{msg}"
    );

    let mut bad = synthetic_step(1, mesh);
    bad.contact_gap[0] = f64::NEG_INFINITY;
    let msg = w.append_step(&bad).unwrap_err().to_string();
    assert!(msg.contains("/results/contact/gap"), "{msg}");

    let mut bad = synthetic_step(1, mesh);
    bad.contact_pressure[7] = f64::NAN;
    let msg = w.append_step(&bad).unwrap_err().to_string();
    assert!(
        msg.contains("/results/contact/pressure") && msg.contains("node 7 (id 15)"),
        "{msg}"
    );

    let mut bad = synthetic_step(1, mesh);
    bad.contact_pressure.pop();
    let msg = w.append_step(&bad).unwrap_err().to_string();
    assert!(
        msg.contains("/results/contact/pressure") && msg.contains("19 values for 20 nodes"),
        "{msg}"
    );

    // The steps before had a pressure: a step without one would leave a hole.
    let mut bad = synthetic_step(1, mesh);
    bad.contact_pressure.clear();
    let msg = w.append_step(&bad).unwrap_err().to_string();
    assert!(
        msg.contains("/results/contact/pressure") && msg.contains("no contact pressure"),
        "{msg}"
    );

    let mut bad = synthetic_step(1, mesh);
    bad.stats.residual = f64::NAN;
    let msg = w.append_step(&bad).unwrap_err().to_string();
    assert!(msg.contains("/stats/residual"), "{msg}");

    let mut bad = synthetic_step(1, mesh);
    bad.stats.max_penetration = f64::INFINITY;
    let msg = w.append_step(&bad).unwrap_err().to_string();
    assert!(msg.contains("/stats/max_penetration"), "{msg}");

    let mut bad = synthetic_step(1, mesh);
    bad.stats.max_penetration = -1e-6;
    let msg = w.append_step(&bad).unwrap_err().to_string();
    assert!(
        msg.contains("/stats/max_penetration") && msg.contains(">= 0"),
        "{msg}"
    );

    let mut bad = synthetic_step(1, mesh);
    bad.reaction.pop();
    let msg = w.append_step(&bad).unwrap_err().to_string();
    assert!(
        msg.contains("/results/reaction") && msg.contains("19 values for 20 nodes"),
        "{msg}"
    );

    let mut bad = synthetic_step(1, mesh);
    bad.contact_status[3] = 7;
    let msg = w.append_step(&bad).unwrap_err().to_string();
    assert!(msg.contains("/results/contact/status"), "{msg}");
}

/// Bad meshes (and a partition of the wrong length) are refused at create.
fn refuse_bad_meshes(dir: &Path) {
    let mut m = synthetic_mesh();
    m.coordinates[3][0] = f64::NAN;
    let msg = ResultWriter::create(&dir.join("m.h5"), &synthetic_info(), &m)
        .err()
        .unwrap()
        .to_string();
    assert!(
        msg.contains("/mesh/coordinates") && msg.contains("node 3"),
        "{msg}"
    );
    let mut m = synthetic_mesh();
    m.bodies[1].connectivity[0][2] = 99;
    let msg = ResultWriter::create(&dir.join("m.h5"), &synthetic_info(), &m)
        .err()
        .unwrap()
        .to_string();
    assert!(msg.contains("/mesh/lid/connectivity"), "{msg}");
    let mut info = synthetic_info();
    info.element_rank.pop();
    let msg = ResultWriter::create(&dir.join("m.h5"), &info, &synthetic_mesh())
        .err()
        .unwrap()
        .to_string();
    assert!(msg.contains("/partition/element_rank"), "{msg}");
}

/// The value of `name="..."` in an XML start tag.
fn xml_attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let start = tag.find(&key)? + key.len();
    let len = tag[start..].find('"')?;
    Some(&tag[start..start + len])
}

fn numbers(text: &str) -> Vec<usize> {
    text.split_whitespace()
        .map(|t| t.parse().unwrap())
        .collect()
}

#[test]
fn xdmf_references_resolve_in_the_hdf5_file() {
    let dir = test_dir("xdmf");
    let path = write_synthetic(&dir, "res", 3);
    let xmf = std::fs::read_to_string(dir.join("res.xmf")).unwrap();
    let f = ResultFile::open(&path).unwrap();
    assert!(xmf.contains("<Xdmf Version=\"3.0\""));
    assert!(xmf.contains("CollectionType=\"Temporal\""));
    assert_eq!(xmf.matches("GridType=\"Uniform\"").count(), 3);
    let times: Vec<f64> = xmf
        .match_indices("<Time Value=\"")
        .map(|(i, m)| {
            let rest = &xmf[i + m.len()..];
            rest[..rest.find('"').unwrap()].parse().unwrap()
        })
        .collect();
    assert_eq!(times, f.time().unwrap());
    assert_eq!(xmf.matches("TopologyType=\"Hexahedron\"").count(), 3);
    assert_eq!(xmf.matches("AttributeType=\"Tensor6\"").count(), 3);

    // Walk every <DataItem ...>: each must be an HDF item naming the file beside the .xmf and
    // a dataset of the declared shape, or, for a per-step attribute, a hyperslab of it in
    // XDMF 3 notation "file:/dataset|start:stride:count:dataset dims" that lies inside the
    // dataset and has as many values as the item declares.
    let mut items = 0;
    let mut slabs = 0;
    let mut pos = 0;
    while let Some(i) = xmf[pos..].find("<DataItem") {
        let start = pos + i;
        let tag_end = start + xmf[start..].find('>').unwrap();
        let tag = &xmf[start..=tag_end];
        let content_end = tag_end + xmf[tag_end..].find("</DataItem>").unwrap();
        let content = xmf[tag_end + 1..content_end].trim();
        pos = content_end;
        items += 1;
        assert_eq!(xml_attr(tag, "Format"), Some("HDF"), "{tag}");
        assert!(xml_attr(tag, "NumberType").is_some() && xml_attr(tag, "Precision").is_some());
        let declared = numbers(xml_attr(tag, "Dimensions").unwrap());
        let (location, slab) = match content.split_once('|') {
            Some((l, s)) => (l, Some(s)),
            None => (content, None),
        };
        let (file, dataset) = location.split_once(':').unwrap();
        assert_eq!(file, "res.h5", "relative file name");
        assert!(dir.join(file).exists());
        let shape = f.shape(dataset).unwrap();
        match slab {
            None => assert_eq!(shape, declared, "{dataset}"),
            Some(slab) => {
                slabs += 1;
                let parts: Vec<Vec<usize>> = slab.split(':').map(numbers).collect();
                assert_eq!(parts.len(), 4, "{slab}");
                let (first, stride, count, dims) = (&parts[0], &parts[1], &parts[2], &parts[3]);
                assert_eq!(dims, &shape, "{dataset}: the slab's dataset dimensions");
                let r = shape.len();
                assert!(first.len() == r && stride.len() == r && count.len() == r);
                for k in 0..r {
                    assert!(stride[k] >= 1 && count[k] >= 1);
                    assert!(
                        first[k] + (count[k] - 1) * stride[k] < shape[k],
                        "{dataset}"
                    );
                }
                assert_eq!(
                    count.iter().product::<usize>(),
                    declared.iter().product::<usize>(),
                    "{dataset}"
                );
            }
        }
    }
    // Per grid: topology, geometry, and seven attributes, each a hyperslab.
    assert_eq!(items, 3 * 9);
    assert_eq!(slabs, 3 * 7);
    // Step 2's displacement is the slab starting at step 2.
    assert!(xmf.contains("res.h5:/results/displacement|2 0 0:1 1 1:1 20 3:3 20 3"));
    assert!(xmf.contains("res.h5:/results/contact/status|2 0:1 1:1 20:3 20"));
    assert!(xmf.contains(
        "<Attribute Name=\"contact_pressure\" AttributeType=\"Scalar\" Center=\"Node\">"
    ));
    assert!(xmf.contains("res.h5:/results/contact/pressure|2 0:1 1:1 20:3 20"));
}
