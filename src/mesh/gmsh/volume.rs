//! A physical volume as a body: its elements in the solver's node order, of one kind.
//!
//! - 8-node hexahedra (type 5) are taken as they are (Gmsh's order is `fem::hex8`'s).
//! - 10-node tetrahedra (type 11): Gmsh numbers the midside nodes of the edges 0-1, 1-2,
//!   2-0, 3-0, 3-2, 3-1; ours (`fem::tet10`, Exodus TETRA10) end with 1-3, 2-3, so Gmsh's
//!   last two are swapped. Midside nodes stay where the file puts them (a curved edge
//!   stays curved).
//! - 4-node tetrahedra (type 4) become 10-node ones: a node is inserted at the midpoint of
//!   every edge. The inserted nodes follow the volume's file nodes (which are in node tag
//!   order), in the order of their edges' corner tag pairs (smaller tag first, pairs sorted):
//!   a numbering fixed by the file alone.

use super::{element_type_name, GmshElement, GmshMesh, GMSH_HEX8, GMSH_TET10, GMSH_TET4};
use crate::fem::kind::ElementKind;
use crate::fem::tet10::MIDSIDE;
use crate::math::Vec3;
use crate::mesh::Connectivity;

/// Our node `a` of a 10-node tetrahedron is Gmsh's node `GMSH_TET10_ORDER[a]`.
const GMSH_TET10_ORDER: [usize; 10] = [0, 1, 2, 3, 4, 5, 6, 7, 9, 8];

/// The elements of one physical volume, numbered locally: the file's nodes in node tag
/// order, then the inserted midside nodes (if the volume has 4-node tetrahedra).
#[derive(Clone, Debug, PartialEq)]
pub struct GmshVolume {
    pub kind: ElementKind,
    /// Tags of the file's nodes of the volume, ascending (local nodes 0..).
    pub node_tags: Vec<u64>,
    /// Positions of the local nodes: the file's, then the inserted ones.
    pub coords: Vec<Vec3>,
    /// The corner tags (smaller first) of the edge of each inserted node, in the order of
    /// the inserted nodes (local node `node_tags.len() + i`); ascending.
    pub midsides: Vec<(u64, u64)>,
    pub element_tags: Vec<u64>,
    /// Local (0-based) node indices in the solver's order of `kind`.
    pub elements: Connectivity,
}

