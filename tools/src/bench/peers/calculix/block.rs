//! CalculiX on the block-on-block scene at the configured sizes, from the deck of the
//! scene as the solver loads it: its wall time and total force beside ours.

use super::output::total_force;
use super::run::{version, Job, Outcome};
use super::{deck::name, scene};
use crate::api::{load_scene_refined, Vec3};
use crate::block::{BLOCK_BASE_N, BLOCK_BOTTOM_SET, BLOCK_SCENE, BLOCK_TOP_SET};
use crate::config::Config;
use crate::runner::solver::repo_root;
use std::path::{Path, PathBuf};

/// CalculiX gets this long per size; larger sizes are skipped after one that does not
/// finish in time.
pub const CCX_TIMEOUT_S: f64 = 300.0;
pub const CCX_THREADS: usize = 2;
/// Slope of the linear pressure-overclosure law (pressure per unit overclosure) of the
/// node-to-surface penalty contact: with contact pressures of order 10 the overclosure is
/// about 1e-6, 1e-4 of the 0.009 the top is pressed down.
pub const CCX_PENALTY: f64 = 1e7;

/// Total reaction forces of the upper block's top and of the lower block's bottom.
pub struct Forces {
    pub top: Vec3,
    pub bottom: Vec3,
}

pub struct CcxSize {
    pub n: usize,
    /// 0 when the deck was not written.
    pub elements: usize,
    pub nodes: usize,
    pub deck: PathBuf,
    pub outcome: Outcome<Forces>,
}

impl CcxSize {
    fn not_run(n: usize, outcome: Outcome<Forces>) -> CcxSize {
        CcxSize {
            n,
            elements: 0,
            nodes: 0,
            deck: PathBuf::new(),
            outcome,
        }
    }
}

pub struct Calculix {
    /// `None`: ccx is not installed (or does not run).
    pub version: Option<String>,
    pub sizes: Vec<CcxSize>,
}

/// Every size of `cfg.calculix` with the repeats of the block-on-block run of that size.
pub fn run(cfg: &Config) -> Calculix {
    let Some(version) = version() else {
        eprintln!(
            "bench: CalculiX not available (no ccx on PATH; `run/setup --calculix` installs it)"
        );
        return Calculix {
            version: None,
            sizes: Vec::new(),
        };
    };
    eprintln!("bench: CalculiX {version}");
    let mut sizes = Vec::new();
    let mut skip: Option<String> = None;
    for &refine in &cfg.calculix {
        let n = BLOCK_BASE_N * refine;
        let size = match &skip {
            Some(why) => CcxSize::not_run(n, Outcome::Skipped(why.clone())),
            None => ccx_size(&cfg.out, refine, cfg.block_repeats(refine))
                .unwrap_or_else(|e| CcxSize::not_run(n, Outcome::Failed(e))),
        };
        match &size.outcome {
            Outcome::Finished { timed, values } => eprintln!(
                "bench:   ccx n = {n}: {:.2} s, total force {:.6}",
                timed.wall.median, -values.top[1]
            ),
            Outcome::Stopped(why) => {
                eprintln!("bench:   ccx n = {n}: {why}");
                skip = Some(format!("n = {n} did not finish ({why})"));
            }
            Outcome::Failed(e) => eprintln!("bench:   ccx n = {n} failed: {e}"),
            Outcome::Skipped(_) => {}
        }
        sizes.push(size);
    }
    Calculix {
        version: Some(version),
        sizes,
    }
}

fn ccx_size(out: &Path, refine: usize, repeats: usize) -> Result<CcxSize, String> {
    let n = BLOCK_BASE_N * refine;
    let problem = load_scene_refined(&repo_root().join(BLOCK_SCENE), refine as u32)
        .map_err(|e| e.to_string())?;
    let job = Job {
        dir: out.join("calculix").join(format!("n{n}")),
        name: format!("block_on_block_n{n}"),
        threads: CCX_THREADS,
        timeout_s: CCX_TIMEOUT_S,
    };
    let deck = job.write_deck(&scene::deck(&problem, CCX_PENALTY)?)?;
    let (elements, nodes) = (problem.mesh.num_elements(), problem.mesh.num_nodes());
    drop(problem);
    let (top_set, bottom_set) = (name("N_", BLOCK_TOP_SET), name("N_", BLOCK_BOTTOM_SET));
    let outcome = job.run_repeated(repeats, |o| {
        match (
            total_force(&o.dat, &top_set),
            total_force(&o.dat, &bottom_set),
        ) {
            (Some(top), Some(bottom)) => Ok(Forces { top, bottom }),
            _ => Err("no total force in the .dat file".to_string()),
        }
    })?;
    Ok(CcxSize {
        n,
        elements,
        nodes,
        deck,
        outcome,
    })
}
