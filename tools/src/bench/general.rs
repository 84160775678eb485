//! `--general`: what general contact costs against explicit pairs as the assembly grows. A
//! stack of B blocks (each [m, m, 2] elements, m alternating between n and n + 1 so that
//! neighbours do not match, pressed by a pressure on the top), once with `[general_contact]`
//! (every exterior face against every other body's: B (B - 1) passes, two per body pair)
//! and once with the B - 1 `[[contact]]` pairs of the touching faces, on 2 ranks: the
//! contact updates' count and time (the solver's `contact updates:` line: the search with
//! its ghost exchange, capture, release and slip), the time per update and its ratio to the
//! pairs', the whole run's time, CG iterations and peak memory. Two sizes: about 10^4 and
//! 10^5 exterior faces (`--quick`: the first). `bench --general [--quick] [--out DIR]`
//! writes `<out>/general/`: report.md, results.json and each run's scene, log and result.

use crate::machine::load_average;
use crate::runner::log::{number_after, number_before, SolverLog};
use crate::runner::process::Limits;
use crate::runner::solver::{solver_exe, Job, Precond};
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// (bodies, n): 32 blocks of 10 and 11 (9760 exterior faces), 128 blocks of 18 and 19
/// (106624).
const SIZES: [(usize, usize); 2] = [(32, 10), (128, 18)];
const RANKS: usize = 2;
/// A run's time limit (s).
const TIMEOUT_S: f64 = 900.0;
/// Each block's height.
const H: f64 = 0.25;

/// The divisions of block i across the stack.
fn divisions(n: usize, i: usize) -> usize {
    n + i % 2
}

/// Exterior faces of the stack: 2 m^2 on top and bottom, 4 x 2 m on the sides per block.
pub fn exterior_faces(bodies: usize, n: usize) -> usize {
    (0..bodies)
        .map(|i| {
            let m = divisions(n, i);
            2 * m * m + 8 * m
        })
        .sum()
}

/// The stack's scene: general contact, or the B - 1 pairs (the upper block's bottom the
/// slave of the lower one's top).
pub fn scene(bodies: usize, n: usize, general: bool) -> String {
    let mut s = String::new();
    let kind = if general {
        "general contact"
    } else {
        "explicit pairs"
    };
    let _ = writeln!(
        s,
        "# {bodies} blocks pressed together ({kind}); written by `bench --general`.\n\
         name = \"stack{bodies}\"\nkinematics = \"small\"\n"
    );
    for i in 0..bodies {
        let m = divisions(n, i);
        let (z0, z1) = (i as f64 * H, (i + 1) as f64 * H);
        let _ = writeln!(
            s,
            "[[body]]\nname = \"b{i}\"\nbox = {{ min = [0.0, 0.0, {z0}], max = [1.0, 1.0, {z1}] }}\n\
             divisions = [{m}, {m}, 2]\nmaterial = {{ model = \"linear_elastic\", E = 1.0e6, nu = 0.3 }}\n"
        );
        for (side, z) in [("bottom", z0), ("top", z1)] {
            let _ = writeln!(
                s,
                "[[side_set]]\nname = \"b{i}_{side}\"\nbody = \"b{i}\"\n\
                 plane = {{ point = [0.0, 0.0, {z}], normal = [0.0, 0.0, 1.0] }}\n"
            );
        }
    }
    for (name, axis, body) in [("x0", "1.0, 0.0, 0.0", ""), ("y0", "0.0, 1.0, 0.0", "")]
        .into_iter()
        .chain([("z0", "0.0, 0.0, 1.0", "body = \"b0\"\n")])
    {
        let c = &name[..1];
        let _ = writeln!(
            s,
            "[[node_set]]\nname = \"{name}\"\n{body}plane = {{ point = [0.0, 0.0, 0.0], normal = [{axis}] }}\n\n\
             [[displacement]]\nnode_set = \"{name}\"\ncomponents = [\"{c}\"]\nvalue = 0.0\n"
        );
    }
    let _ = writeln!(
        s,
        "[[pressure]]\nside_set = \"b{}_top\"\nvalue = 1.0e4\n",
        bodies - 1
    );
    if general {
        let _ = writeln!(s, "[general_contact]\nfriction = \"frictionless\"\n");
    } else {
        for i in 0..bodies - 1 {
            let _ = writeln!(
                s,
                "[[contact]]\nmaster = \"b{i}_top\"\nslave = \"b{}_bottom\"\n",
                i + 1
            );
        }
    }
    let _ = writeln!(s, "[time]\nsegments = [{{ end = 1.0, steps = 1 }}]");
    s
}

/// The contact updates' count and time (s) from a solver log's `contact updates:` line.
pub fn contact_updates(log: &str) -> Option<(u64, f64)> {
    let line = log.lines().find(|l| l.starts_with("contact updates: "))?;
    Some((
        number_after(line, "contact updates: ")?,
        number_before(line, " s (")?,
    ))
}

/// One run of the stack.
struct Run {
    log: SolverLog,
    updates: u64,
    update_s: f64,
}

impl Run {
    fn ms_per_update(&self) -> f64 {
        1e3 * self.update_s / self.updates.max(1) as f64
    }
}

/// One size: the general run and the pairs' run, or why either failed.
struct Size {
    bodies: usize,
    n: usize,
    general: Result<Run, String>,
    pairs: Result<Run, String>,
}

