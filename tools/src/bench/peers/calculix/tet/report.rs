//! The tetrahedra section as Markdown (a table per problem, errors against our hexahedral
//! reference) and JSON.

use super::hertz;
use super::results::{Measured, Row};
use super::scenes::Problem;
use std::fmt::Write as _;
use std::path::Path;

/// `report.md` and `results.json` into `dir`.
pub fn write(
    dir: &Path,
    rows: &[Row],
    hertz: &[hertz::Row],
    ccx_version: Option<&str>,
) -> Result<(), String> {
    let put = |file: &str, text: String| {
        let p = dir.join(file);
        std::fs::write(&p, text).map_err(|e| format!("cannot write {}: {e}", p.display()))
    };
    put("report.md", markdown(rows, hertz, ccx_version))?;
    put("results.json", json(rows, hertz, ccx_version))
}

/// The reference of a problem: our hexahedral run's value, if it finished.
fn reference(rows: &[Row], problem: Problem) -> Option<f64> {
    rows.iter()
        .find(|r| r.case.problem == problem && !r.case.tet)
        .and_then(|r| r.ours.as_ref().ok())
        .map(|m| m.value)
}

fn error(value: f64, reference: Option<f64>) -> String {
    reference.map_or("-".into(), |r| {
        format!("{:+.2}%", 100.0 * (value - r) / r.abs())
    })
}

fn cells(m: &Result<Measured, String>, reference: Option<f64>) -> String {
    match m {
        // ccx prints no Newton iteration for a linear step: its count is 0.
        Ok(m) => format!(
            "{:.4} | {} | {} | {:.1}",
            m.value,
            error(m.value, reference),
            if m.iterations == 0 {
                "-".into()
            } else {
                m.iterations.to_string()
            },
            m.wall
        ),
        Err(_) => "failed | - | - | -".into(),
    }
}

/// The section's Markdown.
pub fn markdown(rows: &[Row], hertz: &[hertz::Row], ccx_version: Option<&str>) -> String {
    let mut w = String::new();
    let _ = writeln!(
        w,
        "## Tetrahedra beside hexahedra and CalculiX\n\nOurs: composite tet10 (Gmsh's 4-node tetrahedra completed to 10 nodes) on 2 ranks, `auto`; the reference is our hex8 with mean dilatation at its finest mesh (the punch's: Prandtl's (2 + pi) sigma_y / sqrt(3) = 296.85 is the rigid-plastic limit). CalculiX {}: C3D10 on the same nodes, 2 threads, its automatic incrementation. Errors against the reference; CG: ours, Newton: ccx's (none printed for a linear step).\n",
        ccx_version.unwrap_or("(not installed)")
    );
    for (problem, title, what) in [
        (
            Problem::Cook,
            "Cook's membrane, nu = 0.4999, plane strain",
            "tip u_y",
        ),
        (
            Problem::Punch,
            "Flat punch, J2 perfectly plastic, 50 increments",
            "mean pressure",
        ),
    ] {
        let reference = reference(rows, problem);
        let _ = writeln!(
            w,
            "### {title}\n\n| mesh | nodes | ours {what} | error | CG | s | ccx {what} | error | Newton | s |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
        );
        for r in rows.iter().filter(|r| r.case.problem == problem) {
            let kind = match (r.case.tet, r.case.bar) {
                (true, false) => "tet10",
                (true, true) => "tet10 + mean dilatation",
                (false, _) => "hex8 + mean dilatation (reference)",
            };
            let ccx = match &r.ccx {
                Some(c) => cells(c, reference),
                None => "- | - | - | -".into(),
            };
            let _ = writeln!(
                w,
                "| {kind} n = {} | {} | {} | {ccx} |",
                r.case.n,
                r.nodes,
                cells(&r.ours, reference)
            );
        }
        let _ = writeln!(w);
        for r in rows.iter().filter(|r| r.case.problem == problem) {
            for (who, m) in [("ours", Some(&r.ours)), ("ccx", r.ccx.as_ref())] {
                if let Some(Err(e)) = m {
                    let _ = writeln!(w, "- {} ({who}): {e}", r.case.name());
                }
            }
        }
    }
    if !hertz.is_empty() {
        w.push_str(&hertz::markdown(hertz));
    }
    w
}

fn json(rows: &[Row], hertz: &[hertz::Row], ccx_version: Option<&str>) -> String {
    let m = |m: &Result<Measured, String>| match m {
        Ok(m) => {
            serde_json::json!({"value": m.value, "iterations": m.iterations, "wall_s": m.wall})
        }
        Err(e) => serde_json::json!({"failed": e}),
    };
    let rows: Vec<serde_json::Value> = rows
        .iter()
        .map(|r| {
            serde_json::json!({
                "case": r.case.name(),
                "tet": r.case.tet,
                "n": r.case.n,
                "mean_dilatation": r.case.bar,
                "nodes": r.nodes,
                "ours": m(&r.ours),
                "ccx": r.ccx.as_ref().map(m),
            })
        })
        .collect();
    let doc =
        serde_json::json!({"ccx_version": ccx_version, "rows": rows, "hertz": hertz::json(hertz)});
    serde_json::to_string_pretty(&doc).unwrap_or_default()
}
