//! Ironing run by the solver and by CalculiX (NLGEOM, node-to-surface penalty contact with
//! friction, the deck from `scene`): the ironing example (`run/examples/ironing.toml`: a
//! rigid half-cylinder die pressed into a neo-Hookean slab, then dragged along it with
//! Coulomb friction) and the block die with sharp edges pressed into a plane-strain slice
//! of the slab (`run/scenes/sliding/ironing_block_shallow.toml`). For each, the die's
//! horizontal and vertical force against the slide distance for both codes in one picture,
//! their medians and means over steady sliding and the differences. `bench --ironing [--out
//! DIR]` writes `<out>/ironing/` (the example) and `<out>/ironing/block/` (the block die):
//! `report.md`, `results.json`, `forces.png`, the deck and both codes' outputs.

use super::output::total_forces;
use super::run::{version, Job, Outcome};
use super::{deck::name, scene};
use crate::api::{load_scene_refined, Problem, ResultFile, Vec3};
use crate::runner::solver::{repo_root, solver_exe};
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// One of our other discretisations of a case: (label, scene, its die force history and
/// wall time, or why there is none).
pub type Variant = (&'static str, &'static str, Result<(Curve, f64), String>);

/// One die dragged over a slab, run by both codes.
pub struct Case {
    /// Its directory under `<out>/ironing/` ("" for the example).
    pub dir: &'static str,
    pub scene: &'static str,
    /// The die's node set: every node prescribed, its total reaction is the die force.
    pub die_set: &'static str,
    /// What the scene is, for the report.
    pub about: &'static str,
    /// Our runs of the same problem otherwise discretised (a row each beside ours):
    /// (label, scene).
    pub variants: &'static [(&'static str, &'static str)],
}

/// The ironing example.
pub const EXAMPLE: Case = Case {
    dir: "",
    scene: "run/examples/ironing.toml",
    die_set: "die",
    about: "a rigid half-cylinder die pressed 0.2 into a neo-Hookean slab, then dragged 3.0 along it, Coulomb mu = 0.3",
    variants: &[],
};

/// The block die with sharp edges. Its contact pressure (about 200 over the die's bottom of
/// area 1) lets ccx's penalty take the die 1e-3 deeper into the slab, 1% of the 0.1 it is
/// pressed in.
pub const BLOCK: Case = Case {
    dir: "block",
    scene: "run/scenes/sliding/ironing_block_shallow.toml",
    die_set: "die_top",
    about: "a rigid block die with sharp edges pressed 0.1 into a plane-strain slice of a neo-Hookean slab (four slab elements under it), then dragged 3.0 along it, Coulomb mu = 0.3",
    variants: &[(
        "ours, mortar",
        "run/scenes/sliding/ironing_block_shallow_mortar.toml",
    )],
};
/// Slope of ccx's pressure-overclosure law: with contact pressures of about 250 the
/// overclosure is about 1.2e-3, 0.6% of the 0.2 the die is pressed in (a penalty of 5e4
/// gives a vertical force 0.9% lower, one of 1e6 does not converge).
pub const IRONING_PENALTY: f64 = 2e5;
/// Steady sliding: the second half of the drag (t from 1.5 to 2 of the scene), after the
/// slab ahead of the die has bulged.
pub const STEADY_FROM: f64 = 1.5;

/// A die force history: (time, total reaction of the die).
pub type Curve = Vec<(f64, Vec3)>;

pub struct Ironing {
    pub case: &'static Case,
    pub ours: Curve,
    pub ours_wall: f64,
    /// `Case::variants` run: (label, scene, history and wall time or why there is none).
    pub variants: Vec<Variant>,
    /// CalculiX's history and wall time, or why there is none.
    pub ccx: Result<(Curve, f64), String>,
    pub ccx_version: Option<String>,
    /// The die's horizontal displacement as a function of time (the slide distance).
    pub slide: Vec<(f64, f64)>,
}

/// Median (F_x, |F_y|) over steady sliding. The median, not the mean: CalculiX's force
/// dips (to about 0.7 of its steady value) at the increments where its node-to-surface
/// contact elements are regenerated, a few in each slab element the die passes; the mean
/// takes those dips in (its vertical force comes out 4% low), the median does not.
pub fn steady(curve: &Curve) -> Option<(f64, f64)> {
    let fx = median(steady_values(curve, |f| f[0]))?;
    let fy = median(steady_values(curve, |f| f[1].abs()))?;
    Some((fx, fy))
}

/// Mean (F_x, |F_y|) over steady sliding, for the report beside the median.
pub fn steady_mean(curve: &Curve) -> Option<(f64, f64)> {
    let mean = |v: Vec<f64>| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
    Some((
        mean(steady_values(curve, |f| f[0]))?,
        mean(steady_values(curve, |f| f[1].abs()))?,
    ))
}

