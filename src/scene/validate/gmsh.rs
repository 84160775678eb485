//! The scene's Gmsh mesh: bodies from physical volumes, node sets from physical groups,
//! side sets from physical surfaces. Gmsh node tags become the solver's node numbers here and
//! nowhere else.

use super::error::{Builder, SceneError};
use crate::fem::kind::ElementKind;
use crate::math::Vec3;
use crate::mesh::gmsh::surface::SurfaceFace;
use crate::mesh::gmsh::GmshMesh;
use crate::mesh::{Connectivity, GlobalMesh};
use crate::scene::types::GmshDef;
use std::collections::HashMap;
use std::path::Path;

/// The mesh file and which solver node each Gmsh node tag became.
pub(super) struct GmshImport {
    mesh: GmshMesh,
    /// Gmsh node tag -> (global node index, body index, physical volume name).
    nodes: HashMap<u64, (u32, usize, String)>,
    /// The corner tags (smaller first) of an edge whose midside node was inserted (a body
    /// of 4-node tetrahedra) -> (global node index, body index).
    midsides: HashMap<(u64, u64), (u32, usize)>,
}

/// The message for a Gmsh key in a scene without a `[gmsh]` table.
pub(super) const NEEDS_GMSH: &str =
    "needs the mesh file: add `[gmsh]` with `file = \"<mesh>.msh\"` (or `[exodus]` with `file = \"<mesh>.e\"`)";

/// The mesh files a scene reads: its `[gmsh] file`, relative to the scene file `file` (none
/// when the scene text does not parse or has no `[gmsh]` table).
pub fn mesh_files(file: &str, text: &str) -> Vec<std::path::PathBuf> {
    let dir = Path::new(file).parent().unwrap_or(Path::new(""));
    toml::from_str::<crate::scene::types::SceneFile>(text)
        .ok()
        .map(|s| {
            s.gmsh
                .into_iter()
                .chain(s.exodus)
                .map(|g| dir.join(g.file))
                .collect()
        })
        .unwrap_or_default()
}

impl Builder {
    /// The scene's Gmsh mesh, or an error at `key` when it has none.
    pub(super) fn needs_gmsh<'a>(
        &self,
        key: &str,
        gmsh: Option<&'a GmshImport>,
    ) -> Result<&'a GmshImport, SceneError> {
        gmsh.ok_or_else(|| self.err(key, NEEDS_GMSH))
    }

    /// Reads the `[gmsh]` file, its path taken relative to the scene file.
    pub(super) fn gmsh_file(&self, def: &GmshDef) -> Result<GmshImport, SceneError> {
        let dir = Path::new(&self.file).parent().unwrap_or(Path::new(""));
        let path = dir.join(&def.file);
        if !path.is_file() {
            return Err(self.err(
                "gmsh.file",
                format!(
                    "no mesh file {} (the path is relative to the scene file)",
                    path.display()
                ),
            ));
        }
        let mesh = GmshMesh::read(&path).map_err(|m| self.err("gmsh.file", m))?;
        Ok(GmshImport {
            mesh,
            nodes: HashMap::new(),
            midsides: HashMap::new(),
        })
    }

    /// Reads the `[exodus]` file, its path taken relative to the scene file.
    pub(super) fn exodus_file(&self, def: &GmshDef) -> Result<GmshImport, SceneError> {
        let dir = Path::new(&self.file).parent().unwrap_or(Path::new(""));
        let path = dir.join(&def.file);
        if !path.is_file() {
            return Err(self.err(
                "exodus.file",
                format!(
                    "no mesh file {} (the path is relative to the scene file)",
                    path.display()
                ),
            ));
        }
        let mesh =
            crate::mesh::exodus::read_exodus(&path).map_err(|m| self.err("exodus.file", m))?;
        Ok(GmshImport {
            mesh,
            nodes: HashMap::new(),
            midsides: HashMap::new(),
        })
    }
}

impl GmshImport {
    /// The nodes (in node tag order, then the inserted midside nodes), element kind and
    /// elements (0-based, local) of body `body`, the physical volume `volume`, whose first
    /// node will be global node `first_node`.
    pub(super) fn add_body(
        &mut self,
        b: &Builder,
        key: &str,
        volume: &str,
        body: usize,
        first_node: usize,
    ) -> Result<(Vec<Vec3>, ElementKind, Connectivity), SceneError> {
        let key = format!("{key}.gmsh_volume");
        let v = self.mesh.volume(volume).map_err(|m| b.err(&key, m))?;
        for (i, tag) in v.node_tags.iter().enumerate() {
            if let Some((_, _, other)) = self.nodes.get(tag) {
                return Err(b.err(
                    &key,
                    format!(
                        "physical volumes '{other}' and '{volume}' of {} share node {tag}; bodies cannot share nodes (mesh them as separate volumes and join them by contact)",
                        self.mesh.file
                    ),
                ));
            }
            self.nodes
                .insert(*tag, ((first_node + i) as u32, body, volume.to_string()));
        }
        let first_midside = first_node + v.node_tags.len();
        for (i, &pair) in v.midsides.iter().enumerate() {
            self.midsides
                .insert(pair, ((first_midside + i) as u32, body));
        }
        Ok((v.coords, v.kind, v.elements))
    }

