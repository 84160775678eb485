//! CalculiX on a problem of the robustness table (the Hertz example, the stick/slip bar):
//! the deck of the scene as the solver loads it (`scene`), the displacements of one node
//! set printed at every increment, run on `CCX_THREADS` threads under a time limit; its
//! wall time and the largest |u| over that set, to set beside ours.

use super::block::CCX_THREADS;
use super::deck::{name, NodePrint, NodeSet};
use super::output::max_displacement;
use super::run::{Job, Outcome};
use super::scene;
use crate::api::Problem;
use std::path::{Path, PathBuf};

/// What CalculiX did on one problem.
pub struct CcxRun {
    /// The deck (empty when it could not be written).
    pub deck: PathBuf,
    /// Largest |u| over the compared node set and every increment.
    pub outcome: Outcome<f64>,
}

/// CalculiX on `problem` in `dir` as job `job` (contact slope `penalty`, stopped after
/// `timeout_s`), printing U over the node set `set` (global ids `nodes`).
pub fn run(
    problem: &Problem,
    dir: &Path,
    job: &str,
    penalty: f64,
    timeout_s: f64,
    set: &str,
) -> CcxRun {
    let job = Job {
        dir: dir.to_path_buf(),
        name: job.into(),
        threads: CCX_THREADS,
        timeout_s,
    };
    let ccx_set = name("N_", set);
    let deck = match deck(problem, penalty, set).and_then(|d| job.write_deck(&d)) {
        Ok(path) => path,
        Err(why) => {
            return CcxRun {
                deck: PathBuf::new(),
                outcome: Outcome::Failed(why),
            }
        }
    };
    let outcome = job
        .run_repeated(1, |o| {
            max_displacement(&o.dat, &ccx_set)
                .ok_or_else(|| format!("no displacements of {ccx_set} in the .dat file"))
        })
        .unwrap_or_else(Outcome::Failed);
    CcxRun { deck, outcome }
}

/// The scene's deck with `set` defined (when no prescribed displacement defines it) and
/// its displacements printed node by node at every increment of every step.
pub fn deck(problem: &Problem, penalty: f64, set: &str) -> Result<super::deck::Deck, String> {
    let mut deck = scene::deck(problem, penalty)?;
    let ccx_set = name("N_", set);
    if !deck.node_sets.iter().any(|s| s.name == ccx_set) {
        let nodes = problem
            .node_set(set)
            .ok_or_else(|| format!("the scene has no node set '{set}'"))?
            .nodes
            .iter()
            .map(|&n| n as usize + 1)
            .collect();
        deck.node_sets.push(NodeSet {
            name: ccx_set.clone(),
            nodes,
        });
    }
    for step in &mut deck.steps {
        step.node_prints.push(NodePrint {
            node_set: ccx_set.clone(),
            variables: "U".into(),
            totals_only: false,
        });
    }
    Ok(deck)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::api::load_scene_refined;
    use crate::runner::solver::repo_root;

    /// The Hertz example: one step with the cylinder top's pressure as *DLOAD (500 at the
    /// step's end on every face of the side set; the labels follow each Gmsh element's
    /// corner order), the symmetry plane held in x, the axis printed.
    #[test]
    fn deck_of_the_hertz_example() {
        let scene = repo_root().join("run/examples/cylinder_on_block.toml");
        let problem = load_scene_refined(&scene, 1).unwrap();
        let text = deck(&problem, 1e8, "cylinder_axis").unwrap().text();
        let after = |start: &str| -> Vec<&str> {
            text.lines()
                .skip_while(|l| *l != start)
                .skip(1)
                .take_while(|l| !l.starts_with('*'))
                .collect()
        };
        let dload = after("*DLOAD");
        let faces = problem.side_set("cylinder_top").unwrap().faces.len();
        assert_eq!(dload.len(), faces);
        let labels = ["P1", "P2", "P3", "P4", "P5", "P6"];
        assert!(
            dload.iter().all(|l| {
                let f: Vec<&str> = l.split(", ").collect();
                f.len() == 3 && labels.contains(&f[1]) && f[2] == "500.0"
            }),
            "{dload:?}"
        );
        assert!(text.contains("N_CYLINDER_AXIS, 1, 1, 0.0\n"), "{text}");
        assert!(text.contains("*NODE PRINT, NSET=N_CYLINDER_AXIS\nU\n"));
        assert_eq!(text.matches("*STEP, INC=").count(), 1);
    }

    /// The stick/slip bar: two frictional pairs, three steps whose pressure at the bar's
    /// end is 0, 5e4 and 0 at their ends, and the bar's top defined for the print.
    #[test]
    fn deck_of_the_stick_slip_bar() {
        let scene = repo_root().join("run/scenes/paper/stick_slip.toml");
        let problem = load_scene_refined(&scene, 1).unwrap();
        let text = deck(&problem, 1e10, "bar_top").unwrap().text();
        assert_eq!(text.matches("*CONTACT PAIR").count(), 2);
        assert!(text.contains(
            "*CONTACT PAIR, INTERACTION=CONTACT_2, TYPE=NODE TO SURFACE\nS_SLAVE_2, S_MASTER_2\n"
        ));
        assert_eq!(text.matches("*FRICTION\n0.5, 1000000000.0\n").count(), 2);
        assert!(text.contains("*NSET, NSET=N_BAR_TOP\n"));
        let values: Vec<&str> = text
            .lines()
            .filter(|l| l.contains(", P6, "))
            .map(|l| l.rsplit(", ").next().unwrap())
            .collect();
        let per_step = problem.side_set("bar_end").unwrap().faces.len();
        assert_eq!(values.len(), 3 * per_step);
        assert_eq!(
            [values[0], values[per_step], values[2 * per_step]],
            ["0.0", "50000.0", "0.0"]
        );
    }
}