fn run_one(exe: &Path, dir: &Path, bodies: usize, n: usize, general: bool) -> Result<Run, String> {
    let name = format!(
        "stack{bodies}_{}",
        if general { "general" } else { "pairs" }
    );
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, scene(bodies, n, general))
        .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    let job = Job {
        scene: path,
        refine: None,
        ranks: RANKS,
        preconditioner: Precond::Auto,
        result: dir.join(PathBuf::from(format!("{name}.h5"))),
    };
    eprintln!(
        "bench: general: {name} ({} exterior faces)",
        exterior_faces(bodies, n)
    );
    let (log, _) = job.run_once(exe, &Limits::timeout(TIMEOUT_S))?;
    let text = std::fs::read_to_string(job.result.with_extension("log")).unwrap_or_default();
    let (updates, update_s) =
        contact_updates(&text).ok_or("no 'contact updates:' line in the log")?;
    Ok(Run {
        log,
        updates,
        update_s,
    })
}

/// Runs both variants of each size and writes the report.
pub fn run(out: &Path, quick: bool) -> Result<(), String> {
    let exe = solver_exe()?;
    let dir = out.join("general");
    std::fs::create_dir_all(&dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let sizes = if quick { &SIZES[..1] } else { &SIZES[..] };
    let results: Vec<Size> = sizes
        .iter()
        .map(|&(bodies, n)| Size {
            bodies,
            n,
            general: run_one(&exe, &dir, bodies, n, true),
            pairs: run_one(&exe, &dir, bodies, n, false),
        })
        .collect();
    let md = markdown(&results);
    let put = |name: &str, text: String| {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))
    };
    put("report.md", md.clone())?;
    put("results.json", json(&results))?;
    println!("{md}");
    let failed: Vec<&String> = results
        .iter()
        .flat_map(|s| [&s.general, &s.pairs])
        .filter_map(|r| r.as_ref().err())
        .collect();
    match failed.first() {
        Some(e) => Err(format!("{} run(s) failed, the first: {e}", failed.len())),
        None => Ok(()),
    }
}

fn markdown(sizes: &[Size]) -> String {
    let mut w = String::from("## General contact against explicit pairs\n\n");
    let _ = writeln!(
        w,
        "A stack of B blocks pressed together, non-matching neighbours, frictionless, one load \
         step, {RANKS} ranks, `auto` preconditioner; general contact (B (B - 1) passes) against \
         the B - 1 pairs of touching faces. A contact update is the search with its ghost \
         exchange, capture, release and slip (the largest rank's time). Load average {}.\n",
        load_average().unwrap_or_else(|| "unknown".into())
    );
    let _ = writeln!(
        w,
        "| bodies | exterior faces | elements | variant | contact updates | ms / update | update ratio | wall (s) | CG | peak MiB / rank |"
    );
    let _ = writeln!(w, "|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|");
    for s in sizes {
        let pairs_ms = s.pairs.as_ref().ok().map(Run::ms_per_update);
        for (label, r) in [("general", &s.general), ("pairs", &s.pairs)] {
            let head = format!("| {} | {} |", s.bodies, exterior_faces(s.bodies, s.n));
            let _ = match r {
                Ok(r) => writeln!(
                    w,
                    "{head} {} | {label} | {} | {:.2} | {} | {:.2} | {} | {:.1} |",
                    r.log.elements,
                    r.updates,
                    r.ms_per_update(),
                    pairs_ms.map_or("-".into(), |p| format!("{:.2}", r.ms_per_update() / p)),
                    r.log.wall,
                    r.log.cg_iterations,
                    r.log.peak_mib
                ),
                Err(e) => writeln!(w, "{head} - | {label} | failed: {e} ||||||"),
            };
        }
    }
    w
}

fn json(sizes: &[Size]) -> String {
    let runs: Vec<serde_json::Value> = sizes
        .iter()
        .flat_map(|s| {
            [("general", &s.general), ("pairs", &s.pairs)].map(|(label, r)| {
                let mut v = serde_json::json!({
                    "bodies": s.bodies,
                    "n": s.n,
                    "exterior_faces": exterior_faces(s.bodies, s.n),
                    "variant": label,
                });
                match r {
                    Ok(r) => {
                        v["contact_updates"] = r.updates.into();
                        v["contact_update_seconds"] = r.update_s.into();
                        v["wall_seconds"] = r.log.wall.into();
                        v["cg_iterations"] = r.log.cg_iterations.into();
                        v["peak_mib_per_rank"] = r.log.peak_mib.into();
                        v["elements"] = r.log.elements.into();
                    }
                    Err(e) => v["error"] = e.clone().into(),
                }
                v
            })
        })
        .collect();
    serde_json::to_string_pretty(&serde_json::json!({ "general": runs })).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_stack_counts_its_exterior_faces() {
        // Two blocks of 3 x 3 x 2 and 4 x 4 x 2: 2*9 + 24 and 2*16 + 32.
        assert_eq!(exterior_faces(2, 3), 42 + 64);
        assert_eq!(exterior_faces(SIZES[0].0, SIZES[0].1), 9760);
        assert_eq!(exterior_faces(SIZES[1].0, SIZES[1].1), 106624);
    }

    #[test]
    fn the_contact_line_is_read_back() {
        let log = "done: 1 steps\ncontact updates: 17, 1.484 s (87.32 ms each; the search)\n";
        assert_eq!(contact_updates(log), Some((17, 1.484)));
        assert_eq!(contact_updates("done: 1 steps\n"), None);
    }
}
