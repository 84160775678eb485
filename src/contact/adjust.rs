//! Strain-free adjustment of the reference configuration (a pair's `adjust`): before the
//! run, every slave node within `adjust` of its pair's master surface, inside or outside
//! it, is moved onto the nearest point of that surface. Two surfaces meshed apart on one
//! curved shape (a pin in its hole, a shrink fit) then start touching at every slave
//! node, instead of overlapping by the facets' sagitta (h^2 / 8R: a master facet is a
//! chord that cuts into the slave body), which the first step would otherwise push out
//! as if it were an interference. The moves are computed from the whole mesh, in the
//! pairs' order and each pair's slave nodes in ascending order, so every rank makes the
//! same ones.

use super::search::MasterSurface;
use crate::math::{norm, sub};
use crate::problem::Problem;

/// What the adjustment of one pair did.
#[derive(Clone, Debug, PartialEq)]
pub struct Adjusted {
    /// Index of the pair in the problem.
    pub pair: usize,
    /// Slave nodes moved.
    pub moved: usize,
    /// The largest move.
    pub largest: f64,
}

/// Whether a pair of `problem` asks for the adjustment.
pub fn wanted(problem: &Problem) -> bool {
    problem
        .contacts
        .iter()
        .any(|c| c.adjust > 0.0 && !c.is_self())
}

/// Moves the slave nodes of every pair with `adjust` > 0 onto its master surface, where
/// they are within `adjust` of it (the search's nearest face within its tolerances), in
/// `problem`'s mesh. Returns one entry per such pair.
pub fn adjust(problem: &mut Problem) -> Vec<Adjusted> {
    let mut done = Vec::new();
    for (p, pair) in problem.contacts.iter().enumerate() {
        if pair.adjust <= 0.0 || pair.is_self() {
            continue;
        }
        let coords = &problem.mesh.coords;
        let surface = MasterSurface::new(pair, |n| coords[n as usize]);
        let moves: Vec<(u32, [f64; 3])> = pair
            .slave_nodes
            .iter()
            .filter_map(|&n| {
                let x = coords[n as usize];
                let it = surface.search(&x)?;
                let onto = surface.point(it.face, &it.s)?;
                let d = norm(&sub(&x, &onto));
                (d > 0.0 && d <= pair.adjust).then_some((n, onto))
            })
            .collect();
        let largest = moves
            .iter()
            .map(|(n, onto)| norm(&sub(&coords[*n as usize], onto)))
            .fold(0.0, f64::max);
        let moved = moves.len();
        for (n, onto) in moves {
            problem.mesh.coords[n as usize] = onto;
        }
        done.push(Adjusted {
            pair: p,
            moved,
            largest,
        });
    }
    done
}

/// One line per adjusted pair, for the log: how many slave nodes moved and how far.
pub fn describe(problem: &Problem, adjusted: &[Adjusted]) -> Vec<String> {
    adjusted
        .iter()
        .map(|a| {
            let pair = &problem.contacts[a.pair];
            format!(
                "contact '{}': {} of {} slave nodes moved onto the master surface before the run (adjust = {:e}; strain-free), the farthest by {:.3e}",
                pair.name,
                a.moved,
                pair.slave_nodes.len(),
                pair.adjust,
                a.largest
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::parse_scene;

    /// Two unit blocks, the upper one `lift` above the lower one's top (negative: sunk
    /// into it), its bottom the slave surface.
    fn stacked(lift: f64, adjust: f64) -> Problem {
        let text = format!(
            r#"
[[body]]
name = "lower"
box = {{ min = [0.0, 0.0, 0.0], max = [1.0, 1.0, 1.0] }}
divisions = [2, 2, 2]
material = {{ model = "linear_elastic", E = 1.0, nu = 0.3 }}
[[body]]
name = "upper"
box = {{ min = [0.0, 0.0, {z}], max = [1.0, 1.0, {top}] }}
divisions = [3, 3, 1]
material = {{ model = "linear_elastic", E = 1.0, nu = 0.3 }}
[[side_set]]
name = "top"
body = "lower"
plane = {{ point = [0.0, 0.0, 1.0], normal = [0.0, 0.0, 1.0] }}
[[side_set]]
name = "bottom"
body = "upper"
plane = {{ point = [0.0, 0.0, {z}], normal = [0.0, 0.0, 1.0] }}
[[node_set]]
name = "base"
body = "lower"
plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }}
[[displacement]]
node_set = "base"
components = ["x", "y", "z"]
value = 0.0
[[contact]]
master = "top"
slave = "bottom"
adjust = {adjust}
[time]
segments = [{{ end = 1.0, steps = 1 }}]
"#,
            z = 1.0 + lift,
            top = 2.0 + lift
        );
        parse_scene(&text, "stacked.toml", "stacked").unwrap()
    }

    fn slave_heights(p: &Problem) -> Vec<f64> {
        let pair = &p.contacts[0];
        pair.slave_nodes
            .iter()
            .map(|&n| p.mesh.coords[n as usize][2])
            .collect()
    }

    #[test]
    fn slave_nodes_within_the_distance_move_onto_the_master_surface() {
        for lift in [-0.01, 0.01] {
            let mut p = stacked(lift, 0.02);
            let before = p.mesh.coords.clone();
            let done = adjust(&mut p);
            assert_eq!(done.len(), 1);
            assert_eq!(
                done[0].moved, 16,
                "the 4 x 4 nodes of the upper block's bottom"
            );
            // The move is the lift, to round-off of the coordinates (1 + lift).
            assert!((done[0].largest - lift.abs()).abs() < 1e-15);
            for z in slave_heights(&p) {
                assert_eq!(z, 1.0);
            }
            // Nothing else moves: the slave nodes only, and only along the normal (to the
            // round-off of the point's interpolation on the face).
            let slaves = &p.contacts[0].slave_nodes;
            for (n, (a, b)) in before.iter().zip(&p.mesh.coords).enumerate() {
                if slaves.contains(&(n as u32)) {
                    assert!((a[0] - b[0]).abs() < 1e-15 && (a[1] - b[1]).abs() < 1e-15);
                } else {
                    assert_eq!(a, b);
                }
            }
        }
    }

    #[test]
    fn nodes_beyond_the_distance_or_without_it_stay() {
        let mut far = stacked(0.03, 0.02);
        assert_eq!(adjust(&mut far)[0].moved, 0);
        assert!(slave_heights(&far).iter().all(|&z| z == 1.03));
        let mut off = stacked(0.01, 0.0);
        assert!(adjust(&mut off).is_empty());
        assert!(slave_heights(&off).iter().all(|&z| z == 1.01));
    }
}
