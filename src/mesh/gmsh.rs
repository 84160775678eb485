//! Gmsh meshes (MSH format 4.1, ASCII or binary, read by [`super::msh41`]): nodes by their
//! tags, and the elements of each physical group. Bodies take the elements of a physical
//! volume (8-node hexahedra, or 4- or 10-node tetrahedra read as 10-node ones: `volume`),
//! side sets the quadrangles and triangles of a physical surface (`surface`), node sets the
//! nodes of any physical group. Errors are plain messages naming the file and the group or
//! element; the scene layer adds its own file and key.
//!
//! Gmsh's 8-node hexahedron (type 5) has its nodes at (u, v, w) = (-1,-1,-1), (1,-1,-1),
//! (1,1,-1), (-1,1,-1), then the same four at w = +1: the order of `fem::hex8::NODE_XI`, so
//! the connectivity is taken as it is. An element whose Jacobian is not positive everywhere
//! is rejected rather than reordered: Gmsh writes positively oriented elements, so one that
//! is not points at a broken mesh.

use crate::math::Vec3;
use std::collections::BTreeMap;
use std::path::Path;

pub mod surface;
pub mod volume;

/// Gmsh's element type numbers used here.
pub const GMSH_LINE2: i32 = 1;
pub const GMSH_TRI3: i32 = 2;
pub const GMSH_QUAD4: i32 = 3;
pub const GMSH_TET4: i32 = 4;
pub const GMSH_HEX8: i32 = 5;
pub const GMSH_TRI6: i32 = 9;
pub const GMSH_TET10: i32 = 11;

/// A physical group: its dimension, tag and (possibly empty) name.
#[derive(Clone, Debug, PartialEq)]
pub struct PhysicalGroup {
    pub dim: i32,
    pub tag: i32,
    pub name: String,
}

impl PhysicalGroup {
    fn label(&self) -> String {
        if self.name.is_empty() {
            format!("(unnamed, tag {})", self.tag)
        } else {
            format!("'{}'", self.name)
        }
    }
}

/// One element as the file gives it: Gmsh tag, type number and node tags.
#[derive(Clone, Debug, PartialEq)]
pub struct GmshElement {
    pub tag: u64,
    pub kind: i32,
    pub nodes: Vec<u64>,
}

/// The parts of a Gmsh file the solver uses.
#[derive(Clone, Debug, PartialEq)]
pub struct GmshMesh {
    /// The file, as it is named in messages.
    pub file: String,
    /// Node coordinates by node tag.
    pub nodes: BTreeMap<u64, Vec3>,
    pub groups: Vec<PhysicalGroup>,
    /// Elements of each group (same order as `groups`), in element tag order.
    pub group_elements: Vec<Vec<GmshElement>>,
}

