//! `[general_contact]`: the exterior faces of every body (faces of one element only)
//! against every other body's, resolved into contact pairs once, here. Each body pair not
//! excluded and not named by a `[[contact]]` pair (those win) gets two passes: the primary
//! one ties the slave body's exterior nodes to the master body's exterior faces, with the
//! interaction's discretisation; the second (node-to-face, `ContactPair::secondary`) ties
//! the master body's nodes to the slave body's faces only when they are inside it by more
//! than the capture tolerance, and its nodes are in the penetration audit, so no node of
//! either body ends inside the other. The slave of the primary pass is the body set by the
//! pair's `slave`, else the one that can move when the other is prescribed in every node,
//! else the finer (smaller mean exterior face), else the one declared later. `self` adds a
//! body's exterior nodes against its own faces (self_contact.rs).

use super::contacts::{fixed_directions, mean_face_size, surface_nodes};
use super::*;
use crate::problem::{ContactPair, Tributaries};
use std::sync::Arc;

/// A body of the general contact: its exterior faces, their mean size, and whether every
/// node of it is prescribed.
pub(super) struct Skin {
    pub(super) faces: Vec<(u32, u8)>,
    pub(super) size: f64,
    pub(super) rigid: bool,
}

impl Builder {
    /// The pairs of `[general_contact]` (none without it), after the explicit ones.
    pub(super) fn general_contacts(
        &self,
        raw: &SceneFile,
        mesh: &GlobalMesh,
        explicit: &[ContactPair],
        node_sets: &[NodeSet],
        dirichlet: &[Dirichlet],
    ) -> Result<Vec<ContactPair>, SceneError> {
        let Some(g) = &raw.general_contact else {
            return Ok(Vec::new());
        };
        let key = "general_contact";
        let nb = mesh.bodies.len();
        let (left_out, excluded) = self.exclusions(g, mesh)?;
        let overrides = self.overrides(g, mesh)?;
        let fixed_dirs = fixed_directions(mesh, node_sets, dirichlet);
        let skins = self.skins(mesh, &left_out, &fixed_dirs)?;
        let named = explicit_body_pairs(mesh, explicit);
        let mut pairs = Vec::new();
        let mut shared = Shared::new(nb);
        for a in 0..nb {
            for b in a + 1..nb {
                let (Some(sa), Some(sb)) = (&skins[a], &skins[b]) else {
                    continue;
                };
                if excluded.contains(&(a, b)) || named.contains(&(a, b)) || (sa.rigid && sb.rigid) {
                    continue;
                }
                let over = overrides
                    .iter()
                    .find(|(p, _)| *p == (a, b))
                    .map(|(_, d)| *d);
                let slave = self.primary_slave(key, mesh, (a, b), (sa, sb), over)?;
                let master = a + b - slave;
                let def = interaction(g, over);
                let ids = (slave, master);
                let skin = |i: usize| if i == a { sa } else { sb };
                let skins = (skin(slave), skin(master));
                pairs.push(self.pass(key, mesh, &mut shared, &def, ids, skins, false)?);
                if !skin(master).rigid && g.symmetric.unwrap_or(true) {
                    let mut second = def.clone();
                    second.discretization = None;
                    let s = (skin(master), skin(slave));
                    let ids = (master, slave);
                    let mut pass = self.pass(key, mesh, &mut shared, &second, ids, s, true)?;
                    pass.partner = Some(explicit.len() + pairs.len() - 1);
                    pairs.push(pass);
                }
            }
        }
        pairs.extend(self.self_contacts(g, mesh, &left_out, &skins)?);
        Ok(pairs)
    }

