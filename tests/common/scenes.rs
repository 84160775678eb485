//! Scenes of the repository, changed for a test.

use std::path::{Path, PathBuf};

use super::paths::repo;

/// `text` (a scene with a `[solver]` table) with the preconditioner `name`.
pub fn with_preconditioner(text: &str, name: &str) -> String {
    text.replace(
        "[solver]\n",
        &format!("[solver]\npreconditioner = \"{name}\"\n"),
    )
}

/// The first 30 of stick_slip's 60 steps (20 of loading, then 10 of sliding; about 0.3 s
/// of one core), written to `d/stick_slip_30.toml`.
pub fn stick_slip_30(d: &Path) -> PathBuf {
    let scene = d.join("stick_slip_30.toml");
    let text = std::fs::read_to_string(repo("run/scenes/paper/stick_slip.toml")).unwrap();
    let three = "segments = [{ end = 1.0, steps = 20 }, { end = 2.0, steps = 20 }, { end = 3.0, steps = 20 }]";
    assert!(text.contains(three));
    let two = "segments = [{ end = 1.0, steps = 20 }, { end = 1.5, steps = 10 }]";
    std::fs::write(&scene, text.replace(three, two)).unwrap();
    scene
}
