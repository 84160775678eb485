//! Node sets and side sets of a scene: their selectors (plane, box, body, Gmsh physical
//! group), checked and resolved to nodes and faces.

use super::*;

impl Builder {
    pub(super) fn selector(
        &self,
        key: &str,
        s: &SetDef,
        default_tol: f64,
    ) -> Result<Option<Selector>, SceneError> {
        let tol = match s.tolerance {
            None => default_tol,
            Some(t) if t.is_finite() && t >= 0.0 => t,
            Some(t) => {
                return Err(self.err(
                    format!("{key}.tolerance"),
                    format!("expected a number >= 0, got {t}"),
                ))
            }
        };
        let given = [
            s.plane.is_some(),
            s.box_.is_some(),
            s.ids.is_some(),
            s.faces.is_some(),
            s.gmsh_group.is_some(),
            s.gmsh_surface.is_some(),
        ]
        .iter()
        .filter(|&&b| b)
        .count();
        if given != 1 {
            return Err(self.err(
                key,
                "expected exactly one of `plane`, `box`, `ids` or `gmsh_group` (node sets), `faces` or `gmsh_surface` (side sets)",
            ));
        }
        if let Some(p) = &s.plane {
            let point = self.finite3(&format!("{key}.plane.point"), &p.point)?;
            let normal = self.finite3(&format!("{key}.plane.normal"), &p.normal)?;
            if !(norm(&normal) > 0.0) {
                return Err(self.err(format!("{key}.plane.normal"), "expected a non-zero vector"));
            }
            return Ok(Some(Selector::plane(point, normal, tol)));
        }
        if let Some(b) = &s.box_ {
            let min = self.finite3(&format!("{key}.box.min"), &b.min)?;
            let max = self.finite3(&format!("{key}.box.max"), &b.max)?;
            if (0..3).any(|i| max[i] < min[i]) {
                return Err(self.err(
                    format!("{key}.box"),
                    "expected max >= min in every direction",
                ));
            }
            return Ok(Some(Selector::Box { min, max, tol }));
        }
        Ok(None)
    }

    pub(super) fn set_body(
        &self,
        key: &str,
        s: &SetDef,
        mesh: &GlobalMesh,
    ) -> Result<Option<usize>, SceneError> {
        match &s.body {
            None => Ok(None),
            Some(name) => mesh
                .bodies
                .iter()
                .position(|b| &b.name == name)
                .map(Some)
                .ok_or_else(|| {
                    self.err(
                        format!("{key}.body"),
                        format!(
                            "no body named '{name}' (defined: {})",
                            list(mesh.bodies.iter().map(|b| &b.name))
                        ),
                    )
                }),
        }
    }

    pub(super) fn node_sets(
        &self,
        raw: &SceneFile,
        mesh: &GlobalMesh,
        gmsh: Option<&GmshImport>,
        diag: f64,
    ) -> Result<Vec<NodeSet>, SceneError> {
        let mut out: Vec<NodeSet> = Vec::new();
        for (i, s) in raw.node_set.iter().enumerate() {
            let key = format!("node_set[{i}]");
            self.set_name(&key, &s.name, out.iter().map(|x| &x.name))?;
            self.not_given(
                &key,
                &[
                    (s.faces.is_some(), "faces"),
                    (s.gmsh_surface.is_some(), "gmsh_surface"),
                ],
                "selects side sets; a node set takes `plane`, `box`, `ids` or `gmsh_group`",
            )?;
            let body = self.set_body(&key, s, mesh)?;
            let nodes = match self.selector(&key, s, 1e-6 * diag)? {
                Some(sel) => select_nodes(mesh, &sel, body),
                None if s.gmsh_group.is_some() => {
                    let group = s.gmsh_group.as_deref().expect("checked");
                    self.needs_gmsh(&format!("{key}.gmsh_group"), gmsh)?
                        .node_set(self, &key, group, body)?
                }
                None => {
                    let ids = s.ids.as_ref().expect("one selector is present");
                    let mut nodes = Vec::with_capacity(ids.len());
                    for &id in ids {
                        if id < 1 || id as usize > mesh.num_nodes() {
                            return Err(self.err(
                                format!("{key}.ids"),
                                format!("node id {id} out of range 1..={}", mesh.num_nodes()),
                            ));
                        }
                        let n = (id - 1) as u32;
                        if let Some(b) = body {
                            if mesh.bodies[b].first_node > n as usize
                                || n as usize
                                    >= mesh.bodies[b].first_node + mesh.bodies[b].num_nodes
                            {
                                return Err(self.err(
                                    format!("{key}.ids"),
                                    format!(
                                        "node id {id} is not in body '{}'",
                                        mesh.bodies[b].name
                                    ),
                                ));
                            }
                        }
                        nodes.push(n);
                    }
                    nodes.sort_unstable();
                    nodes.dedup();
                    nodes
                }
            };
            if nodes.is_empty() {
                return Err(self.err(
                    &key,
                    format!(
                        "node set '{}' selects no nodes (check the plane/box and its tolerance)",
                        s.name
                    ),
                ));
            }
            out.push(NodeSet {
                name: s.name.clone(),
                nodes,
            });
        }
        Ok(out)
    }

