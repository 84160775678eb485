//! A run never destroys a file it was not asked to write, and one output has one writer:
//! `-o` onto an input of the run, a file that is not a result, a FIFO or a device is refused
//! (exit 2, the target untouched); two runs started together on one output: the second is
//! refused at once and the first publishes a complete result; a full disk gives one line,
//! exit 1 and neither `.h5` nor `.xmf`; an earlier result is replaced only by a complete one.
//!
//! The device and full-disk tests need root (`mknod`, `mount` in a private mount namespace
//! made with `unshare`); without it they say so on standard error and pass.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::common;
use common::{fresh_dir, repo, scenes, solver, stderr_text};

fn dir(name: &str) -> PathBuf {
    fresh_dir(&format!("file-safety-{name}"))
}

fn is_root() -> bool {
    // SAFETY: geteuid has no preconditions.
    unsafe { libc::geteuid() == 0 }
}

fn skipped(what: &str) {
    eprintln!("*** SKIPPED (not run, not passed): {what} needs root");
}

/// The bar example copied into `d` (the scene is an input of the runs there).
fn bar(d: &Path) -> PathBuf {
    let p = d.join("bar.toml");
    std::fs::copy(repo("run/examples/bar.toml"), &p).unwrap();
    p
}

fn run_to(scene: &Path, out: &Path, extra: &[&str]) -> Output {
    solver()
        .args(["-q", "run"])
        .arg(scene)
        .args(extra)
        .arg("-o")
        .arg(out)
        .output()
        .unwrap()
}

/// `solver run scene -o out`, not quiet: its log on standard error.
fn run_logged(scene: &Path, out: &Path) -> Output {
    solver()
        .arg("run")
        .arg(scene)
        .arg("-o")
        .arg(out)
        .output()
        .unwrap()
}

/// Every entry of a directory with its bytes (None for what is not a regular file).
fn snapshot(d: &Path) -> Vec<(String, Option<Vec<u8>>)> {
    let mut v: Vec<_> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            let meta = std::fs::symlink_metadata(e.path()).unwrap();
            let bytes = meta.is_file().then(|| std::fs::read(e.path()).unwrap());
            (e.file_name().to_string_lossy().into_owned(), bytes)
        })
        .collect();
    v.sort();
    v
}

/// Runs `scene -o target` (and `extra`), which must exit 2 with `needle` in its one-line
/// message and leave the directory exactly as it was.
fn refused(d: &Path, scene: &Path, target: &Path, extra: &[&str], needle: &str) {
    let before = snapshot(d);
    let o = run_to(scene, target, extra);
    let err = stderr_text(&o);
    println!("{}: {err}", target.display());
    assert_eq!(o.status.code(), Some(2), "{}: {err}", target.display());
    assert!(err.contains(needle), "expected `{needle}` in: {err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        snapshot(d) == before,
        "{}: the directory changed",
        target.display()
    );
}

