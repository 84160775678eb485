//! A coarse cantilever in bending with one-point (`mean`) elements: 16 elements along the
//! length, 4 through the depth, 1 across the width, clamped at x = 0, a shear traction on
//! the free end. The tip deflection against the Timoshenko beam's
//!
//!   delta = P L^3 / (3 E I) + P L / (kappa G A),   kappa = 5/6,
//!
//! with nu = 0 so that the clamp adds no Poisson restraint the beam lacks. The elastic body
//! takes the total hourglass force K q of its default, the assumed-strain stabilisation
//! with the shear modulus only; a `j2_plastic` body that stays elastic, with the same
//! stabilisation by name, takes the incremental one of plastic bodies
//! (`fem::element::hourglass`) and must give the same deflection.

use crate::common;
const E: f64 = 1000.0;
const L: f64 = 8.0;
const H: f64 = 1.0;
const B: f64 = 1.0;
/// Shear traction on the end face; P = TAU H B.
const TAU: f64 = 1.0;

fn scene(material: &str, steps: usize) -> String {
    scene_with(material, steps, 4, "")
}

/// The assumed-strain stabilisation with the shear modulus only, by name (the default of
/// linear elastic bodies; plastic ones default to Flanagan-Belytschko at 0.1).
const AS_MU: &str = "hourglass = \"assumed_strain_mu\"";

/// The beam with `depth` elements through the depth (4 `depth` along) and the body line
/// `extra` (an `hourglass`; none: the body's default).
fn scene_with(material: &str, steps: usize, depth: usize, extra: &str) -> String {
    format!(
        r#"
kinematics = "small"
[[body]]
name = "beam"
box = {{ min = [0.0, 0.0, 0.0], max = [{L}, {H}, {B}] }}
divisions = [{along}, {depth}, 1]
material = {material}
integration = "mean"
{extra}
[[node_set]]
name = "clamp"
plane = {{ point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}
[[node_set]]
name = "tip"
plane = {{ point = [{L}, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}
[[side_set]]
name = "end"
plane = {{ point = [{L}, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}
[[displacement]]
node_set = "clamp"
components = ["x", "y", "z"]
value = 0.0
[[traction]]
side_set = "end"
vector = [0.0, {t}, 0.0]
function = [[0.0, 0.0], [1.0, 1.0]]
[time]
segments = [{{ end = 1.0, steps = {steps} }}]
[solver]
tolerance = 1e-8
max_iterations = 200000
"#,
        t = -TAU,
        along = 4 * depth
    )
}

/// Mean vertical displacement of the end face's nodes.
fn tip_deflection(text: &str) -> f64 {
    let p = common::problem(text);
    let (_, state) = common::solve(&p);
    let tip = &p.node_set("tip").unwrap().nodes;
    -tip.iter()
        .map(|&g| state.displacement[g as usize][1])
        .sum::<f64>()
        / tip.len() as f64
}

fn beam() -> f64 {
    let p = TAU * H * B;
    let i = B * H.powi(3) / 12.0;
    let g = E / 2.0;
    p * L.powi(3) / (3.0 * E * i) + p * L / (5.0 / 6.0 * g * B * H)
}

#[test]
fn coarse_mean_cantilever_matches_the_beam() {
    let exact = beam();
    let elastic = tip_deflection(&scene(
        &format!("{{ model = \"linear_elastic\", E = {E}, nu = 0.0 }}"),
        1,
    ));
    // Yield stress far above the largest bending stress (6 P L / (B H^2) = 48): the J2 body
    // stays elastic and its hourglass forces are accumulated over the steps.
    let plastic = tip_deflection(&scene_with(
        &format!("{{ model = \"j2_plastic\", E = {E}, nu = 0.0, yield_stress = 1e6 }}"),
        4,
        4,
        AS_MU,
    ));
    println!(
        "tip deflection: Timoshenko beam {exact:.6}, mean elastic {elastic:.6} ({:+.3}%), mean j2_plastic in its elastic range {plastic:.6} ({:+.3}%)",
        100.0 * (elastic / exact - 1.0),
        100.0 * (plastic / exact - 1.0)
    );
    // Measured -0.14% with the assumed-strain stabilisation (+4.65% with the
    // Flanagan-Belytschko stiffness at 0.1, the default before). At nu = 0 the stabilisation
    // makes a rectangular element's pure bending exact (the incompatible-mode element's
    // hourglass energy, `fem::element::stabilization`), so what is left is the linear
    // variation of the moment along each element and the solid's end effects against the
    // beam: the issue's 2%.
    assert!((elastic / exact - 1.0).abs() < 0.02, "{elastic} vs {exact}");
    // The incremental hourglass force of an elastic step is the total one up to rounding;
    // the two runs differ only by where the solver stops (tolerance 1e-10 of the
    // reference force, times a condition number of order 1e3 for this slender mesh).
    assert!(
        (plastic / elastic - 1.0).abs() < 1e-6,
        "{plastic} vs {elastic}"
    );
}

/// The cantilever's tip deflection over the beam's for the default (assumed strain, shear
/// modulus only), the assumed strain with lambda and Flanagan-Belytschko at 0.1 (the
/// default before), at 2 and 4 elements through the depth and nu = 0 and 0.3. Printed, for
/// docs/elements.md. At nu = 0.3 the beam formula above (G = E / 2) is only a guide: the
/// reference there is the solid's own converged deflection, 0.994 of it (the assumed
/// strain at 4n x n x n/4 elements, n = 4, 8, 16: 0.98678, 0.99088, 0.99291, and the
/// default from above: 1.00052, 0.99454); the solid's clamp restrains the Poisson
/// contraction the beam lacks.
#[test]
fn cantilever_variants_against_the_beam() {
    let exact = beam();
    for nu in [0.0, 0.3] {
        let material = format!("{{ model = \"linear_elastic\", E = {E}, nu = {nu} }}");
        for depth in [2, 4] {
            let ours = tip_deflection(&scene_with(&material, 1, depth, "")) / exact;
            let lambda = tip_deflection(&scene_with(
                &material,
                1,
                depth,
                "hourglass = \"assumed_strain\"",
            )) / exact;
            let fb = tip_deflection(&scene_with(&material, 1, depth, "hourglass = 0.1")) / exact;
            println!(
                "nu = {nu}, {} x {depth} elements: tip / beam: default (assumed strain, mu) {ours:.5}, assumed strain with lambda {lambda:.5}, Flanagan-Belytschko 0.1 {fb:.5}",
                4 * depth
            );
            // Measured: nu = 0: 0.99458 (2 layers), 0.99857 (4), the same for both
            // assumed strains (lambda = 0), against 1.20391 and 1.04653 for
            // Flanagan-Belytschko; nu = 0.3: 1.02393 and 1.00052 (0.994 the reference).
            // The issue's 2% at nu = 0, also at 2 layers (exact pure bending per element
            // does not need more); at nu = 0.3 the 4 layers within 2% of the reference.
            if nu == 0.0 {
                assert!((ours - 1.0).abs() < 0.02, "{depth} layers: {ours}");
            } else if depth == 4 {
                assert!((ours / 0.994 - 1.0).abs() < 0.02, "{depth} layers: {ours}");
            }
        }
    }
}
