//! Master/slave contact as the paper describes it: a search (bounding-volume hierarchy of
//! master faces, closest-point projection of slave nodes, optional normal smoothing) yields
//! interactions; the control-contact loop freezes the constraint set while CG solves a model
//! problem, then updates it (gap removal with a capture tolerance, release of tensile nodes,
//! the equilibrium query, Coulomb stick/slip).

pub mod active;
pub mod adjust;
pub mod area;
pub mod audit;
mod codec;
pub mod coulomb;
pub mod discretisation;
mod dispatch;
pub mod enforcement;
pub mod facet;
pub mod ghost;
mod held;
pub mod mortar;
mod node_face;
pub mod project;
mod proximity;
pub mod search;
mod self_contact;
pub mod slip;
pub mod state;

pub use crate::problem::ContactPair;
pub use enforcement::Enforcement;

use crate::problem::Discretization;
use discretisation::PairKind;

/// The contact discretisations, one line each, in the order their passes run over the
/// contact set (node-to-face's before mortar's).
static KINDS: &[&dyn PairKind] = &[&node_face::NodeFace, &mortar::Mortar];

/// Every registered discretisation.
fn kinds() -> &'static [&'static dyn PairKind] {
    KINDS
}

/// The registered kind of a pair's discretisation.
fn kind(d: Discretization) -> &'static dyn PairKind {
    *KINDS
        .iter()
        .find(|k| k.discretization() == d)
        .expect("every discretisation is registered in contact::KINDS")
}
