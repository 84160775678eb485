//! The `[[contact]]` pairs of a scene: the master side set and slave node set, Coulomb's
//! coefficient and the search tolerances, checked and resolved into the problem's pairs.

use super::*;
use crate::problem::{ContactPair, Discretization};

/// A pair's search tolerances: normal, tangential, capture, and the smoothing width.
type Tolerances = (f64, f64, f64, Option<f64>);

impl Builder {
    pub(super) fn contacts(
        &self,
        raw: &SceneFile,
        mesh: &GlobalMesh,
        side_sets: &[SideSet],
        node_sets: &[NodeSet],
        dirichlet: &[Dirichlet],
    ) -> Result<Vec<ContactPair>, SceneError> {
        let fixed_dirs = fixed_directions(mesh, node_sets, dirichlet);
        let mut pairs = raw
            .contact
            .iter()
            .enumerate()
            .map(|(i, c)| {
                self.contact_pair(&format!("contact[{i}]"), c, mesh, side_sets, &fixed_dirs)
            })
            .collect::<Result<Vec<_>, _>>()?;
        let general = self.general_contacts(raw, mesh, &pairs, node_sets, dirichlet)?;
        pairs.extend(general);
        Ok(pairs)
    }

    /// One `[[contact]]`: its side sets (distinct, not overlapping, the slave on a body
    /// that can move), friction and tolerances.
    fn contact_pair(
        &self,
        key: &str,
        c: &ContactDef,
        mesh: &GlobalMesh,
        side_sets: &[SideSet],
        fixed_dirs: &[usize],
    ) -> Result<ContactPair, SceneError> {
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
                key,
                format!("master and slave are the same side set '{}'", c.master),
            ));
        }
        let mu = self.friction_coefficient(key, c)?;
        let master_faces: Vec<(u32, u8)> = side_sets[master].faces.clone();
        let slave_nodes = surface_nodes(mesh, &side_sets[slave].faces);
        let master_nodes = surface_nodes(mesh, &master_faces);
        if let Some(n) = slave_nodes
            .iter()
            .find(|n| master_nodes.binary_search(n).is_ok())
        {
            return Err(self.err(
                key,
                format!("master '{}' and slave '{}' overlap (node {} is in both); they must be faces of different surfaces", c.master, c.slave, n + 1),
            ));
        }
        self.check_slave_can_move(key, c, mesh, &side_sets[slave], fixed_dirs)?;
        let face_size = mean_face_size(mesh, &master_faces);
        let (normal, tangential, capture, smoothing) = self.tolerances(key, c, face_size)?;
        let discretization = self.discretization(key, c)?;
        let adjust = match c.adjust {
            None => 0.0,
            Some(d) if d.is_finite() && d >= 0.0 && d <= normal => d,
            Some(d) => {
                return Err(self.err(
                    format!("{key}.adjust"),
                    format!("expected a length >= 0 and at most the normal search tolerance ({normal:e}), got {d}"),
                ))
            }
        };
        let mut pair = ContactPair::new(
            name,
            mesh,
            master_faces,
            slave_nodes,
            mu,
            normal,
            tangential,
            capture,
            smoothing,
            face_size,
        )
        .with_slave_faces(mesh, side_sets[slave].faces.clone(), discretization);
        pair.adjust = adjust;
        Ok(pair)
    }

    /// How the pair's constraints are formed: node-to-face (default) or mortar.
    pub(super) fn discretization(
        &self,
        key: &str,
        c: &ContactDef,
    ) -> Result<Discretization, SceneError> {
        let d = match c.discretization.as_deref() {
            None => Discretization::default(),
            Some(name) => Discretization::from_key(name).ok_or_else(|| {
                let keys: Vec<String> = Discretization::KEYS
                    .iter()
                    .map(|(k, _)| format!("\"{k}\""))
                    .collect();
                self.err(
                    format!("{key}.discretization"),
                    format!("expected {}, got \"{name}\"", keys.join(" or ")),
                )
            })?,
        };
        if d == Discretization::Mortar && c.smoothing_width.is_some() {
            return Err(self.err(
                format!("{key}.smoothing_width"),
                "normal smoothing is for node_face contact; a mortar pair's normals are the slave surface's averaged nodal normals, which are already continuous",
            ));
        }
        Ok(d)
    }

    /// Coulomb's coefficient: 0 when frictionless.
    pub(super) fn friction_coefficient(
        &self,
        key: &str,
        c: &ContactDef,
    ) -> Result<f64, SceneError> {
        match (c.friction.as_deref(), c.mu) {
            (None | Some("frictionless"), None) => Ok(0.0),
            (None | Some("frictionless"), Some(_)) => {
                Err(self.err(format!("{key}.mu"), "mu needs friction = \"coulomb\""))
            }
            (Some("coulomb"), Some(mu)) if mu.is_finite() && mu >= 0.0 => Ok(mu),
            (Some("coulomb"), Some(mu)) => Err(self.err(
                format!("{key}.mu"),
                format!("expected a friction coefficient >= 0, got {mu}"),
            )),
            (Some("coulomb"), None) => Err(self.err(
                format!("{key}.mu"),
                "friction = \"coulomb\" needs mu = <coefficient >= 0>",
            )),
            (Some(other), _) => Err(self.err(
                format!("{key}.friction"),
                format!("expected \"frictionless\" or \"coulomb\", got \"{other}\""),
            )),
        }
    }

    /// A slave surface on a body whose every node is prescribed cannot be pushed out.
    fn check_slave_can_move(
        &self,
        key: &str,
        c: &ContactDef,
        mesh: &GlobalMesh,
        slave: &SideSet,
        fixed_dirs: &[usize],
    ) -> Result<(), SceneError> {
        let mut bodies: Vec<u32> = slave
            .faces
            .iter()
            .map(|&(e, _)| mesh.element_body[e as usize])
            .collect();
        bodies.sort_unstable();
        bodies.dedup();
        for &b in &bodies {
            let body = &mesh.bodies[b as usize];
            if (body.first_node..body.first_node + body.num_nodes).all(|n| fixed_dirs[n] >= 3) {
                return Err(self.err(
                    format!("{key}.slave"),
                    format!("the slave surface '{}' belongs to body '{}', whose every node is prescribed: make it the master", c.slave, body.name),
                ));
            }
        }
        Ok(())
    }

    /// The search tolerances (defaults from the mean master face size) and the normal
    /// smoothing width.
    pub(super) fn tolerances(
        &self,
        key: &str,
        c: &ContactDef,
        face_size: f64,
    ) -> Result<Tolerances, SceneError> {
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
        let capture_tolerance = tol("capture_tolerance", c.capture_tolerance, 1e-6 * face_size)?;
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
        Ok((
            normal_tolerance,
            tangential_tolerance,
            capture_tolerance,
            smoothing_width,
        ))
    }
}

