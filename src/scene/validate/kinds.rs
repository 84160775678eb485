//! What a body's element kind allows in the scene: a tet10 body is the composite
//! tetrahedron, its own formulation (the hexahedra's integration keys are refused, not
//! ignored), and contact does not take its 6-node faces yet (issue 41, item 4).

use super::*;

/// Why the hexahedra's integration keys do not apply to a tet10 body.
const OWN: &str = "a tet10 body is the composite tetrahedron, its own formulation (four stress \
                   points of a projected strain, no hourglass modes): leave the key out";

impl Builder {
    /// Refuses the integration keys of body `key` (`b`) that its `kind` does not take.
    pub(super) fn kind_formulation(
        &self,
        key: &str,
        kind: ElementKind,
        b: &BodyDef,
    ) -> Result<(), SceneError> {
        if kind != ElementKind::Tet10 {
            return Ok(());
        }
        if b.integration == Integration::Mean {
            return Err(self.err(
                format!("{key}.integration"),
                format!("integration = \"mean\" (one-point) applies to hex8 bodies only; {OWN}"),
            ));
        }
        if b.volumetric == Volumetric::MeanDilatation {
            return Err(self.err(
                format!("{key}.volumetric"),
                format!("mean_dilatation applies to hex8 bodies only; {OWN}"),
            ));
        }
        if b.hourglass.is_some() {
            return Err(self.err(
                format!("{key}.hourglass"),
                format!("hourglass control applies to hex8 bodies only; {OWN}"),
            ));
        }
        Ok(())
    }

    /// Contact searches and projects on quadrilateral faces: a side set `set` (a contact
    /// pair's `key`) on a body of another kind is refused until contact takes 6-node
    /// triangles.
    pub(super) fn check_hexahedral(
        &self,
        key: &str,
        mesh: &GlobalMesh,
        set: &SideSet,
    ) -> Result<(), SceneError> {
        let other = set
            .faces
            .iter()
            .map(|&(e, _)| &mesh.bodies[mesh.element_body[e as usize] as usize])
            .find(|b| b.kind != ElementKind::Hex8);
        match other {
            Some(body) => Err(self.err(
                key,
                format!(
                    "side set '{}' lies on body '{}' of {} elements: contact on tet10 faces is \
                     not supported yet",
                    set.name,
                    body.name,
                    body.kind.name()
                ),
            )),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn body(extra: &str) -> BodyDef {
        let text = format!(
            "name = \"part\"\nmaterial = {{ model = \"linear_elastic\", E = 1.0, nu = 0.3 }}\n{extra}"
        );
        toml::from_str(&text).expect("a body table")
    }

    fn builder() -> Builder {
        Builder {
            file: "scene.toml".into(),
        }
    }

    #[test]
    fn a_tet10_body_takes_the_default_and_refuses_the_hexahedra_keys() {
        let b = builder();
        assert!(b
            .kind_formulation("body[0]", ElementKind::Tet10, &body(""))
            .is_ok());
        for (extra, key) in [
            ("integration = \"mean\"", "body[0].integration"),
            ("volumetric = \"mean_dilatation\"", "body[0].volumetric"),
            ("hourglass = 0.05", "body[0].hourglass"),
        ] {
            let e = b
                .kind_formulation("body[0]", ElementKind::Tet10, &body(extra))
                .expect_err(extra);
            assert_eq!(e.key, key);
            assert!(e.to_string().contains("applies to hex8 bodies only"), "{e}");
            assert!(b
                .kind_formulation("body[0]", ElementKind::Hex8, &body(extra))
                .is_ok());
        }
    }

    #[test]
    fn contact_on_a_tet10_side_set_is_refused_with_its_body() {
        let mut mesh = GlobalMesh::default();
        for (name, kind) in [("block", ElementKind::Hex8), ("part", ElementKind::Tet10)] {
            mesh.element_body.push(mesh.bodies.len() as u32);
            mesh.bodies.push(Body {
                name: name.into(),
                kind,
                first_node: 0,
                num_nodes: 0,
                first_element: mesh.bodies.len(),
                num_elements: 1,
            });
        }
        let set = |e: u32| SideSet {
            name: "surface".into(),
            faces: vec![(e, 0)],
        };
        let b = builder();
        assert!(b
            .check_hexahedral("contact[0].master", &mesh, &set(0))
            .is_ok());
        let e = b
            .check_hexahedral("contact[0].slave", &mesh, &set(1))
            .expect_err("a tet10 side set");
        assert_eq!(e.key, "contact[0].slave");
        assert!(
            e.to_string()
                .contains("side set 'surface' lies on body 'part' of tet10 elements: contact on tet10 faces is not supported yet"),
            "{e}"
        );
    }
}
