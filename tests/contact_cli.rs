//! Bad contact input through the command line: `solver check` and `solver run` exit with
//! code 2 and a message naming the file and the key, never a panic, never a result file.

use crate::common;
use common::bad_scene;

/// Refused with exit code 2 naming the file and each of `needles`.
fn expect_error(name: &str, text: &str, needles: &[&str]) {
    bad_scene::expect_error("contact-cli", name, text, needles);
}

fn run_scene(name: &str, text: &str) -> (i32, String) {
    bad_scene::check_and_run("contact-cli", name, text)
}

/// Two stacked unit cubes, the lower top the master, the upper bottom the slave.
const GOOD: &str = r#"
[[body]]
name = "lower"
box = { min = [0.0, 0.0, 0.0], max = [1.0, 1.0, 1.0] }
divisions = [1, 1, 1]
material = { model = "linear_elastic", E = 1000.0, nu = 0.0 }
[[body]]
name = "upper"
box = { min = [0.0, 1.0, 0.0], max = [1.0, 2.0, 1.0] }
divisions = [1, 1, 1]
material = { model = "linear_elastic", E = 1000.0, nu = 0.0 }
[[node_set]]
name = "lower_bottom"
body = "lower"
plane = { point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }
[[node_set]]
name = "upper_top"
body = "upper"
plane = { point = [0.0, 2.0, 0.0], normal = [0.0, 1.0, 0.0] }
[[node_set]]
name = "upper_all"
body = "upper"
box = { min = [0.0, 1.0, 0.0], max = [1.0, 2.0, 1.0] }
[[side_set]]
name = "lower_top"
body = "lower"
plane = { point = [0.0, 1.0, 0.0], normal = [0.0, 1.0, 0.0] }
[[side_set]]
name = "lower_side"
body = "lower"
plane = { point = [1.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }
[[side_set]]
name = "upper_bottom"
body = "upper"
plane = { point = [0.0, 1.0, 0.0], normal = [0.0, 1.0, 0.0] }
[[side_set]]
name = "interface"
plane = { point = [0.0, 1.0, 0.0], normal = [0.0, 1.0, 0.0] }
[[displacement]]
node_set = "lower_bottom"
components = ["x", "y", "z"]
value = 0.0
[[displacement]]
node_set = "upper_top"
components = ["x", "z"]
value = 0.0
[[displacement]]
node_set = "upper_top"
components = ["y"]
function = [[0.0, 0.0], [1.0, -0.01]]
[[contact]]
master = "lower_top"
slave = "upper_bottom"
CONTACT_KEYS
[time]
segments = [{ end = 1.0, steps = 1 }]
"#;

/// The good scene with `keys` (lines) added to its contact table.
fn with_keys(keys: &str) -> String {
    GOOD.replace("CONTACT_KEYS", keys)
}

#[test]
fn good_contact_scene_passes() {
    let (code, err) = run_scene("contact_good", &with_keys("friction = \"frictionless\""));
    assert_eq!(code, 0, "{err}");
    let (code, err) = run_scene(
        "contact_good_coulomb",
        &with_keys("friction = \"coulomb\"\nmu = 0.0\nnormal_tolerance = 0.1\ncapture_tolerance = 0.1\nsmoothing_width = 0.5"),
    );
    assert_eq!(code, 0, "{err}");
}

#[test]
fn missing_side_set() {
    expect_error(
        "contact_missing_master",
        &with_keys("").replace("master = \"lower_top\"", "master = \"lower_tpo\""),
        &["contact[0].master", "'lower_tpo'", "lower_top"],
    );
    expect_error(
        "contact_missing_slave",
        &with_keys("").replace("slave = \"upper_bottom\"", "slave = \"nowhere\""),
        &["contact[0].slave", "'nowhere'", "upper_bottom"],
    );
}

#[test]
fn master_and_slave_the_same_side_set() {
    expect_error(
        "contact_same_set",
        &with_keys("").replace("slave = \"upper_bottom\"", "slave = \"lower_top\""),
        &["contact[0]", "same side set", "'lower_top'"],
    );
}

#[test]
fn master_and_slave_sets_sharing_nodes() {
    // The lower body's x = 1 face shares the edge x = 1, y = 1 with its top.
    expect_error(
        "contact_shared_edge",
        &with_keys("").replace("slave = \"upper_bottom\"", "slave = \"lower_side\""),
        &["contact[0]", "overlap", "'lower_side'", "'lower_top'"],
    );
    // A side set of the plane y = 1 holds the faces of both bodies, the master's included.
    expect_error(
        "contact_shared_faces",
        &with_keys("").replace("slave = \"upper_bottom\"", "slave = \"interface\""),
        &["contact[0]", "overlap", "'interface'"],
    );
}

#[test]
fn slave_on_a_fully_prescribed_body() {
    let text = with_keys("").replace(
        "[[contact]]",
        "[[displacement]]\nnode_set = \"upper_all\"\ncomponents = [\"x\", \"z\"]\nvalue = 0.0\n\
         [[displacement]]\nnode_set = \"upper_all\"\ncomponents = [\"y\"]\n\
         function = [[0.0, 0.0], [1.0, -0.01]]\n[[contact]]",
    );
    expect_error(
        "contact_slave_prescribed",
        &text,
        &["contact[0].slave", "'upper'", "prescribed"],
    );
}

#[test]
fn slave_body_with_a_free_direction_is_not_fully_prescribed() {
    // A guided punch in a plane-strain model: u_z = 0 on every node of the scene and the
    // punch held laterally (u_x = u_z = 0 on all its nodes), pushed down at its top. Every
    // punch node has three Dirichlet conditions, but two of them are the same direction
    // (z): u_y is free everywhere below the top, so the punch is a valid slave body (the
    // scene solves once the check lets it through: the duplicate z rows are accepted).
    let text = with_keys("").replace(
        "[[contact]]",
        "[[node_set]]\nname = \"all\"\nbox = { min = [0.0, 0.0, 0.0], max = [1.0, 2.0, 1.0] }\n\
         [[displacement]]\nnode_set = \"all\"\ncomponents = [\"z\"]\nvalue = 0.0\n\
         [[displacement]]\nnode_set = \"upper_all\"\ncomponents = [\"x\", \"z\"]\nvalue = 0.0\n[[contact]]",
    );
    let (code, err) = run_scene("contact_guided_punch", &text);
    println!("contact_guided_punch: exit {code}: {}", err.trim());
    assert_eq!(
        code, 0,
        "a slave body with u_y free at every node but the top was rejected: {err}"
    );
}

#[test]
fn adjust_outside_zero_to_the_normal_tolerance() {
    expect_error(
        "contact_adjust_negative",
        &with_keys("adjust = -0.001"),
        &["contact[0].adjust", ">= 0", "-0.001"],
    );
    // The default normal tolerance is half the master face size (0.5 here).
    expect_error(
        "contact_adjust_beyond",
        &with_keys("adjust = 0.6"),
        &["contact[0].adjust", "normal search tolerance"],
    );
}

#[test]
fn capture_tolerance_beyond_normal_tolerance() {
    expect_error(
        "contact_capture_tol",
        &with_keys("normal_tolerance = 0.01\ncapture_tolerance = 0.02"),
        &["contact[0].capture_tolerance", "normal"],
    );
    // The default normal tolerance is half the master face size (0.5 here).
    expect_error(
        "contact_capture_tol_default",
        &with_keys("capture_tolerance = 0.6"),
        &["contact[0].capture_tolerance"],
    );
}

#[test]
fn negative_friction_coefficient() {
    expect_error(
        "contact_negative_mu",
        &with_keys("friction = \"coulomb\"\nmu = -0.2"),
        &["contact[0].mu", ">= 0", "-0.2"],
    );
    expect_error(
        "contact_nan_mu",
        &with_keys("friction = \"coulomb\"\nmu = nan"),
        &["contact[0].mu"],
    );
}

#[test]
fn coulomb_without_mu() {
    expect_error(
        "contact_coulomb_no_mu",
        &with_keys("friction = \"coulomb\""),
        &["contact[0].mu", "coulomb"],
    );
}

#[test]
fn mu_without_coulomb() {
    expect_error(
        "contact_mu_frictionless",
        &with_keys("friction = \"frictionless\"\nmu = 0.3"),
        &["contact[0].mu", "coulomb"],
    );
    expect_error(
        "contact_mu_default_friction",
        &with_keys("mu = 0.3"),
        &["contact[0].mu", "coulomb"],
    );
}

#[test]
fn unknown_friction_name() {
    expect_error(
        "contact_unknown_friction",
        &with_keys("friction = \"sticky\""),
        &[
            "contact[0].friction",
            "\"sticky\"",
            "coulomb",
            "frictionless",
        ],
    );
}

#[test]
fn bad_tolerances_and_smoothing() {
    expect_error(
        "contact_negative_normal_tol",
        &with_keys("normal_tolerance = -0.1"),
        &["contact[0].normal_tolerance", "-0.1"],
    );
    expect_error(
        "contact_negative_tangential_tol",
        &with_keys("tangential_tolerance = -1.0"),
        &["contact[0].tangential_tolerance"],
    );
    expect_error(
        "contact_infinite_capture_tol",
        &with_keys("capture_tolerance = inf"),
        &["contact[0].capture_tolerance"],
    );
    expect_error(
        "contact_wide_smoothing",
        &with_keys("smoothing_width = 0.7"),
        &["contact[0].smoothing_width", "0.7"],
    );
    expect_error(
        "contact_zero_smoothing",
        &with_keys("smoothing_width = 0.0"),
        &["contact[0].smoothing_width"],
    );
}

#[test]
fn unknown_contact_key_and_second_pair_index() {
    expect_error(
        "contact_unknown_key",
        &with_keys("frcition = \"coulomb\""),
        &["unknown field `frcition`", "line"],
    );
    // Errors in a second pair name it by its index.
    let text = with_keys("").replace(
        "[time]",
        "[[contact]]\nmaster = \"lower_top\"\nslave = \"upper_bottom\"\nfriction = \"coulomb\"\nmu = -1.0\n[time]",
    );
    expect_error("contact_second_pair", &text, &["contact[1].mu"]);
}
