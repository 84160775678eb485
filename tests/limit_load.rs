//! Beyond a limit load the run stops and says so: a flat punch pressed by a traction that
//! rises to twice Prandtl's limit pressure (2 + pi) sigma_y / sqrt(3) into an
//! elastic-perfectly plastic block in plane strain (half model, symmetry at x = 0, one
//! element through the thickness with u_z = 0). No equilibrium exists past the block's limit
//! load: the run must end with a diagnosed stop that names the plastic body, the last
//! converged time and the region that flows, under the punch; never an endless solve.

mod common;

const SY: f64 = 100.0;
/// Half-width of the punch; the block is 6 a wide and 6 a deep.
const A: f64 = 1.0;
const L: f64 = 6.0;
const N: usize = 10;
const P_MAX: f64 = 2.0 * 296.85;

fn scene() -> String {
    let t = L / N as f64;
    format!(
        r#"
kinematics = "small"
[[body]]
name = "block"
box = {{ min = [0.0, 0.0, 0.0], max = [{L}, {L}, {t}] }}
divisions = [{N}, {N}, 1]
material = {{ model = "j2_plastic", E = 200e3, nu = 0.3, yield_stress = {SY} }}
volumetric = "mean_dilatation"
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
[[side_set]]
name = "punch"
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
[[traction]]
side_set = "punch"
vector = [0.0, -1.0, 0.0]
function = [[0.0, 0.0], [1.0, {P_MAX}]]
[time]
segments = [{{ end = 1.0, steps = 8 }}]
[solver]
max_iterations = 2000
max_cutbacks = 4
"#
    )
}

#[test]
fn a_load_beyond_the_limit_stops_naming_the_flowing_region() {
    let p = common::problem(&scene());
    let (summary, _) = common::run_serial(&p, None);
    let failure = summary
        .failure
        .expect("a load of twice the limit load cannot be carried");
    println!("{failure}");
    assert!(
        failure.contains("a limit load of the plastic body 'block'"),
        "{failure}"
    );
    let after = |key: &str| -> f64 {
        let rest = &failure[failure
            .find(key)
            .unwrap_or_else(|| panic!("{key}: {failure}"))
            + key.len()..];
        rest.split([',', ' '])
            .next()
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("{key}: {failure}"))
    };
    let prandtl = (2.0 + std::f64::consts::PI) * SY / 3f64.sqrt();
    let carried = after("the last converged state is t = ") * P_MAX;
    println!(
        "carried {carried:.2} = {:.3} of Prandtl's {prandtl:.2}",
        carried / prandtl
    );
    // A displacement-based mesh over-estimates the limit load (the kinematic theorem; the
    // prescribed punch at n = 40 levels off 7.7% above Prandtl's value, coarser meshes
    // higher), and the stop comes only once the attempts fail at the limit: so the pressure
    // carried is at least most of Prandtl's (0.9: the last cut-backs may stop short of the
    // discrete limit by a halving of the step) and below the 10 x 10 mesh's own over-estimate
    // (at most 1.4 times: n = 20 carried 1.03 of it with the same load path).
    assert!(
        (0.9 * prandtl..1.4 * prandtl).contains(&carried),
        "{carried} against Prandtl's {prandtl}"
    );
    // The flowing region is Prandtl's mechanism under the punch: it reaches the punch's
    // edge (x = a) at the top surface and stays within the block's upper part.
    let (x_hi, y_lo) = (after(" .. "), after(", y "));
    assert!((A..L).contains(&x_hi), "{failure}");
    assert!(y_lo > 0.5 * L, "{failure}");
}
