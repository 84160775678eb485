//! The large section (`--large`): written into the files of an earlier normal run in
//! place of an earlier large section, and carried over as it is by a later normal run.

use super::block::{case_json, force_cell};
use super::doc::SCHEMA;
use super::json::{Rec, J};
use super::markdown::{cell, dirty, fmt_opt, fmt_steal, identity_text};
use crate::block::{BLOCK_BASE_N, BLOCK_SCENE};
use crate::results::large::{
    model_estimate_mib, model_text, Large, LargeOutcome, LargeRun, MemoryEstimate,
    LARGE_MEMORY_MARGIN, LARGE_MIN_AVAILABLE, LARGE_PILOT, LARGE_REFINE, LARGE_TIMEOUT_S,
};
use crate::results::{EarlierLarge, Results};
use crate::runner::process::MIB;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Heading of the large section of report.md: from it to the end of the file is that
/// section (a normal run writes it last, as it found it).
pub const LARGE_HEADING: &str = "## Large block on block";

fn estimate_json(e: &MemoryEstimate, ranks: usize) -> J {
    let pilot = e
        .pilot
        .iter()
        .map(|&(n, elements, peak)| {
            Rec::default()
                .put("n", n)
                .put("elements", elements)
                .put("peak_mib_per_rank", peak)
                .json()
        })
        .collect();
    Rec::default()
        .put("pilot", J::Arr(pilot))
        .put("marginal_bytes_per_element", e.marginal_bytes)
        .put("elements", e.elements)
        .put("predicted_peak_mib_per_rank", e.predicted_mib_per_rank)
        .put(
            "predicted_total_mib",
            ranks as f64 * e.predicted_mib_per_rank,
        )
        .put("memory_margin", LARGE_MEMORY_MARGIN)
        .put("available_mib", e.available_mib)
        .put("fits", e.fits)
        .json()
}

fn run_json(r: &LargeRun) -> J {
    let head = Rec::default().put("ranks", r.ranks).put(
        "model_estimate_mib_per_rank",
        model_estimate_mib(r.ranks, r.precond),
    );
    let head = match &r.estimate {
        Ok(e) => head.put("memory_check", estimate_json(e, r.ranks)),
        Err(e) => head.put(
            "memory_check",
            Rec::default().put("error", e.as_str()).json(),
        ),
    };
    match &r.outcome {
        LargeOutcome::Finished(c) => head
            .put("status", "finished")
            .extend(case_json(c, r.marginal_bytes()))
            .json(),
        LargeOutcome::Failed(e) => head
            .put("status", "failed")
            .put("reason", e.as_str())
            .json(),
        LargeOutcome::NotRun(e) => head
            .put("status", "not_run")
            .put("reason", e.as_str())
            .json(),
    }
}

/// The `large` object of results.json.
pub fn json(l: &Large) -> J {
    let i = &l.info;
    let m = &i.machine;
    let meta = Rec::default()
        .put("date", m.date.as_str())
        .put("git_commit", m.git_commit.clone())
        .put("git_dirty", m.git_dirty)
        .put("cpu_model", m.cpu_model.as_str())
        .put("logical_cpus", m.logical_cpus)
        .put("total_wall_s", i.total_wall)
        .put("load_average_start", m.load_start.clone())
        .put("load_average_end", i.load_end.clone())
        .put("cpu_steal_fraction", i.steal)
        .json();
    let rec = Rec::default()
        .put("meta", meta)
        .put("scene", BLOCK_SCENE)
        .put("n", BLOCK_BASE_N * LARGE_REFINE)
        .put("refine", LARGE_REFINE)
        .put("preconditioner", l.precond.arg())
        .put("timeout_s", LARGE_TIMEOUT_S)
        .put("min_available_mib", LARGE_MIN_AVAILABLE / MIB)
        .put("runs", J::Arr(l.runs.iter().map(run_json).collect()));
    let rec = match l.speedup() {
        Some(s) => rec.stat("speedup", &s),
        None => rec.put("speedup_median", J::Null),
    };
    match &l.compare {
        Some(Ok(c)) => rec
            .put("bitwise_identical", c.identical())
            .put("compare_summary", c.summary.as_str()),
        Some(Err(e)) => rec
            .put("bitwise_identical", J::Null)
            .put("compare_error", e.as_str()),
        None => rec.put("bitwise_identical", J::Null),
    }
    .json()
}