impl GmshMesh {
    /// The elements of the physical volume `name`, checked: hexahedra or tetrahedra only,
    /// not both, every node present, a positive Jacobian everywhere.
    pub fn volume(&self, name: &str) -> Result<GmshVolume, String> {
        let g = self.find_one(name, 3, "physical volume")?;
        let elements = &self.group_elements[g];
        self.only_types(
            elements,
            &[GMSH_HEX8, GMSH_TET4, GMSH_TET10],
            "8-node hexahedra (Gmsh type 5) and 4- or 10-node tetrahedra (types 4, 11)",
            "physical volume",
            name,
        )?;
        let Some(first) = elements.first() else {
            return Err(format!(
                "physical volume '{name}' of {} has no elements (was the mesh saved after meshing in 3-D?)",
                self.file
            ));
        };
        let gmsh_type = first.kind;
        if elements.iter().any(|e| e.kind != gmsh_type) {
            return Err(format!(
                "physical volume '{name}' of {} has {}; a body is of one element kind: give the hexahedra and the tetrahedra (or the 4- and 10-node tetrahedra) physical volumes of their own",
                self.file,
                super::type_counts(&super::count_types(elements.iter()))
            ));
        }
        let mut node_tags: Vec<u64> = elements.iter().flat_map(|e| e.nodes.clone()).collect();
        node_tags.sort_unstable();
        node_tags.dedup();
        let mut coords = node_tags
            .iter()
            .map(|t| self.node(*t, elements, name))
            .collect::<Result<Vec<Vec3>, String>>()?;
        let midsides = if gmsh_type == GMSH_TET4 {
            edge_pairs(elements)
        } else {
            Vec::new()
        };
        for &(a, b) in &midsides {
            let (xa, xb) = (self.nodes[&a], self.nodes[&b]);
            coords.push(std::array::from_fn(|i| 0.5 * (xa[i] + xb[i])));
        }
        let kind = if gmsh_type == GMSH_HEX8 {
            ElementKind::Hex8
        } else {
            ElementKind::Tet10
        };
        let local = |tag: u64| {
            node_tags
                .binary_search(&tag)
                .expect("every node tag is listed") as u32
        };
        let mut conn = Connectivity::new();
        let mut el: Vec<u32> = Vec::with_capacity(kind.nodes());
        for e in elements {
            el.clear();
            match gmsh_type {
                GMSH_HEX8 => el.extend(e.nodes.iter().map(|&t| local(t))),
                GMSH_TET10 => el.extend(GMSH_TET10_ORDER.iter().map(|&a| local(e.nodes[a]))),
                _ => {
                    el.extend(e.nodes.iter().map(|&t| local(t)));
                    for &(i, j) in &MIDSIDE {
                        let m = midsides
                            .binary_search(&ordered(e.nodes[i], e.nodes[j]))
                            .expect("every edge has its midside node");
                        el.push((node_tags.len() + m) as u32);
                    }
                }
            }
            let x: Vec<Vec3> = el.iter().map(|&n| coords[n as usize]).collect();
            let r = kind.min_jacobian_ratio(&x);
            if !(r > 1e-8) {
                return Err(format!(
                    "element {} ({}) of physical volume '{name}' in {} is inverted or degenerate (min Jacobian ratio {r:.3e})",
                    e.tag,
                    element_type_name(gmsh_type),
                    self.file
                ));
            }
            conn.push(&el);
        }
        Ok(GmshVolume {
            kind,
            node_tags,
            coords,
            midsides,
            element_tags: elements.iter().map(|e| e.tag).collect(),
            elements: conn,
        })
    }
}

fn ordered(a: u64, b: u64) -> (u64, u64) {
    (a.min(b), a.max(b))
}

