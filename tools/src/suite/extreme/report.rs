//! `out/extreme/report.md` and `summary.md`: how it was produced, the summary table, the
//! failures and stops, then every scene with its checks; prints the table.

use super::outcome::{names, Run, Verdict};
use super::scenes::{MUST_STOP, SCENE_DIR};
use crate::facts::Facts;
use crate::record::read;
use crate::text::{cell, n, number_between, table, Doc};
use std::path::Path;

const INTRO: &str =
    "Hard scenes for the solver: each must either converge and pass its physical check or \
    stop with a message naming the step, the time and the cause (exit code 1, the \
    completed steps kept in `<name>.failed.h5`); never a NaN in a file, never a hang.\n";

const LEGEND: &str =
    "*outcome*: **pass**: completed and every check passes (for `off_edge`, whose load \
    cannot be carried: stopped cleanly); **diagnosed stop**: the run stopped with exit \
    code 1 and a message naming the step and the time, the completed steps in \
    `<name>.failed.h5`, and no NaN; **FAIL**: a check fails, the run crashed, hung, wrote \
    a NaN, stopped without that diagnosis, or 2 ranks differ from 1 rank. *steps*: \
    completed / scheduled load steps. *cut-backs*, *CG iterations*, *contact updates*: \
    totals over the completed steps (from `/stats`). *check*: the first failing check, \
    else the first; every check is listed below. *wall*: the 1-rank process. *2 ranks*: \
    `solver post compare` of the 1- and 2-rank files. *message*: the 1-rank run's error \
    message when it did not complete.\n";

/// Everything the report is written from.
pub struct Extreme<'a> {
    pub out: &'a Path,
    pub scenes: &'a [String],
    pub ranks: &'a [usize],
    pub limit: i64,
    pub runs: &'a [Vec<Run>],
    pub verdicts: &'a [Verdict],
}

/// The scheduled load steps of a scene (the sum of its time segments' steps).
fn steps_total(name: &str) -> String {
    let text = read(Path::new(&format!("{SCENE_DIR}/{name}.toml"))).unwrap_or_default();
    let total = text.parse::<toml::Table>().ok().and_then(|doc| {
        doc.get("time")?
            .get("segments")?
            .as_array()?
            .iter()
            .map(|s| s.get("steps")?.as_integer())
            .sum::<Option<i64>>()
    });
    total.map_or("None".into(), |t| t.to_string())
}

/// The comment at the head of the scene file, as a sentence.
fn scene_comment(name: &str) -> String {
    let text = read(Path::new(&format!("{SCENE_DIR}/{name}.toml"))).unwrap_or_default();
    let lines: Vec<&str> = text
        .lines()
        .take_while(|l| l.starts_with('#'))
        .map(|l| l[1..].trim())
        .collect();
    let joined = lines.join(" ");
    let t = joined.strip_prefix("Extreme: ").unwrap_or(&joined);
    let mut c = t.chars();
    c.next().map_or(String::new(), |f| {
        f.to_uppercase().collect::<String>() + c.as_str()
    })
}

/// (steps completed, cut-backs, CG iterations, contact updates) of the 1-rank run.
fn stats_cells(r1: &Run) -> [String; 4] {
    let Some(res) = &r1.result else {
        return ["0".into(), "-".into(), "-".into(), "-".into()];
    };
    let cut: u64 = res.stats.iter().map(|s| s.cutbacks).sum();
    let failing = number_between(&r1.message(), "after ", " cut-backs");
    [
        res.n.to_string(),
        format!(
            "{cut}{}",
            failing.map_or(String::new(), |m| format!(" (+{m} in the failing step)"))
        ),
        res.stats
            .iter()
            .map(|s| s.cg_iterations)
            .sum::<u64>()
            .to_string(),
        res.stats
            .iter()
            .map(|s| s.contact_updates)
            .sum::<u64>()
            .to_string(),
    ]
}

