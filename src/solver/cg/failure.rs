//! Why a model problem could not be solved, and the message that says so.
/// How often a model problem may double the multilevel fine smoother's bound (a factor of
/// 16 in all) before the cycle counts as broken.
pub(super) const MAX_WIDEN: usize = 4;

/// Why a model problem could not be solved. Rank-agreed.
#[derive(Clone, Debug, PartialEq)]
pub enum SolveFailure {
    Element(String),
    NotConverged {
        iterations: usize,
        residual: f64,
        reference: f64,
    },
    NonPositiveCurvature {
        iterations: usize,
    },
    NonFinite {
        iterations: usize,
    },
    /// The multilevel preconditioner gave r.z <= 0 for a residual above the tolerance.
    IndefinitePreconditioner {
        iterations: usize,
    },
    Unbounded {
        iterations: usize,
        max_displacement: f64,
    },
    ContactNotSettled {
        updates: usize,
        detail: String,
    },
    /// A body its supports leave free along a rigid-body motion its loads push along
    /// (`Cg::check_equilibrium`): the body, the motions and the residual left there.
    NoEquilibrium(String),
    /// An allocation was refused (on some rank); not retried with a shorter step.
    OutOfMemory(String),
    /// A slave node stayed inside a master body after gap removal (the penetration audit
    /// of the equilibrium query).
    Penetration {
        /// Global node id, 1-based.
        node: u64,
        pair: String,
        depth: f64,
        tolerance: f64,
        /// Under small kinematics: the message then says that small sliding was exceeded.
        small_kinematics: bool,
        /// A boundary face of the master body outside the master surface that is nearer to
        /// the node than the master surface: element (1-based), local face, distance.
        entry: Option<Box<(u64, u8, f64)>>,
        /// Whether the pair's slave nodes were moved onto the master surface before the
        /// run (`adjust`): if not, the message names it.
        adjusted: bool,
    },
}

impl std::fmt::Display for SolveFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SolveFailure::Element(m) | SolveFailure::OutOfMemory(m) => write!(f, "{m}"),
            SolveFailure::NotConverged { iterations, residual, reference } => {
                write!(
                    f,
                    "CG did not converge in {iterations} iterations (residual {residual:.3e}, reference force {reference:.3e})"
                )?;
                if *residual < 1e-8 * reference {
                    // The residual came down by eight orders and stalled: a round-off floor
                    // (stiff bodies carry internal forces far above the load), not a
                    // missing support.
                    write!(f, "; it stalled far below the load: the tolerance may be below what round-off allows (a large stiffness contrast), try a larger solver.tolerance")?;
                }
                Ok(())
            }
            SolveFailure::NonPositiveCurvature { iterations } => {
                write!(f, "non-positive curvature along the search direction after {iterations} CG iterations (unstable or unconstrained structure)")
            }
            SolveFailure::NoEquilibrium(m) => write!(f, "the model problem has no equilibrium: {m}"),
            SolveFailure::NonFinite { iterations } => write!(f, "non-finite residual after {iterations} CG iterations"),
            SolveFailure::IndefinitePreconditioner { iterations } => write!(
                f,
                "the multilevel preconditioner is not positive definite on this model problem (r.z <= 0 after {iterations} CG iterations, its smoother's bound widened {}x); try solver.preconditioner = \"jacobi\"",
                1 << MAX_WIDEN
            ),
            SolveFailure::Unbounded { max_displacement, .. } => write!(
                f,
                "the displacement grew without bound (max |u| = {max_displacement:.3e}): a body is not held (a rigid-body motion, or friction that cannot carry the load)"
            ),
            SolveFailure::ContactNotSettled { updates, detail } => {
                write!(f, "contact did not settle after {updates} contact updates: {detail}")
            }
            SolveFailure::Penetration { node, pair, depth, tolerance, small_kinematics, entry, adjusted } => {
                write!(
                    f,
                    "slave node {node} of contact '{pair}' is inside the master body by {depth:.3e} (capture tolerance {tolerance:.3e}) and gap removal did not bring it out"
                )?;
                match entry.as_deref() {
                    Some((element, face, distance)) if *distance <= *tolerance => write!(f, "; it lies on a face of the master body that is not in the master surface, faces = [[{element}, {face}]] (the bodies' faces are coplanar there, as on a symmetry or plane-strain plane)")?,
                    Some((element, face, distance)) => write!(f, "; it is nearer ({distance:.3e}) to a face of the master body that is not in the master surface, faces = [[{element}, {face}]]: nothing holds a slave node there, so it entered the body unresisted; add the master body's faces the slave surface can reach (e.g. a die's front face) to the master side set")?,
                    None => {}
                }
                if !*adjusted {
                    write!(f, "; if the two surfaces were meshed apart on one curved shape (a pin in a hole), the master facets cut into the slave body by their sagitta before any load: `adjust = <distance>` in the contact moves the slave nodes onto the master surface before the run, strain-free")?;
                }
                if *small_kinematics {
                    write!(f, "; small sliding was exceeded: under kinematics = \"small\" the master faces keep their reference normals, which holds only while the bodies slide and rotate little; kinematics = \"large\" follows the sliding")?;
                }
                Ok(())
            }
        }
    }
}
