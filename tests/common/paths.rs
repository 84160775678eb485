//! Paths and processes: the solver binary, files of the repository, a fresh directory per
//! test, a command's standard error.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The solver binary of this build.
pub fn solver() -> Command {
    Command::new(env!("CARGO_BIN_EXE_solver"))
}

/// A path inside the repository.
pub fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// The scene file of one of the paper's tests.
pub fn paper_scene(name: &str) -> String {
    repo(&format!("run/scenes/paper/{name}.toml"))
        .display()
        .to_string()
}

/// An empty directory `name` under cargo's temporary directory for tests, in a directory
/// named after the calling test file (the tests of all files run at once in one binary),
/// emptied if an earlier run left it.
#[track_caller]
pub fn fresh_dir(name: &str) -> PathBuf {
    let caller = Path::new(std::panic::Location::caller().file());
    let file = caller
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("tests");
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(file).join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Meshes `geo` into `out` with the Gmsh that run/setup installs (3-D, MSH 4.1, then
/// `args`: `-setnumber NAME VALUE`, `-order 2`); panics with Gmsh's message when it fails.
pub fn gmsh(geo: &Path, args: &[&str], out: PathBuf) -> PathBuf {
    let run = Command::new("gmsh")
        .args(["-3", "-format", "msh41"])
        .args(args)
        .arg(geo)
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap_or_else(|e| panic!("gmsh did not start ({e}): install it with run/setup --gmsh"));
    assert!(
        run.status.success(),
        "gmsh failed on {}: {}",
        geo.display(),
        String::from_utf8_lossy(&run.stderr)
    );
    out
}

/// A command's standard error, trimmed.
pub fn stderr_text(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).trim().to_string()
}
