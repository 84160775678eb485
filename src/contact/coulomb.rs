//! Coulomb's law for one contact constraint after a model problem: the onset of slip of
//! a sticking node, slip driven by prescribed motion, the reversal of slip, and the
//! friction force's direction (a return mapping with the node's secant stiffness).

use super::active::{Active, Mode};
use super::search::MasterSurface;
use super::slip::{coulomb_tangent, friction_direction, secant_stiffness, SLIP_NOISE};
use crate::math::{dot, norm, scale, sub, Vec3};
use crate::mesh::local::LocalMesh;
use crate::problem::Problem;

/// Whether a sticking node's tangential force exceeds its capacity mu |f_n| (beyond
/// round-off and the force tolerance): it starts to slip.
pub(super) fn exceeds(a: &Active, mu: f64, force_tol: f64) -> bool {
    let capacity = mu * a.normal_force.max(0.0);
    let ft = norm(&a.tangential_force);
    ft > capacity * (1.0 + 1e-9) && ft > force_tol
}

/// Whether a node leaves the constraint set as tensile: its normal force pulls (beyond
/// `force_tol`), unless it sticks and carries a tangential force beyond its capacity. Such
/// a node's normal force is that of a node held tangentially too, and the stick may be
/// what pulls it off (a die dragging the slab's surface along stretches it behind the
/// die's edge); it slips first, at the capacity of its normal force, zero (the onset of
/// `judge_stick`), and leaves the set if its normal force still pulls once it slides.
/// Released at once, such a node springs back into the master body it was pressed by,
/// further than the search's normal tolerance when the bodies were pressed deeper than
/// that (the block die of `run/scenes/sliding/`).
pub(super) fn tensile(a: &Active, mu: f64, force_tol: f64) -> bool {
    let slips_first = a.mode == Mode::Stick && exceeds(a, mu, force_tol);
    a.normal_force < -force_tol && !slips_first
}

/// The slip since the start of the step, relative to the master point. The face is held
/// unless the node has moved beyond the ghosting margin of its face (a body running
/// away); then the search releases it, and the slip test has nothing to measure against.
pub(super) fn step_slip(
    a: &Active,
    mesh: &LocalMesh,
    u: &[Vec3],
    start: &[Vec3],
    surface: &MasterSurface,
) -> Option<Vec3> {
    let l = mesh.owned_node(a.slave)?;
    let (now, then) = surface.face_corners(a.face)?;
    let w = surface.shape(a.face, &a.s);
    let mut d = sub(&u[l], &start[l]);
    for j in 0..4 {
        d = sub(&d, &scale(&sub(&now[j], &then[j]), w[j]));
    }
    Some(a.along_surface(&d))
}

/// A sticking node: the onset of slip, or slip `driven` by prescribed motion (see
/// `driven_slip`). Returns whether it starts to slip.
pub(super) fn judge_stick(
    a: &mut Active,
    problem: &Problem,
    measured: Option<Vec3>,
    driven: Option<Vec3>,
    force_tol: f64,
) -> bool {
    let capacity = problem.contacts[a.pair].mu * a.normal_force.max(0.0);
    let ft = norm(&a.tangential_force);
    if exceeds(a, problem.contacts[a.pair].mu, force_tol) {
        // The onset: the friction force takes the direction of the force the stick
        // constraint carried (the slip it releases goes that way).
        a.secant = measured.map(|d| (a.tangential_force, d));
        a.mode = Mode::Slip {
            dir: scale(&a.tangential_force, 1.0 / ft),
            magnitude: capacity,
        };
        return true;
    }
    if let Some(d) = driven {
        // Prescribed motion (or another tie) moved the node along the master from its
        // stick point: it slips, the friction force against the slip, whatever force the
        // stick carried (the driving rows took it).
        a.secant = measured.map(|m| (scale(&d, -capacity / norm(&d)), m));
        a.mode = Mode::Slip {
            dir: scale(&d, -1.0 / norm(&d)),
            magnitude: capacity,
        };
        return true;
    }
    false
}

