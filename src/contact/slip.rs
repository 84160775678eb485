//! The slip of a contact node and the friction it carries: whether prescribed motion drives
//! a sticking node along its master, the secant estimate of a node's tangential stiffness,
//! the return mapping that turns a slipping node's friction force against its slip, and the
//! tangential springs slipping nodes carry in the model problem.

use super::active::{Active, ContactState, Mode};
use super::ghost;
use crate::comm::Comm;
use crate::math::{dot, matvec, norm, scale, sub, Mat3, Vec3};
use crate::mesh::local::LocalMesh;
use crate::problem::Problem;
use crate::springs::Spring;

/// A slip shorter than this fraction of the face size is round-off: it does not turn the
/// friction direction.
pub(super) const SLIP_NOISE: f64 = 1e-10;

/// A secant over a change of the slip smaller than this fraction of the slip is not
/// taken (the solver's error would dominate it); the last estimate is kept.
const SECANT_MIN: f64 = 1e-7;

/// How far a sticking node sits from its stick point along the master surface (the master
/// point plus the node's offset beyond an edge), when more than round-off (on the rank
/// that owns the node). Its tie rows hold it there unless rows
/// that take precedence (Dirichlet rows, another pair's normal) drive it along the master:
/// then the node moves relative to the master and Coulomb's law makes it slip.
pub(super) fn driven_slip(
    surface: &super::search::MasterSurface,
    problem: &Problem,
    mesh: &LocalMesh,
    u: &[Vec3],
    a: &Active,
) -> Option<Vec3> {
    let l = mesh.owned_node(a.slave)?;
    let (now, _) = surface.face_corners(a.face)?;
    let w = surface.shape(a.face, &a.s);
    let mut d = ghost::position(mesh, u, l);
    for j in 0..4 {
        d = sub(&d, &scale(&now[j], w[j]));
    }
    // Beyond its face's edge a node is held at its offset from the edge's point.
    let d = sub(&d, &a.offset);
    let d = a.along_surface(&d);
    let noise = SLIP_NOISE * problem.contacts[a.pair].face_size;
    (norm(&d) > noise).then_some(d)
}

/// The node's tangential stiffness from two (force held, slip) states of one step: the
/// force the rest of the structure puts on the node changes with its slip by -K slip, so
/// the force held changes by K slip; the Rayleigh quotient of that change is the estimate.
/// When the slip changed by less than SECANT_MIN of itself the quotient is not taken (the
/// solver's error would dominate it), but the force held still changed by |df| over a slip
/// change of at most the cutoff: the stiffness is at least |df| / cutoff, and the estimate
/// `k` is raised to that bound. (A node whose slip prescribed motion sets has an unbounded
/// stiffness; an estimate frozen below it turns the friction force a little per update
/// only.) Otherwise `k` is kept when there is no previous state or the quotient is not
/// positive.
pub(super) fn secant_stiffness(
    previous: Option<(Vec3, Vec3)>,
    held: Vec3,
    slip: Vec3,
    noise: f64,
    k: f64,
) -> f64 {
    let Some((f0, d0)) = previous else {
        return k;
    };
    let dd = sub(&slip, &d0);
    let df = sub(&held, &f0);
    let length2 = dot(&dd, &dd);
    let cutoff = noise + SECANT_MIN * norm(&slip);
    if length2.sqrt() <= cutoff {
        let bound = norm(&df) / cutoff;
        return if bound.is_finite() { k.max(bound) } else { k };
    }
    let q = dot(&df, &dd) / length2;
    if q > 0.0 && q.is_finite() {
        q
    } else {
        k
    }
}

/// Coulomb's friction direction (unit, on the slave) for a slipping node that held the
/// force `held` (along `dir`) and slipped by `slip` this step. The friction force must
/// oppose the slip; setting it against the measured slip directly overshoots near the onset
/// of slip (there the slip's direction turns strongly with the friction force's). Instead
/// the force that would hold the node where the step began is estimated,
/// g = held - k slip with the secant stiffness k, and the friction force is set along it:
/// the return mapping of an elastic stick, exact in one update when the node's stiffness
/// is isotropic, and a contraction for an estimate within a factor of two. Without an
/// estimate, for a slip of round-off size, or when the friction force would turn by less
/// than `force_tol` (the force the model problem resolves), the direction is kept.
pub(super) fn friction_direction(
    dir: Vec3,
    held: Vec3,
    slip: Vec3,
    k: f64,
    noise: f64,
    force_tol: f64,
) -> Vec3 {
    if k <= 0.0 || norm(&slip) <= noise {
        return dir;
    }
    let g = sub(&held, &scale(&slip, k));
    let length = norm(&g);
    if !(length > 0.0 && length.is_finite()) {
        return dir;
    }
    let turned = scale(&g, 1.0 / length);
    if norm(&sub(&turned, &dir)) * norm(&held) <= force_tol {
        dir
    } else {
        turned
    }
}

