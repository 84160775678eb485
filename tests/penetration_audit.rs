//! The penetration audit of the equilibrium query: a slave node driven deeper than the
//! normal search tolerance in one increment is found inside the master body and tied back
//! to its surface, never left inside with a run that reports success.
//!
//! Scene: run/scenes/sliding/deep_increment.toml (a block starting 0.2 above a rigid base
//! whose top is pushed down by 0.3 in one step; normal tolerance 0.02). Without the audit
//! the search sees no face within 0.02 of the bottom nodes, which end 0.1 inside the base
//! with "in contact 0, max penetration 0" and exit 0.
//!
//! Tolerances. Gap removal ties each bottom node to the base top exactly (a linear
//! constraint row, imposed to round-off of the coordinates, 1e-15); the capture tolerance
//! (1e-6 face sizes = 5e-7) is what the issue allows, and is asserted. The contact forces
//! on the block balance the reaction on its top to the solver's residual (about 1e-10 of
//! the reference force; summed over the 93 nodes at most 1e-9 of it): asserted at 1e-6 of
//! the contact force, well above that round-off and far below any lost node's share (1/16).

mod common;

use common::{problem, repo, solve};

#[test]
fn a_node_driven_past_the_search_tolerance_is_tied_back() {
    let path = repo("run/scenes/sliding/deep_increment.toml");
    let text = std::fs::read_to_string(&path).expect("the scene is in the repository");
    let p = problem(&text);
    let (summary, state) = solve(&p);
    let pair = &p.contacts[0];
    let capture = pair.capture_tolerance;
    assert!(
        pair.normal_tolerance < 0.1,
        "the increment must beat the search tolerance"
    );
    // Every bottom node of the block is on the base top, and in contact.
    let block = &p.mesh.bodies[1];
    let mut bottom = 0;
    for &s in &pair.slave_nodes {
        let y = p.mesh.coords[s as usize][1] + state.displacement[s as usize][1];
        assert!(
            y >= 1.0 - capture,
            "slave node {} ends at y = {y}, inside the base by {:.3e}",
            s + 1,
            1.0 - y
        );
        assert!(
            (y - 1.0).abs() <= capture,
            "slave node {} off the base: y = {y}",
            s + 1
        );
        bottom += 1;
    }
    assert_eq!(
        state.constraints.len(),
        bottom,
        "every bottom node in contact"
    );
    // Reported penetration is the audit's measure: at most the capture tolerance.
    let last = summary.steps.last().expect("one step");
    assert!(
        last.contact.max_penetration <= capture,
        "max penetration {:.3e} > capture tolerance {capture:.3e}",
        last.contact.max_penetration
    );
    // Equilibrium of the block: contact forces against the reaction on its top.
    let nodes = block.first_node..block.first_node + block.num_nodes;
    let contact: f64 = nodes.clone().map(|a| state.contact_force[a][1]).sum();
    let top: f64 = nodes.map(|a| state.reaction[a][1]).sum();
    assert!(contact > 0.0, "the base pushes the block up: {contact}");
    assert!(
        (contact + top).abs() <= 1e-6 * contact,
        "contact {contact} against top reaction {top}"
    );
}