/// Whether Newton's update of the friction direction applies to a slipping node whose
/// model problem carried Coulomb's tangent: its slip `slip` is more than round-off
/// (`noise`) and it has a tangent (beyond its stick range, see `coulomb_tangent`).
pub(super) fn newton_applies(a: &Active, slip: &Vec3, noise: f64) -> bool {
    norm(slip) > noise && coulomb_tangent(a).is_some()
}

/// A slipping node with the step's slip `slip`: the reversal of slip (it sticks again),
/// or the friction force's new direction (a return mapping with the node's secant
/// stiffness) at the capacity of the last model problem. Returns whether it sticks again.
///
/// `newton`: the model problem carried Coulomb's tangent at this node and the slip is
/// measurable (`newton_applies`); its friction force is then set against its slip, the
/// Newton update of -capacity s / |s| (the drag of the extreme suite: the friction
/// directions of a step settle in 2 or 3 updates instead of 6 to 9).
pub(super) fn judge_slip(
    a: &mut Active,
    pair: &crate::problem::ContactPair,
    (dir, magnitude): (Vec3, f64),
    slip: Vec3,
    (judge_reversal, newton, spring): (bool, bool, Option<f64>),
    force_tol: f64,
) -> bool {
    let capacity = pair.mu * a.normal_force.max(0.0);
    // A node that moved along its friction force has reversed: it does not slip in this
    // step (the step's slip is one vector, against the friction force, or zero), so it
    // sticks where the step found it. (Sticking where the last model problem left it would
    // keep a slide made under a friction force still being settled, e.g. the last step's.)
    if (a.reversals == 0 || judge_reversal) && dot(&slip, &dir) > 1e-12 * pair.face_size {
        a.reversals += 1;
        a.mode = Mode::Stick;
        a.secant = None;
        if let Some((face, s, offset)) = a.start {
            a.face = face;
            a.s = s;
            a.offset = offset;
        }
        return true;
    }
    let held = scale(&dir, magnitude);
    let noise = SLIP_NOISE * pair.face_size;
    // The slip across the direction, which an onset spring c pulled back: the node held
    // held - c across in all (the secant's force).
    let across = sub(&slip, &scale(&dir, dot(&slip, &dir)));
    let carried = match spring {
        Some(c) => sub(&held, &scale(&across, c)),
        None => held,
    };
    a.slip_stiffness = secant_stiffness(a.secant, carried, slip, noise, a.slip_stiffness);
    a.secant = Some((carried, slip));
    // Friction acts along the master surface. The direction is turned from the force
    // held (along the last direction) less the slip's pull; a direction that has picked up
    // a part along the normal (the normal moves by round-off from update to update) keeps
    // it in the force held, and wherever the return mapping shortens the tangential part
    // that part grows relative to it, update after update, until the friction force points
    // along the normal (a mortar sphere pressed on a block: from 1.6e-16 to 0.99 of the
    // direction in 75 updates, its force taken by the normal row, the step never settling).
    // So the force held and the slip across are taken along the surface here.
    let held_along = a.along_surface(&held);
    let across_along = a.along_surface(&across);
    let dir = if newton {
        let against = scale(&slip, -1.0 / norm(&slip));
        if norm(&sub(&against, &dir)) * norm(&held) <= force_tol {
            dir
        } else {
            against
        }
    } else {
        match spring {
            // The model problem carried the onset spring c across the direction: the
            // force is turned by the spring's pull on the slip across it (the slip along
            // the direction does not turn it).
            // (Judged by force alone: the spring c may be stiff enough that a slip below
            // the slip noise still pulls more than the force tolerance, and the settled
            // state must leave no spring stretched beyond it.)
            Some(c) => friction_direction(dir, held_along, across_along, c, 0.0, force_tol),
            None => friction_direction(dir, held_along, slip, a.slip_stiffness, noise, force_tol),
        }
    };
    a.mode = Mode::Slip {
        dir,
        magnitude: capacity,
    };
    false
}