/// Coulomb's tangent across the friction direction of a slipping node whose last update
/// measured a step's slip s beyond its stick range (k |s| > capacity, k its secant
/// stiffness): the friction force -capacity s / |s| turns with the slip across its
/// direction at the rate capacity / |s|. Returns that stiffness and the projector across
/// the direction in the tangent plane; None for a node without a measured slip or still
/// near the onset of slip (there the tangent is unbounded, and the return mapping turns
/// the force instead).
pub(super) fn coulomb_tangent(a: &Active) -> Option<(f64, Mat3)> {
    let Mode::Slip { dir, magnitude } = a.mode else {
        return None;
    };
    // A node at a fold slides along its edge only: there is no direction across.
    if a.fold.is_some() {
        return None;
    }
    let (_, slip) = a.secant?;
    let length = norm(&slip);
    if !(a.slip_stiffness * length > magnitude) {
        return None;
    }
    let c = magnitude / length;
    if !(c > 0.0 && c.is_finite()) {
        return None;
    }
    Some((c, across_direction(&dir, &a.normal)?))
}

/// The projector onto the tangent plane's direction across the friction direction `dir`
/// (the plane normal to `n`); None when `dir` lies mostly along the normal.
fn across_direction(dir: &Vec3, n: &Vec3) -> Option<Mat3> {
    let d = sub(dir, &scale(n, dot(dir, n)));
    let l = norm(&d);
    if !(l > 0.5) {
        return None;
    }
    let d = scale(&d, 1.0 / l);
    Some(std::array::from_fn(|i| {
        std::array::from_fn(|j| crate::math::IDENTITY[i][j] - n[i] * n[j] - d[i] * d[j])
    }))
}

/// A node's own stiffness along the directions `p` projects on: the trace of p K p for its
/// diagonal block K.
fn stiffness_along(p: &Mat3, nodal: &Mat3) -> f64 {
    (0..3)
        .map(|i| dot(&p[i], &matvec(nodal, &p[i])))
        .sum::<f64>()
}

/// The onset spring's stiffness is at most this multiple of the node's own stiffness
/// across its direction (its diagonal block): a direction then settles by about
/// 1 / (1 + ONSET_CAP) per update near the onset, and CG sees a spring no stiffer than
/// ten neighbours.
pub(super) const ONSET_CAP: f64 = 10.0;

/// The spring a slipping node within its stick range (no Coulomb tangent) carries across
/// its friction direction in the model problem: Coulomb's law near the onset of slip, in
/// the form the return mapping states it. The force is set along held - c s_perp, the part
/// of the step's slip s across the direction taken back by a spring c; the model problem
/// carries that spring (anchored where s_perp is zero), so it sees how the slipping nodes
/// turn one another's forces, and the update takes the return mapping with the same c.
/// For one node of stiffness K whose converged slip is s*, the direction's error shrinks by
/// K (c |s*| - capacity) / ((K + c) capacity) per update: c = capacity / |s| (the slip
/// last measured, the exact value once it is s*), at most ONSET_CAP times `nodal`, the
/// node's own stiffness across the direction. Returns c, the projector across the
/// direction in the tangent plane and the slip across it, s_perp; None without a measured
/// slip or a stiffness.
pub(super) fn onset_spring(a: &Active, nodal: &Mat3) -> Option<(f64, Mat3, Vec3)> {
    let Mode::Slip { dir, magnitude } = a.mode else {
        return None;
    };
    let (_, slip) = a.secant?;
    if !(magnitude > 0.0) || a.fold.is_some() {
        return None;
    }
    let p = across_direction(&dir, &a.normal)?;
    let k = stiffness_along(&p, nodal);
    if !(k > 0.0 && k.is_finite()) {
        return None;
    }
    let cap = ONSET_CAP * k;
    let length = norm(&slip);
    let c = if length * cap > magnitude {
        magnitude / length
    } else {
        cap
    };
    c.is_finite().then(|| (c, p, matvec(&p, &slip)))
}