impl Extreme<'_> {
    pub fn summary(&self) -> String {
        let header = [
            "scene",
            "outcome",
            "steps",
            "cut-backs",
            "CG iterations",
            "contact updates",
            "check",
            "value",
            "limit",
            "wall [s]",
            "2 ranks",
            "message",
        ];
        let rows: Vec<Vec<String>> = self
            .scenes
            .iter()
            .zip(self.runs.iter().zip(self.verdicts))
            .map(|(name, (runs, v))| {
                let r1 = &runs[0];
                let [done, cut, cg, upd] = stats_cells(r1);
                let (check, value, limit) = v
                    .checks
                    .main()
                    .map_or(("-".into(), "-".into(), "-".into()), |c| {
                        (c.name.clone(), n(c.value), n(c.limit))
                    });
                vec![
                    name.clone(),
                    if v.kind == "FAIL" {
                        "**FAIL**".into()
                    } else {
                        v.kind.to_string()
                    },
                    format!("{done}/{}", steps_total(name)),
                    cut,
                    cg,
                    upd,
                    cell(&check),
                    value,
                    limit,
                    r1.rec.time.map_or("-".into(), |t| format!("{t:.2}")),
                    cell(&v.two),
                    cell(&if r1.rec.rc_is("0") {
                        String::new()
                    } else {
                        r1.message()
                    }),
                ]
            })
            .collect();
        table(&header, &rows)
    }

    pub fn count(&self, kind: &str) -> usize {
        self.verdicts.iter().filter(|v| v.kind == kind).count()
    }

    pub fn write(&self, facts: &Facts, table: &str) -> String {
        let mut d = Doc::default();
        let two = self.ranks.len() == 2;
        let ranks: Vec<String> = self.ranks.iter().map(usize::to_string).collect();
        d.w("# Extreme scenes\n");
        d.w(INTRO);
        d.w("## How this was produced\n");
        d.w(format!(
            "- Command: `run/extreme{}` (builds, runs every scene of `{SCENE_DIR}/` on {} rank(s) \
             with at most {} s per run, checks each result from its file, compares 1 and 2 ranks \
             with `solver post compare`, bitwise).",
            if two { "" } else { " --one-rank" },
            ranks.join(" and "),
            self.limit
        ));
        d.w(format!(
            "- Date: {}; git commit: {}",
            facts.date, facts.commit
        ));
        d.w(format!(
            "- Solver: {}, release build; {}",
            facts.solver, facts.mpi
        ));
        d.w(format!("- Machine: {} cores ({})", facts.cores, facts.cpu));
        d.w(format!(
            "- run/extreme took {} s up to this report, including the build.\n",
            facts.elapsed
        ));
        d.w("## Summary\n");
        d.w(format!(
            "{} scenes: {} pass, {} end with a diagnosed stop, {} FAIL.\n",
            self.scenes.len(),
            self.count("pass"),
            self.count("diagnosed stop"),
            self.count("FAIL")
        ));
        d.w(format!("{table}\n"));
        d.w(LEGEND);
        let fails: Vec<(&String, &Verdict)> = self
            .scenes
            .iter()
            .zip(self.verdicts)
            .filter(|(_, v)| v.kind == "FAIL")
            .collect();
        if !fails.is_empty() {
            d.w("**FAIL:**\n");
            for (name, v) in &fails {
                d.w(format!("- `{name}`: {}", cell(&v.problems.join("; "))));
            }
            d.w("");
        }
        self.stops(&mut d);
        d.w("## Scenes\n");
        for (i, name) in self.scenes.iter().enumerate() {
            self.scene(&mut d, name, &self.runs[i], &self.verdicts[i]);
        }
        d.text()
    }

    fn stops(&self, d: &mut Doc) {
        let stops: Vec<usize> = (0..self.scenes.len())
            .filter(|&i| self.runs[i][0].rec.rc_is("1"))
            .collect();
        if stops.is_empty() {
            return;
        }
        d.w("**Stops with a message** (exit code 1):\n");
        for i in stops {
            let name = &self.scenes[i];
            let r1 = &self.runs[i][0];
            let nm = names(&r1.message());
            let what = if MUST_STOP.contains(&name.as_str()) {
                "expected: the load cannot be carried"
            } else if self.verdicts[i].kind != "FAIL" {
                "the scene is solvable; the solver gave up"
            } else {
                "FAIL"
            };
            d.w(format!(
                "- `{name}` ({what}): `{}`; names the step: {}, the time: {}, a node, element or body: {}.",
                r1.message(),
                yes(nm.step),
                yes(nm.time),
                yes(nm.place)
            ));
        }
        d.w("");
    }

    fn scene(&self, d: &mut Doc, name: &str, runs: &[Run], v: &Verdict) {
        let r1 = &runs[0];
        d.w(format!("### `{name}`: {}\n", v.kind));
        d.w(scene_comment(name) + "\n");
        let files: Vec<String> = r1.files.iter().map(|s| format!("`{name}{s}`")).collect();
        d.w(format!(
            "- Command: `solver -q run {SCENE_DIR}/{name}.toml -o {}/np1/{name}.h5`; exit code {}{}; files: {}.",
            self.out.display(),
            r1.rc(),
            r1.rec.time.map_or(String::new(), |t| format!(", {t:.2} s")),
            if files.is_empty() { "none".into() } else { files.join(", ") }
        ));
        let [done, cut, cg, upd] = stats_cells(r1);
        d.w(format!(
            "- Steps completed: {done}/{}; cut-backs: {cut}; CG iterations: {cg}; contact updates: {upd}.",
            steps_total(name)
        ));
        if !r1.rec.rc_is("0") {
            let nm = names(&r1.message());
            d.w(format!(
                "- Message: `{}` (names the step: {}, the time: {}, a node, element or body: {}).",
                r1.message(),
                yes(nm.step),
                yes(nm.time),
                yes(nm.place)
            ));
        }
        if self.ranks.len() == 2 {
            d.w(format!("- 2 ranks: {}.", v.two));
        }
        for p in &v.problems {
            d.w(format!("- **Problem:** {}", cell(p)));
        }
        d.w("");
        if !v.checks.checks.is_empty() {
            d.w("| | check | value | limit |");
            d.w("|---|---|---|---|");
            for c in &v.checks.checks {
                d.w(format!(
                    "| {} | {} | {} | {} |",
                    if c.ok { "ok" } else { "**FAIL**" },
                    cell(&c.name),
                    n(c.value),
                    n(c.limit)
                ));
            }
            d.w("");
        }
        if !v.checks.reported.is_empty() {
            d.w("Reported (no limit):\n");
            for (k, val) in &v.checks.reported {
                d.w(format!("- {}: {}", cell(k), val.show()));
            }
            d.w("");
        }
        for note in &v.checks.notes {
            d.w(format!("Note: {note}\n"));
        }
    }
}

fn yes(b: bool) -> &'static str {
    if b {
        "yes"
    } else {
        "no"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scene_comments_and_step_counts_come_from_the_scene_files() {
        // The suite reads its scenes relative to the repository, where run/extreme starts
        // it; cargo runs the tools' tests in tools/.
        let repo = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
        std::env::set_current_dir(repo).unwrap();
        let c = scene_comment("off_edge");
        assert!(
            c.starts_with(char::is_uppercase) && !c.starts_with("Extreme: "),
            "{c}"
        );
        assert_eq!(steps_total("off_edge"), "6");
        assert_eq!(steps_total("no_such_scene"), "None");
    }
}