#[test]
fn output_onto_an_input_or_a_file_not_ours_is_refused() {
    let d = dir("inputs");
    let scene = bar(&d);
    refused(&d, &scene, &scene, &[], "it is the scene file of this run");
    // The same file under another name.
    std::fs::hard_link(&scene, d.join("alias.h5")).unwrap();
    refused(
        &d,
        &scene,
        &d.join("alias.h5"),
        &[],
        "it is the scene file of this run",
    );
    std::fs::remove_file(d.join("alias.h5")).unwrap();

    // A Gmsh scene's mesh file (refused before the mesh is solved).
    let mesh = d.join("mesh.msh");
    std::fs::copy(repo("run/gmsh/cylinder_on_block.msh"), &mesh).unwrap();
    let gmsh_scene = d.join("cylinder.toml");
    let text = std::fs::read_to_string(repo("run/examples/cylinder_on_block.toml"))
        .unwrap()
        .replace("../gmsh/cylinder_on_block.msh", "mesh.msh");
    std::fs::write(&gmsh_scene, text).unwrap();
    refused(
        &d,
        &gmsh_scene,
        &mesh,
        &[],
        "it is the mesh file of this run",
    );

    // The restart file of the run.
    let first = d.join("first.h5");
    assert!(run_to(&scene, &first, &[]).status.success());
    let restart = ["--restart", first.to_str().unwrap()];
    refused(
        &d,
        &scene,
        &first,
        &restart,
        "it is the restart file of this run",
    );

    // Files that are not results of ours, a directory, a symbolic link.
    std::fs::write(d.join("notes.h5"), "my notes\n").unwrap();
    refused(
        &d,
        &scene,
        &d.join("notes.h5"),
        &[],
        "it exists and is not a result file of this solver",
    );
    {
        let f = hdf5::File::create(d.join("other.h5")).unwrap();
        f.new_dataset_builder()
            .with_data(&[1.0f64][..])
            .create("x")
            .unwrap();
    }
    refused(
        &d,
        &scene,
        &d.join("other.h5"),
        &[],
        "it exists and is not a result file of this solver",
    );
    std::fs::create_dir(d.join("folder.h5")).unwrap();
    refused(&d, &scene, &d.join("folder.h5"), &[], "it is a directory");
    std::os::unix::fs::symlink(&first, d.join("link.h5")).unwrap();
    refused(&d, &scene, &d.join("link.h5"), &[], "it is a symbolic link");
    // A companion name taken by a file of someone else's: `q.xmf` beside `q.h5`.
    std::fs::write(d.join("q.xmf"), "<html/>\n").unwrap();
    refused(
        &d,
        &scene,
        &d.join("q.h5"),
        &[],
        "q.xmf: not usable as the result file: it exists and is not an XDMF file",
    );
}

#[test]
fn an_output_whose_parent_is_a_file_is_a_bad_command_line() {
    let d = dir("parent");
    let scene = bar(&d);
    refused(
        &d,
        &scene,
        &d.join("bar.toml/out.h5"),
        &[],
        "is a regular file, not a directory",
    );
    refused(
        &d,
        &scene,
        &d.join("bar.toml/sub/out.h5"),
        &[],
        "is a regular file, not a directory",
    );
}

fn file_type(p: &Path) -> (String, u64) {
    use std::os::unix::fs::{FileTypeExt, MetadataExt};
    let m = std::fs::symlink_metadata(p).unwrap();
    let t = m.file_type();
    let kind = if t.is_fifo() {
        "fifo"
    } else if t.is_char_device() {
        "char device"
    } else if t.is_file() {
        "file"
    } else {
        "other"
    };
    (kind.to_string(), m.rdev())
}

#[test]
fn output_onto_a_fifo_or_a_device_is_refused() {
    let d = dir("devices");
    let scene = bar(&d);
    let fifo = d.join("pipe.h5");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o644) }, 0);
    refused(&d, &scene, &fifo, &[], "it is a FIFO (named pipe)");
    assert_eq!(file_type(&fifo).0, "fifo");

    if !is_root() {
        skipped("`-o` onto a device node made with mknod, and onto /dev/null and /dev/full in a private mount namespace,");
        return;
    }
    // A device node of our own: the null device's numbers (1, 3).
    let node = d.join("null.h5");
    let c = std::ffi::CString::new(node.to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path; makedev has no preconditions.
    let made = unsafe { libc::mknod(c.as_ptr(), libc::S_IFCHR | 0o666, libc::makedev(1, 3)) };
    assert_eq!(made, 0, "mknod: {}", std::io::Error::last_os_error());
    let before = file_type(&node);
    refused(&d, &scene, &node, &[], "it is a character device");
    assert_eq!(file_type(&node), before);

    // /dev/null and /dev/full themselves, in a private mount namespace whose /dev is a fresh
    // tmpfs holding just those two nodes (a failure there cannot touch the machine's /dev).
    let script = format!(
        "mount -t tmpfs tmpfs /dev && mknod -m 666 /dev/null c 1 3 && mknod -m 666 /dev/full c 1 7 && \
         for t in /dev/null /dev/full; do {exe} -q run {scene} -o $t; echo \"exit $t $?\"; done; \
         stat -c '%n %F %t,%T' /dev/null /dev/full; ls -A /dev | tr '\\n' ' '",
        exe = env!("CARGO_BIN_EXE_solver"),
        scene = scene.display()
    );
    let o = Command::new("unshare")
        .args(["--mount", "--propagation", "private", "sh", "-c", &script])
        .output()
        .expect("running unshare");
    let out = String::from_utf8_lossy(&o.stdout).to_string();
    let err = stderr_text(&o);
    println!("{out}{err}");
    assert!(o.status.success(), "{out}{err}");
    for t in ["/dev/null", "/dev/full"] {
        assert!(out.contains(&format!("exit {t} 2")), "{out}");
        assert!(
            err.contains(&format!(
                "{t}: not usable as the result file: it is a character device"
            )),
            "{err}"
        );
    }
    assert!(
        out.contains("/dev/null character special file 1,3"),
        "{out}"
    );
    assert!(
        out.contains("/dev/full character special file 1,7"),
        "{out}"
    );
    assert!(
        out.trim_end().ends_with("full null"),
        "nothing else in /dev: {out}"
    );
}

