//! `suite study` (run/study): error against run time. The paper scenes with exact answers,
//! refined by several factors (`refine_scene_text`, never hand-made copies) and solved at
//! several CG tolerances, on 1 and 2 MPI ranks. Each run's error comes from `solver post
//! verify --json` (the same checks as the paper tests), its wall time, CG iterations and
//! contact updates from the same report. Writes `results.csv`, `report.md` and one log-log
//! PNG per scene series.
//!
//! The tree: `cases` (the series and how their errors are read), `solve` (one run: scene
//! file, solver, verify, comparison), `row` (one run's results), `csv` and `report` (the
//! two files, which read the rows).

mod cases;
mod csv;
mod report;
mod row;
mod solve;

use cases::{pick_error, value, CASES, RANKS, TOLERANCES};
use row::{opt, Row};
use solve::{same, scene_file, solve};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// `suite study [--quick] [--out DIR]`.
pub fn main(args: &[String]) -> Result<(), String> {
    let mut quick = false;
    let mut out = PathBuf::from("out/study");
    let mut args = args.iter();
    while let Some(a) = args.next() {
        match a.as_str() {
            "--quick" => quick = true,
            "--out" => match args.next() {
                Some(d) => out = PathBuf::from(d),
                None => return Err("--out needs a directory".into()),
            },
            "-h" | "--help" => {
                println!("usage: suite study [--quick] [--out DIR]");
                return Ok(());
            }
            other => {
                return Err(format!(
                    "unknown option '{other}' (expected --quick or --out DIR)"
                ))
            }
        }
    }
    run(quick, &out)
}

fn run(quick: bool, out: &Path) -> Result<(), String> {
    let start = Instant::now();
    let scenes = out.join("scenes");
    let results = out.join("results");
    for d in [&scenes, &results] {
        std::fs::create_dir_all(d).map_err(|e| format!("{}: {e}", d.display()))?;
    }
    let solver = Path::new("target/release/solver");
    if !solver.exists() {
        return Err("target/release/solver is missing (run/study builds it)".into());
    }
    let tolerances: &[f64] = if quick { &[1e-5, 1e-9] } else { TOLERANCES };
    let mut rows = Vec::new();
    for case in CASES {
        let factors: Vec<u32> = if quick {
            case.factors.iter().copied().take(2).collect()
        } else {
            case.factors.to_vec()
        };
        let source = format!("run/scenes/paper/{}.toml", case.scene);
        let text = std::fs::read_to_string(&source).map_err(|e| format!("{source}: {e}"))?;
        for &f in &factors {
            for &tol in tolerances {
                let scene = scene_file(&text, case.scene, f, tol, &scenes)?;
                let mut first: Option<PathBuf> = None;
                for &np in RANKS {
                    let h5 = results.join(format!("{}_r{f}_tol{tol:e}_np{np}.h5", case.scene));
                    let (status, report) = solve(solver, &scene, &h5, np);
                    let identical = match (&first, np) {
                        (Some(a), n) if n > 1 && status == "ok" => Some(same(solver, a, &h5)),
                        _ => None,
                    };
                    if np == 1 && status == "ok" {
                        first = Some(h5.clone());
                    }
                    let reported = |name: &str| report.as_ref().and_then(|r| value(r, name));
                    for &(label, _, pick) in case.series {
                        let error = report.as_ref().and_then(|r| pick_error(r, pick));
                        let row = Row {
                            series: label.to_string(),
                            scene: case.scene.to_string(),
                            factor: f,
                            tolerance: tol,
                            ranks: np,
                            error,
                            wall_time: reported("wall time [s]"),
                            cg_iterations: reported("CG iterations (total)"),
                            contact_updates: reported("contact updates (total)"),
                            identical,
                            status: status.clone(),
                        };
                        eprintln!(
                            "study: {:<30} r{f} tol {tol:.0e} {np} rank(s): error {}  time {}  CG {}  {}",
                            label,
                            opt(row.error),
                            opt(row.wall_time),
                            opt(row.cg_iterations),
                            row.status
                        );
                        rows.push(row);
                    }
                }
            }
        }
    }
    csv::write_csv(&out.join("results.csv"), &rows)?;
    let report = report::report(&rows, out, start.elapsed().as_secs_f64(), quick)?;
    let path = out.join("report.md");
    std::fs::write(&path, &report).map_err(|e| format!("{}: {e}", path.display()))?;
    println!("{report}");
    Ok(())
}