fn steady_values(curve: &Curve, of: impl Fn(&Vec3) -> f64) -> Vec<f64> {
    curve
        .iter()
        .filter(|(t, _)| *t > STEADY_FROM + 1e-9)
        .map(|(_, f)| of(f))
        .collect()
}

fn median(mut v: Vec<f64>) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    })
}

/// Runs both codes into `<out>/ironing/` and writes the report there.
pub fn run(out: &Path) -> Result<Vec<Ironing>, String> {
    [&EXAMPLE, &BLOCK]
        .into_iter()
        .map(|case| run_case(case, out))
        .collect()
}

fn run_case(case: &'static Case, out: &Path) -> Result<Ironing, String> {
    let dir = report_dir(out).join(case.dir);
    std::fs::create_dir_all(&dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let scene_path = repo_root().join(case.scene);
    let problem = load_scene_refined(&scene_path, 1).map_err(|e| e.to_string())?;
    let die = problem
        .node_set(case.die_set)
        .ok_or_else(|| format!("{} has no node set '{}'", case.scene, case.die_set))?
        .nodes
        .clone();
    let (ours, ours_wall) = run_ours(case.scene, &scene_path, &dir.join("ours.h5"), &die)?;
    let variants = case
        .variants
        .iter()
        .enumerate()
        .map(|(k, &(label, scene))| {
            let h5 = dir.join(format!("ours_variant{k}.h5"));
            (
                label,
                scene,
                run_ours(scene, &repo_root().join(scene), &h5, &die),
            )
        })
        .collect();
    let ccx_version = version();
    let ccx = match &ccx_version {
        None => Err("CalculiX not available (no ccx on PATH; `run/setup --calculix`)".into()),
        Some(_) => calculix(case, &problem, &dir),
    };
    let ironing = Ironing {
        case,
        ours,
        ours_wall,
        variants,
        ccx,
        ccx_version,
        slide: slide(case, &problem),
    };
    plot(&ironing, &dir.join("forces.png"))?;
    let (md, json) = (markdown(&ironing), json(&ironing));
    std::fs::write(dir.join("report.md"), &md).map_err(|e| e.to_string())?;
    std::fs::write(dir.join("results.json"), json).map_err(|e| e.to_string())?;
    println!("{md}");
    Ok(ironing)
}

/// Our run of the scene (`name` in messages) into `h5`, and the die force at every step
/// from its result file.
fn run_ours(name: &str, scene: &Path, h5: &Path, die: &[u32]) -> Result<(Curve, f64), String> {
    let _ = std::fs::remove_file(h5);
    let start = Instant::now();
    let o = std::process::Command::new(solver_exe()?)
        .args(["-q", "run"])
        .arg(scene)
        .arg("-o")
        .arg(h5)
        .output()
        .map_err(|e| format!("cannot start the solver: {e}"))?;
    let wall = start.elapsed().as_secs_f64();
    if !o.status.success() {
        return Err(format!(
            "the solver failed on {}: {}",
            name,
            String::from_utf8_lossy(&o.stderr).trim()
        ));
    }
    let f = ResultFile::open(h5).map_err(|e| e.to_string())?;
    let times = f.time().map_err(|e| e.to_string())?;
    let mut curve = Vec::new();
    for (k, &t) in times.iter().enumerate() {
        let r = f.reaction(k).map_err(|e| e.to_string())?;
        let mut sum = [0.0; 3];
        for &n in die {
            for i in 0..3 {
                sum[i] += r[n as usize][i];
            }
        }
        curve.push((t, sum));
    }
    Ok((curve, wall))
}

/// CalculiX on the deck of the scene, the die's total reaction at every increment.
fn calculix(case: &Case, problem: &Problem, dir: &Path) -> Result<(Curve, f64), String> {
    let job = Job {
        dir: dir.join("calculix"),
        name: "ironing".into(),
        threads: 2,
        timeout_s: 600.0,
    };
    job.write_deck(&scene::deck(problem, IRONING_PENALTY)?)?;
    let set = name("N_", case.die_set);
    match job.run_repeated(1, |o| Ok(total_forces(&o.dat, &set)))? {
        Outcome::Finished { timed, values } => Ok((values, timed.wall.median)),
        Outcome::Stopped(why) | Outcome::Failed(why) | Outcome::Skipped(why) => Err(why),
    }
}

/// The die's prescribed x displacement at the breakpoints of its function.
fn slide(case: &Case, problem: &Problem) -> Vec<(f64, f64)> {
    let set = problem
        .node_sets
        .iter()
        .position(|s| s.name == case.die_set);
    problem
        .dirichlet
        .iter()
        .find(|d| Some(d.node_set) == set && d.direction[0] == 1.0)
        .map(|d| {
            let mut t = problem.start_time;
            let mut out = vec![(t, d.function.eval(t))];
            for &s in &problem.step_times {
                t = s;
                out.push((t, d.function.eval(t)));
            }
            out
        })
        .unwrap_or_default()
}

/// Slide distance at time `t`, linear between the step ends.
fn slide_at(slide: &[(f64, f64)], t: f64) -> f64 {
    for w in slide.windows(2) {
        if t <= w[1].0 {
            let a = (t - w[0].0) / (w[1].0 - w[0].0);
            return w[0].1 + a * (w[1].1 - w[0].1);
        }
    }
    slide.last().map_or(0.0, |s| s.1)
}

/// A curve of the picture: its label, points and colour.
type Line = (String, Vec<(f64, f64)>, RGBColor);

fn plot(ir: &Ironing, path: &Path) -> Result<(), String> {
    let series = |c: &Curve, i: usize| -> Vec<(f64, f64)> {
        c.iter()
            .filter(|(t, _)| *t >= 1.0)
            .map(|(t, f)| (slide_at(&ir.slide, *t), if i == 0 { f[0] } else { -f[1] }))
            .collect()
    };
    let mut lines: Vec<Line> = vec![
        ("ours: F_x".into(), series(&ir.ours, 0), RED),
        ("ours: -F_y".into(), series(&ir.ours, 1), BLUE),
    ];
    if let Ok((c, _)) = &ir.ccx {
        lines.push(("CalculiX: F_x".into(), series(c, 0), RGBColor(240, 150, 0)));
        lines.push(("CalculiX: -F_y".into(), series(c, 1), RGBColor(0, 160, 200)));
    }
    for (label, _, run) in &ir.variants {
        if let Ok((c, _)) = run {
            lines.push((format!("{label}: F_x"), series(c, 0), RGBColor(0, 150, 0)));
            lines.push((
                format!("{label}: -F_y"),
                series(c, 1),
                RGBColor(200, 0, 200),
            ));
        }
    }
    let xmax = lines
        .iter()
        .flat_map(|l| l.1.iter().map(|p| p.0))
        .fold(0.0, f64::max);
    let ymax = lines
        .iter()
        .flat_map(|l| l.1.iter().map(|p| p.1))
        .fold(0.0, f64::max);
    let root = BitMapBackend::new(path, (1000, 650)).into_drawing_area();
    let e = |e: &dyn std::fmt::Display| format!("cannot draw {}: {e}", path.display());
    root.fill(&WHITE).map_err(|x| e(&x))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!("{}: die force against slide distance", title(ir.case)),
            ("sans-serif", 24),
        )
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..xmax.max(1e-9), 0.0..1.1 * ymax.max(1e-9))
        .map_err(|x| e(&x))?;
    chart
        .configure_mesh()
        .x_desc("slide distance (die u_x)")
        .y_desc("die force")
        .draw()
        .map_err(|x| e(&x))?;
    for (label, pts, colour) in lines {
        chart
            .draw_series(LineSeries::new(pts, colour.stroke_width(2)))
            .map_err(|x| e(&x))?
            .label(label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE)
        .border_style(BLACK)
        .position(SeriesLabelPosition::MiddleRight)
        .draw()
        .map_err(|x| e(&x))?;
    root.present().map_err(|x| e(&x))
}