/// Starts two runs of `scene` on the output `out` at once; returns (exit code, standard
/// error, process id) of each, in the order they exit.
fn race(scene: &Path, out: &Path) -> Vec<(Option<i32>, String, u32)> {
    use std::io::Read;
    let spawn = || {
        solver()
            .args(["-q", "run"])
            .arg(scene)
            .arg("-o")
            .arg(out)
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap()
    };
    let mut runs = [spawn(), spawn()];
    let mut order = Vec::new();
    while order.len() < 2 {
        for (i, r) in runs.iter_mut().enumerate() {
            if !order.iter().any(|(j, _)| *j == i) {
                if let Some(s) = r.try_wait().unwrap() {
                    order.push((i, s.code()));
                }
            }
        }
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    order
        .into_iter()
        .map(|(i, code)| {
            let mut msg = String::new();
            let err = runs[i].stderr.as_mut().unwrap();
            err.read_to_string(&mut msg).unwrap();
            (code, msg.trim().to_string(), runs[i].id())
        })
        .collect()
}

/// One trial: the run that exits first was refused (exit 2, naming the other's process),
/// the other completed a readable result with the reference's last step.
fn concurrent_trial(d: &Path, scene: &Path, last: &[[f64; 3]], k: usize) -> String {
    let t = d.join(format!("trial{k}"));
    std::fs::create_dir_all(&t).unwrap();
    let out = t.join("r.h5");
    let ended = race(scene, &out);
    let ((first, msg, _), (second, _, holder)) = (&ended[0], &ended[1]);
    assert_eq!(
        *first,
        Some(2),
        "trial {k}: the refused run exits 2 and first: {msg}"
    );
    assert_eq!(*second, Some(0), "trial {k}: the other completes");
    let named = format!("another run is writing this result (process {holder} ");
    assert!(msg.contains(&named), "trial {k}: {msg}");
    // Complete and readable: every checksum, every step, the reference's last step.
    let f = solver::output::ResultFile::open(&out).unwrap();
    assert_eq!(
        f.attributes().unwrap().exit_status,
        "completed",
        "trial {k}"
    );
    assert_eq!(f.num_steps(), 30, "trial {k}");
    f.verify().unwrap();
    assert!(f.displacement(29).unwrap() == last, "trial {k}");
    let mut left: Vec<_> = std::fs::read_dir(&t)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["r.h5", "r.xmf"], "trial {k}");
    msg.clone()
}

#[test]
fn two_runs_started_together_on_one_output_the_second_is_refused_at_once() {
    let d = dir("concurrent");
    // About 0.3 s of one core, so the two runs of a trial overlap even on a loaded machine,
    // where the refusal comes within milliseconds of the start.
    let scene = scenes::stick_slip_30(&d);
    let reference = d.join("reference.h5");
    assert!(run_to(&scene, &reference, &[]).status.success());
    let last = solver::output::ResultFile::open(&reference)
        .unwrap()
        .displacement(29)
        .unwrap();
    let trials = 20;
    // Two trials at a time (four processes on the machine's two cores).
    let start = std::time::Instant::now();
    let mut messages = Vec::new();
    for pair in (0..trials).collect::<Vec<_>>().chunks(2) {
        let done: Vec<String> = std::thread::scope(|s| {
            let (d, scene, last) = (&d, &scene, &last);
            let h: Vec<_> = pair
                .iter()
                .map(|&k| s.spawn(move || concurrent_trial(d, scene, last, k)))
                .collect();
            h.into_iter().map(|h| h.join().unwrap()).collect()
        });
        messages.extend(done);
    }
    println!("{}", messages[0]);
    println!(
        "{trials} trials: the second run refused at once, the first complete with the reference's last step bitwise ({:.1} s)",
        start.elapsed().as_secs_f64()
    );
}

