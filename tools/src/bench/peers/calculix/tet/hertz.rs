//! The Hertz cylinder on tetrahedra beside CalculiX (issue 41's acceptance): the example
//! `run/examples/cylinder_on_block_tet.toml` (Gmsh's 10-node tetrahedra, 3172 nodes) with
//! mortar and with node-to-face contact, ours on 2 ranks (`auto`), and ccx's C3D10 on the
//! same nodes (the scene's deck: penalty contact at the slope of the robustness table's
//! hexahedral Hertz rows, node-to-surface and surface-to-surface, its automatic
//! incrementation, 2 threads), one after the other. Each one's nodal contact pressure at the slave nodes is compared with
//! Hertz's as `solver post hertz` compares ours: the peak over p0 and the RMS error within
//! 1.5 a. The Hertz solution is the one of the load our mortar run's contact carried (all
//! three apply the same pressure to the cylinder's top).

use super::super::deck::PairType;
use super::super::output::{last_contact_pressures, last_face_contact_pressures};
use super::super::plasticity::ours;
use super::super::run::{Job, Outcome};
use super::super::scene::deck;
use crate::api::{load_scene_refined, ResultFile};
use crate::robustness::HERTZ_PENALTY;
use crate::runner::solver::repo_root;
use solver::post::hertz::{compare, HertzComparison};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The example, and the text of it that the node-to-face variant changes.
const SCENE: &str = "run/examples/cylinder_on_block_tet.toml";
const MORTAR: &str = "discretization = \"mortar\"";
const MESH_LINE: &str = "file = \"../tet/cylinder_on_block.msh\"";
const MESH: &str = "run/tet/cylinder_on_block.msh";

/// What one code measured.
#[derive(Clone, Debug)]
pub struct Measured {
    pub wall: f64,
    /// Our CG iterations, or ccx's Newton iterations.
    pub iterations: u64,
    /// Peak pressure over p0, minus 1.
    pub peak: f64,
    /// RMS error within 1.5 a, over p0 (None where the positions of the pressures are not
    /// known: ccx prints surface-to-surface pressures at integration points, no position).
    pub rms: Option<f64>,
}

/// One run: who, and what it measured or why it did not.
pub struct Row {
    pub label: &'static str,
    pub result: Result<Measured, String>,
}

/// Ours with mortar and (unless `quick`) node-to-face, then ccx when `ccx`, its
/// node-to-surface pairs (unless `quick`: 90 s) and its surface-to-surface ones, each in a
/// directory of `dir`, stopped after `timeout_s`.
pub fn run(dir: &Path, quick: bool, ccx: bool, timeout_s: f64) -> Vec<Row> {
    let scene = repo_root().join(SCENE);
    eprintln!("bench: tet: Hertz on tetrahedra, mortar: ours on 2 ranks");
    let mortar = ours_run(&scene, &dir.join("mortar"), timeout_s);
    let mut rows = vec![Row {
        label: "ours, mortar",
        result: mortar
            .as_ref()
            .map(|(m, _)| m.clone())
            .map_err(Clone::clone),
    }];
    if !quick {
        eprintln!("bench: tet: Hertz on tetrahedra, node-to-face: ours on 2 ranks");
        let node_face = node_face_scene(&dir.join("node_face"))
            .and_then(|s| ours_run(&s, &dir.join("node_face"), timeout_s));
        rows.push(Row {
            label: "ours, node-to-face",
            result: node_face.map(|(m, _)| m),
        });
    }
    let mut kinds = vec![
        ("CalculiX C3D10, node-to-surface", PairType::NodeToSurface),
        (
            "CalculiX C3D10, surface-to-surface",
            PairType::SurfaceToSurface,
        ),
    ];
    if quick {
        kinds.remove(0);
    }
    for (label, kind) in kinds {
        let result = if !ccx {
            Err("CalculiX not available (no ccx on PATH; `run/setup --calculix`)".into())
        } else {
            eprintln!("bench: tet: Hertz on tetrahedra: {label} on 2 threads");
            let sub = match kind {
                PairType::NodeToSurface => "calculix_node_to_surface",
                PairType::SurfaceToSurface => "calculix_surface_to_surface",
            };
            match &mortar {
                Ok((_, c)) => calculix(&scene, c, kind, &dir.join(sub), timeout_s),
                Err(_) => Err("no Hertz load to compare with: our mortar run failed".into()),
            }
        };
        rows.push(Row { label, result });
    }
    for r in &rows {
        match &r.result {
            Ok(m) => eprintln!(
                "bench:   {}: {:.1} s, {} iterations, peak {:+.2}%, RMS {} of p0",
                r.label,
                m.wall,
                m.iterations,
                100.0 * m.peak,
                percent(m.rms)
            ),
            Err(e) => eprintln!("bench:   {}: failed: {e}", r.label),
        }
    }
    rows
}

