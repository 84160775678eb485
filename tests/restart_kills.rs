//! A restart never writes into its input: a restart killed (SIGKILL) at any moment leaves
//! its input as it was and, once it wrote its first restart state, a file of its own; a
//! further restart from the newest of the two ends bitwise identical to an uninterrupted run.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use crate::common;
use common::{fresh_dir, restart, scenes, solver, stderr_text};

fn dir(name: &str) -> PathBuf {
    fresh_dir(&format!("restart-kills-{name}"))
}

/// How one trial went.
#[derive(Debug)]
enum Outcome {
    /// Killed; continued from the killed restart's own file.
    FromOwnFile,
    /// Killed before its own file held a restart state (`true`: the file was there but
    /// refused, `false`: not there yet); continued from the input.
    FromInput(bool),
    /// The restart had finished before the kill.
    Finished,
}

/// `solver -q run scene --restart input -o out`.
fn restart_run(scene: &Path, input: &Path, out: &Path) -> Command {
    let mut c = solver();
    c.args(["-q", "run"])
        .arg(scene)
        .arg("--restart")
        .arg(input)
        .arg("-o")
        .arg(out);
    c
}

fn trial(d: &Path, scene: &Path, input: &Path, full: &Path, delay: Duration) -> Outcome {
    let before = std::fs::read(input).unwrap();
    let out = d.join("cut.h5");
    let mut child = restart_run(scene, input, &out).spawn().unwrap();
    std::thread::sleep(delay);
    let _ = child.kill();
    let status = child.wait().unwrap();
    assert_eq!(
        std::fs::read(input).unwrap(),
        before,
        "the restart's input is never written"
    );
    let outcome = if status.success() {
        Outcome::Finished
    } else {
        // The killed restart's file: the first temporary name its input does not have.
        let own = d.join("cut.h5.2.tmp");
        let from_own = own.exists() && {
            let o = restart_run(scene, &own, &out).output().unwrap();
            let err = stderr_text(&o);
            assert!(
                o.status.success() || o.status.code() == Some(2),
                "{delay:?}: {err}"
            );
            if !o.status.success() {
                println!("{delay:?}: its own file refused: {err}");
            }
            o.status.success()
        };
        if from_own {
            Outcome::FromOwnFile
        } else {
            let o = restart_run(scene, input, &out).output().unwrap();
            let err = stderr_text(&o);
            assert!(o.status.success(), "{delay:?}: from the input: {err}");
            Outcome::FromInput(own.exists())
        }
    };
    let (_, report) = restart::post_compare(full, &out);
    assert!(
        report.contains("result: bitwise identical"),
        "{delay:?} ({outcome:?}):\n{report}"
    );
    outcome
}

/// Kills spread over `span` (the measured length of an uninterrupted restart), 20 slots,
/// each kill at a fixed pseudo-random point of its slot.
fn kill_delays(span: Duration) -> Vec<Duration> {
    let slot = span.as_micros().max(20_000) as u64 / 20;
    let mut x: u64 = 0x2545_f491_4f6c_dd1d;
    (0..20u64)
        .map(|k| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            Duration::from_micros(slot * k + x % slot)
        })
        .collect()
}

/// Trials continued from the killed restart's own file, from the input, from the input
/// with an own file that was refused, and restarts that had finished before the kill.
fn tally(outcomes: &[(Duration, Outcome)]) -> [usize; 4] {
    let count = |f: &dyn Fn(&Outcome) -> bool| outcomes.iter().filter(|(_, o)| f(o)).count();
    [
        count(&|o| matches!(o, Outcome::FromOwnFile)),
        count(&|o| matches!(o, Outcome::FromInput(_))),
        count(&|o| matches!(o, Outcome::FromInput(true))),
        count(&|o| matches!(o, Outcome::Finished)),
    ]
}

#[test]
fn a_restart_killed_at_20_moments_always_leaves_a_file_to_continue_from() {
    let start = Instant::now();
    let d = dir("setup");
    // 20 steps of loading, then 10 of sliding, so that the kills fall all over the restart.
    let scene = scenes::stick_slip_30(&d);
    let full = d.join("full.h5");
    assert!(solver()
        .args(["-q", "run"])
        .arg(&scene)
        .arg("-o")
        .arg(&full)
        .status()
        .unwrap()
        .success());
    // The input of every trial: a run killed after step 20 (the end of the loading).
    let base = d.join("cut.h5");
    let s = solver()
        .args(["-q", "run"])
        .arg(&scene)
        .arg("-o")
        .arg(&base)
        .env("SOLVER_TEST_ABORT_AFTER_STEP", "20")
        .status()
        .unwrap();
    assert!(!s.success());
    let input = d.join("cut.h5.tmp");
    assert!(input.exists());
    // How long a restart takes uninterrupted on this machine: the kills are spread over it
    // (a fixed window went stale when the friction scenes got faster).
    let timed = d.join("timed.h5.tmp");
    std::fs::copy(&input, &timed).unwrap();
    let began = Instant::now();
    assert!(restart_run(&scene, &timed, &d.join("timed_out.h5"))
        .status()
        .unwrap()
        .success());
    let delays = kill_delays(began.elapsed());
    // Two trials at a time, each in a directory of its own with a copy of the input.
    let outcomes: Vec<(Duration, Outcome)> = std::thread::scope(|s| {
        let handles: Vec<_> = [0usize, 1]
            .into_iter()
            .map(|half| {
                let (scene, full, input, delays) = (&scene, &full, &input, &delays);
                s.spawn(move || {
                    (half..delays.len())
                        .step_by(2)
                        .map(|k| {
                            let t = dir(&format!("trial{k}"));
                            let copy = t.join("cut.h5.tmp");
                            std::fs::copy(input, &copy).unwrap();
                            (delays[k], trial(&t, scene, &copy, full, delays[k]))
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        let mut all: Vec<_> = handles
            .into_iter()
            .flat_map(|h| h.join().unwrap())
            .collect();
        all.sort_by_key(|(d, _)| *d);
        all
    });
    for (delay, outcome) in &outcomes {
        println!(
            "killed after {:>5.1} ms: {outcome:?}",
            delay.as_secs_f64() * 1e3
        );
    }
    let [own, input_used, refused, finished] = tally(&outcomes);
    println!(
        "20 kills: {own} continued from the killed restart's own file, {input_used} from the untouched input ({refused} of them with an own file not yet restartable), {finished} had finished; all bitwise identical to the uninterrupted run ({:.1} s)",
        start.elapsed().as_secs_f64()
    );
    // The kills are spread over the restart's own length, so most land inside it, and a restart that got
    // past copying the earlier steps leaves a file of its own to continue from.
    assert!(
        finished <= 10,
        "too few kills inside the restart: {finished} had finished"
    );
    assert!(
        own >= 1,
        "no killed restart left a file of its own to continue from"
    );
}