    /// One pass: the slave body's exterior nodes against the master body's exterior faces.
    #[allow(clippy::too_many_arguments)]
    fn pass(
        &self,
        key: &str,
        mesh: &GlobalMesh,
        shared: &mut Shared,
        def: &ContactDef,
        (slave, master): (usize, usize),
        (s, m): (&Skin, &Skin),
        secondary: bool,
    ) -> Result<ContactPair, SceneError> {
        let (sn, mn) = (&mesh.bodies[slave].name, &mesh.bodies[master].name);
        let key = format!("{key} ({sn}, {mn})");
        let mu = self.friction_coefficient(&key, def)?;
        let (normal, tangential, capture, smoothing) = self.tolerances(&key, def, m.size)?;
        let discretization = self.discretization(&key, def)?;
        let suffix = if secondary { " (second pass)" } else { "" };
        let mut pair = shared.master(mesh, master, m).clone();
        pair.name = format!("general:{mn}/{sn}{suffix}");
        pair.mu = mu;
        pair.normal_tolerance = normal;
        pair.tangential_tolerance = tangential;
        pair.capture_tolerance = capture;
        pair.smoothing_width = smoothing;
        pair.discretization = discretization;
        let side = shared.slave(mesh, slave, s);
        pair.slave_nodes = side.nodes.clone();
        pair.slave_faces = side.faces.clone();
        pair.slave_face_nodes = side.face_nodes.clone();
        pair.slave_normals = Some(side.normals.clone());
        pair.slave_tributaries = Some(side.tributaries.clone());
        pair.secondary = secondary;
        Ok(pair)
    }

    fn primary_slave(
        &self,
        key: &str,
        mesh: &GlobalMesh,
        (a, b): (usize, usize),
        (sa, sb): (&Skin, &Skin),
        over: Option<&GeneralPairDef>,
    ) -> Result<usize, SceneError> {
        if let Some(name) = over.and_then(|d| d.slave.as_ref()) {
            let k = format!(
                "{key}.pair ({}, {}).slave",
                mesh.bodies[a].name, mesh.bodies[b].name
            );
            let s = [a, b]
                .into_iter()
                .find(|&i| mesh.bodies[i].name == *name)
                .ok_or_else(|| self.err(&k, format!("'{name}' is not one of the pair's bodies")))?;
            if (if s == a { sa } else { sb }).rigid {
                return Err(self.err(
                    &k,
                    format!("body '{name}' has every node prescribed: it cannot be the slave"),
                ));
            }
            return Ok(s);
        }
        Ok(if sb.rigid {
            a
        } else if sa.rigid || sb.size < sa.size * (1.0 - 1e-9) {
            b
        } else if sa.size < sb.size * (1.0 - 1e-9) {
            a
        } else {
            b
        })
    }

    /// Each body's exterior faces (None for a body left out): a hexahedron's quadrilaterals,
    /// a tet10's 6-node triangles.
    fn skins(
        &self,
        mesh: &GlobalMesh,
        left_out: &[bool],
        fixed_dirs: &[usize],
    ) -> Result<Vec<Option<Skin>>, SceneError> {
        let mut faces: Vec<Vec<(u32, u8)>> = vec![Vec::new(); mesh.bodies.len()];
        for (e, f) in mesh.boundary_faces() {
            faces[mesh.element_body[e as usize] as usize].push((e, f));
        }
        let mut out = Vec::new();
        for (i, body) in mesh.bodies.iter().enumerate() {
            if left_out[i] {
                out.push(None);
                continue;
            }
            let fs = std::mem::take(&mut faces[i]);
            let rigid =
                (body.first_node..body.first_node + body.num_nodes).all(|n| fixed_dirs[n] >= 3);
            out.push(Some(Skin {
                size: mean_face_size(mesh, &fs),
                faces: fs,
                rigid,
            }));
        }
        Ok(out)
    }

    /// `exclude`: bodies left out (one name) and body pairs left out (two names).
    #[allow(clippy::type_complexity)]
    fn exclusions(
        &self,
        g: &GeneralContactDef,
        mesh: &GlobalMesh,
    ) -> Result<(Vec<bool>, Vec<(usize, usize)>), SceneError> {
        let mut left_out = vec![false; mesh.bodies.len()];
        let mut pairs = Vec::new();
        for (i, names) in g.exclude.iter().enumerate() {
            let k = format!("general_contact.exclude[{i}]");
            let ids = names
                .iter()
                .map(|n| self.body_index(&k, mesh, n))
                .collect::<Result<Vec<_>, _>>()?;
            match ids[..] {
                [a] => left_out[a] = true,
                [a, b] if a != b => pairs.push((a.min(b), a.max(b))),
                _ => {
                    return Err(self.err(
                        &k,
                        "expected one body name (the body left out) or two different ones (the pair left out)",
                    ))
                }
            }
        }
        Ok((left_out, pairs))
    }

