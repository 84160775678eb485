//! Exodus II meshes (Cubit's, Sierra's, MOOSE's `.e`/`.exo`/`.g`), read through netCDF into
//! the form a Gmsh mesh takes ([`GmshMesh`]), so that the scene's checks and numbering are
//! the Gmsh mesh's: element blocks become groups of dimension 3 (bodies), side sets groups of
//! dimension 2 whose quadrangles are the hexahedron faces they name, node sets groups of
//! dimension 0 (one point element per node). The node and element number maps give the
//! tags (our ids), as Gmsh's tags do; a file without maps numbers from 1.
//!
//! Blocks and sets are found by their names (`eb_names`, `ns_names`, `ss_names`), or
//! `block_<id>`, `nodelist_<id>` and `surface_<id>` where unnamed (Cubit's and IOSS's
//! defaults). HEX8 blocks (`HEX`, `HEX8`, `HEXAHEDRON`) and TETRA4 and TETRA10 blocks
//! (`TETRA`, `TETRA4`, `TETRA10`, `TET4`, `TET10`) are read, the 4-node tetrahedra as 10-node
//! ones as a Gmsh mesh's are; Exodus's node orders and side numbers are those of `fem::hex8`
//! and `fem::tet10` (sides 1-based), and a tetrahedron's side becomes the triangle of its
//! corners.

use std::collections::BTreeMap;
use std::path::Path;

use netcdf::File;

use super::gmsh::{
    GmshElement, GmshMesh, PhysicalGroup, GMSH_HEX8, GMSH_QUAD4, GMSH_TET10, GMSH_TET4, GMSH_TRI3,
};
use crate::fem::hex8::FACES;
use crate::fem::tet10;
use crate::output::exodus::{rows_to_names, NcChar};

/// Gmsh's 1-node point element, which node sets are made of.
const GMSH_POINT: i32 = 15;

/// The file as read: plain errors naming the file and the item.
struct Reader<'a> {
    nc: File,
    file: &'a str,
}

impl Reader<'_> {
    fn len(&self, dim: &str) -> usize {
        self.nc.dimension_len(dim).unwrap_or(0)
    }

    fn ints(&self, var: &str) -> Result<Vec<i64>, String> {
        let v = self
            .nc
            .variable(var)
            .ok_or_else(|| format!("{}: missing variable {var}", self.file))?;
        v.get_values::<i64, _>(..)
            .map_err(|e| format!("{}: cannot read {var}: {e}", self.file))
    }

    fn floats(&self, var: &str) -> Result<Vec<f64>, String> {
        let v = self
            .nc
            .variable(var)
            .ok_or_else(|| format!("{}: missing variable {var}", self.file))?;
        v.get_values::<f64, _>(..)
            .map_err(|e| format!("{}: cannot read {var}: {e}", self.file))
    }

    /// The names of `count` blocks or sets from `var`, `<default>_<id>` where empty.
    fn names(&self, var: &str, ids: &[i64], default: &str) -> Vec<String> {
        let width = self.len("len_name").max(1);
        let read = self
            .nc
            .variable(var)
            .and_then(|v| v.get_values::<NcChar, _>(..).ok())
            .map(|b| rows_to_names(&b, width))
            .unwrap_or_default();
        ids.iter()
            .enumerate()
            .map(|(i, id)| match read.get(i) {
                Some(n) if !n.trim().is_empty() => n.trim().to_string(),
                _ => format!("{default}_{id}"),
            })
            .collect()
    }

    /// The ids of `count` blocks or sets (`<prefix>_prop1`), 1.. when absent.
    fn ids(&self, prefix: &str, count: usize) -> Vec<i64> {
        self.ints(&format!("{prefix}_prop1"))
            .ok()
            .filter(|v| v.len() == count)
            .unwrap_or_else(|| (1..=count as i64).collect())
    }

    /// The number map `var` of `count` entries (1.. when absent), as tags.
    fn map(&self, var: &str, count: usize) -> Result<Vec<u64>, String> {
        if self.nc.variable(var).is_none() {
            return Ok((1..=count as u64).collect());
        }
        let ids = self.ints(var)?;
        if ids.len() != count {
            return Err(format!(
                "{}: {var} has {} entries for {count}",
                self.file,
                ids.len()
            ));
        }
        ids.iter()
            .map(|&i| u64::try_from(i).ok().filter(|&i| i > 0))
            .collect::<Option<Vec<u64>>>()
            .ok_or_else(|| format!("{}: {var} holds an id below 1", self.file))
    }
}