#[cfg(test)]
mod tests {
    use super::super::active::new_active;
    use super::super::search::Interaction;
    use super::*;

    fn node(normal_force: f64, tangential: f64, mode: Mode) -> Active {
        let it = Interaction {
            face: 0,
            s: [0.0; 2],
            normal: [0.0, 1.0, 0.0],
            gap: 0.0,
            offset: [0.0; 3],
        };
        let mut a = new_active(0, 7, &it, 0.3);
        a.normal_force = normal_force;
        a.tangential_force = [tangential, 0.0, 0.0];
        a.mode = mode;
        a
    }

    #[test]
    fn the_friction_direction_stays_along_the_surface_when_the_return_mapping_shortens_it() {
        let mesh = crate::mesh::GlobalMesh::default();
        let pair = crate::problem::ContactPair::new(
            "p".into(),
            &mesh,
            vec![],
            vec![],
            0.3,
            0.1,
            0.1,
            1e-6,
            None,
            1.0,
        );
        // A slipping node (normal +y) whose direction picked up a part 1e-3 along the
        // normal; its step's slip, along the surface, has a part along the direction, so
        // the return mapping g = held - k slip has a tangential part of 1.118 against the
        // force held of 3. Before, the normal part of g was kept: 3e-3 / 1.118, grown by
        // 2.7 times in one update (and so on, update after update). Now the direction lies
        // in the tangent plane, to round-off, and points along g's tangential part.
        let e = 1e-3;
        let l = (1.0f64 + e * e).sqrt();
        let dir = [1.0 / l, e / l, 0.0];
        let mut a = node(
            10.0,
            0.0,
            Mode::Slip {
                dir,
                magnitude: 3.0,
            },
        );
        a.reversals = 1;
        a.slip_stiffness = 1.0;
        let slip = [2.0, 0.0, 0.5];
        judge_slip(&mut a, &pair, (dir, 3.0), slip, (false, false, None), 1e-9);
        let Mode::Slip {
            dir: now,
            magnitude,
        } = a.mode
        else {
            panic!("still slipping: {:?}", a.mode)
        };
        assert!(now[1].abs() <= 1e-15, "normal part {}", now[1]);
        // g's tangential part: 3 / l - 2 along x, -0.5 along z.
        let g = [3.0 / l - 2.0, -0.5];
        let gl = (g[0] * g[0] + g[1] * g[1]).sqrt();
        assert!((now[0] - g[0] / gl).abs() <= 1e-14 && (now[2] - g[1] / gl).abs() <= 1e-14);
        // The capacity is mu times the normal force.
        assert!((magnitude - 3.0).abs() <= 1e-14);
    }

    #[test]
    fn a_tensile_node_that_sticks_with_a_tangential_force_slips_before_it_is_released() {
        let tol = 1e-6;
        let slip = Mode::Slip {
            dir: [1.0, 0.0, 0.0],
            magnitude: 0.0,
        };
        // Sticking, pulled off, carrying a tangential force: slips first.
        assert!(!tensile(&node(-1.0, 0.5, Mode::Stick), 0.3, tol));
        // Sticking, pulled off, no tangential force beyond the tolerance: released.
        assert!(tensile(&node(-1.0, 0.5 * tol, Mode::Stick), 0.3, tol));
        // Slipping or frictionless and pulled off: released.
        assert!(tensile(&node(-1.0, 0.5, slip), 0.3, tol));
        assert!(tensile(&node(-1.0, 0.0, Mode::Free), 0.0, tol));
        // Pulled within the tolerance, or pressed: kept.
        assert!(!tensile(&node(-0.5 * tol, 0.0, slip), 0.3, tol));
        assert!(!tensile(&node(1.0, 0.1, Mode::Stick), 0.3, tol));
    }
}
