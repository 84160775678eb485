//! The flat-punch block the plasticity tests share: a block L x L in plane strain (one
//! element through the thickness, u_z = 0), half of the problem (symmetry at x = 0), the
//! base held and the far side held in x; the punch of half-width A presses on its top.

/// Half-width of the punch.
pub const A: f64 = 1.0;
/// Width and depth of the block.
pub const L: f64 = 6.0;

/// The block at `n` x `n` elements of J2 material (E, nu, sigma_y) with the element line
/// `element` (`volumetric = ...` or `integration = ...`), its supports, the node set
/// "punch" (the top nodes under the punch) and the side set "punch_face" (the top faces
/// under it). The caller adds the punch's load, `[time]` and `[solver]`.
pub fn block(n: usize, e: f64, nu: f64, sy: f64, element: &str) -> String {
    let t = L / n as f64;
    format!(
        r#"
kinematics = "small"
[[body]]
name = "block"
box = {{ min = [0.0, 0.0, 0.0], max = [{L}, {L}, {t}] }}
divisions = [{n}, {n}, 1]
material = {{ model = "j2_plastic", E = {e}, nu = {nu}, yield_stress = {sy} }}
{element}
[[node_set]]
name = "all"
box = {{ min = [0.0, 0.0, 0.0], max = [{L}, {L}, {t}] }}
[[node_set]]
name = "x0"
plane = {{ point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}
[[node_set]]
name = "bottom"
plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}
[[node_set]]
name = "right"
plane = {{ point = [{L}, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}
[[node_set]]
name = "punch"
box = {{ min = [0.0, {L}, 0.0], max = [{A}, {L}, {t}] }}
[[side_set]]
name = "punch_face"
box = {{ min = [0.0, {L}, 0.0], max = [{A}, {L}, {t}] }}
[[displacement]]
node_set = "all"
components = ["z"]
value = 0.0
[[displacement]]
node_set = "x0"
components = ["x"]
value = 0.0
[[displacement]]
node_set = "bottom"
components = ["x", "y"]
value = 0.0
[[displacement]]
node_set = "right"
components = ["x"]
value = 0.0
"#
    )
}

/// The punch's top nodes moved down by `depth` over t in [0, 1].
pub fn pressed(depth: f64) -> String {
    format!(
        "[[displacement]]\nnode_set = \"punch\"\ncomponents = [\"y\"]\nfunction = [[0.0, 0.0], [1.0, {}]]\n",
        -depth
    )
}
