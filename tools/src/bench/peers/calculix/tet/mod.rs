//! Tetrahedra beside hexahedra and CalculiX (issue 41's acceptance): Cook's membrane at
//! nu = 0.4999 and the flat punch in an elastic-perfectly plastic block, each on three
//! Gmsh tetrahedral meshes (4-node tetrahedra the solver completes to its composite tet10,
//! as it is and with the mean dilatation) beside ccx's C3D10 on the same nodes (the scene's deck, `scene::deck_with`; Cook's
//! shear traction as ccx's own consistent nodal forces, `face_loads`), against our hex8
//! with mean dilatation at its finest mesh (Cook at n = 64; the punch at 80 x 80,
//! `run/scenes/plasticity/punch_80.toml`). Ours on 2 ranks (`auto`), ccx on 2 threads, one
//! after the other. Then the Hertz cylinder on tetrahedra beside C3D10 (`hertz`). `bench --tet [--quick] [--out DIR]` writes `<out>/tet/`: `report.md`,
//! `results.json` and each case's directory (mesh, scene, logs, result file, deck).

mod hertz;
mod report;
pub mod results;
pub mod scenes;

use super::deck::{name, ElementType, NodePrint, NodeSet};
use super::output::{last_displacements, total_forces};
use super::plasticity::{ours, thickness, PUNCH_HALF_WIDTH, PUNCH_SET};
use super::run::{Job, Outcome};
use super::scene::{deck_with, Options};
use crate::api::{load_scene_refined, ResultFile};
use crate::runner::solver::repo_root;
use results::{Measured, Row};
use scenes::{Case, Problem};
use std::path::Path;

/// Wall-clock limit of each run (ours and ccx's).
const TIMEOUT_S: f64 = 1200.0;
/// The node set whose mean u_y is Cook's answer.
const TIP_SET: &str = "tip";

/// The cases: per problem the hexahedral reference first, then every tetrahedral mesh
/// without and with the mean dilatation.
fn cases(quick: bool) -> Vec<Case> {
    let (cook, punch): (&[usize], &[usize]) = if quick {
        (&[4, 8], &[5, 10])
    } else {
        (&[4, 8, 16], &[5, 10, 15])
    };
    let mut out = Vec::new();
    for (problem, reference, meshes) in [
        (Problem::Cook, if quick { 16 } else { 64 }, cook),
        (Problem::Punch, if quick { 40 } else { 80 }, punch),
    ] {
        out.push(Case {
            problem,
            tet: false,
            n: reference,
            bar: true,
        });
        for &n in meshes {
            for bar in [false, true] {
                out.push(Case {
                    problem,
                    tet: true,
                    n,
                    bar,
                });
            }
        }
    }
    out
}