/// Reads an Exodus II file as a [`GmshMesh`] (see the module's notes).
pub fn read_exodus(path: &Path) -> Result<GmshMesh, String> {
    let file = path.display().to_string();
    let nc = netcdf::open(path).map_err(|e| {
        format!("{file} is not a readable Exodus II (netCDF) file (truncated or damaged?): {e}")
    })?;
    let r = Reader { nc, file: &file };
    check_size(&r, path)?;
    if r.len("num_dim") != 3 {
        return Err(format!(
            "{file}: the mesh has {} dimensions; only 3-D meshes are read",
            r.len("num_dim")
        ));
    }
    let num_nodes = r.len("num_nodes");
    let node_tags = r.map("node_num_map", num_nodes)?;
    let mut nodes = BTreeMap::new();
    let (x, y, z) = (
        r.floats("coordx")?,
        r.floats("coordy")?,
        r.floats("coordz")?,
    );
    if x.len() != num_nodes || y.len() != num_nodes || z.len() != num_nodes {
        return Err(format!(
            "{file}: coordx/y/z do not hold {num_nodes} nodes each"
        ));
    }
    for (i, &t) in node_tags.iter().enumerate() {
        if nodes.insert(t, [x[i], y[i], z[i]]).is_some() {
            return Err(format!("{file}: node_num_map holds id {t} twice"));
        }
    }
    let mut mesh = GmshMesh {
        file: file.clone(),
        nodes,
        groups: Vec::new(),
        group_elements: Vec::new(),
    };
    let blocks = read_blocks(&r, &node_tags, &mut mesh)?;
    read_node_sets(&r, &node_tags, &mut mesh)?;
    read_side_sets(&r, &blocks, &mut mesh)?;
    Ok(mesh)
}

/// Every element of the file in order: its tag, Gmsh type and node tags (in Gmsh's order).
struct Elements {
    tags: Vec<u64>,
    kinds: Vec<i32>,
    nodes: Vec<Vec<u64>>,
    /// The block name of each element (for messages).
    block: Vec<usize>,
    names: Vec<String>,
}

fn read_blocks(r: &Reader, node_tags: &[u64], mesh: &mut GmshMesh) -> Result<Elements, String> {
    let count = r.len("num_el_blk");
    let ids = r.ids("eb", count);
    let names = r.names("eb_names", &ids, "block");
    let elem_tags = r.map("elem_num_map", r.len("num_elem"))?;
    let mut all = Elements {
        tags: Vec::new(),
        kinds: Vec::new(),
        nodes: Vec::new(),
        block: Vec::new(),
        names: names.clone(),
    };
    for b in 0..count {
        let var = format!("connect{}", b + 1);
        let label = format!("element block '{}' (id {})", names[b], ids[b]);
        let n_el = r.len(&format!("num_el_in_blk{}", b + 1));
        let per = r.len(&format!("num_nod_per_el{}", b + 1));
        let kind =
            r.nc.variable(&var)
                .and_then(|v| v.attribute_value("elem_type"))
                .and_then(|a| a.ok())
                .and_then(|a| String::try_from(a).ok())
                .unwrap_or_default();
        let upper = kind.trim().to_ascii_uppercase();
        let gmsh_type = match (upper.as_str(), per) {
            ("HEX" | "HEX8" | "HEXAHEDRON", 8) => GMSH_HEX8,
            ("TETRA" | "TETRA4" | "TET" | "TET4", 4) => GMSH_TET4,
            ("TETRA" | "TETRA10" | "TET10", 10) => GMSH_TET10,
            _ if n_el == 0 => GMSH_HEX8,
            _ => {
                return Err(format!(
                    "{}: {label} has element type '{kind}' ({per} nodes); only HEX8, TETRA4 and TETRA10 blocks are read",
                    r.file
                ))
            }
        };
        let conn = if n_el > 0 { r.ints(&var)? } else { Vec::new() };
        let mut elements = Vec::with_capacity(n_el);
        for (e, row) in conn.chunks(per.max(1)).enumerate() {
            let g = all.tags.len();
            let tag = *elem_tags.get(g).ok_or_else(|| {
                format!("{}: the blocks hold more elements than num_elem", r.file)
            })?;
            let mut nodes = Vec::with_capacity(per);
            for &id in row {
                let k = usize::try_from(id - 1)
                    .ok()
                    .filter(|&k| k < node_tags.len());
                nodes.push(
                    node_tags[k.ok_or_else(|| {
                        format!(
                        "{}: element {} of {label} refers to node {id}, but the file has {} nodes",
                        r.file,
                        e + 1,
                        node_tags.len()
                    )
                    })?],
                );
            }
            if gmsh_type == GMSH_TET10 {
                // Exodus's TETRA10 order is ours; Gmsh's swaps the last two nodes.
                nodes.swap(8, 9);
            }
            all.tags.push(tag);
            all.kinds.push(gmsh_type);
            all.nodes.push(nodes.clone());
            all.block.push(b);
            elements.push(GmshElement {
                tag,
                kind: gmsh_type,
                nodes,
            });
        }
        elements.sort_by_key(|e| e.tag);
        push_group(mesh, 3, ids[b], &names[b], elements);
    }
    Ok(all)
}