/// The section of report.md; `dir` holds the result files and logs.
pub fn markdown(l: &Large, dir: &Path) -> String {
    let mut s = String::new();
    intro_markdown(l, dir, &mut s);
    let w = &mut s;
    let _ = writeln!(
        w,
        "| ranks | elements | CG iterations | contact updates | time s | process s | peak MiB/rank | B/element | marginal B/element | contact force y | coarse space |"
    );
    let _ = writeln!(w, "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|");
    for r in &l.runs {
        let _ = match &r.outcome {
            LargeOutcome::Finished(c) => writeln!(
                w,
                "| {} | {} | {} | {} | {:.1} | {:.1} | {:.1} | {:.0} | {} | {} | {} |",
                r.ranks,
                c.elements(),
                c.cg_iterations(),
                c.runs.log.contact_updates,
                c.runs.wall.median,
                c.runs.process_wall.median,
                c.runs.peak_mib.median,
                c.bytes_per_element(),
                fmt_opt(r.marginal_bytes(), 0),
                force_cell(c),
                cell(c.preconditioner_line())
            ),
            LargeOutcome::Failed(e) => {
                writeln!(w, "| {} | failed: {} |||||||||", r.ranks, cell(e))
            }
            LargeOutcome::NotRun(e) => {
                writeln!(w, "| {} | not run: {} |||||||||", r.ranks, cell(e))
            }
        };
    }
    let _ = writeln!(w);
    for r in &l.runs {
        let _ = match &r.estimate {
            Ok(e) => writeln!(
                w,
                "- memory check, {} rank(s): {}",
                r.ranks,
                e.text(r.ranks)
            ),
            Err(e) => writeln!(w, "- memory check, {} rank(s): failed: {e}", r.ranks),
        };
        let measured = r.finished().map(|c| c.runs.peak_mib.median);
        let _ = writeln!(
            w,
            "- {} rank(s): {}",
            r.ranks,
            model_text(r.ranks, r.precond, measured)
        );
    }
    if let Some(sp) = l.speedup() {
        let _ = writeln!(
            w,
            "- speed-up {:.2}; bitwise identical: {}",
            sp.median,
            identity_text(&l.compare)
        );
    }
    s
}

fn intro_markdown(l: &Large, dir: &Path, w: &mut String) {
    let i = &l.info;
    let m = &i.machine;
    let _ = writeln!(
        w,
        "{LARGE_HEADING} (n = {}, `run/bench --large`)\n",
        BLOCK_BASE_N * LARGE_REFINE
    );
    let _ = writeln!(
        w,
        "{} on {}, commit {}{}; load average {} at the start, {} at the end; hypervisor \
         steal {}; {:.0} s in all. `{BLOCK_SCENE}` refined by {LARGE_REFINE} (n = {} \
         elements per edge per block), `--preconditioner {}`, one run per rank \
         count. Before each, {} runs at n = {} on the same rank count measure the \
         peak memory per rank; extrapolated linearly in elements per rank it must fit \
         {LARGE_MEMORY_MARGIN} times over in the memory available, and the run is stopped \
         if the machine's available memory falls below {:.0} MiB or after {:.0} h. \
         Columns as in the block-on-block table; \"marginal\" is the growth of the peak \
         per element added per rank from the larger pilot run. Result files and logs in \
         `{}`.\n",
        m.date,
        m.cpu_model,
        m.git_commit.as_deref().unwrap_or("unknown"),
        dirty(m.git_dirty),
        m.load_start.as_deref().unwrap_or("unknown"),
        i.load_end.as_deref().unwrap_or("unknown"),
        fmt_steal(i.steal),
        i.total_wall,
        BLOCK_BASE_N * LARGE_REFINE,
        l.precond.arg(),
        l.precond.label(),
        LARGE_PILOT
            .map(|f| (BLOCK_BASE_N * f).to_string())
            .join(" and "),
        LARGE_MIN_AVAILABLE / MIB,
        LARGE_TIMEOUT_S / 3600.0,
        dir.display(),
    );
}

