//! The `[[contact]]` pairs of a scene: the master side set and slave node set, Coulomb's
//! coefficient and the search tolerances, checked and resolved into the problem's pairs.

use super::*;

impl Builder {
    pub(super) fn contacts(
        &self,
        raw: &SceneFile,
        mesh: &GlobalMesh,
        side_sets: &[SideSet],
        node_sets: &[NodeSet],
        dirichlet: &[Dirichlet],
    ) -> Result<Vec<crate::problem::ContactPair>, SceneError> {
        use crate::problem::ContactPair;
        let mut out: Vec<ContactPair> = Vec::new();
        // Directions fixed by Dirichlet conditions, per node, to find slave bodies that
        // cannot move.
        // Independent directions fixed by Dirichlet conditions, per node (a node in two
        // sets fixing the same component counts it once), to find slave bodies that cannot
        // move.
        let mut dirs: Vec<Vec<Vec3>> = vec![Vec::new(); mesh.num_nodes()];
        for d in dirichlet {
            for &n in &node_sets[d.node_set].nodes {
                let basis = &mut dirs[n as usize];
                let mut r = d.direction;
                for q in basis.iter() {
                    let c = crate::math::dot(&r, q);
                    for k in 0..3 {
                        r[k] -= c * q[k];
                    }
                }
                let l = norm(&r);
                if l > 1e-8 && basis.len() < 3 {
                    basis.push(scale(&r, 1.0 / l));
                }
            }
        }
        let fixed_dirs: Vec<usize> = dirs.iter().map(|b| b.len()).collect();
        for (i, c) in raw.contact.iter().enumerate() {
            let key = format!("contact[{i}]");
            let name = c
                .name
                .clone()
                .unwrap_or_else(|| format!("{}/{}", c.master, c.slave));
            let find = |k: &str, n: &str| -> Result<usize, SceneError> {
                side_sets.iter().position(|s| s.name == n).ok_or_else(|| {
                    self.err(
                        format!("{key}.{k}"),
                        format!(
                            "no side set named '{n}' (defined: {})",
                            list(side_sets.iter().map(|s| &s.name))
                        ),
                    )
                })
            };
            let master = find("master", &c.master)?;
            let slave = find("slave", &c.slave)?;
            if master == slave {
                return Err(self.err(
                    &key,
                    format!("master and slave are the same side set '{}'", c.master),
                ));
            }
            let mu = match (c.friction.as_deref(), c.mu) {
                (None | Some("frictionless"), None) => 0.0,
                (None | Some("frictionless"), Some(_)) => {
                    return Err(self.err(format!("{key}.mu"), "mu needs friction = \"coulomb\""))
                }
                (Some("coulomb"), Some(mu)) if mu.is_finite() && mu >= 0.0 => mu,
                (Some("coulomb"), Some(mu)) => {
                    return Err(self.err(
                        format!("{key}.mu"),
                        format!("expected a friction coefficient >= 0, got {mu}"),
                    ))
                }
                (Some("coulomb"), None) => {
                    return Err(self.err(
                        format!("{key}.mu"),
                        "friction = \"coulomb\" needs mu = <coefficient >= 0>",
                    ))
                }
                (Some(other), _) => {
                    return Err(self.err(
                        format!("{key}.friction"),
                        format!("expected \"frictionless\" or \"coulomb\", got \"{other}\""),
                    ))
                }
            };
            let master_faces: Vec<(u32, u8)> = side_sets[master].faces.clone();
            let mut slave_nodes: Vec<u32> = side_sets[slave]
                .faces
                .iter()
                .flat_map(|&(e, f)| mesh.face_nodes(e, f))
                .collect();
            slave_nodes.sort_unstable();
            slave_nodes.dedup();
            let mut master_nodes: Vec<u32> = master_faces
                .iter()
                .flat_map(|&(e, f)| mesh.face_nodes(e, f))
                .collect();
            master_nodes.sort_unstable();
            master_nodes.dedup();
            if let Some(n) = slave_nodes
                .iter()
                .find(|n| master_nodes.binary_search(n).is_ok())
            {
                return Err(self.err(
                    &key,
                    format!("master '{}' and slave '{}' overlap (node {} is in both); they must be faces of different surfaces", c.master, c.slave, n + 1),
                ));
            }
            let slave_bodies: Vec<u32> = {
                let mut b: Vec<u32> = side_sets[slave]
                    .faces
                    .iter()
                    .map(|&(e, _)| mesh.element_body[e as usize])
                    .collect();
                b.sort_unstable();
                b.dedup();
                b
            };
            for &b in &slave_bodies {
                let body = &mesh.bodies[b as usize];
                if (body.first_node..body.first_node + body.num_nodes).all(|n| fixed_dirs[n] >= 3) {
                    return Err(self.err(
                        format!("{key}.slave"),
                        format!("the slave surface '{}' belongs to body '{}', whose every node is prescribed: make it the master", c.slave, body.name),
                    ));
                }
            }
            let face_size = {
                let total: f64 = master_faces
                    .iter()
                    .map(|&(e, f)| {
                        let nodes = mesh.face_nodes(e, f);
                        let x: [Vec3; 4] = std::array::from_fn(|a| mesh.coords[nodes[a] as usize]);
                        crate::fem::face::area(&x).sqrt()
                    })
                    .sum();
                total / master_faces.len() as f64
            };
            let tol = |k: &str, v: Option<f64>, default: f64| -> Result<f64, SceneError> {
                match v {
                    None => Ok(default),
                    Some(t) if t.is_finite() && t >= 0.0 => Ok(t),
                    Some(t) => Err(self.err(
                        format!("{key}.{k}"),
                        format!("expected a length >= 0, got {t}"),
                    )),
                }
            };
            let normal_tolerance = tol("normal_tolerance", c.normal_tolerance, 0.5 * face_size)?;
            let tangential_tolerance = tol(
                "tangential_tolerance",
                c.tangential_tolerance,
                0.1 * face_size,
            )?;
            let capture_tolerance =
                tol("capture_tolerance", c.capture_tolerance, 1e-6 * face_size)?;
            if capture_tolerance > normal_tolerance {
                return Err(self.err(
                    format!("{key}.capture_tolerance"),
                    format!("the capture tolerance ({capture_tolerance:e}) must not exceed the normal search tolerance ({normal_tolerance:e})"),
                ));
            }
            let smoothing_width = match c.smoothing_width {
                None => None,
                Some(w) if w.is_finite() && w > 0.0 && w <= 0.5 => Some(w),
                Some(w) => {
                    return Err(self.err(
                        format!("{key}.smoothing_width"),
                        format!("expected a fraction of the face size in (0, 0.5], got {w}"),
                    ))
                }
            };
            out.push(ContactPair::new(
                name,
                mesh,
                master_faces,
                slave_nodes,
                mu,
                normal_tolerance,
                tangential_tolerance,
                capture_tolerance,
                smoothing_width,
                face_size,
            ));
        }
        Ok(out)
    }
}