/// Our run and its comparison with Hertz.
fn ours_run(
    scene: &Path,
    dir: &Path,
    timeout_s: f64,
) -> Result<(Measured, HertzComparison), String> {
    let (wall, log, h5) = ours::solve(scene, dir, timeout_s)?;
    let file = ResultFile::open(&h5).map_err(|e| e.to_string())?;
    let c = compare(&file).map_err(|e| e.to_string())?;
    let m = Measured {
        wall,
        iterations: log.cg_total,
        peak: c.peak_error(),
        rms: Some(c.rms_error),
    };
    Ok((m, c))
}

/// The example with node-to-face contact, written into `dir` (its mesh by absolute path).
fn node_face_scene(dir: &Path) -> Result<PathBuf, String> {
    let path = repo_root().join(SCENE);
    let text = std::fs::read_to_string(&path)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let once = |text: &str, from: &str, to: &str| match text.matches(from).count() {
        1 => Ok(text.replace(from, to)),
        k => Err(format!(
            "{}: expected '{from}' once, found it {k} time(s)",
            path.display()
        )),
    };
    let text = once(&text, MORTAR, "discretization = \"node_face\"")?;
    let mesh = repo_root().join(MESH);
    let text = once(
        &text,
        MESH_LINE,
        &format!("file = {:?}", mesh.display().to_string()),
    )?;
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let out = dir.join("scene.toml");
    std::fs::write(&out, text).map_err(|e| format!("cannot write {}: {e}", out.display()))?;
    Ok(out)
}

/// The example's deck with its pairs of `kind` and the contact pressures printed.
fn hertz_deck(scene: &Path, kind: PairType) -> Result<super::super::deck::Deck, String> {
    let problem = load_scene_refined(scene, 1).map_err(|e| format!("{}: {e}", scene.display()))?;
    let mut deck = deck(&problem, HERTZ_PENALTY)?;
    for pair in &mut deck.contact_pairs {
        pair.kind = kind;
    }
    for step in &mut deck.steps {
        step.contact_print = true;
    }
    Ok(deck)
}

/// ccx on the example's deck, its pairs of `kind`, with its contact pressures printed;
/// its pressures against the Hertz solution of `hertz` (at our slave nodes for
/// node-to-surface; the peak only for surface-to-surface).
fn calculix(
    scene: &Path,
    hertz: &HertzComparison,
    kind: PairType,
    dir: &Path,
    timeout_s: f64,
) -> Result<Measured, String> {
    let deck = hertz_deck(scene, kind)?;
    let job = Job {
        dir: dir.to_path_buf(),
        name: "hertz_tet".into(),
        threads: 2,
        timeout_s,
    };
    job.write_deck(&deck)?;
    let end = |t: f64| (t - 1.0).abs() < 1e-6;
    let stopped = |t: f64| format!("ccx stopped at time {t}");
    let missing = || "no contact pressures in the .dat file".to_string();
    let read = |o: &super::super::run::Output| -> Result<(f64, Option<f64>), String> {
        let p0 = hertz.hertz.p0;
        match kind {
            PairType::NodeToSurface => match last_contact_pressures(&o.dat) {
                Some((t, p)) if end(t) => {
                    // ccx's ids are 1-based, the comparison's 0-based.
                    let at: HashMap<usize, f64> = p.into_iter().map(|(n, p)| (n - 1, p)).collect();
                    let (peak, rms) = hertz
                        .errors_of(|n| at.get(&n).copied())
                        .ok_or("no slave node within 1.5 a")?;
                    Ok((peak, Some(rms)))
                }
                Some((t, _)) => Err(stopped(t)),
                None => Err(missing()),
            },
            PairType::SurfaceToSurface => match last_face_contact_pressures(&o.dat) {
                Some((t, p)) if end(t) => {
                    let peak = p.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                    Ok(((peak - p0) / p0, None))
                }
                Some((t, _)) => Err(stopped(t)),
                None => Err(missing()),
            },
        }
    };
    match job.run_repeated(1, read)? {
        Outcome::Finished { timed, values } => Ok(Measured {
            wall: timed.wall.median,
            iterations: timed.iterations as u64,
            peak: values.0,
            rms: values.1,
        }),
        Outcome::Stopped(why) | Outcome::Failed(why) | Outcome::Skipped(why) => Err(why),
    }
}

