//! `bench`: the performance benchmark (reported, never asserted).
//!
//! Measures, on this machine:
//! 1. STREAM-like memory bandwidth (copy and triad over arrays much larger than the caches)
//!    (`bandwidth`),
//! 2. the element kernels (`Assembly::internal_force` and `Assembly::diagonal`) on one
//!    core for every integration / material combination on a structured cube mesh, with a
//!    memory-traffic model and the fraction of the measured bandwidth it implies
//!    (`kernels`),
//! 3. CG iterations and wall time of a cube compression solved through the library's
//!    analysis driver (`cube`),
//! 4. the contact search (`MasterSurface::new`, the BVH of master faces, and
//!    `MasterSurface::search` of every slave node) on two stacked blocks with non-matching
//!    meshes, about 1e5 slave nodes against 1e5 master faces (1e4 in quick mode) (`search`),
//! 5. the block-on-block scene (`run/scenes/bench/block_on_block.toml`) refined to n = 10,
//!    20, 40 elements per edge (n = 10 in quick mode), run by `target/release/solver` under
//!    `run/mpirun` on 1 and 2 ranks with each preconditioner (`--preconditioner jacobi` and
//!    `two_level`): CG iterations, contact updates, wall time, peak memory, total contact
//!    force, the coarse space, the two-level / Jacobi ratios of iterations and time, the
//!    difference of the contact forces, the 2-rank speed-up and whether the 1- and 2-rank
//!    result files are bitwise identical; and `solver check --ranks 2, 3` of the largest size
//!    (the partition) (`block`),
//! 6. CalculiX (`ccx`, when installed) on the same problem, from an input deck written here,
//!    on 2 threads within 5 minutes per size: its wall time and total force beside ours
//!    (`peers::calculix`).
//!
//! Writes `<out>/results.json` and `<out>/report.md` (default `out/bench`) and prints the
//! report. Usage: `bench [--quick] [--out DIR]`. Normally started by `run/bench`.
//!
//! `bench --large [--ranks 2|1|1,2] [--preconditioner auto|two_level|multilevel] [--out DIR]`
//! runs only the block on block at n = 80 (about 10^6 elements) with the solver's own choice
//! (`auto`: multilevel at that size) or the preconditioner named, after a memory estimate
//! from n = 20 and 40 on the same rank count (with multilevel under `auto`), and puts it
//! into the same two files as a section
//! of its own (the other sections are left as they are; a later normal run keeps it)
//! (`large`).
//!
//! `bench --ironing [--out DIR]` runs only the ironing example and the block die with
//! CalculiX beside them (`peers::calculix::ironing`) into `<out>/ironing/` and
//! `<out>/ironing/block/`.
//!
//! `bench --plasticity [--quick] [--out DIR]` runs only the flat punch in a J2 block,
//! prescribed (40 x 40, 80 x 80) and through contact (n = 48, 96; `--quick`: 40 x 40 and
//! n = 48), ours on 2 ranks beside CalculiX on 2 threads, into `<out>/plasticity/`
//! (`peers::calculix::plasticity`).
//!
//! `bench --scaling [--out DIR]` runs only the block on block at n = 40 (multilevel) on 1,
//! 2, 4, 8 and 16 ranks: the peak memory per rank fitted as a + b / P, the messages each
//! rank sends per CG iteration, and a latency-bandwidth model of strong and weak scaling to
//! 1024 ranks, into `<out>/scaling/` (`scaling`).
//!
//! `bench --tet [--quick] [--out DIR]` runs only Cook's membrane and the J2 punch on Gmsh
//! tetrahedral meshes, ours (composite tet10) beside CalculiX's C3D10 on the same nodes and
//! our hex8 at its finest mesh, and the Hertz cylinder on tetrahedra beside C3D10, into
//! `<out>/tet/` (`peers::calculix::tet`).
//!
//! `bench --pyamg [--out DIR]` exports the first model problem of the block on block
//! (n = 20, 40) and of the Hertz example x2 (`solver run --export-operator`) and runs
//! PyAMG's smoothed aggregation on it (`run/pyamg_peer.py`) beside our multilevel
//! preconditioner: CG iterations of both, into the same two files as a section of its own
//! (`pyamg`).
//! `bench --robustness [--quick] [--out DIR]` runs only the robustness table: the Hertz
//! example at x1, x2, x4, the extreme suite's hard scenes, the stick/slip bar at
//! 160 x 8 x 1 and the block on block at n = 20 on 2 ranks with every preconditioner under
//! a time limit, and CalculiX beside the Hertz meshes and the bar, into
//! `<out>/robustness/` (`robustness`, `peers::calculix::robustness`).
//!
//! `bench --general [--quick] [--out DIR]` runs only a stack of 32 and of 128 blocks with
//! general contact against the same stack with explicit pairs on 2 ranks (about 10^4 and
//! 10^5 exterior faces; `--quick`: the first): the contact updates' time per update and its
//! ratio to the pairs', into `<out>/general/` (`general`).
//!
//! The tree: `suite` runs the benchmarks in turn into the one results model (`results`),
//! which the report writers (`report`, one file per section, JSON and Markdown side by
//! side) read; `runner` runs programs (the solver under `run/mpirun`, with time limits,
//! peak memory, repeats and its result files); `peers` runs other codes on our problems;
//! `api` is the only place that names the solver library's modules.

