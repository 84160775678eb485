//! A normal run (`bench [--quick]`): every benchmark in turn, into the one results
//! model, then both files. A new benchmark is a module of its own and its line here (a
//! field of `Results`), and its report section (`report/mod.rs`).

use crate::config::Config;
use crate::machine::{machine, RunInfo};
use crate::peers::calculix;
use crate::report;
use crate::results::Results;
use crate::runner::solver::solver_exe;
use crate::{bandwidth, block, cube, kernels, search};
use std::time::Instant;

pub fn run(cfg: Config) -> Result<(), String> {
    let start = Instant::now();
    std::fs::create_dir_all(&cfg.out)
        .map_err(|e| format!("cannot create {}: {e}", cfg.out.display()))?;
    let machine = machine();
    eprintln!(
        "bench: {} mode on {} ({} logical CPUs)",
        if cfg.quick { "quick" } else { "full" },
        machine.cpu_model,
        machine.logical_cpus
    );
    let stream = bandwidth::run(&cfg, machine.logical_cpus);
    let kernels = kernels::run(&cfg)?;
    let cubes = cube::run(&cfg)?;
    let contact = search::run(&cfg)?;
    let exe = solver_exe()?;
    let blocks = block::run(&cfg, &exe)?;
    let partitions = block::partitions(&cfg, &exe);
    let calculix = calculix::block::run(&cfg);
    let results = Results {
        quick: cfg.quick,
        kernel_n: cfg.kernel_n,
        stream,
        kernels,
        cubes,
        contact,
        blocks,
        block_tolerance: block::block_tolerance(),
        partitions,
        calculix,
        large: report::large::earlier(&cfg.out),
        info: RunInfo::finish(machine, start),
    };
    let (jpath, rpath, text) = report::write(&results, &cfg.out)?;
    println!("{text}");
    eprintln!("bench: wrote {} and {}", jpath.display(), rpath.display());
    let failed = results.failed_block_runs();
    if failed > 0 {
        return Err(format!(
            "{failed} block-on-block run(s) failed; see the report"
        ));
    }
    Ok(())
}