fn title(case: &Case) -> &'static str {
    if case.dir.is_empty() {
        "Ironing"
    } else {
        "Ironing with the block die"
    }
}

fn percent(ours: f64, peer: f64) -> f64 {
    100.0 * (ours - peer) / peer.abs()
}

fn markdown(ir: &Ironing) -> String {
    let mut w = format!("## {}: the solver beside CalculiX\n\n", title(ir.case));
    let _ = writeln!(
        w,
        "`{}` ({}): the die's force over steady sliding (t > {STEADY_FROM}), median and mean. CalculiX {}: NLGEOM, NEO HOOKE with the same initial moduli, node-to-surface penalty contact (slope {IRONING_PENALTY:e}) with friction, the scene's increments (it cuts some). Picture: `forces.png`.\n",
        ir.case.scene,
        ir.case.about,
        ir.ccx_version.as_deref().unwrap_or("(not run)")
    );
    let _ = writeln!(
        w,
        "| code | points | F_x median | abs(F_y) median | F_x / abs(F_y) | F_x mean | abs(F_y) mean | wall (s) |"
    );
    let _ = writeln!(w, "|---|---:|---:|---:|---:|---:|---:|---:|");
    let row = |w: &mut String, code: &str, c: &Curve, wall: f64| {
        if let (Some((fx, fy)), Some((mx, my))) = (steady(c), steady_mean(c)) {
            let n = steady_values(c, |f| f[0]).len();
            let _ = writeln!(
                w,
                "| {code} | {n} | {fx:.4} | {fy:.4} | {:.4} | {mx:.4} | {my:.4} | {wall:.1} |",
                fx / fy
            );
        }
    };
    row(&mut w, "ours", &ir.ours, ir.ours_wall);
    for (label, _, run) in &ir.variants {
        if let Ok((c, wall)) = run {
            row(&mut w, label, c, *wall);
        }
    }
    match &ir.ccx {
        Ok((c, wall)) => {
            row(&mut w, "CalculiX", c, *wall);
            let _ = writeln!(w);
            differences(&mut w, "ours", &ir.ours, c);
            for (label, _, run) in &ir.variants {
                if let Ok((v, _)) = run {
                    differences(&mut w, label, v, c);
                }
            }
        }
        Err(why) => {
            let _ = writeln!(w, "\nCalculiX: {why}");
        }
    }
    for (label, scene, run) in &ir.variants {
        match run {
            Ok(_) => {
                let _ = writeln!(w, "`{label}`: `{scene}`.");
            }
            Err(why) => {
                let _ = writeln!(w, "`{label}` (`{scene}`): {why}");
            }
        }
    }
    w
}