#[test]
fn a_stale_lock_is_taken_over_and_a_held_one_refuses() {
    let d = dir("locks");
    let scene = bar(&d);
    let out = d.join("r.h5");
    // A lock file left by a process that no longer runs (no pid reaches 2^31 - 16).
    std::fs::write(d.join("r.h5.lock"), "pid = 2147483632\nhost = gone\n").unwrap();
    let o = run_logged(&scene, &out);
    let err = stderr_text(&o);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("took over the lock of process 2147483632 on gone, which no longer runs"),
        "{err}"
    );
    assert!(out.exists() && !d.join("r.h5.lock").exists());
    // A lock another process holds (flock(1) keeps it while `sleep` runs).
    let mut holder = Command::new("flock")
        .arg(d.join("r.h5.lock"))
        .args(["sleep", "30"])
        .spawn()
        .expect("flock(1)");
    let lock = d.join("r.h5.lock");
    while !lock.exists() {
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    std::thread::sleep(std::time::Duration::from_millis(100));
    let before = std::fs::read(&out).unwrap();
    let o = run_to(&scene, &out, &[]);
    let _ = holder.kill();
    let _ = holder.wait();
    let err = stderr_text(&o);
    println!("{err}");
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("another run is writing this result"), "{err}");
    assert_eq!(
        std::fs::read(&out).unwrap(),
        before,
        "the result is untouched"
    );
}

#[test]
fn an_earlier_result_is_replaced_only_by_a_complete_one() {
    let d = dir("earlier");
    let scene = bar(&d);
    let out = d.join("r.h5");
    assert!(run_to(&scene, &out, &[]).status.success());
    let result = std::fs::read(&out).unwrap();
    let xmf = std::fs::read(d.join("r.xmf")).unwrap();
    // A run that fails (an element inverts in its first step) writes r.failed.h5 and leaves
    // the earlier r.h5 and r.xmf as they were.
    let o = run_logged(&repo("mpi-tests/fault.toml"), &out);
    let err = stderr_text(&o);
    println!("{err}");
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(d.join("r.failed.h5").exists() && d.join("r.failed.xmf").exists());
    assert_eq!(std::fs::read(&out).unwrap(), result);
    assert_eq!(std::fs::read(d.join("r.xmf")).unwrap(), xmf);
    assert!(
        err.contains("r.h5 is from an earlier run, started"),
        "{err}"
    );
    // A run killed part-way leaves its temporary file and the earlier result.
    let o = solver()
        .args(["-q", "run"])
        .arg(&scene)
        .arg("-o")
        .arg(&out)
        .env("SOLVER_TEST_ABORT_AFTER_STEP", "2")
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert_eq!(std::fs::read(&out).unwrap(), result);
    assert!(d.join("r.h5.tmp").exists());
    // A completed run replaces r.h5 by renaming, and never touches the killed run's file.
    let tmp = std::fs::read(d.join("r.h5.tmp")).unwrap();
    let o = run_logged(&scene, &out);
    let err = stderr_text(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("runs that did not finish left"), "{err}");
    assert!(err.contains("r.failed.h5 is from an earlier run"), "{err}");
    assert_eq!(std::fs::read(d.join("r.h5.tmp")).unwrap(), tmp);
    let f = solver::output::ResultFile::open(&out).unwrap();
    assert_eq!(f.attributes().unwrap().exit_status, "completed");
    assert_eq!(f.num_steps(), 4);
}

