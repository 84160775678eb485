//! Physical surfaces as faces (side sets) and the midside nodes a node set of a
//! 4-node-tetrahedron mesh takes along its edges.

use super::{GmshMesh, GMSH_LINE2, GMSH_QUAD4, GMSH_TET4, GMSH_TRI3, GMSH_TRI6};

/// One element of a physical surface as a face: a quadrangle (to match a hexahedron's
/// face) or a triangle (a tetrahedron's).
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceFace {
    pub tag: u64,
    /// Gmsh's element type (3, 2 or 9).
    pub gmsh_type: i32,
    /// The corners' node tags (4 or 3), in the file's order.
    pub corners: Vec<u64>,
    /// The midside nodes' tags of a 6-node triangle (edges 0-1, 1-2, 2-0), else empty.
    pub midsides: Vec<u64>,
}

impl GmshMesh {
    /// The faces of the physical surface `name`: 4-node quadrangles and 3- or 6-node
    /// triangles, in element tag order.
    pub fn surface_faces(&self, name: &str) -> Result<Vec<SurfaceFace>, String> {
        let g = self.find_one(name, 2, "physical surface")?;
        let elements = &self.group_elements[g];
        self.only_types(
            elements,
            &[GMSH_QUAD4, GMSH_TRI3, GMSH_TRI6],
            "4-node quadrangles (Gmsh type 3) and 3- or 6-node triangles (types 2, 9)",
            "physical surface",
            name,
        )?;
        if elements.is_empty() {
            return Err(format!(
                "physical surface '{name}' of {} has no elements",
                self.file
            ));
        }
        Ok(elements
            .iter()
            .map(|e| {
                let corners = if e.kind == GMSH_QUAD4 { 4 } else { 3 };
                SurfaceFace {
                    tag: e.tag,
                    gmsh_type: e.kind,
                    corners: e.nodes[..corners].to_vec(),
                    midsides: e.nodes[corners..].to_vec(),
                }
            })
            .collect())
    }

    /// The edges (corner tags, smaller first, ascending) of the linear simplices (2-node
    /// lines, 3-node triangles, 4-node tetrahedra) of every physical group named `name`:
    /// where they are edges of 4-node tetrahedra, the group holds their inserted midside
    /// nodes too.
    pub fn group_edges(&self, name: &str) -> Result<Vec<(u64, u64)>, String> {
        let mut edges = Vec::new();
        for g in self.find(name, &[0, 1, 2, 3])? {
            for e in &self.group_elements[g] {
                if matches!(e.kind, GMSH_LINE2 | GMSH_TRI3 | GMSH_TET4) {
                    for (i, &a) in e.nodes.iter().enumerate() {
                        for &b in &e.nodes[i + 1..] {
                            edges.push((a.min(b), a.max(b)));
                        }
                    }
                }
            }
        }
        edges.sort_unstable();
        edges.dedup();
        Ok(edges)
    }
}