mod api;
mod bandwidth;
mod block;
mod config;
mod cube;
mod general;
mod kernels;
mod large;
mod machine;
mod peers;
mod pyamg;
mod report;
mod results;
mod robustness;
mod runner;
mod scaling;
mod search;
mod stats;
mod suite;
mod tet_cube;

use config::Config;
use runner::solver::Precond;
use std::path::PathBuf;
use std::process::ExitCode;

const USAGE: &str = concat!(
    "usage: bench [--quick] [--out DIR]\n",
    "       bench --large [--ranks R[,R]] [--preconditioner P] [--out DIR]\n",
    "       bench --ironing [--out DIR]\n",
    "       bench --pyamg [--out DIR]\n",
    "       bench --robustness [--quick] [--out DIR]\n",
    "       bench --plasticity [--quick] [--out DIR]\n",
    "       bench --scaling [--out DIR]\n",
    "       bench --tet [--quick] [--out DIR]\n",
    "       bench --general [--quick] [--out DIR]\n",
    "  --quick      smaller sizes and fewer repeats (a smoke test, about a minute)\n",
    "  --large      only the block on block at n = 80 (about 10^6 elements), after\n",
    "               a memory check; merged into results.json and report.md as a section of\n",
    "               its own\n",
    "  --ironing    only the ironing example and the block die beside CalculiX: die\n",
    "               forces, a picture, in <out>/ironing/ and <out>/ironing/block/\n",
    "  --pyamg      only PyAMG's smoothed aggregation beside our multilevel preconditioner on\n",
    "               the exported first model problem (block on block n = 20, 40; Hertz x2):\n",
    "               CG iterations of both; merged into results.json and report.md\n",
    "  --robustness only the robustness table: Hertz x1, x2, x4, extreme scenes, stick/slip\n",
    "               160 x 8 x 1, block n = 20 on 2 ranks with jacobi, two_level, multilevel\n",
    "               and auto (240 s limit per run), CalculiX beside Hertz and the bar\n",
    "               (600 s limit), in <out>/robustness/ (with --quick: a subset, 60 s limit)\n",
    "  --plasticity only the flat punch in a J2 block beside CalculiX (ours 2 ranks, ccx 2\n",
    "               threads, C3D8I): prescribed at 40 x 40 and 80 x 80 (50 increments),\n",
    "               through contact at n = 48 and 96 (12 steps); wall times, CG per\n",
    "               increment, Newton iterations, final pressures, in <out>/plasticity/\n",
    "               (with --quick: 40 x 40 and n = 48)\n",
    "  --scaling    only the block on block at n = 40 (multilevel) on 1, 2, 4, 8, 16 ranks\n",
    "               (oversubscribed): peak memory per rank fitted as a + b / P, messages\n",
    "               per CG iteration, a model of scaling to 1024 ranks, in <out>/scaling/\n",
    "  --tet        only tetrahedra: Cook's membrane (nu = 0.4999) and the J2 punch on three\n",
    "               Gmsh tet meshes, ours (tet10) and CalculiX C3D10 on the same nodes,\n",
    "               against our hex8 at its finest mesh, and the Hertz cylinder on tets\n",
    "               beside C3D10, in <out>/tet/ (with --quick: two meshes, fewer Hertz runs)\n",
    "  --general    only general contact against explicit pairs on stacks of 32 and 128\n",
    "               blocks (10^4 and 10^5 exterior faces; --quick: the first): time per\n",
    "               contact update and its ratio, in <out>/general/\n",
    "  --ranks R,.. rank counts of --large, in order (default 2; 1,2 or 2,1 for both)\n",
    "  --preconditioner P\n",
    "               auto (default: multilevel there), two_level or multilevel, for --large\n",
    "               (its section replaces an\n",
    "               earlier one, whichever preconditioner that was)\n",
    "  --out DIR    where results.json and report.md go (default out/bench)",
);

/// What the command line asks for.
#[derive(Debug, PartialEq)]
enum Mode {
    Normal { quick: bool },
    Large { ranks: Vec<usize>, precond: Precond },
    Ironing,
    Pyamg,
    Robustness { quick: bool },
    Plasticity { quick: bool },
    Scaling,
    Tet { quick: bool },
    General { quick: bool },
}