fn percent(x: Option<f64>) -> String {
    x.map_or("-".into(), |x| format!("{:.2}%", 100.0 * x))
}

/// The section's Markdown table.
pub fn markdown(rows: &[Row]) -> String {
    let mut w = String::from(
        "### Hertz cylinder on tetrahedra (run/examples/cylinder_on_block_tet.toml, 3172 nodes)\n\nThe nodal contact pressure at the cylinder's slave nodes against Hertz's line contact (`solver post hertz`'s comparison; p0 and a from the load our mortar run's contact carried). Ours on 2 ranks; CalculiX's C3D10 on the same nodes on 2 threads, penalty contact (slope 1e8), node-to-surface (pressures at the slave nodes, compared as ours) and surface-to-surface (pressures at the slave faces' integration points, which ccx prints without positions: the peak only).\n\n| run | peak - p0 | RMS error | iterations | s |\n|---|---:|---:|---:|---:|\n",
    );
    for r in rows {
        let cells = match &r.result {
            Ok(m) => format!(
                "{:+.2}% | {} | {} | {:.1}",
                100.0 * m.peak,
                percent(m.rms),
                m.iterations,
                m.wall
            ),
            Err(e) => format!("failed: {e} | - | - | -"),
        };
        w.push_str(&format!("| {} | {cells} |\n", r.label));
    }
    w.push_str("\nIterations: ours CG, ccx's Newton.\n");
    w
}

/// The rows as JSON.
pub fn json(rows: &[Row]) -> serde_json::Value {
    let rows: Vec<serde_json::Value> = rows
        .iter()
        .map(|r| match &r.result {
            Ok(m) => serde_json::json!({"run": r.label, "peak_error": m.peak, "rms_error": m.rms,
                "iterations": m.iterations, "wall_s": m.wall}),
            Err(e) => serde_json::json!({"run": r.label, "failed": e}),
        })
        .collect();
    serde_json::Value::Array(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The deck ccx runs: the example's 10-node tetrahedra as C3D10, one pair of the kind
    /// asked, and the contact pressures printed in its one step.
    #[test]
    fn deck_of_the_tetrahedral_hertz_example() {
        let scene = repo_root().join(SCENE);
        for (kind, name) in [
            (PairType::NodeToSurface, "NODE TO SURFACE"),
            (PairType::SurfaceToSurface, "SURFACE TO SURFACE"),
        ] {
            let text = hertz_deck(&scene, kind).unwrap().text();
            assert_eq!(text.matches("*ELEMENT, TYPE=C3D10").count(), 2, "{name}");
            assert_eq!(text.matches("*CONTACT PAIR").count(), 1);
            assert!(text.contains(&format!(
                "*CONTACT PAIR, INTERACTION=CONTACT, TYPE={name}\n"
            )));
            assert!(text.contains("*CONTACT PRINT\nCSTR\n*END STEP\n"), "{name}");
            assert_eq!(text.matches("*STEP").count(), 1);
        }
    }

    /// The node-to-face variant differs from the example in its discretization and its
    /// mesh's path only.
    #[test]
    fn node_to_face_variant_of_the_example() {
        let dir = std::env::temp_dir().join(format!("bench_hertz_tet_{}", std::process::id()));
        let path = node_face_scene(&dir).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let original = std::fs::read_to_string(repo_root().join(SCENE)).unwrap();
        assert!(text.contains("discretization = \"node_face\"") && !text.contains(MORTAR));
        assert_eq!(text.lines().count(), original.lines().count());
        let problem = load_scene_refined(&path, 1).unwrap();
        assert_eq!(problem.mesh.num_nodes(), 3172);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