/// Every edge of the 4-node tetrahedra, as its corner tags (smaller first), ascending.
fn edge_pairs(elements: &[GmshElement]) -> Vec<(u64, u64)> {
    let mut pairs: Vec<(u64, u64)> = elements
        .iter()
        .flat_map(|e| {
            MIDSIDE
                .iter()
                .map(|&(i, j)| ordered(e.nodes[i], e.nodes[j]))
        })
        .collect();
    pairs.sort_unstable();
    pairs.dedup();
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::tet10::NODE_XI;

    /// An ASCII file with the physical volume "solid" of the elements `elements` (tag,
    /// nodes) of Gmsh type `gmsh_type` on the nodes `nodes` (tag, position).
    fn file(nodes: &[(u64, Vec3)], gmsh_type: i32, elements: &[(u64, Vec<u64>)]) -> String {
        let (n, m) = (nodes.len(), elements.len());
        let (lo, hi) = (
            nodes.iter().map(|x| x.0).min(),
            nodes.iter().map(|x| x.0).max(),
        );
        let mut s = format!(
            "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n3 1 \"solid\"\n$EndPhysicalNames\n\
$Entities\n0 0 0 1\n1 0 0 0 1 1 1 1 1 0\n$EndEntities\n$Nodes\n1 {n} {} {}\n3 1 0 {n}\n",
            lo.unwrap(),
            hi.unwrap()
        );
        for (t, _) in nodes {
            s += &format!("{t}\n");
        }
        for (_, x) in nodes {
            s += &format!("{} {} {}\n", x[0], x[1], x[2]);
        }
        let last = elements.iter().map(|e| e.0).max().unwrap();
        s += &format!("$EndNodes\n$Elements\n1 {m} 1 {last}\n3 1 {gmsh_type} {m}\n");
        for (t, el) in elements {
            let ids: Vec<String> = el.iter().map(u64::to_string).collect();
            s += &format!("{t} {}\n", ids.join(" "));
        }
        s + "$EndElements\n"
    }

    #[test]
    fn gmsh_10_node_order_is_mapped_and_a_shifted_midside_node_kept() {
        // Gmsh's nodes: ours with the last two swapped; node tag = Gmsh index + 1.
        let mut nodes: Vec<(u64, Vec3)> = (0..10)
            .map(|g| (g as u64 + 1, NODE_XI[GMSH_TET10_ORDER[g]]))
            .collect();
        nodes[4].1 = [0.5, -0.1, 0.05];
        let text = file(&nodes, GMSH_TET10, &[(1, (1..=10).collect())]);
        let v = GmshMesh::from_bytes(text.as_bytes(), "t.msh")
            .unwrap()
            .volume("solid")
            .unwrap();
        assert_eq!(v.kind, ElementKind::Tet10);
        assert!(v.midsides.is_empty());
        let el = v.elements.element(0);
        for (a, &n) in el.iter().enumerate() {
            let want = if a == 4 {
                [0.5, -0.1, 0.05]
            } else {
                NODE_XI[a]
            };
            assert_eq!(v.coords[n as usize], want, "node {a}");
        }
    }

    #[test]
    fn four_node_tetrahedra_get_their_edge_midpoints_in_tag_pair_order() {
        // Two tetrahedra sharing the face (tags 30, 10, 20): 5 corners, 9 edges.
        let nodes = [
            (10, [1.0, 0.0, 0.0]),
            (20, [0.0, 1.0, 0.0]),
            (30, [0.0, 0.0, 0.0]),
            (40, [0.0, 0.0, 1.0]),
            (50, [0.0, 0.0, -1.0]),
        ];
        let text = file(
            &nodes,
            GMSH_TET4,
            &[(1, vec![30, 10, 20, 40]), (2, vec![30, 20, 10, 50])],
        );
        let v = GmshMesh::from_bytes(text.as_bytes(), "t.msh")
            .unwrap()
            .volume("solid")
            .unwrap();
        assert_eq!(v.node_tags, vec![10, 20, 30, 40, 50]);
        let pairs = [
            (10, 20),
            (10, 30),
            (10, 40),
            (10, 50),
            (20, 30),
            (20, 40),
            (20, 50),
            (30, 40),
            (30, 50),
        ];
        assert_eq!(v.midsides, pairs);
        assert_eq!(v.coords.len(), 14);
        // Element 1: corners 30 10 20 40 are local 2 0 1 3; its edge 0-1 is (10, 30), the
        // second inserted node (local 5 + 1), edge 1-2 (10, 20) the first, and so on.
        assert_eq!(v.elements.element(0), &[2, 0, 1, 3, 6, 5, 9, 12, 7, 10]);
        for el in v.elements.iter() {
            for (m, &(i, j)) in MIDSIDE.iter().enumerate() {
                let (a, b) = (v.coords[el[i] as usize], v.coords[el[j] as usize]);
                let mid: Vec3 = std::array::from_fn(|k| 0.5 * (a[k] + b[k]));
                assert_eq!(v.coords[el[4 + m] as usize], mid);
            }
        }
    }

    #[test]
    fn an_inverted_tetrahedron_is_named() {
        let nodes: Vec<(u64, Vec3)> = (0..4).map(|a| (a as u64 + 1, NODE_XI[a])).collect();
        let text = file(&nodes, GMSH_TET4, &[(7, vec![1, 3, 2, 4])]);
        let e = GmshMesh::from_bytes(text.as_bytes(), "t.msh")
            .unwrap()
            .volume("solid")
            .unwrap_err();
        assert!(
            e.contains(
                "element 7 (4-node tetrahedron) of physical volume 'solid' in t.msh is inverted"
            ),
            "{e}"
        );
    }
}
