//! Two stacked blocks pressed together, shared by tests/contact.rs and
//! tests/contact_pressure.rs.

use solver::problem::Problem;

/// Two stacked blocks, `lower` [0,1]^3 and `upper` [0,1]x[1,2]x[0,1], of n x n x n
/// elements with `(n_lower, n_upper)`, the lower top the master and the upper bottom the slave; rollers u_y = 0 on the
/// lower bottom, u_x = 0 on x = 0, u_z = 0 on z = 0; the upper top loaded by `top` (scene
/// text); `material` and `kinematics` as the scene keys, `discretization` of the pair, the
/// time `segments`.
pub fn stacked(
    (n_lower, n_upper): (usize, usize),
    (kinematics, material): (&str, &str),
    discretization: &str,
    top: &str,
    segments: &str,
) -> String {
    format!(
        r#"
name = "stacked"
kinematics = "{kinematics}"

[[body]]
name = "lower"
box = {{ min = [0.0, 0.0, 0.0], max = [1.0, 1.0, 1.0] }}
divisions = [{n_lower}, {n_lower}, {n_lower}]
material = {material}

[[body]]
name = "upper"
box = {{ min = [0.0, 1.0, 0.0], max = [1.0, 2.0, 1.0] }}
divisions = [{n_upper}, {n_upper}, {n_upper}]
material = {material}

[[node_set]]
name = "lower_bottom"
body = "lower"
plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}

[[node_set]]
name = "x0"
plane = {{ point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}

[[node_set]]
name = "z0"
plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }}

[[side_set]]
name = "lower_top"
body = "lower"
plane = {{ point = [0.0, 1.0, 0.0], normal = [0.0, 1.0, 0.0] }}

[[side_set]]
name = "upper_bottom"
body = "upper"
plane = {{ point = [0.0, 1.0, 0.0], normal = [0.0, 1.0, 0.0] }}

[[side_set]]
name = "upper_top"
body = "upper"
plane = {{ point = [0.0, 2.0, 0.0], normal = [0.0, 1.0, 0.0] }}

[[displacement]]
node_set = "lower_bottom"
components = ["y"]
value = 0.0

[[displacement]]
node_set = "x0"
components = ["x"]
value = 0.0

[[displacement]]
node_set = "z0"
components = ["z"]
value = 0.0

{top}

[[contact]]
master = "lower_top"
slave = "upper_bottom"
friction = "frictionless"
discretization = "{discretization}"

[time]
segments = [{segments}]

[solver]
tolerance = 1e-12
"#
    )
}

/// A pressure rising to `p` at t = 1 on the upper top.
pub fn pressure_top(p: f64) -> String {
    format!(
        r#"[[pressure]]
side_set = "upper_top"
function = [[0.0, 0.0], [1.0, {p:?}]]"#
    )
}

/// Two load steps to t = 1.
pub const TWO_STEPS: &str = "{ end = 1.0, steps = 2 }";

/// Global ids of the nodes of body `b` on the plane y = `y` (reference coordinates).
pub fn nodes_at_y(p: &Problem, b: usize, y: f64) -> Vec<usize> {
    let body = &p.mesh.bodies[b];
    (body.first_node..body.first_node + body.num_nodes)
        .filter(|&n| (p.mesh.coords[n][1] - y).abs() < 1e-9)
        .collect()
}