    /// `[[general_contact.pair]]`: the body pair each overrides, at most one each.
    #[allow(clippy::type_complexity)]
    fn overrides<'g>(
        &self,
        g: &'g GeneralContactDef,
        mesh: &GlobalMesh,
    ) -> Result<Vec<((usize, usize), &'g GeneralPairDef)>, SceneError> {
        let mut out: Vec<((usize, usize), &GeneralPairDef)> = Vec::new();
        for (i, d) in g.pair.iter().enumerate() {
            let k = format!("general_contact.pair[{i}].bodies");
            let a = self.body_index(&k, mesh, &d.bodies[0])?;
            let b = self.body_index(&k, mesh, &d.bodies[1])?;
            if a == b {
                return Err(self.err(&k, "expected two different bodies"));
            }
            let p = (a.min(b), a.max(b));
            if out.iter().any(|(q, _)| *q == p) {
                return Err(self.err(&k, "this body pair already has a [[general_contact.pair]]"));
            }
            out.push((p, d));
        }
        Ok(out)
    }

    fn body_index(&self, key: &str, mesh: &GlobalMesh, name: &str) -> Result<usize, SceneError> {
        mesh.bodies
            .iter()
            .position(|b| b.name == name)
            .ok_or_else(|| {
                self.err(
                    key,
                    format!(
                        "no body named '{name}' (defined: {})",
                        list(mesh.bodies.iter().map(|b| &b.name))
                    ),
                )
            })
    }
}

/// The interaction of one body pair: the pair's keys where set, the general ones elsewhere.
/// The lists of a body's passes that depend on the body alone, made at its first pass and
/// shared by the rest: of a B-body scene's B (B - 1) passes, each body is the master of B - 1
/// and the slave of B - 1.
struct Shared {
    /// Per body, a pass with the body as master, the settings not yet set.
    masters: Vec<Option<ContactPair>>,
    slaves: Vec<Option<SlaveSide>>,
}

/// A body's exterior as a slave: its nodes, faces, facets and node normals.
struct SlaveSide {
    nodes: Arc<Vec<u32>>,
    faces: Arc<Vec<(u32, u8)>>,
    face_nodes: Arc<Vec<[u32; 4]>>,
    normals: Arc<Vec<Vec3>>,
    tributaries: Tributaries,
}

impl Shared {
    fn new(bodies: usize) -> Self {
        Shared {
            masters: (0..bodies).map(|_| None).collect(),
            slaves: (0..bodies).map(|_| None).collect(),
        }
    }

    fn master(&mut self, mesh: &GlobalMesh, body: usize, m: &Skin) -> &ContactPair {
        self.masters[body].get_or_insert_with(|| {
            ContactPair::new(
                String::new(),
                mesh,
                m.faces.clone(),
                Vec::new(),
                0.0,
                0.0,
                0.0,
                0.0,
                None,
                m.size,
            )
        })
    }

    fn slave(&mut self, mesh: &GlobalMesh, body: usize, s: &Skin) -> &SlaveSide {
        self.slaves[body].get_or_insert_with(|| {
            let nodes = surface_nodes(mesh, &s.faces);
            let normals = node_normals(mesh, &nodes, &s.faces);
            let tributaries = node_tributaries(mesh, &nodes, &s.faces);
            let face_nodes = s
                .faces
                .iter()
                .flat_map(|&(e, f)| mesh.contact_facets(e, f))
                .collect();
            SlaveSide {
                nodes: Arc::new(nodes),
                faces: Arc::new(s.faces.clone()),
                face_nodes: Arc::new(face_nodes),
                normals: Arc::new(normals),
                tributaries: Arc::new(tributaries),
            }
        })
    }
}

pub(super) fn interaction(g: &GeneralContactDef, over: Option<&GeneralPairDef>) -> ContactDef {
    let pick = |o: Option<f64>, d: Option<f64>| o.or(d);
    let o = over.cloned();
    let o = o.as_ref();
    ContactDef {
        name: None,
        master: String::new(),
        slave: String::new(),
        friction: o.and_then(|p| p.friction.clone()).or(g.friction.clone()),
        // A pair that sets its friction sets its own mu (or none, frictionless).
        mu: match o.filter(|p| p.friction.is_some()) {
            Some(p) => p.mu,
            None => pick(o.and_then(|p| p.mu), g.mu),
        },
        normal_tolerance: pick(o.and_then(|p| p.normal_tolerance), g.normal_tolerance),
        tangential_tolerance: pick(
            o.and_then(|p| p.tangential_tolerance),
            g.tangential_tolerance,
        ),
        capture_tolerance: pick(o.and_then(|p| p.capture_tolerance), g.capture_tolerance),
        // The exterior faces of general contact are not adjusted: `adjust` is a pair's.
        adjust: None,
        smoothing_width: pick(o.and_then(|p| p.smoothing_width), g.smoothing_width),
        discretization: o
            .and_then(|p| p.discretization.clone())
            .or(g.discretization.clone()),
    }
}