/// Runs the cases and writes the report (after every case: a long run leaves what it has).
pub fn run(out: &Path, quick: bool) -> Result<(), String> {
    let dir = out.join("tet");
    std::fs::create_dir_all(&dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let ccx = super::run::version();
    let mut rows = Vec::new();
    for case in cases(quick) {
        rows.push(run_case(case, &dir.join(case.name()), ccx.is_some())?);
        report::write(&dir, &rows, &[], ccx.as_deref())?;
    }
    let hertz = hertz::run(&dir.join("hertz"), quick, ccx.is_some(), TIMEOUT_S);
    report::write(&dir, &rows, &hertz, ccx.as_deref())?;
    println!("{}", report::markdown(&rows, &hertz, ccx.as_deref()));
    Ok(())
}

/// The hexahedral punch's reference is the plasticity section's scene; every other case
/// is meshed here.
fn scene_of(case: &Case, dir: &Path) -> Result<std::path::PathBuf, String> {
    if case.problem == Problem::Punch && !case.tet {
        return Ok(repo_root().join(format!("run/scenes/plasticity/punch_{}.toml", case.n)));
    }
    case.write(&repo_root(), dir)
}

fn run_case(case: Case, dir: &Path, ccx: bool) -> Result<Row, String> {
    let scene = scene_of(&case, dir)?;
    let problem = load_scene_refined(&scene, 1).map_err(|e| format!("{}: {e}", scene.display()))?;
    let nodes = problem.mesh.num_nodes();
    eprintln!(
        "bench: tet: {} ({nodes} nodes): ours on 2 ranks",
        case.name()
    );
    // The punch's pressure acts on its half-width times the slab's thickness.
    let area = PUNCH_HALF_WIDTH * thickness(&problem);
    let ours = ours_run(&case, &scene, dir, area);
    match &ours {
        Ok(m) => eprintln!(
            "bench:   {:.1} s, {} CG iterations, {:.4}",
            m.wall, m.iterations, m.value
        ),
        Err(e) => eprintln!("bench:   failed: {e}"),
    }
    // ccx's C3D10 once per tetrahedral mesh, beside our plain composite element.
    let ccx = (case.tet && !case.bar).then(|| {
        if !ccx {
            return Err("CalculiX not available (no ccx on PATH; `run/setup --calculix`)".into());
        }
        eprintln!("bench: tet: {}: CalculiX C3D10 on 2 threads", case.name());
        let c = calculix(&case, &problem, &dir.join("calculix"));
        match &c {
            Ok(m) => eprintln!(
                "bench:   {:.1} s, {} Newton iterations, {:.4}",
                m.wall, m.iterations, m.value
            ),
            Err(e) => eprintln!("bench:   failed: {e}"),
        }
        c
    });
    Ok(Row {
        case,
        nodes,
        ours,
        ccx,
    })
}

fn ours_run(case: &Case, scene: &Path, dir: &Path, area: f64) -> Result<Measured, String> {
    match case.problem {
        Problem::Punch => {
            let o = ours::run(scene, dir, PUNCH_SET, area, TIMEOUT_S)?;
            Ok(Measured {
                wall: o.wall,
                iterations: o.cg_total,
                value: o.pressure,
            })
        }
        Problem::Cook => {
            let (wall, log, h5) = ours::solve(scene, dir, TIMEOUT_S)?;
            Ok(Measured {
                wall,
                iterations: log.cg_total,
                value: tip(&h5)?,
            })
        }
    }
}

/// The mean u_y of the tip set at the last step of our result file.
fn tip(h5: &Path) -> Result<f64, String> {
    let f = ResultFile::open(h5).map_err(|e| e.to_string())?;
    let last = f
        .num_steps()
        .checked_sub(1)
        .ok_or("no steps in the result file")?;
    let nodes = f
        .node_set(TIP_SET)
        .map_err(|e| e.to_string())?
        .filter(|n| !n.is_empty())
        .ok_or_else(|| format!("{}: no node set '{TIP_SET}'", h5.display()))?;
    let u = f.displacement(last).map_err(|e| e.to_string())?;
    // The file's ids are 1-based.
    Ok(nodes.iter().map(|&n| u[n as usize - 1][1]).sum::<f64>() / nodes.len() as f64)
}

/// ccx on the case's deck (C3D10 on our nodes), its automatic incrementation starting from
/// the scene's increment (as the plasticity section: fixed increments diverge there).
fn calculix(case: &Case, problem: &crate::api::Problem, dir: &Path) -> Result<Measured, String> {
    let options = Options {
        penalty: 0.0,
        element: ElementType::C3D8I,
        direct: false,
        without_contact: true,
    };
    let mut deck = deck_with(problem, &options)?;
    let tip = name("N_", TIP_SET);
    if case.problem == Problem::Cook {
        let set = problem
            .node_set(TIP_SET)
            .ok_or_else(|| format!("the scene has no node set '{TIP_SET}'"))?;
        deck.node_sets.push(NodeSet {
            name: tip.clone(),
            nodes: set.nodes.iter().map(|&n| n as usize + 1).collect(),
        });
        for step in &mut deck.steps {
            step.node_prints.push(NodePrint {
                node_set: tip.clone(),
                variables: "U".into(),
                totals_only: false,
            });
        }
    }
    let job = Job {
        dir: dir.to_path_buf(),
        name: case.name(),
        threads: 2,
        timeout_s: TIMEOUT_S,
    };
    job.write_deck(&deck)?;
    let punch = name("N_", PUNCH_SET);
    let area = PUNCH_HALF_WIDTH * thickness(problem);
    let end = |t: f64| (t - 1.0).abs() < 1e-6;
    let read = |o: &super::run::Output| -> Result<f64, String> {
        match case.problem {
            Problem::Cook => match last_displacements(&o.dat, &tip) {
                Some((t, u)) if end(t) && !u.is_empty() => {
                    Ok(u.iter().map(|(_, v)| v[1]).sum::<f64>() / u.len() as f64)
                }
                Some((t, _)) => Err(format!("ccx stopped at time {t}")),
                None => Err(format!("no displacements of {tip} in the .dat file")),
            },
            Problem::Punch => match total_forces(&o.dat, &punch).last() {
                Some(&(t, f)) if end(t) => Ok(-f[1] / area),
                Some(&(t, _)) => Err(format!("ccx stopped at time {t}")),
                None => Err(format!("no total force of {punch} in the .dat file")),
            },
        }
    };
    match job.run_repeated(1, read)? {
        Outcome::Finished { timed, values } => Ok(Measured {
            wall: timed.wall.median,
            iterations: timed.iterations as u64,
            value: values,
        }),
        Outcome::Stopped(why) | Outcome::Failed(why) | Outcome::Skipped(why) => Err(why),
    }
}
