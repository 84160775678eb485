//! The report: `results.json` and `report.md`, both written from the one results model
//! (`results::Results`). Each section of the two files has one file here with its JSON
//! and its Markdown writer side by side, and a line in SECTIONS, which gives the order of
//! both files. A new benchmark adds its section file and its line (and its entry in
//! `doc::DOC`).

pub mod bandwidth;
pub mod block;
pub mod calculix;
pub mod cube;
pub mod doc;
#[cfg(test)]
pub mod fixture;
pub mod json;
pub mod kernels;
pub mod large;
pub mod markdown;
pub mod meta;
pub mod partition;
pub mod robustness;
pub mod search;

use crate::results::Results;
use json::{Rec, J};
use std::path::{Path, PathBuf};

/// One section of both files: its key in results.json and its two writers.
struct Section {
    key: &'static str,
    json: fn(&Results) -> J,
    markdown: fn(&Results, &mut String),
}

/// The sections after the header, in the order of both files.
const SECTIONS: &[Section] = &[
    Section {
        key: "memory_bandwidth",
        json: bandwidth::json,
        markdown: bandwidth::markdown,
    },
    Section {
        key: "element_kernels",
        json: kernels::json,
        markdown: kernels::markdown,
    },
    Section {
        key: "cg_cube",
        json: cube::json,
        markdown: cube::markdown,
    },
    Section {
        key: "contact_search",
        json: search::json,
        markdown: search::markdown,
    },
    Section {
        key: "block_on_block",
        json: block::json,
        markdown: block::markdown,
    },
    Section {
        key: "partition",
        json: partition::json,
        markdown: partition::markdown,
    },
    Section {
        key: "calculix",
        json: calculix::json,
        markdown: calculix::markdown,
    },
    Section {
        key: "large",
        json: large::earlier_json,
        markdown: large::earlier_markdown,
    },
];

/// results.json of a normal run.
pub fn json(r: &Results) -> J {
    SECTIONS
        .iter()
        .fold(
            Rec::default()
                .put("schema", doc::SCHEMA)
                .put("doc", doc::object(None))
                .put("meta", meta::json(r)),
            |rec, s| rec.put(s.key, (s.json)(r)),
        )
        .json()
}

/// report.md of a normal run.
pub fn markdown(r: &Results) -> String {
    let mut s = String::new();
    meta::markdown(r, &mut s);
    for section in SECTIONS {
        (section.markdown)(r, &mut s);
    }
    s
}

/// Writes `<out>/results.json` and `<out>/report.md`; returns their paths and the report.
pub fn write(r: &Results, out: &Path) -> Result<(PathBuf, PathBuf, String), String> {
    let text = serde_json::to_string_pretty(&json(r))
        .map_err(|e| format!("cannot serialise the results: {e}"))?;
    let report = markdown(r);
    let jpath = out.join("results.json");
    let rpath = out.join("report.md");
    std::fs::write(&jpath, text + "\n")
        .map_err(|e| format!("cannot write {}: {e}", jpath.display()))?;
    std::fs::write(&rpath, &report)
        .map_err(|e| format!("cannot write {}: {e}", rpath.display()))?;
    Ok((jpath, rpath, report))
}

#[cfg(test)]
mod tests {
    use super::fixture::{large, results};
    use super::*;
    use crate::runner::process::MIB;

    fn number(j: &J, path: &[&str]) -> f64 {
        let mut v = j;
        for key in path {
            v = match (v, key.parse::<usize>()) {
                (J::Arr(a), Ok(i)) => &a[i],
                _ => v.get(key).unwrap_or_else(|| panic!("no {key} in {path:?}")),
            };
        }
        match v {
            J::Num(x) => *x,
            J::Int(i) => *i as f64,
            _ => panic!("{path:?} is not a number"),
        }
    }

    /// The top-level keys of results.json, in order, and every section documented.
    #[test]
    fn json_sections_in_order() {
        let J::Obj(kv) = json(&results()) else {
            panic!("not an object")
        };
        let keys: Vec<&str> = kv.iter().map(|(k, _)| k.as_str()).collect();
        assert_eq!(
            keys,
            [
                "schema",
                "doc",
                "meta",
                "memory_bandwidth",
                "element_kernels",
                "cg_cube",
                "contact_search",
                "block_on_block",
                "partition",
                "calculix",
                "large"
            ]
        );
        for s in SECTIONS {
            assert!(
                doc::DOC.iter().any(|(k, _)| *k == s.key),
                "{} undocumented",
                s.key
            );
        }
    }