#[test]
fn a_scene_that_is_not_utf8_is_refused_with_line_and_column() {
    let d = dir("utf8");
    let mut bytes = std::fs::read(repo("run/examples/bar.toml")).unwrap();
    // `name = "bär"` in Latin-1 on the first line.
    let first_line = bytes.iter().position(|&b| b == b'\n').unwrap();
    bytes.splice(0..first_line, b"name = \"b\xe4r\"".iter().copied());
    let scene = d.join("latin1.toml");
    std::fs::write(&scene, bytes).unwrap();
    let o = solver().arg("check").arg(&scene).output().unwrap();
    let err = stderr_text(&o);
    println!("{err}");
    assert_eq!(o.status.code(), Some(2));
    assert!(
        err.contains("latin1.toml: not UTF-8 text: line 1, column 10 (byte 9, 0xe4)"),
        "{err}"
    );
}

/// One run of the bar scene into a tmpfs of `kib` KiB in a private mount namespace: exit
/// code, standard error, the files left.
fn run_on_tmpfs(mount: &Path, scene: &Path, kib: u64) -> (i32, String, Vec<String>) {
    run_on_tmpfs_with(mount, scene, kib, "")
}

/// `run_on_tmpfs` with the solver started by `launcher` (e.g. `run/mpirun -np 2 `).
fn run_on_tmpfs_with(
    mount: &Path,
    scene: &Path,
    kib: u64,
    launcher: &str,
) -> (i32, String, Vec<String>) {
    let script = format!(
        "mount -t tmpfs -o size={kib}k tmpfs {m} && {launcher}{exe} -q run {scene} -o {m}/bar.h5; echo \"exit $?\"; ls -A {m}",
        m = mount.display(),
        exe = env!("CARGO_BIN_EXE_solver"),
        scene = scene.display()
    );
    let o = Command::new("unshare")
        .args(["--mount", "--propagation", "private", "sh", "-c", &script])
        .output()
        .expect("running unshare");
    let out = String::from_utf8_lossy(&o.stdout).to_string();
    let mut lines = out.lines();
    let code = lines
        .next()
        .and_then(|l| l.strip_prefix("exit "))
        .and_then(|c| c.parse().ok())
        .unwrap_or_else(|| panic!("{out} {}", stderr_text(&o)));
    (code, stderr_text(&o), lines.map(str::to_string).collect())
}

#[test]
fn a_full_disk_gives_one_line_exit_1_and_no_result() {
    if !is_root() {
        skipped("the full-disk test (a tmpfs mounted in a private mount namespace)");
        return;
    }
    let d = dir("full");
    let scene = bar(&d);
    // The sizes the run needs, measured on the real disk.
    let out = d.join("bar.h5");
    assert!(run_to(&scene, &out, &[]).status.success());
    let page = 4;
    let pages = |p: &Path| std::fs::metadata(p).unwrap().len().div_ceil(4096);
    let (h5, xmf) = (pages(&out), pages(&d.join("bar.xmf")));
    let mount = d.join("mnt");
    std::fs::create_dir_all(&mount).unwrap();
    // Far too small, too small for the steps, and around the size of the finished files
    // (the lock file takes a page too): the XDMF file no longer fits, then everything does.
    let mut sizes = vec![8, page * h5 / 2];
    sizes.extend((h5..=h5 + xmf + 2).map(|p| p * page));
    let (mut failed, mut at_xmf, mut fits) = (0, 0, 0);
    for kib in sizes {
        let (code, err, files) = run_on_tmpfs(&mount, &scene, kib);
        println!("{kib} KiB: exit {code}, {files:?}: {err}");
        if code == 0 {
            assert_eq!(files, ["bar.h5", "bar.xmf"], "{kib} KiB");
            fits += 1;
            continue;
        }
        assert_eq!(code, 1, "{kib} KiB: {err}");
        assert_eq!(err.lines().count(), 1, "{kib} KiB: one line: {err}");
        assert!(err.contains("no space left on device"), "{kib} KiB: {err}");
        assert!(
            files
                .iter()
                .all(|f| f.ends_with(".tmp") && !f.ends_with(".xmf.tmp")),
            "{kib} KiB: no .h5, no .xmf, no lock: {files:?}"
        );
        failed += 1;
        if err.contains("bar.xmf.tmp: no space left on device") {
            at_xmf += 1;
        }
    }
    println!("{failed} sizes full ({at_xmf} of them at the XDMF file), {fits} fitting");
    assert!(failed >= 2 && at_xmf >= 1 && fits >= 1);
}