impl GmshMesh {
    /// Reads a `.msh` file (format 4.1, ASCII or binary).
    pub fn read(path: &Path) -> Result<GmshMesh, String> {
        let file = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| format!("cannot read {file}: {e}"))?;
        Self::from_bytes(&bytes, &file)
    }

    /// Parses the bytes of a `.msh` file; `file` names it in messages.
    pub fn from_bytes(bytes: &[u8], file: &str) -> Result<GmshMesh, String> {
        let version = format_version(bytes)
            .ok_or_else(|| format!("{file} is not a Gmsh mesh file (no $MeshFormat header)"))?;
        if version != "4.1" {
            return Err(format!(
                "{file} is in MSH format {version}; only format 4.1 (ASCII or binary) is read: \
                 save it with `gmsh -save -format msh41` or Mesh.MshFileVersion = 4.1"
            ));
        }
        let msh = super::msh41::parse(bytes)
            .map_err(|e| format!("{file} is not a readable MSH 4.1 file: {e}"))?;
        let nodes: BTreeMap<u64, Vec3> = msh.nodes.into_iter().collect();
        let names = msh.physical_names;
        let entity_groups = msh.entity_groups;

        // Groups: every (dim, tag) an entity names, with its name if $PhysicalNames has one.
        let mut keys: Vec<(i32, i32)> = entity_groups
            .iter()
            .flat_map(|(&(dim, _), tags)| tags.iter().map(move |&t| (dim, t.abs())))
            .collect();
        keys.extend(names.iter().map(|(d, t, _)| (*d, *t)));
        keys.sort_unstable();
        keys.dedup();
        let groups: Vec<PhysicalGroup> = keys
            .iter()
            .map(|&(dim, tag)| PhysicalGroup {
                dim,
                tag,
                name: names
                    .iter()
                    .find(|(d, t, _)| *d == dim && *t == tag)
                    .map(|(_, _, n)| n.clone())
                    .unwrap_or_default(),
            })
            .collect();
        let mut group_elements: Vec<Vec<GmshElement>> = vec![Vec::new(); groups.len()];
        for block in &msh.element_blocks {
            let Some(tags) = entity_groups.get(&(block.entity_dim, block.entity_tag)) else {
                continue;
            };
            for t in tags {
                let g = keys
                    .binary_search(&(block.entity_dim, t.abs()))
                    .expect("every entity's physical tag is a group");
                let per = block.nodes_per_element;
                group_elements[g].extend(block.tags.iter().enumerate().map(|(k, &tag)| {
                    GmshElement {
                        tag,
                        kind: block.element_type,
                        nodes: block.nodes[k * per..(k + 1) * per].to_vec(),
                    }
                }));
            }
        }
        for elements in group_elements.iter_mut() {
            elements.sort_by_key(|e| e.tag);
        }
        Ok(GmshMesh {
            file: file.to_string(),
            nodes,
            groups,
            group_elements,
        })
    }

    /// The groups of one dimension named `name`; an error listing those there are when none is.
    fn find(&self, name: &str, dims: &[i32]) -> Result<Vec<usize>, String> {
        let found: Vec<usize> = (0..self.groups.len())
            .filter(|&g| dims.contains(&self.groups[g].dim) && self.groups[g].name == name)
            .collect();
        if found.is_empty() {
            let kind = match dims {
                [3] => "physical volume",
                [2] => "physical surface",
                _ => "physical group",
            };
            let available: Vec<String> = self
                .groups
                .iter()
                .filter(|g| dims.contains(&g.dim))
                .map(|g| {
                    if dims.len() > 1 {
                        format!("{} ({})", g.label(), dim_word(g.dim))
                    } else {
                        g.label()
                    }
                })
                .collect();
            return Err(format!(
                "{} has no {kind} named '{name}' ({}: {})",
                self.file,
                if dims.len() > 1 {
                    "physical groups"
                } else {
                    "the ones it has"
                },
                if available.is_empty() {
                    "none".to_string()
                } else {
                    available.join(", ")
                }
            ));
        }
        Ok(found)
    }

    /// The one group of dimension `dim` named `name`.
    fn find_one(&self, name: &str, dim: i32, what: &str) -> Result<usize, String> {
        match self.find(name, &[dim])?.as_slice() {
            [g] => Ok(*g),
            several => Err(format!(
                "{} has {} {what}s named '{name}' (tags {}); give them different names",
                self.file,
                several.len(),
                several
                    .iter()
                    .map(|&g| self.groups[g].tag.to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            )),
        }
    }

    /// The node tags of every physical group named `name` (of any dimension), sorted.
    pub fn group_nodes(&self, name: &str) -> Result<Vec<u64>, String> {
        let mut tags: Vec<u64> = Vec::new();
        for g in self.find(name, &[0, 1, 2, 3])? {
            tags.extend(self.group_elements[g].iter().flat_map(|e| e.nodes.clone()));
        }
        tags.sort_unstable();
        tags.dedup();
        if tags.is_empty() {
            return Err(format!(
                "physical group '{name}' of {} has no elements",
                self.file
            ));
        }
        Ok(tags)
    }

    fn node(&self, tag: u64, elements: &[GmshElement], group: &str) -> Result<Vec3, String> {
        self.nodes.get(&tag).copied().ok_or_else(|| {
            let e = elements
                .iter()
                .find(|e| e.nodes.contains(&tag))
                .map_or(0, |e| e.tag);
            format!(
                "element {e} of '{group}' in {} refers to node {tag}, which the file does not define",
                self.file
            )
        })
    }

    /// An error counting the elements of any type other than `kinds` (described by
    /// `supported`).
    fn only_types(
        &self,
        elements: &[GmshElement],
        kinds: &[i32],
        supported: &str,
        what: &str,
        name: &str,
    ) -> Result<(), String> {
        let other = count_types(elements.iter().filter(|e| !kinds.contains(&e.kind)));
        if other.is_empty() {
            return Ok(());
        }
        Err(format!(
            "{what} '{name}' of {} has {}; only {supported} are supported",
            self.file,
            type_counts(&other)
        ))
    }
}

