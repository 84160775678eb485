//! The full tangent preconditioner (`solver.preconditioner = "tangent"`): the same answers
//! as the nodal preconditioners, in far fewer CG iterations where a body yields.

use crate::common;
use partition::Decomposition;
use solver::comm::SerialComm;
use solver::mesh::local::LocalMesh;
use solver::problem::{Preconditioner, Problem};
use solver::solver::Stepper;

/// A flat punch (prescribed displacement of the block's top nodes under it) pressed into
/// an elastic-perfectly plastic block in plane strain, mean dilatation: the mechanism of
/// Prandtl's punch forms within the ten increments.
fn punch(n: usize) -> String {
    format!(
        "{}{}[time]\nsegments = [{{ end = 1.0, steps = 10 }}]\n",
        common::punch::block(n, 200e3, 0.3, 100.0, "volumetric = \"mean_dilatation\""),
        common::punch::pressed(0.06)
    )
}

/// The punch force after each increment and the CG iterations in all.
fn punch_forces(p: &Problem) -> (Vec<f64>, u64) {
    let comm = SerialComm;
    let d = Decomposition::partition(p.mesh.num_nodes(), &p.mesh.elements, 1).unwrap();
    let local = LocalMesh::new(&p.mesh, &d, 0);
    let mut st = Stepper::new(&comm, p, &local, &p.mesh).expect("the stepper is built");
    let punch = &p.node_set("punch").unwrap().nodes;
    let (mut forces, mut cg) = (Vec::new(), 0);
    for (k, &t) in p.step_times.iter().enumerate() {
        cg += st
            .advance(k + 1, t)
            .unwrap_or_else(|f| panic!("{f}"))
            .cg_iterations;
        let (fi, _) = st.forces();
        forces.push(
            punch
                .iter()
                .map(|&g| fi[local.local_node(g).unwrap()][1])
                .sum(),
        );
    }
    (forces, cg)
}

#[test]
fn the_plastic_punch_gives_the_answer_of_the_nodal_preconditioners() {
    // `auto` picks the full tangent for a plastic body: the reference names block Jacobi.
    let mut reference = common::problem(&punch(12));
    reference.solver.preconditioner = Preconditioner::Jacobi;
    let mut tangent = reference.clone();
    tangent.solver.preconditioner = Preconditioner::Tangent;
    let (f0, cg0) = punch_forces(&reference);
    let (f1, cg1) = punch_forces(&tangent);
    let mut worst = 0.0f64;
    for (a, b) in f0.iter().zip(&f1) {
        worst = worst.max((a - b).abs() / a.abs());
    }
    println!(
        "punch 12 x 12: {cg0} CG iterations (block Jacobi), {cg1} (tangent); punch forces differ by at most {worst:.2e} relative"
    );
    // Both solve every increment to |r| <= 1e-10 of the reference force (the default
    // tolerance); the increments' answers differ by that times the conditioning of the
    // history they commit: measured 1e-9 and below. 1e-7 leaves room, far below the
    // punch force's own discretisation error (several percent at this mesh).
    assert!(worst < 1e-7, "{worst:e}");
    assert!(f1.last().unwrap().abs() > 0.0);
}

#[test]
fn a_linear_body_is_solved_in_a_few_iterations() {
    let text = std::fs::read_to_string(common::repo("run/examples/bar.toml")).unwrap();
    let mut p = common::problem(&text);
    let (_, jacobi) = common::solve(&p);
    p.solver.preconditioner = Preconditioner::Tangent;
    let (summary, tangent) = common::solve(&p);
    let scale = jacobi
        .displacement
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let diff = jacobi
        .displacement
        .iter()
        .flatten()
        .zip(tangent.displacement.iter().flatten())
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    let iterations: u64 = summary.steps.iter().map(|r| r.cg_iterations).sum();
    let steps = summary.steps.len() as u64;
    println!("bar: max |u_tangent - u_jacobi| = {diff:.2e} of {scale:.3e}; {iterations} CG iterations in {steps} steps");
    // Both to the default tolerance 1e-10 of the reference force; a well-conditioned bar.
    assert!(diff <= 1e-8 * scale, "{diff:e} against {scale:e}");
    // The factor is the constrained stiffness itself: CG converges in one iteration per
    // model problem, up to round-off (measured: 1 in 4 steps, the later steps starting
    // converged). Three per step leaves room for a pivot raised to its floor; Jacobi takes
    // dozens here.
    assert!(iterations <= 3 * steps, "{iterations} in {steps} steps");
}
