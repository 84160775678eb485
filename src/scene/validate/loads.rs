//! Prescribed displacements and loads of a scene (pressures, tractions, body forces),
//! checked and tied to their node sets, side sets and bodies.

use super::*;

impl Builder {
    /// The index of the node set `name` (named by `key` in an error).
    fn node_set_index(&self, sets: &[NodeSet], key: &str, name: &str) -> Result<usize, SceneError> {
        sets.iter().position(|s| s.name == name).ok_or_else(|| {
            self.err(
                key,
                format!(
                    "no node set named '{name}' (defined: {})",
                    list(sets.iter().map(|s| &s.name))
                ),
            )
        })
    }

    /// The index of the side set `name` (named by `key` in an error).
    fn side_set_index(&self, sets: &[SideSet], key: &str, name: &str) -> Result<usize, SceneError> {
        sets.iter().position(|s| s.name == name).ok_or_else(|| {
            self.err(
                key,
                format!(
                    "no side set named '{name}' (defined: {})",
                    list(sets.iter().map(|s| &s.name))
                ),
            )
        })
    }

    /// `[[displacement]]`: one prescribed direction per component (or the skew direction).
    pub(super) fn displacements(
        &self,
        raw: &SceneFile,
        node_sets: &[NodeSet],
    ) -> Result<Vec<Dirichlet>, SceneError> {
        let (mut dirichlet, mut origin) = (Vec::new(), Vec::new());
        for (i, d) in raw.displacement.iter().enumerate() {
            let key = format!("displacement[{i}]");
            let set = self.node_set_index(node_sets, &format!("{key}.node_set"), &d.node_set)?;
            let function = self.function(&key, d.value, &d.function)?;
            for direction in self.directions(&key, d)? {
                dirichlet.push(Dirichlet {
                    node_set: set,
                    direction,
                    function: function.clone(),
                });
                origin.push(i);
            }
        }
        self.consistent_displacements(&dirichlet, &origin, node_sets)?;
        Ok(dirichlet)
    }

    /// The unit directions of one `[[displacement]]`: its `components` or its `direction`.
    fn directions(&self, key: &str, d: &DisplacementDef) -> Result<Vec<Vec3>, SceneError> {
        let directions: Vec<Vec3> = match (&d.components, &d.direction) {
            (Some(c), None) => {
                if c.is_empty() {
                    return Err(self.err(
                        format!("{key}.components"),
                        "expected one or more of \"x\", \"y\", \"z\"",
                    ));
                }
                let mut dirs = Vec::new();
                for s in c {
                    let axis = match s.as_str() {
                        "x" => 0,
                        "y" => 1,
                        "z" => 2,
                        _ => {
                            return Err(self.err(
                                format!("{key}.components"),
                                format!("expected \"x\", \"y\" or \"z\", got \"{s}\""),
                            ))
                        }
                    };
                    let mut v = [0.0; 3];
                    v[axis] = 1.0;
                    if dirs.contains(&v) {
                        return Err(self.err(
                            format!("{key}.components"),
                            format!("component \"{s}\" given twice"),
                        ));
                    }
                    dirs.push(v);
                }
                dirs
            }
            (None, Some(v)) => {
                let v = self.finite3(&format!("{key}.direction"), v)?;
                let n = norm(&v);
                if !(n > 0.0) {
                    return Err(self.err(format!("{key}.direction"), "expected a non-zero vector"));
                }
                vec![scale(&v, 1.0 / n)]
            }
            (Some(_), Some(_)) => {
                return Err(self.err(key, "give either `components` or `direction`, not both"))
            }
            (None, None) => {
                return Err(self.err(
                    key,
                    "expected `components = [\"x\", ...]` or `direction = [a, b, c]`",
                ))
            }
        };
        Ok(directions)
    }

    /// `[[pressure]]`.
    pub(super) fn pressures(
        &self,
        raw: &SceneFile,
        side_sets: &[SideSet],
    ) -> Result<Vec<Pressure>, SceneError> {
        let mut pressures = Vec::new();
        for (i, p) in raw.pressure.iter().enumerate() {
            let key = format!("pressure[{i}]");
            let side_set =
                self.side_set_index(side_sets, &format!("{key}.side_set"), &p.side_set)?;
            pressures.push(Pressure {
                side_set,
                function: self.function(&key, p.value, &p.function)?,
            });
        }
        Ok(pressures)
    }

    /// `[[traction]]`: a force per unit area, times an optional function of time.
    pub(super) fn tractions(
        &self,
        raw: &SceneFile,
        side_sets: &[SideSet],
    ) -> Result<Vec<Traction>, SceneError> {
        let mut tractions = Vec::new();
        for (i, t) in raw.traction.iter().enumerate() {
            let key = format!("traction[{i}]");
            let side_set =
                self.side_set_index(side_sets, &format!("{key}.side_set"), &t.side_set)?;
            let vector = self.finite3(&format!("{key}.vector"), &t.vector)?;
            let function = match &t.function {
                Some(p) => self.points(&format!("{key}.function"), p)?,
                None => PiecewiseLinear::constant(1.0),
            };
            tractions.push(Traction {
                side_set,
                vector,
                function,
            });
        }
        Ok(tractions)
    }

    /// `[[body_force]]`: an acceleration times the body's density.
    pub(super) fn body_forces(
        &self,
        raw: &SceneFile,
        mesh: &GlobalMesh,
        body_models: &[BodyModel],
    ) -> Result<Vec<BodyForce>, SceneError> {
        let mut body_forces = Vec::new();
        for (i, b) in raw.body_force.iter().enumerate() {
            let key = format!("body_force[{i}]");
            let body = mesh
                .bodies
                .iter()
                .position(|x| x.name == b.body)
                .ok_or_else(|| {
                    self.err(
                        format!("{key}.body"),
                        format!(
                            "no body named '{}' (defined: {})",
                            b.body,
                            list(mesh.bodies.iter().map(|x| &x.name))
                        ),
                    )
                })?;
            let a = self.finite3(&format!("{key}.acceleration"), &b.acceleration)?;
            let density = body_models[body].density;
            if !(density > 0.0) {
                return Err(self.err(
                    format!("{key}.body"),
                    format!(
                        "body '{}' needs a material density > 0 for a body force",
                        b.body
                    ),
                ));
            }
            let function = match &b.function {
                Some(p) => self.points(&format!("{key}.function"), p)?,
                None => PiecewiseLinear::constant(1.0),
            };
            body_forces.push(BodyForce {
                body,
                force_density: scale(&a, density),
                function,
            });
        }
        Ok(body_forces)
    }
}