/// For each pair, whether every master node is prescribed in all three directions (a
/// rigid tool): the master point then does not move within a model problem, and a spring
/// on the slave node alone measures the slip.
pub(super) fn held_masters(problem: &Problem) -> Vec<bool> {
    let mut dirs: std::collections::HashMap<u32, Vec<Vec3>> = std::collections::HashMap::new();
    for bc in &problem.dirichlet {
        for &n in &problem.node_sets[bc.node_set].nodes {
            dirs.entry(n).or_default().push(bc.direction);
        }
    }
    let full = |n: &u32| {
        let Some(d) = dirs.get(n) else { return false };
        // Rank 3: some three of the prescribed directions span space.
        d.iter().any(|a| {
            d.iter().any(|b| {
                let c = crate::math::cross(a, b);
                norm(&c) > 1e-9 && d.iter().any(|e| dot(&c, e).abs() > 1e-9)
            })
        })
    };
    problem
        .contacts
        .iter()
        .map(|p| p.face_nodes.iter().flatten().all(full))
        .collect()
}

/// Newton's turns of a node's friction direction must shrink by at least this factor per
/// update (they shrink quadratically once close: 1e-2, 2.5e-4, 5e-9 on the drag).
pub(super) const NEWTON_CONTRACTION: f64 = 0.9;

/// Whether Newton's `turn` of a node's direction failed to shrink against the node's `last`
/// turn in the same constraint set (a last turn of zero, a direction kept, says nothing).
pub(super) fn newton_stalls(turn: f64, last: f64) -> bool {
    last > 0.0 && turn >= NEWTON_CONTRACTION * last
}

impl ContactState {
    /// Springs at the slipping nodes this rank owns: with `newton`, Coulomb's tangent
    /// (`coulomb_tangent`) where a node has one, unstretched at `u`; at the others, the
    /// onset spring (`onset_spring`, with the structure's nodal stiffness blocks `diag`),
    /// anchored where the node's slip across its direction is zero, once the last update
    /// left the set unchanged (while nodes still start and stop slipping, the directions
    /// turn by up to a radian per update, far beyond the spring's linearisation: the
    /// bolted clamp's first step then never settled). The onset springs' stiffnesses are
    /// kept for the update's return mapping.
    pub fn tangent_springs(
        &mut self,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
        newton: bool,
        diag: &[Mat3],
    ) -> Vec<Spring> {
        let mut out = Vec::new();
        self.onset_springs.clear();
        let held = self
            .held_masters
            .get_or_insert_with(|| held_masters(problem));
        for a in &self.active {
            let Some(l) = mesh.owned_node(a.slave) else {
                continue;
            };
            let key = (a.slave, a.pair);
            let tangent = (newton && !self.newton_off.contains(&key))
                .then(|| coulomb_tangent(a))
                .flatten();
            let (c, p, anchor) = match tangent {
                Some((c, p)) => (c, p, u[l]),
                None if !self.steady || self.newton_off.contains(&key) || !held[a.pair] => continue,
                None => match onset_spring(a, &diag[l]) {
                    Some((c, p, across)) => {
                        self.onset_springs.insert(key, c);
                        (c, p, sub(&u[l], &across))
                    }
                    None => continue,
                },
            };
            out.push(Spring {
                node: l,
                k: std::array::from_fn(|i| std::array::from_fn(|j| c * p[i][j])),
                anchor,
            });
        }
        out
    }

