//! `out/paper/report.md` and `summary.md`: how the report was produced, the summary table,
//! the failures and notes, then a section per paper test (`sections`); prints the table
//! and the failures; returns the exit code.

use super::results::{hertz_rms, Paper, Render, SCENE_DIR};
use super::texts::*;
use crate::text::Doc;
use crate::text::{cell, code, n, num, table};

use crate::facts::Facts;

impl Paper {
    /// The summary table.
    pub fn summary(&self) -> String {
        let header = [
            "scene",
            "checks passed",
            "key error",
            "1-rank wall time",
            "CG iterations",
            "contact updates",
            "2 ranks",
        ];
        let rows: Vec<Vec<String>> = self
            .scenes
            .iter()
            .map(|s| {
                vec![
                    s.clone(),
                    self.checks_cell(s),
                    self.key_error(s),
                    self.wall_cell(s),
                    self.cg_cell(s),
                    self.updates_cell(s),
                    cell(&self.two_ranks(s)),
                ]
            })
            .collect();
        table(&header, &rows)
    }

    /// What the report notes without failing: pictures and figures not drawn.
    pub fn warnings(&self, render: &Render) -> Vec<String> {
        let mut warnings = Vec::new();
        if let Some(why) = &render.absent {
            warnings.push(format!("ParaView pictures not drawn: {why}"));
        } else if !(render.rc == "0" || render.rc.is_empty()) {
            warnings.push(format!(
                "run/render failed (exit {}): {}",
                render.rc,
                if render.errors.is_empty() {
                    "see logs/render.log".to_string()
                } else {
                    render.errors.join("; ")
                }
            ));
        }
        let logs = self.out.join("logs");
        for fig in ["fig2", "fig5", "fig6", "fig_smoothing"] {
            if crate::record::read_trim(&logs.join(format!("{fig}.rc"))) != "0" {
                warnings.push(format!(
                    "figure {fig} was not drawn: {}",
                    crate::record::read_trim(&logs.join(format!("{fig}.log")))
                ));
            }
        }
        warnings
    }

    /// A scene's block: its runs, the comparison, the checks and reported values.
    pub fn scene_block(&self, d: &mut Doc, name: &str, title: Option<&str>) {
        let (r1, r2) = self.pair(name);
        d.w(format!(
            "### `{name}`{}\n",
            title.map_or(String::new(), |t| format!(": {t}"))
        ));
        d.w(format!(
            "Scene: `{SCENE_DIR}/{name}.toml`. 1-rank result: {}.\n",
            r1.result
                .as_ref()
                .map_or("none".into(), |r| format!("[`{r}`]({r})"))
        ));
        if r1.rec.not_run() {
            d.w(format!("Not run: {}\n", r1.message()));
            return;
        }
        let mut line = format!("- 1 rank: exit code {}", r1.rec.rc.as_deref().unwrap_or(""));
        if let Some(t) = r1.rec.time {
            line += &format!(", wall time {t:.2} s (process)");
        }
        if let Some(wt) = r1.reported("wall time [s]") {
            line += &format!(", {} s inside the solver", n(wt));
        }
        if let Some(steps) = r1.steps() {
            line += &format!(
                "; {steps} load step{} completed",
                if steps == 1 { "" } else { "s" }
            );
        }
        d.w(line + ".");
        if !r1.rec.rc_is("0") {
            d.w(format!("- The run stopped: {}", code(&r1.message())));
        }
        d.w(format!(
            "- CG iterations: {}; contact updates: {} (totals over the completed steps).",
            num(r1.reported("CG iterations (total)")),
            num(r1.reported("contact updates (total)"))
        ));
        let wall2 = match r2.rec.time {
            Some(t) if r2.completed() => format!(" (wall time {t:.2} s)"),
            _ => String::new(),
        };
        d.w(format!("- 2 ranks: {}{wall2}.", self.two_ranks(name)));
        let c = self.comparison(name);
        if c.rc.as_deref() == Some("1") && !c.differing.is_empty() {
            let list: Vec<String> = c
                .differing
                .iter()
                .map(|(d, x)| format!("`{d}` {}", n(*x)))
                .collect();
            d.w(format!(
                "- Datasets differing between 1 and 2 ranks (max rel diff): {}.",
                list.join(", ")
            ));
        }
        if let (true, Some(v2)) = (r2.completed(), &r2.verify) {
            d.w(format!(
                "- 2-rank result checked on its own: {}/{} checks pass.",
                v2.passed(),
                v2.checks.len()
            ));
        }
        d.w("");
        verify_block(d, r1);
    }

    /// A figure and its caption, or why it was not drawn.
    pub fn figure(&self, d: &mut Doc, fig: &str, caption: &str) {
        if self.out.join(format!("{fig}.png")).exists() {
            d.w(format!("![{caption}]({fig}.png)\n"));
            d.w(format!(
                "*{caption}* (`{fig}.png`, `solver post figure {fig}`)\n"
            ));
        } else {
            let log = crate::record::read_trim(&self.out.join("logs").join(format!("{fig}.log")));
            d.w(format!("*{fig}.png was not drawn: {log}*\n"));
        }
    }
}

