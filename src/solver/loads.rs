//! External forces: pressure (a follower load under large kinematics), traction and body
//! force, on the rank's local faces and elements.

use super::assembly::{Assembly, ElementError};
use crate::fem::{face, FaceKind};
use crate::math::{add, Vec3};
use crate::mesh::local::LocalMesh;
use crate::problem::Problem;
use crate::problem::{Kinematics, PiecewiseLinear};

struct FaceLoad {
    /// (local element, local face), in ascending global order.
    faces: Vec<(usize, u8)>,
    function: PiecewiseLinear,
    /// None: pressure; Some: traction vector.
    traction: Option<Vec3>,
}

pub struct Loads {
    face_loads: Vec<FaceLoad>,
    body_forces: Vec<(usize, Vec3, PiecewiseLinear)>,
    follower: bool,
}

impl Loads {
    pub fn new(problem: &Problem, mesh: &LocalMesh) -> Self {
        let local_faces = |set: usize| -> Vec<(usize, u8)> {
            // Local element indices are in ascending global order, so a sorted global list
            // maps to a sorted local one.
            problem.side_sets[set]
                .faces
                .iter()
                .filter_map(|&(e, f)| mesh.element_global.binary_search(&e).ok().map(|l| (l, f)))
                .collect()
        };
        let mut face_loads = Vec::new();
        for p in &problem.pressures {
            face_loads.push(FaceLoad {
                faces: local_faces(p.side_set),
                function: p.function.clone(),
                traction: None,
            });
        }
        for t in &problem.tractions {
            face_loads.push(FaceLoad {
                faces: local_faces(t.side_set),
                function: t.function.clone(),
                traction: Some(t.vector),
            });
        }
        let body_forces = problem
            .body_forces
            .iter()
            .map(|b| (b.body, b.force_density, b.function.clone()))
            .collect();
        Loads {
            face_loads,
            body_forces,
            follower: problem.kinematics == Kinematics::Large && !problem.pressures.is_empty(),
        }
    }

    /// True when the external force depends on the displacement (follower pressure).
    pub fn is_follower(&self) -> bool {
        self.follower
    }

    pub fn is_empty(&self) -> bool {
        self.face_loads.is_empty() && self.body_forces.is_empty()
    }

    /// f = f_ext(t, u).
    pub fn external_force(
        &self,
        asm: &Assembly,
        t: f64,
        u: &[Vec3],
        f: &mut [Vec3],
    ) -> Result<(), ElementError> {
        f.iter_mut().for_each(|v| *v = [0.0; 3]);
        let mesh = asm.mesh;
        for load in &self.face_loads {
            let s = load.function.eval(t);
            if s == 0.0 {
                continue;
            }
            for &(e, k) in &load.faces {
                let (kind, el) = (mesh.kind(e), mesh.elements.element(e));
                let position = |a: usize| {
                    let n = el[a] as usize;
                    if self.follower {
                        add(&mesh.coords[n], &u[n])
                    } else {
                        mesh.coords[n]
                    }
                };
                let mut put = |a: usize, fa: &Vec3| {
                    let n = el[a] as usize;
                    for i in 0..3 {
                        f[n][i] += fa[i];
                    }
                };
                let fnodes = kind.face(k as usize);
                match kind.face_kind(k as usize) {
                    FaceKind::Quad4 => {
                        let x: [Vec3; 4] = std::array::from_fn(|a| position(fnodes[a]));
                        let fe = match &load.traction {
                            None => face::pressure_forces(&x, s),
                            Some(v) => face::traction_forces(&x, &[v[0] * s, v[1] * s, v[2] * s]),
                        };
                        for a in 0..4 {
                            put(fnodes[a], &fe[a]);
                        }
                    }
                    // The load on each linear sub-triangle (the composite tetrahedron's
                    // face is piecewise linear on them): every node's share is positive.
                    FaceKind::Tri6 => {
                        for facet in FaceKind::Tri6.contact_facets() {
                            let x: [Vec3; 3] = std::array::from_fn(|a| position(fnodes[facet[a]]));
                            let fe = match &load.traction {
                                None => face::triangle_pressure_forces(&x, s),
                                Some(v) => face::triangle_traction_forces(
                                    &x,
                                    &[v[0] * s, v[1] * s, v[2] * s],
                                ),
                            };
                            for a in 0..3 {
                                put(fnodes[facet[a]], &fe[a]);
                            }
                        }
                    }
                }
            }
        }
        for (body, density, function) in &self.body_forces {
            let s = function.eval(t);
            if s != 0.0 {
                asm.add_body_force(*body, density, s, f)?;
            }
        }
        Ok(())
    }
}