    /// The active slave node (node-to-face) that has slid farthest relative to its master
    /// point since the reference configuration, in face sizes of its pair: (global node id
    /// + 1, face sizes), the lowest node among equals; None without such a node. Collective.
    pub fn largest_slide<C: Comm + ?Sized>(
        &self,
        comm: &C,
        problem: &Problem,
        mesh: &LocalMesh,
        u: &[Vec3],
    ) -> Option<(u64, f64)> {
        let reference = vec![[0.0; 3]; u.len()];
        let surfaces = ghost::surfaces(comm, problem, mesh, u, &reference);
        let mut best = (-1.0f64, i64::MAX);
        for a in &self.active {
            let Some(l) = mesh.owned_node(a.slave) else {
                continue;
            };
            let Some((now, then)) = surfaces[a.pair].face_corners(a.face) else {
                continue;
            };
            let w = surfaces[a.pair].shape(a.face, &a.s);
            let mut d = u[l];
            for j in 0..4 {
                d = sub(&d, &scale(&sub(&now[j], &then[j]), w[j]));
            }
            let slid = norm(&d) / problem.contacts[a.pair].face_size;
            let node = a.slave as i64 + 1;
            if slid > best.0 || (slid == best.0 && node < best.1) {
                best = (slid, node);
            }
        }
        let mut top = [best.0];
        comm.max_f64(&mut top);
        let mut node = [if best.0 == top[0] { best.1 } else { i64::MAX }];
        comm.min_i64(&mut node);
        (top[0] >= 0.0 && node[0] != i64::MAX).then(|| (node[0] as u64, top[0]))
    }

