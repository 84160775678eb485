//! The global mesh (every node and element of the scene, in paper numbering), its
//! generators and its named sets. Rank-local views are built from it by `local`.

pub mod block;
pub mod connectivity;
pub mod exodus;
pub mod gmsh;
pub mod local;
pub mod msh41;
pub mod sets;
pub mod whole;

use crate::fem::kind::ElementKind;
use crate::math::Vec3;
pub use connectivity::Connectivity;

/// A body: a contiguous range of nodes and elements of one kind with one material.
#[derive(serde::Serialize, serde::Deserialize, Clone, Debug)]
pub struct Body {
    pub name: String,
    pub kind: ElementKind,
    pub first_node: usize,
    pub num_nodes: usize,
    pub first_element: usize,
    pub num_elements: usize,
}

/// The whole mesh. Node and element indices are 0-based here; files and messages show
/// them 1-based (the paper numbering).
#[derive(serde::Serialize, serde::Deserialize, Clone, Debug, Default)]
pub struct GlobalMesh {
    pub coords: Vec<Vec3>,
    pub elements: Connectivity,
    pub element_body: Vec<u32>,
    pub bodies: Vec<Body>,
    /// The node and element counts of an outline (`outline`): a mesh whose positions,
    /// connectivity and element bodies are not held, as a run's problem keeps it once its
    /// setup is done. None for a whole mesh.
    pub freed: Option<[usize; 2]>,
}

/// A whole mesh lent to what reads it while it is set up (`solver::Stepper::new`), where an
/// owned one would be freed once read.
impl<'a> From<&'a GlobalMesh> for std::borrow::Cow<'a, GlobalMesh> {
    fn from(mesh: &'a GlobalMesh) -> Self {
        std::borrow::Cow::Borrowed(mesh)
    }
}

impl GlobalMesh {
    pub fn num_nodes(&self) -> usize {
        self.freed.map_or(self.coords.len(), |c| c[0])
    }

    pub fn num_elements(&self) -> usize {
        self.freed.map_or(self.elements.len(), |c| c[1])
    }

    /// The mesh without its positions, connectivity and element bodies: its bodies and
    /// counts (what a run reads of the whole mesh once set up).
    pub fn outline(&self) -> GlobalMesh {
        GlobalMesh {
            bodies: self.bodies.clone(),
            freed: Some([self.num_nodes(), self.num_elements()]),
            ..GlobalMesh::default()
        }
    }

    /// Whether this is an outline (`outline`).
    pub fn is_outline(&self) -> bool {
        self.freed.is_some()
    }

    /// The body of element `e`, from the bodies' element ranges (an outline's too).
    pub fn body_of_element(&self, e: usize) -> usize {
        let b = self
            .bodies
            .partition_point(|b| b.first_element + b.num_elements <= e);
        debug_assert!(b < self.bodies.len(), "element {e} is in a body");
        b
    }

    /// The body of node `n`, from the bodies' node ranges (an outline's too).
    pub fn body_of_node(&self, n: usize) -> Option<usize> {
        let b = self
            .bodies
            .partition_point(|b| b.first_node + b.num_nodes <= n);
        (b < self.bodies.len() && self.bodies[b].first_node <= n).then_some(b)
    }

    /// The kind of element `e` (its body's).
    #[inline]
    pub fn kind(&self, e: usize) -> ElementKind {
        self.bodies[self.element_body[e] as usize].kind
    }

    /// The node positions of element `e`, of `N` nodes (its kind's).
    pub fn element_coords<const N: usize>(&self, e: usize) -> [Vec3; N] {
        let mut x = [[0.0; 3]; N];
        for (a, &n) in self.elements.fixed::<N>(e).iter().enumerate() {
            x[a] = self.coords[n as usize];
        }
        x
    }

    /// Length of the diagonal of the bounding box of all nodes.
    pub fn bounding_diagonal(&self) -> f64 {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for x in &self.coords {
            for i in 0..3 {
                lo[i] = lo[i].min(x[i]);
                hi[i] = hi[i].max(x[i]);
            }
        }
        crate::math::norm(&crate::math::sub(&hi, &lo))
    }

