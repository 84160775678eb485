//! `suite extreme` (run/extreme): hard scenes the solver must either solve (and pass a
//! physical check) or stop on cleanly, with a message naming the step, the time and the
//! cause. Every scene of `run/scenes/extreme/` runs on 1 rank and (unless `--one-rank`) on
//! 2 under a time limit; each result is checked from its file (`checks`, `scenes`: force
//! balance, exact answers where there are some, scale invariance, Coulomb's law, through
//! `solver::post::balance`), 1 rank is compared with 2 bitwise (`solver post compare`),
//! each scene judged (`outcome`) and `out/extreme/report.md` written (`report`). Exit
//! code 0 when no scene FAILs, 1 otherwise.

mod checks;
mod outcome;
mod report;
mod result;
mod scenes;

use crate::facts::Facts;
use crate::runner::{in_order, scenes_in, Suite};
use outcome::{judge, Run};
use scenes::{ORDER, SCENE_DIR};
use std::path::{Path, PathBuf};

/// The unscaled scene each scaled scene is compared with.
fn base_of(name: &str) -> Option<&'static str> {
    matches!(name, "penetration_micro" | "penetration_mega").then_some("penetration")
}

pub fn run(suite: &Suite, one_rank: bool) -> Result<i32, String> {
    let ranks: Vec<usize> = if one_rank { vec![1] } else { vec![1, 2] };
    suite.fresh_dirs()?;
    let scenes = in_order(&ORDER, &scenes_in(Path::new(SCENE_DIR)));
    let shown: Vec<String> = ranks.iter().map(usize::to_string).collect();
    suite.say(&format!(
        "running {} scenes on {} rank(s), at most {} s each",
        scenes.len(),
        shown.join(" "),
        suite.run_limit
    ));
    for n in &scenes {
        for &np in &ranks {
            suite.run_one(n, np, &PathBuf::from(format!("{SCENE_DIR}/{n}.toml")));
        }
    }
    if ranks.len() == 2 {
        for n in &scenes {
            if let (Some(a), Some(b)) = (suite.result_of(n, 1), suite.result_of(n, 2)) {
                let logs = suite.logs();
                suite.solver_to(
                    &[
                        "post",
                        "compare",
                        &a.to_string_lossy(),
                        &b.to_string_lossy(),
                    ],
                    &logs.join(format!("{n}.compare.txt")),
                    None,
                    Some(&logs.join(format!("{n}.compare.rc"))),
                );
            }
        }
    }
    let facts = Facts::gather(suite);
    let runs: Vec<Vec<Run>> = scenes
        .iter()
        .map(|n| {
            ranks
                .iter()
                .map(|&np| Run::load(&suite.out, n, np))
                .collect()
        })
        .collect();
    let verdicts: Vec<_> = scenes
        .iter()
        .zip(&runs)
        .map(|(n, r)| {
            let base = base_of(n)
                .and_then(|b| scenes.iter().position(|s| s == b))
                .and_then(|i| runs[i][0].result.as_ref());
            judge(n, r, base, &suite.logs())
        })
        .collect();
    let ex = report::Extreme {
        out: &suite.out,
        scenes: &scenes,
        ranks: &ranks,
        limit: suite.run_limit,
        runs: &runs,
        verdicts: &verdicts,
    };
    let table = ex.summary();
    let put = |file: &str, text: &str| {
        let p = suite.out.join(file);
        std::fs::write(&p, text).map_err(|e| format!("cannot write {}: {e}", p.display()))
    };
    put("report.md", &ex.write(&facts, &table))?;
    put("summary.md", &format!("{table}\n"))?;
    print_summary(&ex, &table);
    println!();
    suite.say(&format!(
        "report: {}/report.md; total time {} s",
        suite.out.display(),
        suite.elapsed()
    ));
    Ok(if ex.count("FAIL") > 0 { 1 } else { 0 })
}

/// The table, the counts and the failing scenes, on standard output.
fn print_summary(ex: &report::Extreme, table: &str) {
    println!();
    println!("{table}");
    println!();
    println!(
        "{} scenes: {} pass, {} end with a diagnosed stop, {} FAIL",
        ex.scenes.len(),
        ex.count("pass"),
        ex.count("diagnosed stop"),
        ex.count("FAIL")
    );
    for (n, v) in ex.scenes.iter().zip(ex.verdicts) {
        if v.kind == "FAIL" {
            println!("FAIL: {n}: {}", v.problems.join("; "));
        }
    }
}
