//! The MPI layer's traffic counts (`comm::Traffic`, the `communication per rank` line of a
//! parallel run with -v): the block on block (run/scenes/bench/block_on_block.toml, n = 10)
//! on 2 ranks, where each rank owns nodes next to the other's. Every CG iteration applies
//! the operator once, which exchanges the halo with the one neighbour (at least one
//! message per iteration, each holding three values of every shared node), and takes at
//! least two global reductions (r.z and p.Ap); a one-rank run sends no message, and each
//! of its collectives brings it back exactly what it put in.

use crate::common;
use common::{fresh_dir, repo};
use std::process::Command;

/// The numbers of the `per CG iteration:` part of the line: messages, bytes, collectives,
/// the bytes put into collectives and the bytes they brought.
fn per_iteration(log: &str) -> Option<[f64; 5]> {
    let line = log
        .lines()
        .find(|l| l.starts_with("communication per rank"))?;
    let per = &line[line.find("per CG iteration: ")? + "per CG iteration: ".len()..];
    let nums: Vec<f64> = per
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter_map(|w| w.parse().ok())
        .collect();
    nums.get(..5)?.try_into().ok()
}

fn run(ranks: usize) -> String {
    let out = fresh_dir(&format!("communication_np{ranks}")).join("bb.h5");
    let o = Command::new(repo("run/mpirun"))
        .args(["-np", &ranks.to_string(), env!("CARGO_BIN_EXE_solver")])
        .arg("-v")
        .arg("run")
        .arg(repo("run/scenes/bench/block_on_block.toml"))
        .arg("-o")
        .arg(&out)
        .output()
        .expect("mpirun starts");
    let log = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(o.status.success(), "the run failed: {log}");
    log
}

#[test]
fn a_two_rank_run_counts_its_halo_messages_and_reductions() {
    let [messages, bytes, collectives, _, _] =
        per_iteration(&run(2)).expect("a 2-rank run prints its communication");
    println!("per CG iteration: {messages} messages, {bytes} bytes, {collectives} collectives");
    assert!(messages >= 1.0, "{messages} messages per CG iteration");
    // Both blocks are 10 x 10 elements across: a cut through either shares at least one
    // 11 x 11 layer of nodes, 3 values of 8 bytes each, in every message.
    assert!(
        bytes >= messages * 11.0 * 11.0 * 24.0 * 0.99,
        "{bytes} bytes per iteration for {messages} messages"
    );
    assert!(
        collectives >= 2.0,
        "{collectives} collectives per CG iteration"
    );
    // One rank under mpirun still calls the (trivial) reductions, but sends no message;
    // a reduction, gather or all-to-all of one rank gives it back its own values (the two
    // counts are totals over the same iterations, printed the same way).
    let [m1, b1, c1, put, brought] = per_iteration(&run(1)).expect("the line on one rank too");
    assert_eq!((m1, b1), (0.0, 0.0), "one rank sends no message");
    assert!(c1 > 0.0 && put > 0.0, "{c1} collectives of {put} bytes");
    assert_eq!(
        put, brought,
        "bytes put into collectives and brought by them"
    );
}