/// Independent directions fixed by Dirichlet conditions, per node (a node in two sets
/// fixing the same component counts it once), to find slave bodies that cannot move.
pub(super) fn fixed_directions(
    mesh: &GlobalMesh,
    node_sets: &[NodeSet],
    dirichlet: &[Dirichlet],
) -> Vec<usize> {
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
    dirs.iter().map(|b| b.len()).collect()
}

/// The nodes of a set of faces, ascending.
pub(super) fn surface_nodes(mesh: &GlobalMesh, faces: &[(u32, u8)]) -> Vec<u32> {
    let mut nodes: Vec<u32> = faces
        .iter()
        .flat_map(|&(e, f)| mesh.face_nodes(e, f))
        .collect();
    nodes.sort_unstable();
    nodes.dedup();
    nodes
}

/// Mean sqrt(area) of the faces' contact facets (a hexahedron's face, or each of the four
/// sub-triangles of a tet10's face): the length the tolerance defaults scale with.
pub(super) fn mean_face_size(mesh: &GlobalMesh, faces: &[(u32, u8)]) -> f64 {
    let facets: Vec<[u32; 4]> = faces
        .iter()
        .flat_map(|&(e, f)| mesh.contact_facets(e, f))
        .collect();
    let total: f64 = facets
        .iter()
        .map(|nodes| {
            let x: [Vec3; 4] = std::array::from_fn(|a| mesh.coords[nodes[a] as usize]);
            // A triangle's fourth node repeats its third (`contact::facet`).
            if nodes[3] == nodes[2] {
                crate::fem::face::triangle_area(&[x[0], x[1], x[2]]).sqrt()
            } else {
                crate::fem::face::area(&x).sqrt()
            }
        })
        .sum();
    total / facets.len() as f64
}
