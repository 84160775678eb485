//! Scene keys of `j2_plastic`: a bad value is an error naming the file and the key, with a
//! non-zero exit from `solver check` and `solver run`; a good plastic scene passes.

use crate::common;
use common::bad_scene;

const GOOD: &str = r#"
kinematics = "small"
[[body]]
name = "b"
box = { min = [0.0, 0.0, 0.0], max = [1.0, 1.0, 1.0] }
divisions = [1, 1, 1]
material = { model = "j2_plastic", E = 1000.0, nu = 0.3, yield_stress = 1.0, isotropic_hardening = 10.0, kinematic_hardening = 5.0 }
[[node_set]]
name = "bottom"
plane = { point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }
[[displacement]]
node_set = "bottom"
components = ["x", "y", "z"]
value = 0.0
[time]
segments = [{ end = 1.0, steps = 1 }]
"#;

/// `solver check` and `solver run` on `text`: the exit code (both agree) and the message.
fn run(name: &str, text: &str) -> (i32, String) {
    bad_scene::check_and_run("plastic-scene", name, text)
}

fn expect_error(name: &str, text: &str, needles: &[&str]) {
    assert_ne!(text, GOOD, "{name}: the replacement did not apply");
    bad_scene::expect_error("plastic-scene", name, text, needles);
}

#[test]
fn good_plastic_scene_passes() {
    let (code, err) = run("good_plastic", GOOD);
    assert_eq!(code, 0, "{err}");
    let large = GOOD
        .replace("\"small\"", "\"large\"")
        .replace(", kinematic_hardening = 5.0", "");
    let (code, err) = run("good_plastic_large", &large);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn negative_yield_stress() {
    expect_error(
        "negative_yield",
        &GOOD.replace("yield_stress = 1.0", "yield_stress = -1.0"),
        &["body[0].material.yield_stress", "> 0", "-1"],
    );
    expect_error(
        "zero_yield",
        &GOOD.replace("yield_stress = 1.0", "yield_stress = 0.0"),
        &["body[0].material.yield_stress"],
    );
}

#[test]
fn missing_yield_stress() {
    expect_error(
        "missing_yield",
        &GOOD.replace("yield_stress = 1.0, ", ""),
        &["yield_stress"],
    );
}

#[test]
fn hardening_below_the_bound() {
    expect_error(
        "softening_iso",
        &GOOD.replace("isotropic_hardening = 10.0", "isotropic_hardening = -10.0"),
        &["body[0].material.isotropic_hardening", ">= 0", "-10"],
    );
    expect_error(
        "softening_kin",
        &GOOD.replace("kinematic_hardening = 5.0", "kinematic_hardening = -5.0"),
        &["body[0].material.kinematic_hardening", ">= 0", "-5"],
    );
}

#[test]
fn kinematic_hardening_with_large_kinematics() {
    expect_error(
        "large_kinematic",
        &GOOD.replace("\"small\"", "\"large\""),
        &[
            "body[0].material.kinematic_hardening",
            "kinematics = \"small\"",
        ],
    );
}
