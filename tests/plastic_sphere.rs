//! Hill's thick-walled sphere under internal pressure (`common::hill`: the closed form and
//! the thin sector whose flat sides carry u . n = 0) on hexahedra: a box of n elements along
//! the radius, mapped onto the sector.

use crate::common;
use common::hill::{material, p_of_c, sides_and_load, to_sector, ub_of_c, A, B, FRONTS, SY};
use partition::Decomposition;
use solver::comm::SerialComm;
use solver::mesh::local::LocalMesh;
use solver::problem::Problem;
use solver::solver::Stepper;

const BAR: &str = "volumetric = \"mean_dilatation\"";
const MEAN: &str = "integration = \"mean\"";

/// The sector scene with the pressure reaching each of `pressures` at t = 1, 2, ...
fn scene(n: usize, pressures: &[f64], element: &str) -> Problem {
    let w = common::hill::W;
    let text = format!(
        r#"
kinematics = "small"
[[body]]
name = "sphere"
box = {{ min = [{A}, {mw}, {mw}], max = [{B}, {w}, {w}] }}
divisions = [{n}, 1, 1]
{material}
{element}
{sides}[solver]
tolerance = 1e-9
max_iterations = 200000
"#,
        mw = -w,
        material = material(),
        sides = sides_and_load(pressures),
    );
    let mut p = common::problem(&text);
    to_sector(&mut p.mesh.coords);
    p
}

/// For each pressure: (outer radial displacement, outer radius of the yielded zone), and
/// the CG iterations of the run, with the element line `element`. Err when a step fails.
fn solve_with(
    n: usize,
    pressures: &[f64],
    element: &str,
) -> Result<(Vec<(f64, f64)>, u64), String> {
    let p = scene(n, pressures, element);
    let comm = SerialComm;
    let d = Decomposition::partition(p.mesh.num_nodes(), &p.mesh.elements, 1).unwrap();
    let local = LocalMesh::new(&p.mesh, &d, 0);
    let mut st = Stepper::new(&comm, &p, &local, &p.mesh).expect("the stepper is built");
    let mut out = Vec::new();
    let mut cg = 0;
    for (k, &t) in p.step_times.iter().enumerate() {
        let rec = st.advance(k + 1, t).map_err(|f| f.to_string())?;
        cg += rec.cg_iterations;
        if (t - t.round()).abs() > 1e-12 {
            continue;
        }
        // Radial displacement of the outer nodes (x = b in the box: the last layer).
        let mut ub = 0.0;
        let mut count = 0.0;
        for (l, &g) in local.node_global.iter().enumerate() {
            let x = p.mesh.coords[g as usize];
            let r = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
            if (r - B).abs() < 1e-9 {
                let u = st.u[l];
                ub += (u[0] * x[0] + u[1] * x[1] + u[2] * x[2]) / r;
                count += 1.0;
            }
        }
        let eq = st.assembly().owned_eqps().unwrap();
        // Elements are ordered along x (the radius) first: element i spans
        // [a + i h, a + (i+1) h].
        let h = (B - A) / n as f64;
        let front = eq
            .iter()
            .enumerate()
            .filter(|(_, &e)| e > 0.0)
            .map(|(i, _)| A + (i + 1) as f64 * h)
            .fold(A, f64::max);
        out.push((ub / count, front));
    }
    Ok((out, cg))
}

#[test]
fn hill_sphere_converges_under_refinement() {
    converges_under_refinement(BAR);
}

#[test]
fn hill_sphere_converges_under_refinement_with_mean_integration() {
    converges_under_refinement(MEAN);
}

fn converges_under_refinement(element: &str) {
    let pressures: Vec<f64> = FRONTS.iter().map(|&c| p_of_c(c)).collect();
    let mut finest = 0.0f64;
    for n in [8, 16, 32] {
        let (res, cg) =
            solve_with(n, &pressures, element).unwrap_or_else(|e| panic!("{n} elements: {e}"));
        let h = (B - A) / n as f64;
        let mut worst = 0.0f64;
        for ((&c, &p), &(ub, front)) in FRONTS.iter().zip(&pressures).zip(&res) {
            let exact = ub_of_c(c);
            let err = (ub - exact).abs() / exact;
            worst = worst.max(err);
            println!(
                "[{element}] n = {n:>2}: p = {p:8.3} (front c = {c}): u(b) = {ub:.6e}, Hill {exact:.6e}, error {:.3}%; yielded to r = {front:.4} (element size {h:.4})",
                100.0 * err
            );
            // The plastic front is resolved to one element.
            assert!((front - c).abs() <= h + 1e-12, "front {front} vs {c}");
        }
        println!(
            "[{element}] n = {n:>2}: worst u(b) error {:.3}%, {cg} CG iterations",
            100.0 * worst
        );
        finest = worst;
    }
    // The issue's acceptance: the finest mesh within 1 %.
    assert!(finest < 0.01, "finest mesh error {finest}");
}

#[test]
fn hill_sphere_limit_pressure() {
    limit_pressure(BAR);
}

#[test]
fn hill_sphere_limit_pressure_with_mean_integration() {
    limit_pressure(MEAN);
}

fn limit_pressure(element: &str) {
    let limit = 2.0 * SY * (B / A).ln();
    // Just below the limit the sphere carries the load; above it no equilibrium exists.
    let below = solve_with(16, &[p_of_c(1.9), 0.995 * limit], element);
    let above = solve_with(16, &[p_of_c(1.9), 1.02 * limit], element);
    println!(
        "[{element}] limit 2 sigma_y ln(b/a) = {limit:.3}: at 0.995: {:?}",
        below.as_ref().map(|r| r.0.last().copied())
    );
    println!("at 1.02: {:?}", above.as_ref().map(|r| r.0.last().copied()));
    assert!(below.is_ok(), "{below:?}");
    assert!(
        above.is_err(),
        "equilibrium above the limit pressure: {above:?}"
    );
}
