//! Node-to-face contact (the paper's): each slave node of a pair is tied to one point of
//! a bilinear master face. update.rs captures and searches the pairs' slave nodes,
//! recapture.rs ties back the nodes the penetration audit found inside a master body,
//! kind.rs is the `PairKind` the contact set calls. What every discretisation shares
//! (release, Coulomb's law, the rows, the forces read back) is the contact set's
//! (state.rs, coulomb.rs, slip.rs).

mod kind;
mod recapture;
mod update;

pub(super) use kind::NodeFace;
use recapture::recapture;
