//! What the paper report is written from, read back from `out/paper/` once the runs and
//! the post-processing are over: the scene lists, every run (`model`), `solver post hertz`'s
//! text and how run/render ended. The job (`mod.rs`, `post.rs`) produces the files; the
//! report (`report`, `sections`, `pictures`) and the judgement (`verdicts`) read this.

use super::model::PaperRun;
use crate::record::{read, read_trim};
use std::path::{Path, PathBuf};

pub const SCENE_DIR: &str = "run/scenes/paper";
/// The paper scenes in the paper's order (base scene, then its variants).
pub const ORDER: [&str; 16] = [
    "bc_interaction",
    "bc_interaction_mu037",
    "bc_interaction_mu036",
    "bc_interaction_frictionless",
    "bc_interaction_mortar",
    "bc_interaction_mu036_mortar",
    "normal_smoothing",
    "normal_smoothing_off",
    "capture_release",
    "capture_release_mortar",
    "stick_slip",
    "stick_slip_mortar",
    "multi_constraint",
    "multi_constraint_nonmatching",
    "multi_constraint_mortar",
    "multi_constraint_nonmatching_mortar",
];
/// The scenes whose checks must pass.
pub const BASE: [&str; 5] = [
    "bc_interaction",
    "normal_smoothing",
    "capture_release",
    "stick_slip",
    "multi_constraint",
];
/// Variants whose checks must pass as well as the base scenes' (and the mortar ones'):
/// without smoothing, the paper's node at the V is held at the facets' shared edge by both
/// (a fold), the same symmetric answer as with smoothing.
pub const CHECKED_VARIANTS: [&str; 1] = ["normal_smoothing_off"];
/// The Gmsh example, compared with Hertz.
pub const EXAMPLE: &str = "cylinder_on_block";
pub const EXAMPLE_SCENE: &str = "run/examples/cylinder_on_block.toml";
/// The plastic example: run on 1 and 2 ranks, compared, drawn.
pub const PLASTIC_EXAMPLE: &str = "bolted_clamp";
pub const PLASTIC_EXAMPLE_SCENE: &str = "run/examples/bolted_clamp.toml";
/// The tetrahedral example: a part made with Gmsh's OpenCASCADE kernel (issue 41).
pub const TET_EXAMPLE: &str = "bracket";
pub const TET_EXAMPLE_SCENE: &str = "run/examples/bracket.toml";
/// The examples run on 1 and 2 ranks, compared and drawn from an oblique view.
pub const DRAWN_EXAMPLES: [(&str, &str); 2] = [
    (PLASTIC_EXAMPLE, PLASTIC_EXAMPLE_SCENE),
    (TET_EXAMPLE, TET_EXAMPLE_SCENE),
];

/// Everything the report is written from.
pub struct Paper {
    pub out: PathBuf,
    pub scenes: Vec<String>,
    pub example: String,
    pub example_scene: String,
    /// (name, (1 rank, 2 ranks)) of every scene and the example.
    pub runs: Vec<(String, (PaperRun, PaperRun))>,
    pub hertz_rc: String,
    pub hertz_txt: String,
    pub render_rc: String,
    pub render_log: String,
}

impl Paper {
    /// Reads every run back from `out` (after the runs and the post-processing).
    pub fn load(out: &Path, scenes: Vec<String>) -> Paper {
        let logs = out.join("logs");
        let pair = |name: &str, scene: &str| {
            (
                name.to_string(),
                (
                    PaperRun::load(out, name, 1, scene),
                    PaperRun::load(out, name, 2, scene),
                ),
            )
        };
        let mut runs: Vec<_> = scenes
            .iter()
            .map(|n| pair(n, &format!("{SCENE_DIR}/{n}.toml")))
            .collect();
        runs.push(pair(EXAMPLE, EXAMPLE_SCENE));
        for (name, scene) in DRAWN_EXAMPLES {
            runs.push(pair(name, scene));
        }
        Paper {
            out: out.to_path_buf(),
            scenes,
            example: EXAMPLE.into(),
            example_scene: EXAMPLE_SCENE.into(),
            runs,
            hertz_rc: read_trim(&logs.join("hertz.rc")),
            hertz_txt: read(&logs.join("hertz.txt"))
                .map(|t| t.trim_end().to_string())
                .unwrap_or_default(),
            render_rc: read_trim(&logs.join("render.rc")),
            render_log: read_trim(&logs.join("render.log")),
        }
    }
}