/// The differences (`label` - CalculiX) / CalculiX of the medians and of the means.
fn differences(w: &mut String, label: &str, ours: &Curve, ccx: &Curve) {
    if let (Some(a), Some(b)) = (steady(ours), steady(ccx)) {
        let _ = writeln!(
            w,
            "Difference of the medians ({label} - CalculiX) / CalculiX: F_x {:+.2}%, F_y {:+.2}%.",
            percent(a.0, b.0),
            percent(a.1, b.1)
        );
    }
    if let (Some(a), Some(b)) = (steady_mean(ours), steady_mean(ccx)) {
        let _ = writeln!(
            w,
            "Difference of the means ({label} - CalculiX) / CalculiX: F_x {:+.2}%, F_y {:+.2}%.\n",
            percent(a.0, b.0),
            percent(a.1, b.1)
        );
    }
}

fn json(ir: &Ironing) -> String {
    let curve = |c: &Curve| -> Vec<serde_json::Value> {
        c.iter()
            .map(|(t, f)| serde_json::json!({"time": t, "slide": slide_at(&ir.slide, *t), "force": f}))
            .collect()
    };
    let steady_of = |c: &Curve| {
        steady(c).zip(steady_mean(c)).map(|((fx, fy), (mx, my))| {
            serde_json::json!({"fx_median": fx, "abs_fy_median": fy, "fx_mean": mx, "abs_fy_mean": my})
        })
    };
    let ccx = match &ir.ccx {
        Ok((c, wall)) => serde_json::json!({
            "version": ir.ccx_version,
            "wall_s": wall,
            "steady": steady_of(c),
            "curve": curve(c),
        }),
        Err(why) => serde_json::json!({"error": why}),
    };
    let diff = |ours: &Curve| match (&ir.ccx, steady(ours), steady_mean(ours)) {
        (Ok((c, _)), Some(a), Some(am)) => steady(c).zip(steady_mean(c)).map(|(b, bm)| {
            serde_json::json!({
                "fx_median_percent": percent(a.0, b.0),
                "abs_fy_median_percent": percent(a.1, b.1),
                "fx_mean_percent": percent(am.0, bm.0),
                "abs_fy_mean_percent": percent(am.1, bm.1),
            })
        }),
        _ => None,
    };
    let variants: Vec<serde_json::Value> = ir
        .variants
        .iter()
        .map(|(label, scene, run)| match run {
            Ok((c, wall)) => serde_json::json!({
                "label": label,
                "scene": scene,
                "wall_s": wall,
                "steady": steady_of(c),
                "curve": curve(c),
                "difference": diff(c),
            }),
            Err(why) => serde_json::json!({"label": label, "scene": scene, "error": why}),
        })
        .collect();
    let v = serde_json::json!({
        "scene": ir.case.scene,
        "steady_from": STEADY_FROM,
        "ours": {"wall_s": ir.ours_wall, "steady": steady_of(&ir.ours), "curve": curve(&ir.ours)},
        "calculix": ccx,
        "difference": diff(&ir.ours),
        "variants": variants,
    });
    serde_json::to_string_pretty(&v).unwrap_or_default()
}

/// Where `bench --ironing` writes.
pub fn report_dir(out: &Path) -> PathBuf {
    out.join("ironing")
}