    /// The Markdown headings, in the order of the JSON sections, the earlier large section
    /// last.
    #[test]
    fn markdown_sections_in_order() {
        let md = markdown(&results());
        let headings: Vec<&str> = md.lines().filter(|l| l.starts_with('#')).collect();
        assert_eq!(
            headings,
            [
                "# Solver performance benchmark",
                "## Memory bandwidth",
                "## Element kernels (one core)",
                "## CG: cube compression",
                "## Contact search",
                "## Block on block: the solver on 1 and 2 ranks, Jacobi and two-level",
                "### Two-level against Jacobi",
                "### 2 ranks against 1",
                "### Coarse space",
                "## Partition",
                "## CalculiX beside us",
                "## Large block on block (n = 80, `run/bench --large`)"
            ]
        );
        assert!(md.ends_with("\nearlier\n"));
    }

    /// Derived figures as both files give them, against values worked out by hand from
    /// the fixture (its memory grows by 1 MiB per 1000 elements).
    #[test]
    fn derived_figures() {
        let r = results();
        let j = json(&r);
        let sizes = ["block_on_block", "sizes"];
        // n = 20 against n = 10, two-level on 1 rank: the peak grows from 34 to 48 MiB
        // while the elements grow from 2000 to 16000: 14 MiB / 14000 elements.
        let marginal = number(
            &j,
            &[
                &sizes[..],
                &["1", "runs", "2", "marginal_bytes_per_element"],
            ]
            .concat(),
        );
        assert!((marginal - 14.0 * MIB / 14000.0).abs() < 1e-9, "{marginal}");
        // Two-level over Jacobi at n = 40 on 1 rank: 377 / 1892 CG iterations, the times
        // in the same proportion (the fixture's time is 1 ms per iteration).
        let ratio = number(
            &j,
            &[
                &sizes[..],
                &["2", "two_level_over_jacobi", "0", "iteration_ratio"],
            ]
            .concat(),
        );
        assert_eq!(ratio, 377.0 / 1892.0);
        // Its extremes pair 0.9 and 1.2 times the medians.
        let t_min = number(
            &j,
            &[
                &sizes[..],
                &["2", "two_level_over_jacobi", "0", "time_ratio_min"],
            ]
            .concat(),
        );
        assert!(
            (t_min - 377.0 / 1892.0 * 0.9 / 1.2).abs() < 1e-15,
            "{t_min}"
        );
        // CalculiX at n = 10: 4.374205 against our 4.37; its 0.63 s against our 2-rank
        // process time of 0.187 / 2 + 0.4 s.
        let rel = number(&j, &["calculix", "sizes", "0", "relative_difference"]);
        assert!((rel - 0.004205 / 4.37).abs() < 1e-15, "{rel}");
        let md = markdown(&r);
        assert!(md.contains("| 10 | 2000 | 0.49 | 0.63 [0.60, 0.70] | 1.28 | 64 | 3 | 4.370000 | 4.374205 | 4.374205 | +9.62e-4 |"));
        assert!(md.contains(
            "| 20 | 16000 | Jacobi | 2 | failed: exit code 1: step 1 failed / diverged |||||||||"
        ));
        assert!(md.contains("2 rank(s): CG ratio 0.211 (**not met**)"));
        for text in [serde_json::to_string(&j).unwrap(), md] {
            let mut words = text.split(|c: char| !c.is_ascii_alphanumeric());
            assert!(!words.any(|w| w == "NaN" || w == "inf"));
        }
    }

    /// The large section: the speed-up of 1 over 2 ranks (the fixture's 2-rank run takes
    /// half the time) and a row per outcome.
    #[test]
    fn large_section() {
        let l = large();
        let j = large::json(&l);
        assert_eq!(number(&j, &["speedup_median"]), 2.0);
        assert!((number(&j, &["speedup_min"]) - 0.9 / 1.2 * 2.0).abs() < 1e-15);
        let md = large::markdown(&l, Path::new("out/bench/large"));
        assert!(md.starts_with(large::LARGE_HEADING));
        assert!(md.contains("\n| 3 | not run: memory estimate failed: exit code 1: x |||||||||\n"));
        assert!(md.contains("\n| 4 | failed: stopped / after 21600 s |||||||||\n"));
        assert!(md.contains("\n- speed-up 2.00; bitwise identical: yes\n"));
    }
}
