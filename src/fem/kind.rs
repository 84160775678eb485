//! Element kinds: what the layers above the kernels ask of an element type (its node
//! count, its faces as local node lists and their kind, the facets contact sees, its
//! reference nodes and quadrature rule, its name in output files). Every body is of one
//! kind; a scene may mix bodies of different kinds. A new kind is a file of kernels in
//! `fem/` plus one arm in each match below (docs/layout.md, "Adding an element kind").

use crate::fem::hex8;
use crate::fem::tet10::reference as tet10;

/// The kind of a body's elements.
#[derive(
    serde::Serialize, serde::Deserialize, Clone, Copy, Debug, Default, PartialEq, Eq, Hash,
)]
pub enum ElementKind {
    /// The trilinear 8-node hexahedron (`fem::hex8`).
    #[default]
    Hex8,
    /// The 10-node tetrahedron (`fem::tet10`).
    Tet10,
}

/// The kind of an element's face.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FaceKind {
    /// The bilinear 4-node quadrilateral (`fem::face`).
    Quad4,
    /// The 6-node triangle: three corners, then the midpoints of its edges.
    Tri6,
}

/// The sub-facets of a quadrilateral face as contact sees them: the face itself.
const QUAD4_FACETS: [&[usize]; 1] = [&[0, 1, 2, 3]];

/// The sub-facets of a 6-node triangle: the corner triangles and the middle one (each
/// with the face's normal).
const TRI6_FACETS: [&[usize]; 4] = [&[0, 3, 5], &[3, 1, 4], &[5, 4, 2], &[3, 4, 5]];

/// Unit weights of the 2x2x2 Gauss rule.
const HEX8_WEIGHTS: [f64; 8] = [1.0; 8];

impl ElementKind {
    /// Every kind.
    pub const ALL: [ElementKind; 2] = [ElementKind::Hex8, ElementKind::Tet10];

    /// The kind's short name (scene files, messages).
    pub const fn name(self) -> &'static str {
        match self {
            ElementKind::Hex8 => "hex8",
            ElementKind::Tet10 => "tet10",
        }
    }

    /// Nodes per element.
    pub const fn nodes(self) -> usize {
        match self {
            ElementKind::Hex8 => 8,
            ElementKind::Tet10 => 10,
        }
    }

    /// Corner (vertex) nodes, the element's first nodes.
    pub const fn corners(self) -> usize {
        match self {
            ElementKind::Hex8 => 8,
            ElementKind::Tet10 => 4,
        }
    }

    /// Faces per element.
    pub const fn faces(self) -> usize {
        match self {
            ElementKind::Hex8 => hex8::FACES.len(),
            ElementKind::Tet10 => tet10::FACES.len(),
        }
    }

    /// Local nodes of face `k`, ordered so that their normal points out of the element.
    #[inline]
    pub fn face(self, k: usize) -> &'static [usize] {
        match self {
            ElementKind::Hex8 => &hex8::FACES[k],
            ElementKind::Tet10 => &tet10::FACES[k],
        }
    }

    /// Local nodes of face `k` of a kind whose faces are quadrilaterals (`None` for a
    /// face of another kind).
    #[inline]
    pub fn quad_face(self, k: usize) -> Option<&'static [usize; 4]> {
        match self {
            ElementKind::Hex8 => Some(&hex8::FACES[k]),
            ElementKind::Tet10 => None,
        }
    }

    /// The edges, as local node pairs (for a quadratic kind, its corner nodes').
    pub fn edges(self) -> &'static [(usize, usize)] {
        match self {
            ElementKind::Hex8 => &hex8::EDGES,
            ElementKind::Tet10 => &tet10::EDGES,
        }
    }

    /// The kind of face `k`.
    pub const fn face_kind(self, _k: usize) -> FaceKind {
        match self {
            ElementKind::Hex8 => FaceKind::Quad4,
            ElementKind::Tet10 => FaceKind::Tri6,
        }
    }

    /// Reference coordinates of the nodes.
    pub fn reference_nodes(self) -> &'static [[f64; 3]] {
        match self {
            ElementKind::Hex8 => &hex8::NODE_XI,
            ElementKind::Tet10 => &tet10::NODE_XI,
        }
    }

    /// The volume quadrature rule: reference points and their weights.
    pub fn quadrature(self) -> (&'static [[f64; 3]], &'static [f64]) {
        match self {
            ElementKind::Hex8 => (&hex8::GAUSS, &HEX8_WEIGHTS),
            ElementKind::Tet10 => (&tet10::QUADRATURE, &tet10::WEIGHTS),
        }
    }

    /// The XDMF topology type of a body of this kind.
    pub const fn xdmf_topology(self) -> &'static str {
        match self {
            ElementKind::Hex8 => "Hexahedron",
            ElementKind::Tet10 => "Tetrahedron_10",
        }
    }

    /// Smallest Jacobian determinant over the element relative to its mean (non-positive:
    /// inverted or degenerate), for the node positions `x` (`nodes()` of them).
    pub fn min_jacobian_ratio(self, x: &[crate::math::Vec3]) -> f64 {
        match self {
            ElementKind::Hex8 => {
                hex8::min_jacobian_ratio(x.try_into().expect("a hex8 has 8 nodes"))
            }
            ElementKind::Tet10 => {
                tet10::min_jacobian_ratio(x.try_into().expect("a tet10 has 10 nodes"))
            }
        }
    }
}

impl FaceKind {
    /// Nodes per face.
    pub const fn nodes(self) -> usize {
        match self {
            FaceKind::Quad4 => 4,
            FaceKind::Tri6 => 6,
        }
    }

    /// Corner (vertex) nodes per face, the face's first nodes.
    pub const fn corners(self) -> usize {
        match self {
            FaceKind::Quad4 => 4,
            FaceKind::Tri6 => 3,
        }
    }

    /// The linear facets contact searches and projects on, as lists of the face's local
    /// nodes ordered with the face's normal (a quadrilateral is one facet; a 6-node
    /// triangle is four triangles).
    pub fn contact_facets(self) -> &'static [&'static [usize]] {
        match self {
            FaceKind::Quad4 => &QUAD4_FACETS,
            FaceKind::Tri6 => &TRI6_FACETS,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_face_lists_its_kinds_node_count() {
        for kind in ElementKind::ALL {
            assert_eq!(kind.reference_nodes().len(), kind.nodes());
            let (points, weights) = kind.quadrature();
            assert_eq!(points.len(), weights.len());
            for k in 0..kind.faces() {
                let face = kind.face(k);
                assert_eq!(face.len(), kind.face_kind(k).nodes());
                assert!(face.iter().all(|&a| a < kind.nodes()));
            }
        }
    }
}
