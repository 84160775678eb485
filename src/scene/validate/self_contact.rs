//! `[general_contact] self`: a body's exterior nodes against its own exterior faces, one
//! node-to-face pass per body (`ContactPair::neighbourhood`), with the general contact's
//! default interaction. A node is never tied to the faces around it (those sharing a node
//! with a face that holds it) nor to a face whose normal does not oppose its own (the
//! general slave normals); one side of each contact zone is the slave
//! (`contact::self_contact`).

use super::contacts::surface_nodes;
use super::general::{interaction, node_normals, Skin};
use super::*;
use crate::problem::ContactPair;
use std::collections::HashMap;
use std::sync::Arc;

impl Builder {
    /// The self contact passes of the bodies `self` names (none without it).
    pub(super) fn self_contacts(
        &self,
        g: &GeneralContactDef,
        mesh: &GlobalMesh,
        left_out: &[bool],
        skins: &[Option<Skin>],
    ) -> Result<Vec<ContactPair>, SceneError> {
        let bodies = self.self_bodies(g, mesh, left_out, skins)?;
        if bodies.is_empty() {
            return Ok(Vec::new());
        }
        let def = interaction(g, None);
        let key = "general_contact.self";
        if self.discretization(key, &def)? != Discretization::NodeFace {
            return Err(self.err(
                key,
                "self contact is node-to-face only (mortar self contact is not done): leave \
                 general_contact.discretization unset and give the body pairs that want mortar \
                 a [[general_contact.pair]] with discretization = \"mortar\"",
            ));
        }
        let mut out = Vec::new();
        for b in bodies {
            let s = skins[b]
                .as_ref()
                .expect("a body in self contact has a skin");
            let name = &mesh.bodies[b].name;
            let k = format!("{key} ({name})");
            let (normal, tangential, capture, smoothing) = self.tolerances(&k, &def, s.size)?;
            let mut pair = ContactPair::new(
                format!("general:{name}/self"),
                mesh,
                s.faces.clone(),
                surface_nodes(mesh, &s.faces),
                self.friction_coefficient(&k, &def)?,
                normal,
                tangential,
                capture,
                smoothing,
                s.size,
            )
            .with_slave_faces(mesh, s.faces.clone(), Discretization::NodeFace);
            pair.slave_normals = Some(Arc::new(node_normals(mesh, &pair.slave_nodes, &s.faces)));
            pair.neighbourhood = Some(neighbourhood(&pair.slave_nodes, &pair.face_nodes));
            out.push(pair);
        }
        Ok(out)
    }

    /// The bodies in self contact, ascending: `self = true` every body not left out whose
    /// nodes are not all prescribed, `false` none, a list the bodies it names.
    fn self_bodies(
        &self,
        g: &GeneralContactDef,
        mesh: &GlobalMesh,
        left_out: &[bool],
        skins: &[Option<Skin>],
    ) -> Result<Vec<usize>, SceneError> {
        let key = "general_contact.self";
        let movable = |b: usize| skins[b].as_ref().is_some_and(|s| !s.rigid);
        let names = match &g.self_contact {
            None | Some(toml::Value::Boolean(false)) => return Ok(Vec::new()),
            Some(toml::Value::Boolean(true)) => {
                return Ok((0..mesh.bodies.len()).filter(|&b| movable(b)).collect())
            }
            Some(toml::Value::Array(names)) => names,
            Some(v) => {
                return Err(self.err(
                    key,
                    format!(
                        "expected true, false or a list of body names, got {}",
                        v.type_str()
                    ),
                ))
            }
        };
        let mut out = Vec::new();
        for (i, v) in names.iter().enumerate() {
            let k = format!("{key}[{i}]");
            let Some(name) = v.as_str() else {
                return Err(self.err(&k, format!("expected a body name, got {}", v.type_str())));
            };
            let b = mesh
                .bodies
                .iter()
                .position(|body| body.name == name)
                .ok_or_else(|| {
                    self.err(
                        &k,
                        format!(
                            "no body named '{name}' (defined: {})",
                            list(mesh.bodies.iter().map(|b| &b.name))
                        ),
                    )
                })?;
            if left_out[b] {
                return Err(self.err(
                    &k,
                    format!("body '{name}' is left out by general_contact.exclude"),
                ));
            }
            if !movable(b) {
                return Err(self.err(
                    &k,
                    format!("body '{name}' has every node prescribed: it cannot touch itself"),
                ));
            }
            if out.contains(&b) {
                return Err(self.err(&k, format!("body '{name}' is listed twice")));
            }
            out.push(b);
        }
        out.sort_unstable();
        Ok(out)
    }
}

/// Per slave node, the facets (indices in `face_nodes`, ascending) around it: every facet
/// that shares a node with a facet holding the node. A node at a corner is as near to the
/// faces next to the faces it is on as to those (at zero distance across the corner's
/// edges), and none of them is a surface it can come to touch.
pub(super) fn neighbourhood(slave_nodes: &[u32], face_nodes: &[[u32; 4]]) -> Vec<Vec<u32>> {
    let mut facets_of: HashMap<u32, Vec<u32>> = HashMap::new();
    for (f, nodes) in face_nodes.iter().enumerate() {
        let mut nodes = *nodes;
        nodes.sort_unstable();
        for (k, &n) in nodes.iter().enumerate() {
            if k == 0 || nodes[k - 1] != n {
                facets_of.entry(n).or_default().push(f as u32);
            }
        }
    }
    let none = Vec::new();
    slave_nodes
        .iter()
        .map(|n| {
            let mut out: Vec<u32> = facets_of
                .get(n)
                .unwrap_or(&none)
                .iter()
                .flat_map(|&f| face_nodes[f as usize])
                .flat_map(|m| facets_of.get(&m).unwrap_or(&none).iter().copied())
                .collect();
            out.sort_unstable();
            out.dedup();
            out
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::neighbourhood;

    #[test]
    fn the_faces_around_a_node_are_those_touching_its_faces() {
        // A strip of four quadrilaterals in a row, nodes 0-4 below and 5-9 above; face k
        // is [k, k + 1, k + 6, k + 5]. Node 0 is on face 0, whose nodes 1 and 6 are on
        // face 1 too; node 2 is on faces 1 and 2, whose nodes reach faces 0 to 3.
        let faces: Vec<[u32; 4]> = (0..4).map(|k| [k, k + 1, k + 6, k + 5]).collect();
        let n = neighbourhood(&[0, 2, 4], &faces);
        assert_eq!(n, vec![vec![0, 1], vec![0, 1, 2, 3], vec![2, 3]]);
        // A triangle's fourth node repeats its third, and counts once.
        let tri = vec![[0, 1, 2, 2], [2, 3, 4, 4], [4, 5, 6, 6]];
        assert_eq!(
            neighbourhood(&[0, 3], &tri),
            vec![vec![0, 1], vec![0, 1, 2]]
        );
    }
}