#[derive(Debug, PartialEq)]
struct Args {
    mode: Mode,
    out: PathBuf,
}

/// The command line (without the program name); `Ok(None)` asks for the usage. Arguments
/// are taken in order: the first that is wrong, or `--help`, decides.
/// The value of `--preconditioner` (for `--large`).
fn large_precond(name: Option<&str>) -> Result<Precond, String> {
    match name {
        Some("auto") => Ok(Precond::Auto),
        Some("two_level") => Ok(Precond::TwoLevel),
        Some("multilevel") => Ok(Precond::Multilevel),
        _ => Err("--preconditioner needs auto, two_level or multilevel".into()),
    }
}

fn parse_args(args: impl IntoIterator<Item = String>) -> Result<Option<Args>, String> {
    let mut quick = false;
    let mut large = false;
    let mut ironing = false;
    let mut pyamg = false;
    let mut robustness = false;
    let mut plasticity = false;
    let mut scaling = false;
    let mut tet = false;
    let mut general = false;
    let mut ranks: Option<Vec<usize>> = None;
    let mut precond: Option<Precond> = None;
    let mut out = PathBuf::from("out/bench");
    let mut args = args.into_iter();
    while let Some(a) = args.next() {
        match a.as_str() {
            "--quick" => quick = true,
            "--large" => large = true,
            "--ironing" => ironing = true,
            "--pyamg" => pyamg = true,
            "--robustness" => robustness = true,
            "--plasticity" => plasticity = true,
            "--scaling" => scaling = true,
            "--tet" => tet = true,
            "--general" => general = true,
            "--ranks" => {
                let list: Option<Vec<usize>> = args.next().and_then(|v| {
                    v.split(',')
                        .map(|r| r.trim().parse().ok().filter(|&r: &usize| r >= 1))
                        .collect()
                });
                match list {
                    Some(l) if !l.is_empty() => ranks = Some(l),
                    _ => return Err("--ranks needs rank counts such as 2 or 1,2".into()),
                }
            }
            "--preconditioner" => precond = Some(large_precond(args.next().as_deref())?),
            "--out" => match args.next() {
                Some(d) => out = PathBuf::from(d),
                None => return Err("--out needs a directory".into()),
            },
            "-h" | "--help" => return Ok(None),
            other => return Err(format!("unknown argument '{other}'")),
        }
    }
    if large && quick {
        return Err("--large and --quick do not go together".into());
    }
    if ironing && (large || quick) {
        return Err("--ironing goes with --out only".into());
    }
    if robustness && (large || ironing) {
        return Err("--robustness goes with --quick and --out only".into());
    }
    if ranks.is_some() && !large {
        return Err("--ranks goes with --large only".into());
    }
    if precond.is_some() && !large {
        return Err("--preconditioner goes with --large only".into());
    }
    if pyamg && (ironing || large || quick || robustness) {
        return Err("--pyamg goes with --out only".into());
    }
    if plasticity && (large || ironing || pyamg || robustness) {
        return Err("--plasticity goes with --quick and --out only".into());
    }
    if scaling && (quick || large || ironing || pyamg || robustness || plasticity) {
        return Err("--scaling goes with --out only".into());
    }
    let others = large || ironing || pyamg || robustness || plasticity || scaling;
    if (tet || general) && (others || (tet && general)) {
        let which = if general { "--general" } else { "--tet" };
        return Err(format!("{which} goes with --quick and --out only"));
    }
    let mode = if general {
        Mode::General { quick }
    } else if tet {
        Mode::Tet { quick }
    } else if scaling {
        Mode::Scaling
    } else if plasticity {
        Mode::Plasticity { quick }
    } else if pyamg {
        Mode::Pyamg
    } else if robustness {
        Mode::Robustness { quick }
    } else if ironing {
        Mode::Ironing
    } else if large {
        Mode::Large {
            ranks: ranks.unwrap_or(results::large::LARGE_DEFAULT_RANKS.to_vec()),
            precond: precond.unwrap_or(Precond::Auto),
        }
    } else {
        Mode::Normal { quick }
    };
    Ok(Some(Args { mode, out }))
}

