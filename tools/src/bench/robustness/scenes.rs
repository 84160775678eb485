//! The scenes of the robustness table, as files the solver reads: the Hertz example at a
//! refinement factor (its Gmsh mesh made by `run/gmsh/make_examples F` when missing), the
//! paper's stick/slip bar at 160 x 8 x 1, the extreme suite's scenes as they are and the
//! block on block through `--refine`. Derived scenes are written into the output
//! directory; each derivation fails with a message naming the text it did not find.

use crate::runner::solver::repo_root;
use std::path::{Path, PathBuf};
use std::process::Command;

pub const HERTZ_SCENE: &str = "run/examples/cylinder_on_block.toml";
/// The mesh line of the Hertz scene, which a refined scene points elsewhere.
const HERTZ_MESH_LINE: &str = "file = \"../gmsh/cylinder_on_block.msh\"";
pub const STICK_SLIP_SCENE: &str = "run/scenes/paper/stick_slip.toml";
/// The bar's and the two plates' divisions in the paper scene, and at 160 x 8 x 1.
const STICK_SLIP_BAR: (&str, &str) = ("divisions = [40, 2, 1]", "divisions = [160, 8, 1]");
const STICK_SLIP_PLATE: (&str, &str) = ("divisions = [10, 1, 1]", "divisions = [40, 1, 1]");
pub const EXTREME_DIR: &str = "run/scenes/extreme";

/// `text` with `from` replaced by `to` exactly `count` times, else an error naming `what`.
fn replace_exactly(
    text: &str,
    from: &str,
    to: &str,
    count: usize,
    what: &str,
) -> Result<String, String> {
    let found = text.matches(from).count();
    if found != count {
        return Err(format!(
            "{what}: expected '{from}' {count} time(s), found it {found} time(s)"
        ));
    }
    Ok(text.replace(from, to))
}

/// The Gmsh mesh of the Hertz example at refinement factor `f` (1: the checked-in one).
pub fn hertz_mesh(f: usize) -> PathBuf {
    let name = if f == 1 {
        "cylinder_on_block.msh".to_string()
    } else {
        format!("cylinder_on_block_x{f}.msh")
    };
    repo_root().join("run/gmsh").join(name)
}

/// The Hertz scene text at factor `f`, reading `mesh` (an absolute path).
pub fn hertz_text(base: &str, f: usize, mesh: &Path) -> Result<String, String> {
    let text = replace_exactly(
        base,
        HERTZ_MESH_LINE,
        &format!("file = \"{}\"", mesh.display()),
        1,
        HERTZ_SCENE,
    )?;
    replace_exactly(
        &text,
        "name = \"cylinder_on_block\"",
        &format!("name = \"cylinder_on_block_x{f}\""),
        1,
        HERTZ_SCENE,
    )
}

/// Writes the Hertz scene at factor `f` into `dir`, making its mesh first when missing.
pub fn hertz(dir: &Path, f: usize) -> Result<PathBuf, String> {
    let mesh = hertz_mesh(f);
    if !mesh.is_file() {
        eprintln!(
            "bench: robustness: making {} (run/gmsh/make_examples {f})",
            mesh.display()
        );
        let out = Command::new(repo_root().join("run/gmsh/make_examples"))
            .arg(f.to_string())
            .output()
            .map_err(|e| format!("cannot run run/gmsh/make_examples: {e}"))?;
        if !out.status.success() || !mesh.is_file() {
            return Err(format!(
                "run/gmsh/make_examples {f} did not write {}: {}",
                mesh.display(),
                crate::runner::log::last_line(&String::from_utf8_lossy(&out.stderr))
            ));
        }
    }
    let base = read(HERTZ_SCENE)?;
    write(
        dir,
        &format!("cylinder_on_block_x{f}.toml"),
        &hertz_text(&base, f, &mesh)?,
    )
}

/// The stick/slip scene text with the bar at 160 x 8 x 1 and the plates at 40 x 1 x 1.
pub fn stick_slip_text(base: &str) -> Result<String, String> {
    let text = replace_exactly(
        base,
        STICK_SLIP_BAR.0,
        STICK_SLIP_BAR.1,
        1,
        STICK_SLIP_SCENE,
    )?;
    let text = replace_exactly(
        &text,
        STICK_SLIP_PLATE.0,
        STICK_SLIP_PLATE.1,
        2,
        STICK_SLIP_SCENE,
    )?;
    replace_exactly(
        &text,
        "name = \"stick_slip\"",
        "name = \"stick_slip_160x8\"",
        1,
        STICK_SLIP_SCENE,
    )
}

/// Writes the stick/slip bar at 160 x 8 x 1 into `dir`.
pub fn stick_slip(dir: &Path) -> Result<PathBuf, String> {
    let base = read(STICK_SLIP_SCENE)?;
    write(dir, "stick_slip_160x8.toml", &stick_slip_text(&base)?)
}

/// An extreme scene by name.
pub fn extreme(name: &str) -> Result<PathBuf, String> {
    let path = repo_root().join(EXTREME_DIR).join(format!("{name}.toml"));
    if path.is_file() {
        Ok(path)
    } else {
        Err(format!("no extreme scene {}", path.display()))
    }
}

fn read(rel: &str) -> Result<String, String> {
    let path = repo_root().join(rel);
    std::fs::read_to_string(&path).map_err(|e| format!("cannot read {}: {e}", path.display()))
}

fn write(dir: &Path, name: &str, text: &str) -> Result<PathBuf, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let path = dir.join(name);
    std::fs::write(&path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::api::parse;

    /// The stick/slip bar at 160 x 8 x 1 with plates of 40 x 1 x 1: 1280 + 2 x 40 elements.
    #[test]
    fn stick_slip_is_refined() {
        let text = stick_slip_text(&read(STICK_SLIP_SCENE).unwrap()).unwrap();
        let problem = parse(&text).unwrap();
        assert_eq!(problem.mesh.num_elements(), 160 * 8 + 2 * 40);
        assert_eq!(problem.name, "stick_slip_160x8");
        let e = stick_slip_text("name = \"x\"").unwrap_err();
        assert!(
            e.contains("expected 'divisions = [40, 2, 1]' 1 time(s), found it 0"),
            "{e}"
        );
    }

    /// The Hertz scene at x2 reads the mesh it is given and is named after the factor.
    #[test]
    fn hertz_scene_reads_the_refined_mesh() {
        let base = read(HERTZ_SCENE).unwrap();
        let text = hertz_text(&base, 2, Path::new("/m/c_x2.msh")).unwrap();
        assert!(text.contains("file = \"/m/c_x2.msh\"\n"));
        assert!(text.contains("name = \"cylinder_on_block_x2\"\n"));
        assert!(hertz_text("", 2, Path::new("/m")).is_err());
    }
}
