//! Near a limit load: when an increment of a plastic body fails for good, where the body
//! flowed in the failed attempt, so the message says a mechanism formed and where.

use super::Stepper;
use crate::comm::{self, Comm};
use crate::contact::Enforcement;
use crate::math::Vec3;
use crate::solver::cg::SolveFailure;

/// Elements whose plastic strain grew by at least this fraction of the largest growth are
/// the flowing region the message bounds. A tenth: in a failed attempt the growth peaks
/// where the iterate went furthest, which depends on the solver's path (the punch of
/// tests/limit_load.rs: half the peak took 2 elements under the punch with the full
/// tangent, 3 with block Jacobi); a tenth takes the mechanism (7 elements reaching past
/// the punch's edge with either).
const FLOWING: f64 = 0.1;

impl<C: Comm + ?Sized, E: Enforcement> Stepper<'_, C, E> {
    /// The line for a failed increment of a plastic body that stalled or lost its stiffness
    /// (what a load beyond the limit load does): the last converged time, the growth of the
    /// equivalent plastic strain in the failed attempt at `u` (its largest, the element and
    /// body, and the box of the elements that grew by more than FLOWING of that). None for other
    /// causes, elastic scenes, or an attempt where nothing flowed. Collective.
    pub(super) fn limit_load_note(&self, cause: &SolveFailure, u: &[Vec3]) -> Option<String> {
        let stalled = match cause {
            SolveFailure::NotConverged {
                residual,
                reference,
                ..
            } => *residual >= 1e-8 * reference,
            SolveFailure::NonPositiveCurvature { .. } | SolveFailure::Unbounded { .. } => true,
            _ => false,
        };
        if !stalled {
            return None;
        }
        let growth = self.asm.owned_eqps_growth(u);
        // Every rank decides alike: no rank may be missing its growth.
        let missing = comm::max_f64(self.comm, if growth.is_none() { 1.0 } else { 0.0 });
        let growth = growth.filter(|_| missing == 0.0)?;
        let local_max = growth.iter().map(|&(_, g)| g).fold(0.0, f64::max);
        let max = comm::max_f64(self.comm, local_max);
        if !(max > 0.0) {
            return None;
        }
        let mesh = self.mesh;
        // The element of the largest growth: the lowest global id among those that have it.
        let at_max = growth
            .iter()
            .filter(|&&(_, g)| g == max)
            .map(|&(e, _)| mesh.element_global[e] as f64)
            .fold(f64::INFINITY, f64::min);
        let element = -comm::max_f64(self.comm, -at_max);
        let body = growth
            .iter()
            .find(|&&(e, g)| g == max && mesh.element_global[e] as f64 == element)
            .map_or(-1.0, |&(e, _)| mesh.element_body[e] as f64);
        let body = comm::max_f64(self.comm, body) as usize;
        let (mut lo, mut hi, mut count) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3], 0i64);
        for &(e, g) in &growth {
            if g < FLOWING * max {
                continue;
            }
            count += 1;
            for &a in mesh.elements.element(e) {
                let x = mesh.coords[a as usize];
                for i in 0..3 {
                    lo[i] = lo[i].min(x[i]);
                    hi[i] = hi[i].max(x[i]);
                }
            }
        }
        let mut counts = [count];
        self.comm.sum_i64(&mut counts);
        for i in 0..3 {
            lo[i] = -comm::max_f64(self.comm, -lo[i]);
            hi[i] = comm::max_f64(self.comm, hi[i]);
        }
        let name = &self.problem.mesh.bodies[body].name;
        Some(format!(
            "a limit load of the plastic body '{name}'?: the last converged state is t = {:.6}, and in the failed attempt its equivalent plastic strain grew by up to {max:.3e} (element {}), by more than a tenth of that in {} elements within x {:.4} .. {:.4}, y {:.4} .. {:.4}, z {:.4} .. {:.4} (a mechanism forming there loses the stiffness that carries more load)",
            self.time,
            element as u64 + 1,
            counts[0],
            lo[0],
            hi[0],
            lo[1],
            hi[1],
            lo[2],
            hi[2]
        ))
    }
}