/// The body pairs (lower index first) an explicit `[[contact]]` pair names: its master
/// faces' bodies with its slave nodes' bodies.
fn explicit_body_pairs(mesh: &GlobalMesh, explicit: &[ContactPair]) -> Vec<(usize, usize)> {
    let node_body = |n: u32| {
        mesh.bodies
            .iter()
            .position(|b| (b.first_node..b.first_node + b.num_nodes).contains(&(n as usize)))
            .unwrap_or(usize::MAX)
    };
    let mut out = Vec::new();
    for p in explicit {
        let mut masters: Vec<usize> = p
            .master_faces
            .iter()
            .map(|&(e, _)| mesh.element_body[e as usize] as usize)
            .collect();
        masters.sort_unstable();
        masters.dedup();
        let mut slaves: Vec<usize> = p.slave_nodes.iter().map(|&n| node_body(n)).collect();
        slaves.sort_unstable();
        slaves.dedup();
        for &m in &masters {
            for &s in &slaves {
                out.push((m.min(s), m.max(s)));
            }
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// Each node's outward normal: the mean of the unit normals of the faces around it (in the
/// reference configuration), by position in `nodes` (ascending).
pub(super) fn node_normals(mesh: &GlobalMesh, nodes: &[u32], faces: &[(u32, u8)]) -> Vec<Vec3> {
    let mut sum = vec![[0.0; 3]; nodes.len()];
    // Per contact facet: a hexahedron's face, or each of a tet10 face's sub-triangles,
    // whose fourth node repeats its third (the diagonals' cross product is then the
    // triangle's normal; its repeated node counts once).
    for facet in faces.iter().flat_map(|&(e, f)| mesh.contact_facets(e, f)) {
        let n = facet_normal(mesh, &facet);
        let corners = if facet[3] == facet[2] { 3 } else { 4 };
        for &a in &facet[..corners] {
            let i = nodes
                .binary_search(&a)
                .expect("a face's node is a surface node");
            for k in 0..3 {
                sum[i][k] += n[k];
            }
        }
    }
    sum.into_iter()
        .map(|v| scale(&v, 1.0 / norm(&v).max(f64::MIN_POSITIVE)))
        .collect()
}

/// Each node's slave surface around it (`ContactPair::slave_tributaries`), by position in
/// `nodes` (ascending): per facet around it, the offset halfway to the facet's centre (the
/// mean of its corners) and its unit outward normal, in the reference configuration.
fn node_tributaries(mesh: &GlobalMesh, nodes: &[u32], faces: &[(u32, u8)]) -> Vec<Vec<[Vec3; 2]>> {
    let mut out = vec![Vec::new(); nodes.len()];
    for facet in faces.iter().flat_map(|&(e, f)| mesh.contact_facets(e, f)) {
        let corners = if facet[3] == facet[2] { 3 } else { 4 };
        let x: [Vec3; 4] = std::array::from_fn(|a| mesh.coords[facet[a] as usize]);
        let n = facet_normal(mesh, &facet);
        let mut centre = [0.0; 3];
        for p in &x[..corners] {
            centre = crate::math::add(&centre, &scale(p, 1.0 / corners as f64));
        }
        for (a, &node) in facet[..corners].iter().enumerate() {
            let i = nodes
                .binary_search(&node)
                .expect("a face's node is a surface node");
            out[i].push([scale(&crate::math::sub(&centre, &x[a]), 0.5), n]);
        }
    }
    out
}

/// A contact facet's unit outward normal in the reference configuration: the cross product
/// of its diagonals (a triangle's fourth node repeats its third, and the product is then
/// its normal).
fn facet_normal(mesh: &GlobalMesh, facet: &[u32; 4]) -> Vec3 {
    let x: [Vec3; 4] = std::array::from_fn(|a| mesh.coords[facet[a] as usize]);
    let n = crate::math::cross(
        &crate::math::sub(&x[2], &x[0]),
        &crate::math::sub(&x[3], &x[1]),
    );
    scale(&n, 1.0 / norm(&n))
}
