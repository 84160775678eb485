//! Plasticity beside CalculiX (issue 46's acceptance): a rigid flat punch pressed into an
//! elastic-perfectly plastic block in plane strain, as a prescribed punch (50 increments,
//! `run/scenes/plasticity/punch_40.toml`, `punch_80.toml`) and as a punch body through
//! node-to-face contact (12 steps, `contact_punch_48.toml`, `contact_punch_96.toml`, the
//! scenes of `tests/plastic_punch.rs`). Ours on 2 ranks (`auto`), ccx on the same mesh
//! (the scene's deck from `scene::deck_with`, C3D8I, `*PLASTIC`) on 2 threads, one after
//! the other: wall times, our CG iterations (total and the largest of one increment), ccx's
//! Newton iterations and the punch's final mean pressure of both beside Prandtl's.
//! `bench --plasticity [--quick] [--out DIR]` writes `<out>/plasticity/`: `report.md`,
//! `results.json`, each case's logs, result file and deck.

pub mod ours;
mod report;
pub mod results;

use super::deck::{name, ElementType};
use super::output::total_forces;
use super::run::{version, Job, Outcome};
use super::scene::{deck_with, Options};
use crate::api::{load_scene_refined, Material, Problem};
use crate::runner::solver::repo_root;
use results::{Case, Ccx, Kind, Row, CASES, CONTACT_PENALTY};
use std::path::{Path, PathBuf};

/// The punch's half-width (every scene's; the pressure's area is it times the thickness).
pub const PUNCH_HALF_WIDTH: f64 = 1.0;
/// The node set whose y reaction is the punch force, in every scene.
pub const PUNCH_SET: &str = "punch";
/// Wall-clock limit of each run (ours and ccx's).
const TIMEOUT_S: f64 = 1200.0;
const QUICK_TIMEOUT_S: f64 = 300.0;
/// Where `bench --plasticity` writes.
pub fn report_dir(out: &Path) -> PathBuf {
    out.join("plasticity")
}

/// Runs the cases (the quick ones with `quick`) and writes the report.
pub fn run(out: &Path, quick: bool) -> Result<(), String> {
    let dir = report_dir(out);
    std::fs::create_dir_all(&dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let timeout = if quick { QUICK_TIMEOUT_S } else { TIMEOUT_S };
    let ccx_version = version();
    let mut rows = Vec::new();
    for case in CASES
        .iter()
        .filter(|c| !quick || matches!(c.name, "punch_40" | "contact_punch_48"))
    {
        rows.push(run_case(case, &dir, timeout, ccx_version.is_some())?);
        // Written after every case: a long run leaves what it has.
        report::write(&dir, &rows, ccx_version.as_deref())?;
    }
    println!("{}", report::markdown(&rows, ccx_version.as_deref()));
    Ok(())
}

/// Ours, then ccx, on one case.
fn run_case(case: &'static Case, dir: &Path, timeout: f64, ccx: bool) -> Result<Row, String> {
    let scene = repo_root().join(case.scene);
    let problem = load_scene_refined(&scene, 1).map_err(|e| format!("{}: {e}", case.scene))?;
    let area = PUNCH_HALF_WIDTH * thickness(&problem);
    let case_dir = dir.join(case.name);
    eprintln!(
        "bench: plasticity: {}: ours on {} ranks",
        case.name,
        results::RANKS
    );
    let ours = ours::run(&scene, &case_dir, PUNCH_SET, area, timeout);
    match &ours {
        Ok(o) => eprintln!(
            "bench:   {:.1} s, {} CG iterations (at most {} in one increment), pressure {:.2}",
            o.wall,
            o.cg_total,
            o.cg_max().0,
            o.pressure
        ),
        Err(e) => eprintln!("bench:   failed: {e}"),
    }
    let ccx = if ccx {
        eprintln!("bench: plasticity: {}: CalculiX on 2 threads", case.name);
        let c = calculix(case, &problem, &case_dir.join("calculix"), area, timeout);
        match &c {
            Ok(c) => eprintln!(
                "bench:   {:.1} s, {} Newton iterations, pressure {:.2}",
                c.wall, c.newton_iterations, c.pressure
            ),
            Err(e) => eprintln!("bench:   failed: {e}"),
        }
        c
    } else {
        Err("CalculiX not available (no ccx on PATH; `run/setup --calculix`)".into())
    };
    Ok(Row {
        case,
        increments: problem.step_times.len(),
        prandtl: prandtl(&problem)?,
        ours,
        ccx,
    })
}

/// The block's thickness (the mesh's extent in z).
pub fn thickness(problem: &Problem) -> f64 {
    let z = problem.mesh.coords.iter().map(|x| x[2]);
    z.clone().fold(f64::MIN, f64::max) - z.fold(f64::MAX, f64::min)
}

/// Prandtl's (2 + pi) sigma_y / sqrt(3) of the scene's plastic body.
fn prandtl(problem: &Problem) -> Result<f64, String> {
    problem
        .body_models
        .iter()
        .find_map(|m| match &m.material {
            Material::J2Plastic(j) => Some(j.yield_stress),
            _ => None,
        })
        .map(|sy| (2.0 + std::f64::consts::PI) * sy / 3f64.sqrt())
        .ok_or_else(|| format!("{} has no j2_plastic body", problem.name))
}

/// ccx on the case's deck: C3D8I, ccx's own incrementation starting from the scene's
/// increment and never above it (it cuts an increment where its iterations do not
/// converge). Not `*STATIC, DIRECT` (the scene's fixed increments): at 40 x 40 ccx stops
/// in the second increment with "solution seems to diverge; please try automatic
/// incrementation".
fn calculix(
    case: &Case,
    problem: &Problem,
    dir: &Path,
    area: f64,
    timeout_s: f64,
) -> Result<Ccx, String> {
    let options = Options {
        penalty: CONTACT_PENALTY,
        element: ElementType::C3D8I,
        direct: false,
        without_contact: case.kind == Kind::Prescribed,
    };
    let job = Job {
        dir: dir.to_path_buf(),
        name: case.name.into(),
        threads: 2,
        timeout_s,
    };
    job.write_deck(&deck_with(problem, &options)?)?;
    let set = name("N_", PUNCH_SET);
    let read = |o: &super::run::Output| {
        let forces = total_forces(&o.dat, &set);
        match forces.last() {
            Some(&(t, f)) if (t - 1.0).abs() < 1e-6 => Ok((forces.len(), -f[1] / area)),
            Some(&(t, _)) => Err(format!("ccx stopped at time {t}")),
            None => Err(format!("no total force of {set} in the .dat file")),
        }
    };
    match job.run_repeated(1, read)? {
        Outcome::Finished { timed, values } => Ok(Ccx {
            wall: timed.wall.median,
            newton_iterations: timed.iterations,
            increments: values.0,
            pressure: values.1,
            element: options.element,
        }),
        Outcome::Stopped(why) | Outcome::Failed(why) | Outcome::Skipped(why) => Err(why),
    }
}