/// Writes the large section into `<out>/results.json` and `<out>/report.md`, replacing an
/// earlier one and keeping the rest (files that do not exist yet get only this section).
pub fn merge(out: &Path, json: J, section: &str) -> Result<(PathBuf, PathBuf), String> {
    let jpath = out.join("results.json");
    let rpath = out.join("report.md");
    let mut root = std::fs::read_to_string(&jpath)
        .ok()
        .and_then(|t| serde_json::from_str::<J>(&t).ok())
        .filter(|j| matches!(j, J::Obj(_)))
        .unwrap_or_else(|| {
            Rec::default()
                .put("schema", SCHEMA)
                .put(
                    "doc",
                    super::doc::object(Some(&["schema", "statistics", "large", "units"])),
                )
                .json()
        });
    root.set("large", json);
    let mut report = std::fs::read_to_string(&rpath)
        .unwrap_or_else(|_| "# Solver performance benchmark\n\n".to_string());
    if let Some(i) = report.find(LARGE_HEADING) {
        report.truncate(i);
    } else if !report.ends_with("\n\n") {
        report.push('\n');
    }
    report.push_str(section);
    let text = serde_json::to_string_pretty(&root)
        .map_err(|e| format!("cannot serialise the results: {e}"))?;
    std::fs::write(&jpath, text + "\n")
        .map_err(|e| format!("cannot write {}: {e}", jpath.display()))?;
    std::fs::write(&rpath, &report)
        .map_err(|e| format!("cannot write {}: {e}", rpath.display()))?;
    Ok((jpath, rpath))
}

/// The large section of earlier files in `out`, for a normal run to keep: its JSON and
/// its part of report.md (from LARGE_HEADING to the end).
pub fn earlier(out: &Path) -> Option<EarlierLarge> {
    let json = std::fs::read_to_string(out.join("results.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<J>(&t).ok())
        .and_then(|j| j.get("large").cloned())
        .filter(|j| !matches!(j, J::Null));
    let text = std::fs::read_to_string(out.join("report.md"))
        .ok()
        .and_then(|r| r.find(LARGE_HEADING).map(|i| r[i..].to_string()));
    if json.is_none() && text.is_none() {
        return None;
    }
    Some(EarlierLarge {
        json: json.unwrap_or(J::Null),
        markdown: text.unwrap_or_default(),
    })
}

/// The `large` key of a normal run's results.json: the earlier section, or null.
pub fn earlier_json(r: &Results) -> J {
    r.large.as_ref().map_or(J::Null, |l| l.json.clone())
}

/// The end of a normal run's report.md: the earlier section, if there is one.
pub fn earlier_markdown(r: &Results, w: &mut String) {
    if let Some(l) = &r.large {
        let _ = write!(w, "\n{}", l.markdown);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `--large` puts its section into the normal run's files in place of an earlier one,
    /// and a normal run finds it there to keep.
    #[test]
    fn large_section_is_merged_and_found() {
        let out = std::env::temp_dir().join(format!("bench-large-{}", std::process::id()));
        std::fs::create_dir_all(&out).unwrap();
        let report = |out: &Path| std::fs::read_to_string(out.join("report.md")).unwrap();
        let keys = |out: &Path| -> Vec<String> {
            let t = std::fs::read_to_string(out.join("results.json")).unwrap();
            match serde_json::from_str::<J>(&t).unwrap() {
                J::Obj(kv) => kv.into_iter().map(|(k, _)| k).collect(),
                _ => panic!("not an object"),
            }
        };
        // No earlier files: only the large section.
        merge(&out, J::Int(1), &format!("{LARGE_HEADING} (a)\n")).unwrap();
        assert_eq!(keys(&out), ["schema", "doc", "large"]);
        assert!(report(&out).ends_with(&format!("\n\n{LARGE_HEADING} (a)\n")));
        // A normal run's files: the section goes last, then replaces itself.
        std::fs::write(
            out.join("results.json"),
            r#"{"schema":"s","meta":{},"block_on_block":[],"large":null,"calculix":{}}"#,
        )
        .unwrap();
        std::fs::write(out.join("report.md"), "# Bench\n\n## CalculiX\n\ntable\n").unwrap();
        assert!(earlier(&out).is_none());
        merge(&out, J::Int(2), &format!("{LARGE_HEADING} (b)\n")).unwrap();
        merge(&out, J::Int(3), &format!("{LARGE_HEADING} (c)\n")).unwrap();
        assert_eq!(
            keys(&out),
            ["schema", "meta", "block_on_block", "large", "calculix"]
        );
        assert_eq!(
            report(&out),
            format!("# Bench\n\n## CalculiX\n\ntable\n\n{LARGE_HEADING} (c)\n")
        );
        let l = earlier(&out).unwrap();
        assert!(matches!(l.json, J::Int(3)));
        assert_eq!(l.markdown, format!("{LARGE_HEADING} (c)\n"));
        let _ = std::fs::remove_dir_all(&out);
    }
}