    /// Faces that belong to exactly one element, as (element, local face), in element
    /// then face order. Two elements share a face when they have its corners; every face
    /// is listed under its smallest corner node, so only the faces of one node's list are
    /// compared (a few each) and the lists take one index per face.
    pub fn boundary_faces(&self) -> Vec<(u32, u8)> {
        let n = self.elements.len();
        let key = |id: u64| {
            let (e, k) = ((id / MAX_FACES) as usize, (id % MAX_FACES) as usize);
            face_key(self.kind(e), self.elements.element(e), k)
        };
        let ids = || {
            (0..n).flat_map(move |e| {
                (0..self.kind(e).faces()).map(move |k| e as u64 * MAX_FACES + k as u64)
            })
        };
        let mut start = vec![0usize; self.coords.len() + 1];
        for id in ids() {
            start[key(id)[0] as usize + 1] += 1;
        }
        for a in 0..self.coords.len() {
            start[a + 1] += start[a];
        }
        let mut listed = vec![0u64; start[self.coords.len()]];
        let mut next = start.clone();
        for id in ids() {
            let a = key(id)[0] as usize;
            listed[next[a]] = id;
            next[a] += 1;
        }
        drop(next);
        let mut shared = vec![false; n * MAX_FACES as usize];
        for a in 0..self.coords.len() {
            let list = &listed[start[a]..start[a + 1]];
            for (i, &p) in list.iter().enumerate() {
                for &q in &list[i + 1..] {
                    if key(p) == key(q) {
                        shared[p as usize] = true;
                        shared[q as usize] = true;
                    }
                }
            }
        }
        ids()
            .filter(|&id| !shared[id as usize])
            .map(|id| ((id / MAX_FACES) as u32, (id % MAX_FACES) as u8))
            .collect()
    }

    /// Global node indices of a face, ordered with an outward normal (the face kind's
    /// node order).
    pub fn face_nodes(&self, element: u32, face: u8) -> impl ExactSizeIterator<Item = u32> + '_ {
        let el = self.elements.element(element as usize);
        let kind = self.kind(element as usize);
        kind.face(face as usize).iter().map(move |&a| el[a])
    }

    /// A face's sorted corner nodes, padded with `u32::MAX` to four (the same from either
    /// element that shares the face).
    pub fn face_key(&self, element: u32, face: u8) -> [u32; 4] {
        let e = element as usize;
        face_key(self.kind(e), self.elements.element(e), face as usize)
    }

    /// The linear facets contact takes a face as (`FaceKind::contact_facets`), each as four
    /// global node ids ordered with the face's outward normal: a quadrilateral face is one,
    /// a 6-node triangle four sub-triangles, whose fourth node repeats the third
    /// (`contact::facet`).
    pub fn contact_facets(&self, element: u32, face: u8) -> Vec<[u32; 4]> {
        let e = element as usize;
        let (kind, el) = (self.kind(e), self.elements.element(e));
        let local = kind.face(face as usize);
        kind.face_kind(face as usize)
            .contact_facets()
            .iter()
            .map(|f| std::array::from_fn(|a| el[local[f[a.min(f.len() - 1)]]]))
            .collect()
    }

    /// Global node indices of a quadrilateral face (what contact, the Gmsh side sets and
    /// face loads take today), ordered with an outward normal.
    pub fn quad_face_nodes(&self, element: u32, face: u8) -> [u32; 4] {
        let el = self.elements.element(element as usize);
        let f = self
            .kind(element as usize)
            .quad_face(face as usize)
            .expect("a quadrilateral face");
        f.map(|a| el[a])
    }
}

/// Faces of an element, at most: a face's index in `boundary_faces` is element x this +
/// face.
const MAX_FACES: u64 = {
    let (hex, tet) = (ElementKind::Hex8.faces(), ElementKind::Tet10.faces());
    (if hex > tet { hex } else { tet }) as u64
};

/// A face's key: its sorted corner nodes (the same from either element that shares it),
/// padded for faces of fewer corners.
fn face_key(kind: ElementKind, el: &[u32], k: usize) -> [u32; 4] {
    let f = kind.face(k);
    let mut key = [u32::MAX; 4];
    for (slot, &a) in key.iter_mut().zip(&f[..kind.face_kind(k).corners()]) {
        *slot = el[a];
    }
    key.sort_unstable();
    key
}

/// Three hexahedra in a row along x, one body of 16 nodes (four per cross-section, in the
/// order the elements' connectivity gives), at `coords`: a fixture of the unit tests.
#[cfg(test)]
pub(crate) fn hexahedra_in_a_row(coords: Vec<Vec3>) -> GlobalMesh {
    let elements: Vec<[u32; 8]> = (0..3u32)
        .map(|e| {
            let b = 4 * e;
            [b, b + 4, b + 5, b + 1, b + 2, b + 6, b + 7, b + 3]
        })
        .collect();
    GlobalMesh {
        coords,
        elements: Connectivity::from_fixed(&elements),
        element_body: vec![0; 3],
        bodies: vec![Body {
            name: "b".into(),
            kind: ElementKind::Hex8,
            first_node: 0,
            num_nodes: 16,
            first_element: 0,
            num_elements: 3,
        }],
        freed: None,
    }
}
