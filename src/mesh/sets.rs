//! Geometric selection of nodes and faces.

use super::GlobalMesh;
use crate::math::{dot, norm, scale, sub, Vec3};

/// A geometric selector with an absolute tolerance.
#[derive(Clone, Copy, Debug)]
pub enum Selector {
    Plane {
        point: Vec3,
        unit_normal: Vec3,
        tol: f64,
    },
    Box {
        min: Vec3,
        max: Vec3,
        tol: f64,
    },
}

impl Selector {
    pub fn plane(point: Vec3, normal: Vec3, tol: f64) -> Self {
        let n = norm(&normal);
        Selector::Plane {
            point,
            unit_normal: scale(&normal, 1.0 / n),
            tol,
        }
    }

    pub fn contains(&self, x: &Vec3) -> bool {
        match self {
            Selector::Plane {
                point,
                unit_normal,
                tol,
            } => dot(&sub(x, point), unit_normal).abs() <= *tol,
            Selector::Box { min, max, tol } => {
                (0..3).all(|i| x[i] >= min[i] - tol && x[i] <= max[i] + tol)
            }
        }
    }
}

/// Nodes of the given bodies (all bodies when `bodies` is None) the selector contains.
pub fn select_nodes(mesh: &GlobalMesh, sel: &Selector, body: Option<usize>) -> Vec<u32> {
    let range = match body {
        Some(b) => {
            let b = &mesh.bodies[b];
            b.first_node..b.first_node + b.num_nodes
        }
        None => 0..mesh.num_nodes(),
    };
    range
        .filter(|&n| sel.contains(&mesh.coords[n]))
        .map(|n| n as u32)
        .collect()
}

/// Boundary faces all four of whose nodes the selector contains.
pub fn select_faces(
    mesh: &GlobalMesh,
    boundary: &[(u32, u8)],
    sel: &Selector,
    body: Option<usize>,
) -> Vec<(u32, u8)> {
    boundary
        .iter()
        .copied()
        .filter(|&(e, _)| body.is_none_or(|b| mesh.element_body[e as usize] as usize == b))
        .filter(|&(e, f)| {
            mesh.face_nodes(e, f)
                .all(|n| sel.contains(&mesh.coords[n as usize]))
        })
        .collect()
}