    /// Springs across the friction direction of the slipping nodes this rank owns,
    /// unstretched at `u`; `diag` holds the structure's nodal diagonal stiffness blocks.
    pub fn slip_springs(&self, mesh: &LocalMesh, u: &[Vec3], diag: &[Mat3]) -> Vec<Spring> {
        let mut out = Vec::new();
        for a in &self.active {
            let Mode::Slip { dir, .. } = a.mode else {
                continue;
            };
            if a.fold.is_some() {
                continue;
            }
            let Some(l) = mesh.owned_node(a.slave) else {
                continue;
            };
            let Some(p) = across_direction(&dir, &a.normal) else {
                continue;
            };
            let nodal = stiffness_along(&p, &diag[l]).max(0.0);
            // The node's own stiffness across the direction. (The consistent tangent,
            // capacity / |slip|, is unbounded at the start of a step and made the contact
            // loop wander in the measurements; see docs/contact.md.)
            let k = nodal;
            if k > 0.0 && k.is_finite() {
                out.push(Spring {
                    node: l,
                    k: std::array::from_fn(|i| std::array::from_fn(|j| k * p[i][j])),
                    anchor: u[l],
                });
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn secant_is_the_rayleigh_quotient_of_a_linear_spring() {
        // held = 3 slip exactly: the quotient is 3 up to round-off of the subtraction.
        let k = secant_stiffness(
            Some(([0.3, 0.0, 0.0], [0.1, 0.0, 0.0])),
            [0.9, 0.3, 0.0],
            [0.3, 0.1, 0.0],
            1e-12,
            1.0,
        );
        assert!((k - 3.0).abs() < 1e-12, "{k}");
    }

    #[test]
    fn a_slip_that_does_not_move_bounds_the_stiffness_from_below() {
        // The slip unchanged (prescribed motion), the force held turned by 0.1: the estimate
        // is raised to |df| / cutoff = 0.1 / (1e-12 + 1e-7 * 0.5) exactly as computed here.
        let slip = [0.5, 0.0, 0.0];
        let cutoff = 1e-12 + SECANT_MIN * 0.5;
        let k = secant_stiffness(
            Some(([-1.0, 0.0, 0.0], slip)),
            [-1.0, 0.1, 0.0],
            slip,
            1e-12,
            2.0,
        );
        assert_eq!(k, 0.1 / cutoff);
        // The force held unchanged as well: nothing is learned, the estimate is kept.
        let k = secant_stiffness(
            Some(([-1.0, 0.0, 0.0], slip)),
            [-1.0, 0.0, 0.0],
            slip,
            1e-12,
            2.0,
        );
        assert_eq!(k, 2.0);
        // No earlier state in the step: kept.
        assert_eq!(
            secant_stiffness(None, [1.0, 0.0, 0.0], slip, 1e-12, 2.0),
            2.0
        );
    }

    fn slipping(slip: Vec3, k: f64) -> Active {
        Active {
            pair: 0,
            slave: 0,
            face: 0,
            s: [0.0, 0.0],
            normal: [0.0, 1.0, 0.0],
            offset: [0.0; 3],
            mode: Mode::Slip {
                dir: [-1.0, 0.0, 0.0],
                magnitude: 3.0,
            },
            normal_force: 10.0,
            tangential_force: [0.0; 3],
            slip_stiffness: k,
            secant: Some(([-3.0, 0.0, 0.0], slip)),
            start: None,
            reversals: 0,
            fold: None,
            left: None,
        }
    }

    #[test]
    fn coulomb_tangent_is_the_derivative_of_the_friction_force_across_its_direction() {
        // A node slipping 0.01 along x with a capacity of 3 (k |s| = 30 > 3): the force
        // F(s) = -3 s / |s| turns by -300 e across the direction for a slip e along z
        // (the tangent plane's other direction), and does not change along the normal.
        let slip = [0.01, 0.0, 0.0];
        let (c, p) = coulomb_tangent(&slipping(slip, 3000.0)).expect("beyond the stick range");
        assert_eq!(c, 300.0);
        let force = |s: Vec3| scale(&s, -3.0 / norm(&s));
        let e = 1e-7;
        let moved = force([0.01, 0.0, e]);
        let fd = (moved[2] - force(slip)[2]) / e;
        // Finite difference of first order: its error is of order e / |s| = 1e-5 relative.
        assert!((fd + c).abs() <= 1e-4 * c, "{fd} against -{c}");
        assert_eq!(matvec(&p, &[0.0, 0.0, 1.0]), [0.0, 0.0, 1.0]);
        assert_eq!(matvec(&p, &[1.0, 0.0, 0.0]), [0.0, 0.0, 0.0]);
        assert_eq!(matvec(&p, &[0.0, 1.0, 0.0]), [0.0, 0.0, 0.0]);
    }

    #[test]
    fn newton_stalls_when_its_turn_does_not_shrink() {
        // The drag's converging turns shrink quadratically: never a stall.
        assert!(!newton_stalls(2.5e-4, 1e-2));
        assert!(!newton_stalls(5e-9, 2.5e-4));
        // A cycling direction turns alike each update, a diverging one more: stalls.
        assert!(newton_stalls(1e-3, 1e-3));
        assert!(newton_stalls(2e-3, 1e-3));
        assert!(newton_stalls(0.95e-3, 1e-3));
        // After a kept direction (turn 0) there is nothing to compare with.
        assert!(!newton_stalls(1e-5, 0.0));
    }

    #[test]
    fn onset_spring_is_capacity_over_slip_capped_at_ten_times_the_node() {
        // Capacity 3, the node's own stiffness across its direction (z) 100: a slip of
        // 0.01 gives capacity / |s| = 300 (below 10 x 100), a slip of 1e-4 would give
        // 30000, capped at 1000. The spring acts across the direction in the tangent
        // plane (z here: the normal is y, the direction x), and the slip across it is
        // the slip's z part.
        let nodal: Mat3 = [[50.0, 0.0, 0.0], [0.0, 70.0, 0.0], [0.0, 0.0, 100.0]];
        let (c, p, across) =
            onset_spring(&slipping([-0.01, 0.0, 0.0], 1.0), &nodal).expect("a spring");
        assert_eq!(c, 300.0);
        assert_eq!(across, [0.0, 0.0, 0.0]);
        assert_eq!(matvec(&p, &[1.0, 2.0, 3.0]), [0.0, 0.0, 3.0]);
        let (c, _, across) =
            onset_spring(&slipping([-1e-4, 0.0, 2e-5], 1.0), &nodal).expect("a spring");
        assert_eq!(c, ONSET_CAP * 100.0);
        assert_eq!(across, [0.0, 0.0, 2e-5]);
        // No measured slip, or no stiffness across the direction: no spring.
        let mut a = slipping([-0.01, 0.0, 0.0], 1.0);
        a.secant = None;
        assert!(onset_spring(&a, &nodal).is_none());
        assert!(onset_spring(&slipping([-0.01, 0.0, 0.0], 1.0), &[[0.0; 3]; 3]).is_none());
    }

    #[test]
    fn no_coulomb_tangent_near_the_onset_or_without_a_slip() {
        // k |s| = 1 < 3: still within the stick range, where the tangent 3 / |s| would
        // exceed the node's own stiffness.
        assert!(coulomb_tangent(&slipping([0.01, 0.0, 0.0], 100.0)).is_none());
        let mut a = slipping([0.01, 0.0, 0.0], 3000.0);
        a.secant = None;
        assert!(coulomb_tangent(&a).is_none());
        a = slipping([0.01, 0.0, 0.0], 3000.0);
        a.mode = Mode::Stick;
        assert!(coulomb_tangent(&a).is_none());
    }
}