    fn global_node(&self, b: &Builder, key: &str, tag: u64, what: &str) -> Result<u32, SceneError> {
        self.nodes.get(&tag).map(|n| n.0).ok_or_else(|| {
            b.err(
                key,
                format!(
                    "{what} has node {tag}, which is in no body's physical volume (only nodes of the [[body]] volumes of {} can be used)",
                    self.mesh.file
                ),
            )
        })
    }

    /// Global nodes of the physical groups named `group`, optionally only those of `body`.
    pub(super) fn node_set(
        &self,
        b: &Builder,
        key: &str,
        group: &str,
        body: Option<usize>,
    ) -> Result<Vec<u32>, SceneError> {
        let key = format!("{key}.gmsh_group");
        let tags = self.mesh.group_nodes(group).map_err(|m| b.err(&key, m))?;
        let mut nodes = Vec::with_capacity(tags.len());
        for tag in tags {
            let what = format!("physical group '{group}'");
            let n = self.global_node(b, &key, tag, &what)?;
            if body.is_none_or(|bi| self.nodes[&tag].1 == bi) {
                nodes.push(n);
            }
        }
        if !self.midsides.is_empty() {
            let edges = self.mesh.group_edges(group).map_err(|m| b.err(&key, m))?;
            for pair in edges {
                if let Some(&(n, bi)) = self.midsides.get(&pair) {
                    if body.is_none_or(|only| only == bi) {
                        nodes.push(n);
                    }
                }
            }
        }
        nodes.sort_unstable();
        Ok(nodes)
    }

    /// The (element, local face) under each quadrangle or triangle of the physical
    /// surface `surface` (matched by its corners; a 6-node triangle's midside nodes must be
    /// the face's), optionally only faces of `body`. Every one must be a boundary face of a
    /// body.
    pub(super) fn side_set(
        &self,
        b: &Builder,
        key: &str,
        surface: &str,
        mesh: &GlobalMesh,
        boundary: &[(u32, u8)],
        body: Option<usize>,
    ) -> Result<Vec<(u32, u8)>, SceneError> {
        let key = format!("{key}.gmsh_surface");
        let elements = self
            .mesh
            .surface_faces(surface)
            .map_err(|m| b.err(&key, m))?;
        let on_boundary: HashMap<[u32; 4], (u32, u8)> = boundary
            .iter()
            .map(|&(e, f)| (mesh.face_key(e, f), (e, f)))
            .collect();
        let mut faces = Vec::with_capacity(elements.len());
        for s in elements {
            let what = format!(
                "{} {} of physical surface '{surface}'",
                if s.corners.len() == 4 {
                    "quadrangle"
                } else {
                    "triangle"
                },
                s.tag
            );
            let mut k = [u32::MAX; 4];
            for (slot, &tag) in k.iter_mut().zip(&s.corners) {
                *slot = self.global_node(b, &key, tag, &what)?;
            }
            k.sort_unstable();
            let Some(&(e, f)) = on_boundary.get(&k) else {
                return Err(self.unmatched(b, &key, &what, mesh, k));
            };
            self.check_midsides(b, &key, &what, mesh, (e, f), &s)?;
            if body.is_none_or(|bi| mesh.element_body[e as usize] as usize == bi) {
                faces.push((e, f));
            }
        }
        faces.sort_unstable();
        faces.dedup();
        Ok(faces)
    }

    /// The error for a surface element whose corners `k` (sorted) are no boundary face.
    fn unmatched(
        &self,
        b: &Builder,
        key: &str,
        what: &str,
        mesh: &GlobalMesh,
        k: [u32; 4],
    ) -> SceneError {
        let inner = (0..mesh.num_elements())
            .any(|e| (0..mesh.kind(e).faces() as u8).any(|f| mesh.face_key(e as u32, f) == k));
        b.err(
            key,
            format!(
                "{what} in {} is {}",
                self.mesh.file,
                if inner {
                    "a face between two elements, not on a body's boundary"
                } else {
                    "not a face of any body's element (its corners are no hexahedron's or tetrahedron's face)"
                }
            ),
        )
    }

    /// A 6-node triangle's midside nodes are those of the face its corners matched.
    fn check_midsides(
        &self,
        b: &Builder,
        key: &str,
        what: &str,
        mesh: &GlobalMesh,
        (e, f): (u32, u8),
        s: &SurfaceFace,
    ) -> Result<(), SceneError> {
        if s.midsides.is_empty() {
            return Ok(());
        }
        let corners = mesh.kind(e as usize).face_kind(f as usize).corners();
        let mut want: Vec<u32> = mesh.face_nodes(e, f).skip(corners).collect();
        let mut have: Vec<u32> = s
            .midsides
            .iter()
            .map(|t| self.nodes.get(t).map_or(u32::MAX, |n| n.0))
            .collect();
        want.sort_unstable();
        have.sort_unstable();
        if want == have {
            return Ok(());
        }
        Err(b.err(
            key,
            format!(
                "{what} in {} has the corners of a face of element {} but not its midside nodes (tags {:?}); is the surface meshed at another order than the volume?",
                self.mesh.file,
                e + 1,
                s.midsides
            ),
        ))
    }
}