/// Exit codes: 0 done, 1 a run failed (the report says which), 2 a bad command line.
fn main() -> ExitCode {
    let args = match parse_args(std::env::args().skip(1)) {
        Ok(Some(args)) => args,
        Ok(None) => {
            println!("{USAGE}");
            return ExitCode::SUCCESS;
        }
        Err(msg) => {
            eprintln!("bench: {msg}\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    let done = match args.mode {
        Mode::Large { ranks, precond } => large::run(&args.out, &ranks, precond),
        Mode::Ironing => peers::calculix::ironing::run(&args.out).map(|_| ()),
        Mode::Pyamg => pyamg::run(&args.out),
        Mode::Robustness { quick } => robustness::run(&args.out, quick),
        Mode::Plasticity { quick } => peers::calculix::plasticity::run(&args.out, quick),
        Mode::Scaling => scaling::run(&args.out),
        Mode::Tet { quick } => peers::calculix::tet::run(&args.out, quick),
        Mode::General { quick } => general::run(&args.out, quick),
        Mode::Normal { quick } => suite::run(Config::new(quick, args.out)),
    };
    match done {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("bench: {e}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(args: &[&str]) -> Result<Option<Args>, String> {
        parse_args(args.iter().map(|a| a.to_string()))
    }

    fn normal(quick: bool, out: &str) -> Result<Option<Args>, String> {
        Ok(Some(Args {
            mode: Mode::Normal { quick },
            out: PathBuf::from(out),
        }))
    }

    #[test]
    fn command_lines() {
        assert_eq!(parse(&[]), normal(false, "out/bench"));
        assert_eq!(parse(&["--quick", "--out", "d"]), normal(true, "d"));
        assert_eq!(
            parse(&["--large"]),
            Ok(Some(Args {
                mode: Mode::Large {
                    ranks: vec![2],
                    precond: Precond::Auto
                },
                out: PathBuf::from("out/bench"),
            }))
        );
        assert_eq!(
            parse(&["--ranks", "2, 1", "--large"]),
            Ok(Some(Args {
                mode: Mode::Large {
                    ranks: vec![2, 1],
                    precond: Precond::Auto
                },
                out: PathBuf::from("out/bench"),
            }))
        );
        assert_eq!(
            parse(&["--large", "--preconditioner", "multilevel"]),
            Ok(Some(Args {
                mode: Mode::Large {
                    ranks: vec![2],
                    precond: Precond::Multilevel
                },
                out: PathBuf::from("out/bench"),
            }))
        );
        assert_eq!(
            parse(&["--ironing", "--out", "d"]),
            Ok(Some(Args {
                mode: Mode::Ironing,
                out: PathBuf::from("d"),
            }))
        );
        assert_eq!(
            parse(&["--ironing", "--large"]),
            Err("--ironing goes with --out only".into())
        );
        assert_eq!(
            parse(&["--robustness", "--quick"]),
            Ok(Some(Args {
                mode: Mode::Robustness { quick: true },
                out: PathBuf::from("out/bench"),
            }))
        );
        assert_eq!(
            parse(&["--robustness", "--ironing"]),
            Err("--robustness goes with --quick and --out only".into())
        );
        assert_eq!(
            parse(&["--plasticity", "--quick", "--out", "d"]),
            Ok(Some(Args {
                mode: Mode::Plasticity { quick: true },
                out: PathBuf::from("d"),
            }))
        );
        assert_eq!(
            parse(&["--plasticity", "--large"]),
            Err("--plasticity goes with --quick and --out only".into())
        );
        assert_eq!(
            parse(&["--tet", "--quick"]),
            Ok(Some(Args {
                mode: Mode::Tet { quick: true },
                out: PathBuf::from("out/bench"),
            }))
        );
        assert_eq!(
            parse(&["--tet", "--scaling"]),
            Err("--tet goes with --quick and --out only".into())
        );
        assert_eq!(parse(&["--help", "--bogus"]), Ok(None));
        assert_eq!(parse(&["-h"]), Ok(None));
    }

    #[test]
    fn bad_command_lines() {
        let err = |args: &[&str]| parse(args).unwrap_err();
        assert_eq!(err(&["--bogus", "--help"]), "unknown argument '--bogus'");
        assert_eq!(
            err(&["--large", "--quick"]),
            "--large and --quick do not go together"
        );
        assert_eq!(err(&["--ranks", "2"]), "--ranks goes with --large only");
        for bad in [
            &["--large", "--ranks"][..],
            &["--large", "--ranks", "0"],
            &["--large", "--ranks", "1,x"],
            &["--large", "--ranks", ""],
        ] {
            assert_eq!(
                err(bad),
                "--ranks needs rank counts such as 2 or 1,2",
                "{bad:?}"
            );
        }
        assert_eq!(err(&["--out"]), "--out needs a directory");
        assert_eq!(
            err(&["--preconditioner", "multilevel"]),
            "--preconditioner goes with --large only"
        );
        for bad in [
            &["--large", "--preconditioner"][..],
            &["--large", "--preconditioner", "jacobi"],
        ] {
            assert_eq!(
                err(bad),
                "--preconditioner needs auto, two_level or multilevel",
                "{bad:?}"
            );
        }
    }
}
