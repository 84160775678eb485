//! What a body's element kind allows in the scene: a tet10 body is the composite
//! tetrahedron, its own integration (the hexahedra's one-point keys are refused, not
//! ignored); it takes the mean dilatation under small kinematics.

use super::*;

/// Why the hexahedra's integration keys do not apply to a tet10 body.
const OWN: &str = "a tet10 body is the composite tetrahedron, its own formulation (four stress \
                   points of a projected strain, no hourglass modes): leave the key out";

impl Builder {
    /// Refuses the integration keys of body `key` (`b`) that its `kind` does not take
    /// (`large`: the scene's kinematics are large).
    pub(super) fn kind_formulation(
        &self,
        key: &str,
        kind: ElementKind,
        b: &BodyDef,
        large: bool,
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
        if b.volumetric == Volumetric::MeanDilatation && large {
            return Err(self.err(
                format!("{key}.volumetric"),
                "mean_dilatation on a tet10 body takes kinematics = \"small\" (the composite \
                 tetrahedron's F-bar is not built): leave the key out, or use small kinematics",
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
            .kind_formulation("body[0]", ElementKind::Tet10, &body(""), true)
            .is_ok());
        for (extra, key) in [
            ("integration = \"mean\"", "body[0].integration"),
            ("hourglass = 0.05", "body[0].hourglass"),
        ] {
            let e = b
                .kind_formulation("body[0]", ElementKind::Tet10, &body(extra), false)
                .expect_err(extra);
            assert_eq!(e.key, key);
            assert!(e.to_string().contains("applies to hex8 bodies only"), "{e}");
            assert!(b
                .kind_formulation("body[0]", ElementKind::Hex8, &body(extra), true)
                .is_ok());
        }
        // The mean dilatation: small kinematics only.
        let bar = body("volumetric = \"mean_dilatation\"");
        assert!(b
            .kind_formulation("body[0]", ElementKind::Tet10, &bar, false)
            .is_ok());
        let e = b
            .kind_formulation("body[0]", ElementKind::Tet10, &bar, true)
            .expect_err("large");
        assert_eq!(e.key, "body[0].volumetric");
        assert!(
            e.to_string().contains("takes kinematics = \"small\""),
            "{e}"
        );
    }
}
