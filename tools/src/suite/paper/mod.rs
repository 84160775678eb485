//! `suite paper` (run/paper): the paper's five verification tests (Mitchell and Heinstein,
//! sections 4.1-4.5, as scenes.md makes them concrete) on 1 and 2 MPI ranks, checked
//! against their exact answers (`solver post verify`), 1 rank compared with 2 bitwise
//! (`solver post compare`), the figures (`solver post figure`), the Gmsh cylinder against
//! Hertz (`solver post hertz`), ParaView pictures when ParaView is there (run/render), and
//! `out/paper/report.md`. Exit code 0 when every base scene passes its checks and every run
//! that should complete did; 1 otherwise.
//!
//! The phases: `runs` (the solver on each scene), `post` (verify, compare, figures, Hertz,
//! pictures), then the judgement (`verdicts`) and the report (`report`, with the sections'
//! fixed text in `sections` and the pictures' captions in `pictures`), which read what the
//! runs left through `results` (and `model`, one run).

mod model;
mod pictures;
mod post;
mod report;
mod results;
mod sections;
mod texts;
mod verdicts;

use crate::facts::Facts;
use crate::runner::{in_order, scenes_in, Suite};
use results::{Paper, DRAWN_EXAMPLES, EXAMPLE, EXAMPLE_SCENE, ORDER, SCENE_DIR};
use std::path::{Path, PathBuf};

/// The whole job; returns the exit code.
pub fn run(suite: &Suite) -> Result<i32, String> {
    suite.fresh_dirs()?;
    let scenes = in_order(&ORDER, &scenes_in(Path::new(SCENE_DIR)));
    suite.say(&format!("running {} scenes on 1 and 2 ranks", scenes.len()));
    for n in &scenes {
        let scene = PathBuf::from(format!("{SCENE_DIR}/{n}.toml"));
        suite.run_one(n, 1, &scene);
        suite.run_one(n, 2, &scene);
    }
    suite.run_one(EXAMPLE, 1, Path::new(EXAMPLE_SCENE));
    suite.run_one(EXAMPLE, 2, Path::new(EXAMPLE_SCENE));
    for (name, scene) in DRAWN_EXAMPLES {
        suite.run_one(name, 1, Path::new(scene));
        suite.run_one(name, 2, Path::new(scene));
    }
    post::checks(suite, &scenes);
    post::figures(suite);
    post::hertz(suite);
    post::render(suite);
    let facts = Facts::gather(suite);
    let paper = Paper::load(&suite.out, scenes);
    let status = report::write(&paper, &facts)?;
    println!();
    suite.say(&format!(
        "report: {}/report.md; total time {} s",
        suite.out.display(),
        suite.elapsed()
    ));
    if status == 0 {
        suite.say("all base-scene checks pass");
    } else {
        suite.say("FAILED (see above)");
    }
    Ok(status)
}
