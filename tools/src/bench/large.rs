//! `--large`: the block on block at about 10^6 elements (n = 80) under `auto` (multilevel
//! at that size) or the preconditioner named, each rank count after a memory check from two
//! pilot sizes (multilevel under `auto`: smaller, the pilots would run others). Its section
//! is merged into the files of an earlier normal run (`report::large`); what it measured is
//! `results::large`.

use crate::block::{block_case, BlockCase, BLOCK_BASE_N, SOLVER_TIMEOUT_S};
use crate::machine::{machine, RunInfo};
use crate::report;
use crate::results::large::{
    model_text, Large, LargeOutcome, LargeRun, MemoryEstimate, LARGE_MIN_AVAILABLE, LARGE_PILOT,
    LARGE_REFINE, LARGE_TIMEOUT_S,
};
use crate::runner::process::{memory_available, Limits, MIB};
use crate::runner::solver::{compare_results, solver_exe, Precond};
use std::path::Path;
use std::time::Instant;

/// The pilots, the memory check and the large run on `ranks` ranks.
fn large_run(exe: &Path, dir: &Path, ranks: usize, precond: Precond) -> LargeRun {
    let limits = Limits::timeout(SOLVER_TIMEOUT_S);
    // `auto` keeps multilevel on standby below MULTILEVEL_NODES (the n = 20 pilot, 18522
    // nodes): the pilots name it.
    let pilot_precond = match precond {
        Precond::Auto => Precond::Multilevel,
        p => p,
    };
    eprintln!(
        "bench: large, {ranks} rank(s): pilot runs n = {:?} ({}) for the memory estimate",
        LARGE_PILOT.map(|f| BLOCK_BASE_N * f),
        pilot_precond.label()
    );
    let pilot: Result<Vec<BlockCase>, String> = LARGE_PILOT
        .iter()
        .map(|&f| block_case(exe, dir, f, ranks, pilot_precond, 1, &limits))
        .collect();
    let available = memory_available().map(|m| m / MIB);
    let estimate =
        pilot.and_then(|p| MemoryEstimate::new(&p.iter().collect::<Vec<_>>(), ranks, available));
    let outcome = match &estimate {
        Err(e) => LargeOutcome::NotRun(format!("memory estimate failed: {e}")),
        Ok(m) if !m.fits => LargeOutcome::NotRun(format!("not enough memory: {}", m.text(ranks))),
        Ok(m) => {
            eprintln!("bench: large, {ranks} rank(s): {}", m.text(ranks));
            eprintln!(
                "bench: large, {ranks} rank(s): n = {} ({} elements), {}; this takes a while",
                BLOCK_BASE_N * LARGE_REFINE,
                m.elements,
                precond.label()
            );
            let limits = Limits {
                timeout_s: LARGE_TIMEOUT_S,
                rss_limit: None,
                min_available: Some(LARGE_MIN_AVAILABLE),
            };
            match block_case(exe, dir, LARGE_REFINE, ranks, precond, 1, &limits) {
                Ok(c) => LargeOutcome::Finished(Box::new(c)),
                Err(e) => LargeOutcome::Failed(e),
            }
        }
    };
    match &outcome {
        LargeOutcome::Finished(c) => eprintln!(
            "bench: large, {ranks} rank(s): {}",
            model_text(ranks, precond, Some(c.runs.peak_mib.median))
        ),
        LargeOutcome::Failed(why) => eprintln!("bench: large, {ranks} rank(s) failed: {why}"),
        LargeOutcome::NotRun(why) => eprintln!("bench: large, {ranks} rank(s) not run: {why}"),
    }
    LargeRun {
        ranks,
        precond,
        estimate,
        outcome,
    }
}

/// `bench --large`: the large runs, merged into `<out>/results.json` and `<out>/report.md`.
pub fn run(out: &Path, ranks: &[usize], precond: Precond) -> Result<(), String> {
    let start = Instant::now();
    let dir = out.join("large");
    std::fs::create_dir_all(&dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let machine = machine();
    let exe = solver_exe()?;
    eprintln!(
        "bench: large block on block (n = {}, {}) on {ranks:?} rank(s)",
        BLOCK_BASE_N * LARGE_REFINE,
        precond.label()
    );
    let runs: Vec<LargeRun> = ranks
        .iter()
        .map(|&r| large_run(&exe, &dir, r, precond))
        .collect();
    let finished: Vec<&BlockCase> = runs.iter().filter_map(LargeRun::finished).collect();
    let compare = match finished.as_slice() {
        [a, b, ..] => Some(compare_results(&exe, &a.result, &b.result)),
        _ => None,
    };
    let large = Large {
        info: RunInfo::finish(machine, start),
        precond,
        runs,
        compare,
    };
    let section = report::large::markdown(&large, &dir);
    let (jpath, rpath) = report::large::merge(out, report::large::json(&large), &section)?;
    println!("{section}");
    eprintln!("bench: wrote {} and {}", jpath.display(), rpath.display());
    let failed = large.runs.iter().filter(|r| r.finished().is_none()).count();
    if failed > 0 {
        return Err(format!(
            "{failed} large run(s) did not finish; see the report"
        ));
    }
    Ok(())
}
