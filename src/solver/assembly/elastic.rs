//! The elastic matrices of the elements of small-kinematics plastic bodies, kept for the
//! run, and which of them stand for their element at one state (`Assembly::mark_elastic`).

use crate::fem::element;

/// The elastic matrices of the local elements of small-kinematics plastic bodies, each
/// computed when its element is first marked (`Assembly::mark_elastic`) and kept for the
/// run: a function of the element's geometry and material only.
#[derive(Default)]
pub struct ElasticMatrices {
    pub(super) matrix: Vec<Option<Box<element::ElementMatrix>>>,
}

/// The elastic matrices and which elements they stand for at one state (`marks`, one flag
/// per local element): an element marked there has every stress point elastic, so its
/// internal force's derivative is its elastic matrix.
#[derive(Clone, Copy)]
pub struct Elastic<'a> {
    pub matrices: &'a ElasticMatrices,
    pub marks: &'a [bool],
}

impl<'a> Elastic<'a> {
    /// Element `e`'s elastic matrix when it is marked.
    #[inline]
    pub fn get(&self, e: usize) -> Option<&'a element::ElementMatrix> {
        if *self.marks.get(e)? {
            self.matrices.matrix.get(e)?.as_deref()
        } else {
            None
        }
    }
}
