//! Element connectivity of any mix of element kinds: every element's node ids in one flat
//! array. While every element has the same node count (a mesh of one kind) an element's
//! nodes are found by that stride, so a one-kind mesh costs what `Vec<[u32; 8]>` cost;
//! the first element of another node count adds a start offset per element.

use partition::Cells;

#[derive(serde::Serialize, serde::Deserialize, Clone, Debug, Default, PartialEq, Eq)]
pub struct Connectivity {
    nodes: Vec<u32>,
    /// Nodes of every element while `start` is empty.
    stride: usize,
    /// Element `e`'s nodes are `nodes[start[e]..start[e + 1]]`; empty while every element
    /// has `stride` nodes.
    start: Vec<usize>,
    len: usize,
}

impl Connectivity {
    pub fn new() -> Self {
        Self::default()
    }

    /// A connectivity of `elements`, all of `N` nodes.
    pub fn from_fixed<const N: usize>(elements: &[[u32; N]]) -> Self {
        Connectivity {
            nodes: elements.iter().flatten().copied().collect(),
            stride: N,
            start: Vec::new(),
            len: elements.len(),
        }
    }

    /// Number of elements.
    #[inline]
    pub fn len(&self) -> usize {
        self.len
    }

    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The node ids of element `e`.
    #[inline]
    pub fn element(&self, e: usize) -> &[u32] {
        if self.start.is_empty() {
            &self.nodes[e * self.stride..(e + 1) * self.stride]
        } else {
            &self.nodes[self.start[e]..self.start[e + 1]]
        }
    }

    /// The node ids of element `e`, which has `N` nodes (a kind's kernels know their own
    /// node count); panics if it has another.
    #[inline]
    pub fn fixed<const N: usize>(&self, e: usize) -> &[u32; N] {
        self.element(e)
            .try_into()
            .expect("the element's node count is its kind's")
    }

    /// Every element's node ids, in element order.
    pub fn iter(&self) -> Iter<'_> {
        Iter { of: self, next: 0 }
    }

    /// Appends an element.
    pub fn push(&mut self, element: &[u32]) {
        if self.len == 0 && self.start.is_empty() {
            self.stride = element.len();
        }
        if self.start.is_empty() && element.len() != self.stride {
            self.start = (0..=self.len).map(|e| e * self.stride).collect();
        }
        self.nodes.extend_from_slice(element);
        if !self.start.is_empty() {
            self.start.push(self.nodes.len());
        }
        self.len += 1;
    }

    /// Appends every element of `other`, each node id mapped by `f`.
    pub fn extend_mapped(&mut self, other: &Connectivity, f: impl Fn(u32) -> u32) {
        let mut buf = Vec::new();
        for el in other.iter() {
            buf.clear();
            buf.extend(el.iter().map(|&n| f(n)));
            self.push(&buf);
        }
    }

    /// The elements `elements`, in their order, each node id mapped by `f`.
    pub fn select(
        &self,
        elements: impl IntoIterator<Item = usize>,
        f: impl Fn(u32) -> u32,
    ) -> Connectivity {
        let mut out = Connectivity::new();
        let mut buf = Vec::new();
        for e in elements {
            buf.clear();
            buf.extend(self.element(e).iter().map(|&n| f(n)));
            out.push(&buf);
        }
        out
    }
}

/// The elements' node ids in element order.
pub struct Iter<'a> {
    of: &'a Connectivity,
    next: usize,
}

impl<'a> Iterator for Iter<'a> {
    type Item = &'a [u32];

    #[inline]
    fn next(&mut self) -> Option<&'a [u32]> {
        (self.next < self.of.len).then(|| {
            self.next += 1;
            self.of.element(self.next - 1)
        })
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = self.of.len - self.next;
        (n, Some(n))
    }
}

impl ExactSizeIterator for Iter<'_> {}

impl<'a> IntoIterator for &'a Connectivity {
    type Item = &'a [u32];
    type IntoIter = Iter<'a>;

    fn into_iter(self) -> Iter<'a> {
        self.iter()
    }
}

impl Cells for Connectivity {
    fn count(&self) -> usize {
        self.len
    }

    fn nodes(&self, e: usize) -> &[u32] {
        self.element(e)
    }
}

/// A connectivity as a message (a rank's part of the mesh, sent by the rank that
/// partitions it: `run::decompose`).
impl crate::comm::message::Message for Connectivity {
    fn write(&self, w: &mut crate::comm::message::Writer<'_>) {
        w.put(&self.nodes);
        w.index(self.stride);
        w.put(&self.start);
        w.index(self.len);
    }
    fn read(r: &mut crate::comm::message::Reader) -> Option<Self> {
        let c = Connectivity {
            nodes: r.get()?,
            stride: r.index()?,
            start: r.get()?,
            len: r.index()?,
        };
        // Every element's range lies in the node list.
        let fits = if c.start.is_empty() {
            c.stride.checked_mul(c.len) == Some(c.nodes.len())
        } else {
            c.start.len() == c.len + 1
                && c.start.is_sorted()
                && c.start.last() == Some(&c.nodes.len())
        };
        fits.then_some(c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_kind_uses_its_stride_and_a_second_kind_adds_offsets() {
        let mut c = Connectivity::from_fixed(&[[0, 1, 2, 3, 4, 5, 6, 7], [8; 8]]);
        assert_eq!(c.len(), 2);
        assert_eq!(c.fixed::<8>(1), &[8; 8]);
        assert!(c.start.is_empty());
        c.push(&[1, 2, 3, 4, 5, 6, 7, 8, 9, 10]);
        assert_eq!(c.element(0), &[0, 1, 2, 3, 4, 5, 6, 7]);
        assert_eq!(c.element(1), &[8; 8]);
        assert_eq!(c.element(2), &[1, 2, 3, 4, 5, 6, 7, 8, 9, 10]);
        assert_eq!(c.iter().map(<[u32]>::len).sum::<usize>(), 26);
    }
}