/// On 2 ranks the writing rank's HDF5 keeps the datasets whose close failed on the full
/// disk, and its shutdown in MPI_Finalize crashed on them (a segmentation fault after the
/// message): the run must end with the message and exit 1, like one rank.
#[test]
fn a_full_disk_on_two_ranks_ends_with_the_message_not_a_signal() {
    if !is_root() {
        skipped("the full-disk test on 2 ranks (a tmpfs mounted in a private mount namespace)");
        return;
    }
    let d = dir("full_np2");
    let scene = bar(&d);
    let out = d.join("bar.h5");
    assert!(run_to(&scene, &out, &[]).status.success());
    // Half the finished file: the steps no longer fit (as in the test above).
    let kib = 4 * std::fs::metadata(&out).unwrap().len().div_ceil(4096) / 2;
    let mount = d.join("mnt");
    std::fs::create_dir_all(&mount).unwrap();
    let mpirun = format!("{}/run/mpirun -np 2 ", env!("CARGO_MANIFEST_DIR"));
    let (code, err, files) = run_on_tmpfs_with(&mount, &scene, kib, &mpirun);
    println!("{kib} KiB on 2 ranks: exit {code}, {files:?}: {err}");
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("no space left on device"), "{err}");
    assert!(
        !err.contains("signal") && !err.contains("Segmentation"),
        "ended by a signal: {err}"
    );
    assert!(files.iter().all(|f| f.ends_with(".tmp")), "{files:?}");
}

/// `solver post plot ... -o target` on the result `r`.
fn plot_to(r: &Path, target: &Path) -> Output {
    solver()
        .args(["post", "plot"])
        .arg(r)
        .args(["--quantity", "displacement", "--component", "x"])
        .args(["--node-set", "right", "--history", "-o"])
        .arg(target)
        .output()
        .unwrap()
}

#[test]
fn a_picture_never_replaces_what_is_not_a_picture() {
    let d = dir("picture");
    let scene = bar(&d);
    let r = d.join("r.h5");
    assert_eq!(run_to(&scene, &r, &[]).status.code(), Some(0));
    std::fs::write(d.join("notes.png"), "my notes").unwrap();
    std::fs::create_dir(d.join("dir.png")).unwrap();
    std::os::unix::fs::symlink(&scene, d.join("link.png")).unwrap();
    std::fs::hard_link(&r, d.join("r-too.png")).unwrap();
    let cases = [
        ("bar.toml", "names no picture format"),
        ("r.h5", "names no picture format"),
        ("r.xmf", "names no picture format"),
        ("notes.png", "is not a picture"),
        ("dir.png", "a directory"),
        ("link.png", "a symbolic link"),
        ("r-too.png", "the result file of this command"),
        ("notes.png/p.png", "not a directory"),
    ];
    for (name, needle) in cases {
        let before = snapshot(&d);
        let o = plot_to(&r, &d.join(name));
        let err = stderr_text(&o);
        println!("{name}: {err}");
        assert_eq!(o.status.code(), Some(2), "{name}: {err}");
        assert!(err.contains(needle), "expected `{needle}` in: {err}");
        assert!(snapshot(&d) == before, "{name}: the directory changed");
    }
    // A new path is written, and a picture of ours is replaced, with no file left beside it.
    let png = d.join("p.png");
    for _ in 0..2 {
        let o = plot_to(&r, &png);
        assert_eq!(o.status.code(), Some(0), "{}", stderr_text(&o));
        assert!(std::fs::read(&png)
            .unwrap()
            .starts_with(b"\x89PNG\r\n\x1a\n"));
    }
    let names: Vec<String> = snapshot(&d).into_iter().map(|(n, _)| n).collect();
    assert!(names.iter().all(|n| !n.contains("tmp")), "{names:?}");
}