/// Elements by type: (count, first tag) of each type.
fn count_types<'a>(elements: impl Iterator<Item = &'a GmshElement>) -> BTreeMap<i32, (usize, u64)> {
    let mut out: BTreeMap<i32, (usize, u64)> = BTreeMap::new();
    for e in elements {
        out.entry(e.kind).or_insert((0, e.tag)).0 += 1;
    }
    out
}

/// "3 elements of Gmsh type 6 (6-node prism; the first is element 12) and ...".
fn type_counts(counts: &BTreeMap<i32, (usize, u64)>) -> String {
    counts
        .iter()
        .map(|(&t, &(n, first))| {
            format!(
                "{n} element{} of Gmsh type {t} ({}; the first is element {first})",
                if n == 1 { "" } else { "s" },
                element_type_name(t)
            )
        })
        .collect::<Vec<_>>()
        .join(" and ")
}

fn dim_word(dim: i32) -> &'static str {
    match dim {
        0 => "point",
        1 => "curve",
        2 => "surface",
        _ => "volume",
    }
}

/// What a Gmsh element type number stands for (the common ones).
pub fn element_type_name(kind: i32) -> String {
    let s = match kind {
        1 => "2-node line",
        2 => "3-node triangle",
        3 => "4-node quadrangle",
        4 => "4-node tetrahedron",
        5 => "8-node hexahedron",
        6 => "6-node prism",
        7 => "5-node pyramid",
        8 => "3-node line",
        9 => "6-node triangle",
        10 => "9-node quadrangle",
        11 => "10-node tetrahedron",
        12 => "27-node hexahedron",
        13 => "18-node prism",
        14 => "14-node pyramid",
        15 => "1-node point",
        16 => "8-node quadrangle",
        17 => "20-node hexahedron",
        18 => "15-node prism",
        19 => "13-node pyramid",
        _ => return format!("higher-order or special element {kind}"),
    };
    s.to_string()
}