fn push_group(mesh: &mut GmshMesh, dim: i32, id: i64, name: &str, elements: Vec<GmshElement>) {
    mesh.groups.push(PhysicalGroup {
        dim,
        tag: id as i32,
        name: name.to_string(),
    });
    mesh.group_elements.push(elements);
}

fn read_node_sets(r: &Reader, node_tags: &[u64], mesh: &mut GmshMesh) -> Result<(), String> {
    let count = r.len("num_node_sets");
    let ids = r.ids("ns", count);
    let names = r.names("ns_names", &ids, "nodelist");
    for s in 0..count {
        let nodes = if r.len(&format!("num_nod_ns{}", s + 1)) > 0 {
            r.ints(&format!("node_ns{}", s + 1))?
        } else {
            Vec::new()
        };
        let mut elements = Vec::with_capacity(nodes.len());
        for &n in &nodes {
            let k = usize::try_from(n - 1).ok().filter(|&k| k < node_tags.len());
            let tag = node_tags[k.ok_or_else(|| {
                format!(
                    "{}: node set '{}' names node {n}, but the file has {} nodes",
                    r.file,
                    names[s],
                    node_tags.len()
                )
            })?];
            elements.push(GmshElement {
                tag,
                kind: GMSH_POINT,
                nodes: vec![tag],
            });
        }
        push_group(mesh, 0, ids[s], &names[s], elements);
    }
    Ok(())
}

fn read_side_sets(r: &Reader, all: &Elements, mesh: &mut GmshMesh) -> Result<(), String> {
    let count = r.len("num_side_sets");
    let ids = r.ids("ss", count);
    let names = r.names("ss_names", &ids, "surface");
    // Quadrangle tags after the elements' own, so that no tag is used twice.
    let mut next_tag = all.tags.iter().copied().max().unwrap_or(0) + 1;
    for s in 0..count {
        let (elems, sides) = if r.len(&format!("num_side_ss{}", s + 1)) > 0 {
            (
                r.ints(&format!("elem_ss{}", s + 1))?,
                r.ints(&format!("side_ss{}", s + 1))?,
            )
        } else {
            (Vec::new(), Vec::new())
        };
        let label = format!("side set '{}' (id {})", names[s], ids[s]);
        let mut quads = Vec::with_capacity(elems.len());
        for (&e, &side) in elems.iter().zip(&sides) {
            let k = usize::try_from(e - 1)
                .ok()
                .filter(|&k| k < all.tags.len())
                .ok_or_else(|| {
                    format!(
                        "{}: {label} names element {e}, but the file's blocks hold {} elements",
                        r.file,
                        all.tags.len()
                    )
                })?;
            let hex = all.kinds[k] == GMSH_HEX8;
            let sides = if hex { 6 } else { 4 };
            let f = usize::try_from(side - 1).ok().filter(|&f| f < sides).ok_or_else(|| {
                format!(
                    "{}: {label} names side {side} of element {e} (block '{}'); a {} has sides 1 to {sides}",
                    r.file,
                    all.names[all.block[k]],
                    if hex { "HEX8" } else { "TETRA" }
                )
            })?;
            // A tetrahedron's side as the triangle of its corners (matched by them).
            let (kind, corners): (i32, &[usize]) = if hex {
                (GMSH_QUAD4, &FACES[f])
            } else {
                (GMSH_TRI3, &tet10::FACES[f][..3])
            };
            quads.push(GmshElement {
                tag: next_tag,
                kind,
                nodes: corners.iter().map(|&a| all.nodes[k][a]).collect(),
            });
            next_tag += 1;
        }
        push_group(mesh, 2, ids[s], &names[s], quads);
    }
    Ok(())
}

/// A classic netCDF file cut short still opens, and reads past its end as zeros: its
/// variables' bytes (a lower bound, without the header and padding) must fit in the file.
/// Only classic files (signature `CDF`): a netCDF-4 file is HDF5, which checks itself, and
/// may be compressed below this bound.
fn check_size(r: &Reader, path: &Path) -> Result<(), String> {
    let mut magic = [0u8; 3];
    let classic = std::fs::File::open(path)
        .and_then(|mut f| std::io::Read::read_exact(&mut f, &mut magic))
        .is_ok()
        && &magic == b"CDF";
    if !classic {
        return Ok(());
    }
    let have = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    let mut need = 0u64;
    for v in r.nc.variables() {
        let dims = v.dimensions();
        let records = dims.first().filter(|d| d.is_unlimited()).map(|d| d.len());
        let per: usize = dims
            .iter()
            .skip(usize::from(records.is_some()))
            .map(|d| d.len())
            .product();
        let bytes = (per * v.vartype().size()) as u64;
        need += bytes * records.map_or(1, |n| n as u64);
    }
    if have < need {
        return Err(format!(
            "{} is truncated: its variables need at least {need} bytes, the file has {have}",
            r.file
        ));
    }
    Ok(())
}