/// How run/render ended: ParaView absent (why), or its exit code and error lines.
pub struct Render {
    pub absent: Option<String>,
    pub rc: String,
    pub errors: Vec<String>,
}

impl Render {
    pub fn of(paper: &Paper) -> Render {
        let errors: Vec<String> = paper
            .render_log
            .lines()
            .filter(|l| l.starts_with("run/render:") || l.starts_with("render: error"))
            .map(str::to_string)
            .collect();
        let absent = (paper.render_rc == "3")
            .then(|| {
                errors
                    .last()
                    .map_or(paper.render_log.as_str(), String::as_str)
                    .replace("run/render: ", "")
            })
            .filter(|why| !why.is_empty());
        Render {
            absent,
            rc: paper.render_rc.clone(),
            errors,
        }
    }
}

/// The RMS error of `solver post hertz` (`RMS error ...: X% of p0`), as printed.
pub fn hertz_rms(txt: &str) -> Option<String> {
    txt.lines().find_map(|l| {
        let rest = &l[l.find("RMS error")?..];
        let after = &rest[rest.find(':')? + 1..];
        let v = after.trim_start();
        let num: String = v
            .chars()
            .take_while(|c| c.is_ascii_digit() || *c == '-' || *c == '.')
            .collect();
        (!num.is_empty() && v[num.len()..].starts_with("% of p0")).then_some(num)
    })
}

/// `peak pressure: Hertz p0 P, FE F (D%)`: (P, F, D).
pub fn hertz_peak(txt: &str) -> Option<(String, String, String)> {
    txt.lines().find_map(|l| {
        let rest = &l[l.find("peak pressure: Hertz p0 ")? + "peak pressure: Hertz p0 ".len()..];
        let (p0, rest) = rest.split_once(", FE ")?;
        let (fe, rest) = rest.split_once(" (")?;
        let pct = rest.split_once("%)")?.0;
        let simple = |s: &str| !s.is_empty() && !s.contains(char::is_whitespace);
        (simple(p0)
            && simple(fe)
            && !pct.is_empty()
            && pct.chars().all(|c| c.is_ascii_digit() || "+-.".contains(c)))
        .then(|| (p0.into(), fe.into(), pct.into()))
    })
}

/// `half-width a: Hertz A, FE outermost node in contact B (node spacing C)`: (A, B, C).
pub fn hertz_half(txt: &str) -> Option<(String, String, String)> {
    txt.lines().find_map(|l| {
        let key = "half-width a: Hertz ";
        let rest = &l[l.find(key)? + key.len()..];
        let (a, rest) = rest.split_once(", FE outermost node in contact ")?;
        let (b, rest) = rest.split_once(" (node spacing ")?;
        let c = rest.split_once(')')?.0;
        Some((a.into(), b.into(), c.into()))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const HERTZ: &str = "Hertz line contact (plane strain)\n\
  half-width a: Hertz 1.474, FE outermost node in contact 1.155 (node spacing 0.2735)\n\
  peak pressure: Hertz p0 4319, FE 4719 (+9.3%)\n\
  RMS error of the nodal pressure within |x| <= 1.5 a (26 nodes): 7.2% of p0\n";

    #[test]
    fn the_hertz_numbers_are_read_as_printed() {
        assert_eq!(hertz_rms(HERTZ).as_deref(), Some("7.2"));
        assert_eq!(
            hertz_peak(HERTZ),
            Some(("4319".into(), "4719".into(), "+9.3".into()))
        );
        assert_eq!(
            hertz_half(HERTZ),
            Some(("1.474".into(), "1.155".into(), "0.2735".into()))
        );
        assert_eq!(hertz_rms("no result"), None);
    }
}
