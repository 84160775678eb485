//! The global mesh (every node and element of the scene, in paper numbering), its
//! generators and its named sets. Rank-local views are built from it by `local`.

pub mod block;
pub mod exodus;
pub mod gmsh;
pub mod local;
pub mod msh41;
pub mod sets;

use crate::fem::hex8::FACES;
use crate::math::Vec3;
use std::collections::HashMap;

/// A body: a contiguous range of nodes and elements with one material.
#[derive(Clone, Debug)]
pub struct Body {
    pub name: String,
    pub first_node: usize,
    pub num_nodes: usize,
    pub first_element: usize,
    pub num_elements: usize,
}

/// The whole mesh. Node and element indices are 0-based here; files and messages show
/// them 1-based (the paper numbering).
#[derive(Clone, Debug, Default)]
pub struct GlobalMesh {
    pub coords: Vec<Vec3>,
    pub elements: Vec<[u32; 8]>,
    pub element_body: Vec<u32>,
    pub bodies: Vec<Body>,
}

impl GlobalMesh {
    pub fn num_nodes(&self) -> usize {
        self.coords.len()
    }

    pub fn num_elements(&self) -> usize {
        self.elements.len()
    }

    pub fn element_coords(&self, e: usize) -> [Vec3; 8] {
        let mut x = [[0.0; 3]; 8];
        for (a, &n) in self.elements[e].iter().enumerate() {
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
    /// then face order.
    pub fn boundary_faces(&self) -> Vec<(u32, u8)> {
        let mut count: HashMap<[u32; 4], u32> = HashMap::new();
        for el in &self.elements {
            for f in FACES.iter() {
                *count.entry(face_key(el, f)).or_insert(0) += 1;
            }
        }
        let mut out = Vec::new();
        for (e, el) in self.elements.iter().enumerate() {
            for (k, f) in FACES.iter().enumerate() {
                if count[&face_key(el, f)] == 1 {
                    out.push((e as u32, k as u8));
                }
            }
        }
        out
    }

    /// Global node indices of a face, ordered with an outward normal.
    pub fn face_nodes(&self, element: u32, face: u8) -> [u32; 4] {
        let el = &self.elements[element as usize];
        let f = FACES[face as usize];
        [el[f[0]], el[f[1]], el[f[2]], el[f[3]]]
    }
}

fn face_key(el: &[u32; 8], f: &[usize; 4]) -> [u32; 4] {
    let mut k = [el[f[0]], el[f[1]], el[f[2]], el[f[3]]];
    k.sort_unstable();
    k
}