    pub(super) fn side_sets(
        &self,
        raw: &SceneFile,
        mesh: &GlobalMesh,
        gmsh: Option<&GmshImport>,
        boundary: &[(u32, u8)],
        diag: f64,
    ) -> Result<Vec<SideSet>, SceneError> {
        let mut out: Vec<SideSet> = Vec::new();
        for (i, s) in raw.side_set.iter().enumerate() {
            let key = format!("side_set[{i}]");
            self.set_name(&key, &s.name, out.iter().map(|x| &x.name))?;
            self.not_given(
                &key,
                &[
                    (s.ids.is_some(), "ids"),
                    (s.gmsh_group.is_some(), "gmsh_group"),
                ],
                "selects nodes; a side set takes `plane`, `box`, `faces` or `gmsh_surface`",
            )?;
            let body = self.set_body(&key, s, mesh)?;
            let faces = match self.selector(&key, s, 1e-6 * diag)? {
                Some(sel) => select_faces(mesh, boundary, &sel, body),
                None if s.gmsh_surface.is_some() => {
                    let surface = s.gmsh_surface.as_deref().expect("checked");
                    self.needs_gmsh(&format!("{key}.gmsh_surface"), gmsh)?
                        .side_set(self, &key, surface, mesh, boundary, body)?
                }
                None => {
                    let pairs = s.faces.as_ref().expect("one selector is present");
                    let mut faces = Vec::with_capacity(pairs.len());
                    for p in pairs {
                        let of_element = (p[0] >= 1 && p[0] as usize <= mesh.num_elements())
                            .then(|| mesh.kind(p[0] as usize - 1).faces());
                        if !of_element.is_some_and(|n| (0..n as i64).contains(&p[1])) {
                            let most = ElementKind::ALL.iter().map(|k| k.faces()).max();
                            return Err(self.err(
                                format!("{key}.faces"),
                                format!(
                                    "expected [element id in 1..={}, face in 0..={}], got {p:?}",
                                    mesh.num_elements(),
                                    of_element.or(most).unwrap_or(1) - 1
                                ),
                            ));
                        }
                        let f = ((p[0] - 1) as u32, p[1] as u8);
                        if !boundary.contains(&f) {
                            return Err(self.err(
                                format!("{key}.faces"),
                                format!("face {p:?} is not on the boundary of its body"),
                            ));
                        }
                        faces.push(f);
                    }
                    faces.sort_unstable();
                    faces.dedup();
                    faces
                }
            };
            if faces.is_empty() {
                return Err(self.err(&key, format!("side set '{}' selects no boundary faces (check the plane/box and its tolerance)", s.name)));
            }
            out.push(SideSet {
                name: s.name.clone(),
                faces,
            });
        }
        Ok(out)
    }

    /// An error for the first of `given` that is present: `` `<key>` <message>``.
    pub(super) fn not_given(
        &self,
        key: &str,
        given: &[(bool, &str)],
        message: &str,
    ) -> Result<(), SceneError> {
        match given.iter().find(|g| g.0) {
            Some((_, what)) => {
                Err(self.err(format!("{key}.{what}"), format!("`{what}` {message}")))
            }
            None => Ok(()),
        }
    }

    pub(super) fn set_name<'a>(
        &self,
        key: &str,
        name: &str,
        mut existing: impl Iterator<Item = &'a String>,
    ) -> Result<(), SceneError> {
        if name.is_empty() || name.contains('/') {
            return Err(self.err(
                format!("{key}.name"),
                "expected a non-empty name without '/'",
            ));
        }
        if existing.any(|n| n == name) {
            return Err(self.err(
                format!("{key}.name"),
                format!("set name '{name}' used twice"),
            ));
        }
        Ok(())
    }
}
