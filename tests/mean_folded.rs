//! A mean-integrated hexahedron folded at a corner: its one integration point (the centre)
//! stays positive, so nothing fails, and the run says so instead (`Assembly::
//! folded_mean_elements`): a warning at the first step that ends with such elements, their
//! count on each step's line.

use crate::common;

/// A unit cube of one mean element, its face x = 0 held, the opposite corner (1, 1, 1)
/// pushed along (-1, -1, -1) by 0.8 in four steps: dented at the first step (0.2), turned
/// inside out at that corner from the second (0.4) on, while the three free nodes follow.
const FOLD: &str = r#"
name = "fold"
kinematics = "large"

[[body]]
name = "cube"
box = { min = [0.0, 0.0, 0.0], max = [1.0, 1.0, 1.0] }
divisions = [1, 1, 1]
integration = "mean"
material = { model = "neo_hookean", E = 1000.0, nu = 0.3 }

[[node_set]]
name = "corner"
body = "cube"
box = { min = [0.9, 0.9, 0.9], max = [1.1, 1.1, 1.1] }

[[node_set]]
name = "held"
body = "cube"
plane = { point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }

[[displacement]]
node_set = "held"
components = ["x", "y", "z"]
value = 0.0

[[displacement]]
node_set = "corner"
components = ["x", "y", "z"]
function = [[0.0, 0.0], [1.0, -0.8]]

[time]
segments = [{ end = 1.0, steps = 4 }]
"#;

/// `solver run` on the scene `text`, in a fresh directory of its own.
fn run(name: &str, text: &str) -> std::process::Output {
    let dir = common::synthetic::test_dir(name);
    let scene = dir.join("scene.toml");
    std::fs::write(&scene, text).unwrap();
    common::solver()
        .arg("run")
        .arg(&scene)
        .arg("-o")
        .arg(dir.join("scene.h5"))
        .output()
        .unwrap()
}

#[test]
fn a_folded_mean_element_is_reported_not_passed_over() {
    let out = run("mean_folded", FOLD);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let lines: Vec<&str> = err.lines().collect();
    let step = |k: usize| {
        *lines
            .iter()
            .find(|l| l.starts_with(&format!("step {k}/4")))
            .unwrap_or_else(|| panic!("no line of step {k}:\n{err}"))
    };
    assert!(!step(1).contains("folded"), "{}", step(1));
    for k in 2..=4 {
        assert!(step(k).contains("folded elements 1 "), "{}", step(k));
    }
    let warnings: Vec<&&str> = lines.iter().filter(|l| l.starts_with("warning")).collect();
    assert_eq!(warnings.len(), 1, "{err}");
    assert!(
        warnings[0].starts_with("warning: t = 0.5: 1 element(s) of mean-integrated bodies folded")
            && warnings[0].contains("the most folded: element 1,"),
        "{}",
        warnings[0]
    );
}

/// The same cube, its corner (1, 1, 1) pushed along (-1, -1, -1) by 0.6 at t = 1 and 1.4
/// at t = 2 and its face x = 1 along -x as far, through the held face: folded from t = 0.5,
/// then crushed until its centre inverts (t = 1.504). The stop names the inverted element
/// and says that the last completed step ended with a folded one.
#[test]
fn a_stop_after_folded_mean_elements_says_so() {
    let crush = FOLD
        .replace(
            "function = [[0.0, 0.0], [1.0, -0.8]]",
            "function = [[0.0, 0.0], [1.0, -0.6], [2.0, -1.4]]\n\n\
             [[node_set]]\nname = \"face\"\nbody = \"cube\"\n\
             plane = { point = [1.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }\n\n\
             [[displacement]]\nnode_set = \"face\"\ndirection = [1.0, 0.0, 0.0]\n\
             function = [[0.0, 0.0], [1.0, -0.6], [2.0, -1.4]]",
        )
        .replace(
            "segments = [{ end = 1.0, steps = 4 }]",
            "segments = [{ end = 2.0, steps = 8 }]",
        );
    let out = run("mean_folded_crushed", &crush);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("element 1: inverted element"), "{err}");
    assert!(
        err.contains(
            "ended with 1 mean-integrated element(s) folded at a corner (the warning above)"
        ),
        "{err}"
    );
}
