//! What a body's element kind allows in the scene: a tet10 body is the composite
//! tetrahedron, its own formulation (the hexahedra's integration keys are refused, not
//! ignored). (Contact on its 6-node faces is refused by `contacts.rs`.)

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
}