/// The 1-rank result's checks, reported values and notes from `solver post verify`.
fn verify_block(d: &mut Doc, r1: &super::model::PaperRun) {
    let Some(v) = &r1.verify else {
        let why = if r1.verify_error.is_empty() {
            "no result file"
        } else {
            &r1.verify_error
        };
        d.w(format!("Not verified: {}\n", code(why)));
        return;
    };
    if !v.checks.is_empty() {
        d.w("| | check (`solver post verify`) | value | limit |");
        d.w("|---|---|---|---|");
        for c in &v.checks {
            d.w(format!(
                "| {} | {} | {} | {} |",
                if c.pass { "ok" } else { "**FAIL**" },
                cell(&c.name),
                num(c.value),
                num(c.limit)
            ));
        }
        d.w("");
    }
    let other: Vec<&(String, Option<f64>)> = v
        .reported
        .iter()
        .filter(|(k, _)| {
            ![
                "CG iterations (total)",
                "contact updates (total)",
                "wall time [s]",
            ]
            .contains(&k.as_str())
        })
        .collect();
    if !other.is_empty() {
        d.w("Reported (no limit):\n");
        for (k, v) in other {
            d.w(format!("- {k}: {}", num(*v)));
        }
        d.w("");
    }
    for note in &v.notes {
        d.w(format!("Note from verify: {note}\n"));
    }
}

/// The head of the report: how it was produced, the summary, failures and notes.
fn head(
    d: &mut Doc,
    paper: &Paper,
    facts: &Facts,
    render: &Render,
    summary: &str,
    failures: &[String],
    warnings: &[String],
) {
    d.w("# Contact verification: the paper's five tests\n");
    d.w(INTRO);
    d.w("## How this was produced\n");
    d.w(format!(
        "- Command: `run/paper` (builds, runs every scene of `{SCENE_DIR}/` on 1 and 2 MPI ranks, \
         checks each result with `solver post verify`, compares 1 and 2 ranks with \
         `solver post compare` (bitwise), draws the figures with `solver post figure`)."
    ));
    d.w(format!("- Date: {}", facts.date));
    d.w(format!("- Git commit: {}", facts.commit));
    d.w(format!(
        "- Solver: {}, release build; {}; {}",
        facts.solver, facts.rustc, facts.mpi
    ));
    if let Some(why) = &render.absent {
        d.w(format!(
            "- ParaView pictures: **not drawn**: {why}. Every other part of this report is \
             complete without them."
        ));
    } else if render.rc == "0" {
        let pv = if facts.paraview.is_empty() {
            "ParaView"
        } else {
            &facts.paraview
        };
        d.w(format!(
            "- ParaView pictures of the last step: `run/render` ({pv}, pvpython off-screen under Xvfb)."
        ));
    } else {
        d.w(format!(
            "- ParaView pictures: `run/render` failed (exit {}); see `logs/render.log`.",
            render.rc
        ));
    }
    d.w(format!(
        "- Machine: {} cores ({}), {} memory, {}, Linux {}",
        facts.cores, facts.cpu, facts.mem, facts.os, facts.kernel
    ));
    d.w(format!(
        "- run/paper took {} s up to this report, including the (incremental) build.",
        facts.elapsed
    ));
    d.w(RESULTS_WHERE);
    d.w("## Summary\n");
    d.w(format!("{summary}\n"));
    d.w(SUMMARY_LEGEND);
    if failures.is_empty() {
        d.w(ALL_PASS);
    } else {
        d.w("**Failures:**\n");
        for f in failures {
            d.w(format!("- {}", cell(f)));
        }
        d.w("");
    }
    for x in warnings {
        d.w(format!("**Note:** {x}\n"));
    }
    let _ = paper;
}

/// Writes report.md and summary.md, prints the table, the notes and the failures; the exit
/// code.
pub fn write(paper: &Paper, facts: &Facts) -> Result<i32, String> {
    let render = Render::of(paper);
    let summary = paper.summary();
    let failures = paper.failures();
    let warnings = paper.warnings(&render);
    let mut d = Doc::default();
    head(
        &mut d, paper, facts, &render, &summary, &failures, &warnings,
    );
    paper.sections(&mut d, &render);
    let put = |file: &str, text: &str| {
        let p = paper.out.join(file);
        std::fs::write(&p, text).map_err(|e| format!("cannot write {}: {e}", p.display()))
    };
    put("report.md", &d.text())?;
    put("summary.md", &format!("{summary}\n"))?;
    println!();
    println!("{summary}");
    println!();
    let mut ex = format!(
        "{} (Gmsh example): 2 ranks: {}",
        paper.example,
        paper.two_ranks(&paper.example)
    );
    if let Some(rms) = hertz_rms(&paper.hertz_txt) {
        ex += &format!("; Hertz RMS error {rms}% of p0");
    }
    println!("{ex}");
    for x in &warnings {
        println!("note: {x}");
    }
    for f in &failures {
        println!("FAILED: {f}");
    }
    Ok(if failures.is_empty() { 0 } else { 1 })
}
