//! What the decomposition reads of a mesh's elements: how many there are and each one's
//! node ids. Elements of any kind (node count) may be mixed.

/// A mesh's elements as lists of node ids.
pub trait Cells {
    /// Number of elements.
    fn count(&self) -> usize;
    /// The node ids of element `e`.
    fn nodes(&self, e: usize) -> &[u32];
}

impl<const N: usize> Cells for [[u32; N]] {
    fn count(&self) -> usize {
        self.len()
    }

    fn nodes(&self, e: usize) -> &[u32] {
        &self[e]
    }
}

impl<const N: usize> Cells for &[[u32; N]] {
    fn count(&self) -> usize {
        self.len()
    }

    fn nodes(&self, e: usize) -> &[u32] {
        &self[e]
    }
}

impl<const N: usize> Cells for Vec<[u32; N]> {
    fn count(&self) -> usize {
        self.len()
    }

    fn nodes(&self, e: usize) -> &[u32] {
        &self[e]
    }
}