/// The version in the `$MeshFormat` header, if the bytes start like a Gmsh file.
fn format_version(bytes: &[u8]) -> Option<String> {
    let head = &bytes[..bytes.len().min(256)];
    let text = String::from_utf8_lossy(head);
    let mut lines = text.lines().map(str::trim).skip_while(|l| l.is_empty());
    if lines.next()? != "$MeshFormat" {
        return None;
    }
    lines.next()?.split_whitespace().next().map(str::to_string)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::hex8::NODE_XI;

    /// One unit cube in the ASCII format, with a physical volume and a physical surface
    /// (its z = 0 face), nodes placed at Gmsh's reference positions of a type 5 element.
    fn cube(hex_nodes: &str) -> String {
        format!(
            "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n2\n2 2 \"bottom\"\n3 1 \"cube\"\n$EndPhysicalNames\n\
$Entities\n0 0 1 1\n1 0 0 0 1 1 0 1 2 0\n1 0 0 0 1 1 1 1 1 0\n$EndEntities\n\
$Nodes\n1 8 1 8\n3 1 0 8\n1\n2\n3\n4\n5\n6\n7\n8\n\
0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n$EndNodes\n\
$Elements\n2 2 1 2\n2 1 3 1\n1 1 2 3 4\n3 1 5 1\n2 {hex_nodes}\n$EndElements\n"
        )
    }

    #[test]
    fn gmsh_hexahedron_order_is_ours() {
        // The nodes sit at (1 + xi) / 2 of Gmsh's reference coordinates, so the element is
        // the identity map scaled by one half: same node order, positive Jacobian.
        let m = GmshMesh::from_bytes(cube("1 2 3 4 5 6 7 8").as_bytes(), "cube.msh").unwrap();
        let v = m.volume("cube").unwrap();
        assert_eq!(v.elements.element(0), &[0, 1, 2, 3, 4, 5, 6, 7]);
        for a in 0..8 {
            for i in 0..3 {
                assert_eq!(v.coords[a][i], 0.5 * (1.0 + NODE_XI[a][i]));
            }
        }
        let bottom = m.surface_faces("bottom").unwrap();
        assert_eq!(bottom.len(), 1);
        assert_eq!(
            (bottom[0].tag, &bottom[0].corners[..]),
            (1, &[1, 2, 3, 4][..])
        );
        assert_eq!(m.group_nodes("bottom").unwrap(), vec![1, 2, 3, 4]);
    }

    #[test]
    fn sparse_node_tags_are_kept() {
        // Tags with gaps, not from 1: the hexahedron refers to them by tag.
        let text = cube("10 20 30 40 50 60 70 80")
            .replace(
                "1 8 1 8\n3 1 0 8\n1\n2\n3\n4\n5\n6\n7\n8\n",
                "1 8 10 80\n3 1 0 8\n10\n20\n30\n40\n50\n60\n70\n80\n",
            )
            .replace("1 1 2 3 4\n", "1 10 20 30 40\n");
        let m = GmshMesh::from_bytes(text.as_bytes(), "sparse.msh").unwrap();
        assert_eq!(m.nodes[&70], [1.0, 1.0, 1.0]);
        let v = m.volume("cube").unwrap();
        assert_eq!(v.node_tags, vec![10, 20, 30, 40, 50, 60, 70, 80]);
        assert_eq!(v.elements.element(0), &[0, 1, 2, 3, 4, 5, 6, 7]);
        assert_eq!(m.group_nodes("bottom").unwrap(), vec![10, 20, 30, 40]);
    }

    #[test]
    fn inverted_element_is_named() {
        let m = GmshMesh::from_bytes(cube("5 6 7 8 1 2 3 4").as_bytes(), "cube.msh").unwrap();
        let e = m.volume("cube").unwrap_err();
        assert!(e.contains("element 2 ") && e.contains("inverted"), "{e}");
    }

    #[test]
    fn missing_group_lists_the_others() {
        let m = GmshMesh::from_bytes(cube("1 2 3 4 5 6 7 8").as_bytes(), "cube.msh").unwrap();
        let e = m.volume("block").unwrap_err();
        assert!(
            e.contains("no physical volume named 'block'") && e.contains("'cube'"),
            "{e}"
        );
        let e = m.surface_faces("cube").unwrap_err();
        assert!(e.contains("'bottom'"), "{e}");
    }

    #[test]
    fn other_versions_are_refused() {
        let e =
            GmshMesh::from_bytes(b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n", "old.msh").unwrap_err();
        assert!(e.contains("format 2.2"), "{e}");
        let e = GmshMesh::from_bytes(b"solid\n", "x.msh").unwrap_err();
        assert!(e.contains("not a Gmsh mesh file"), "{e}");
    }
}
