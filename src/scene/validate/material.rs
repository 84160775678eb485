//! The `material` table of a body: elastic constants, density and, for `j2_plastic`, the
//! yield stress and hardening moduli, checked against the scene's kinematics.

use super::{Builder, SceneError};
use crate::material::{J2Plastic, LinearElastic, Material, NeoHookean};
use crate::problem::Kinematics;
use crate::scene::types::MaterialDef;

/// Plastic parameters as given: (yield stress, isotropic, kinematic hardening).
type Plastic = (f64, f64, f64);

impl Builder {
    pub(super) fn material(
        &self,
        key: &str,
        m: &MaterialDef,
        kin: Kinematics,
    ) -> Result<(Material, f64), SceneError> {
        let (e, nu, density, plastic): (f64, f64, f64, Option<Plastic>) = match *m {
            MaterialDef::LinearElastic { e, nu, density } => (e, nu, density, None),
            MaterialDef::NeoHookean { e, nu, density } => (e, nu, density, None),
            MaterialDef::J2Plastic {
                e,
                nu,
                density,
                yield_stress,
                isotropic_hardening,
                kinematic_hardening,
            } => (
                e,
                nu,
                density,
                Some((yield_stress, isotropic_hardening, kinematic_hardening)),
            ),
        };
        if !(e.is_finite() && e > 0.0) {
            return Err(self.err(
                format!("{key}.E"),
                format!("expected Young's modulus > 0, got {e}"),
            ));
        }
        if !(nu.is_finite() && nu > -1.0 && nu < 0.5) {
            return Err(self.err(
                format!("{key}.nu"),
                format!("expected Poisson's ratio in (-1, 0.5), got {nu}"),
            ));
        }
        if !(density.is_finite() && density >= 0.0) {
            return Err(self.err(
                format!("{key}.density"),
                format!("expected a density >= 0, got {density}"),
            ));
        }
        let mat = match (m, kin) {
            (MaterialDef::LinearElastic { .. }, Kinematics::Small) => {
                Material::LinearElastic(LinearElastic::new(e, nu))
            }
            (MaterialDef::NeoHookean { .. }, Kinematics::Large) => {
                Material::NeoHookean(NeoHookean::new(e, nu))
            }
            (MaterialDef::LinearElastic { .. }, Kinematics::Large) => {
                return Err(self.err(format!("{key}.model"), "linear_elastic needs kinematics = \"small\"; use neo_hookean for kinematics = \"large\""))
            }
            (MaterialDef::NeoHookean { .. }, Kinematics::Small) => {
                return Err(self.err(format!("{key}.model"), "neo_hookean needs kinematics = \"large\""))
            }
            (MaterialDef::J2Plastic { .. }, kin) => {
                let p = plastic.unwrap_or_default();
                Material::J2Plastic(self.j2(key, e, nu, p, kin)?)
            }
        };
        Ok((mat, density))
    }

    fn j2(
        &self,
        key: &str,
        e: f64,
        nu: f64,
        (yield_stress, isotropic, kinematic): Plastic,
        kin: Kinematics,
    ) -> Result<J2Plastic, SceneError> {
        if !(yield_stress.is_finite() && yield_stress > 0.0) {
            return Err(self.err(
                format!("{key}.yield_stress"),
                format!("expected a yield stress > 0, got {yield_stress}"),
            ));
        }
        // Softening (a negative modulus) makes the load step's energy non-convex: the
        // minimisation the solver performs has no unique answer and the mesh decides it.
        for (name, v) in [
            ("isotropic_hardening", isotropic),
            ("kinematic_hardening", kinematic),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(self.err(
                    format!("{key}.{name}"),
                    format!("expected a hardening modulus >= 0 (softening is not supported: the load step would have no unique solution), got {v}"),
                ));
            }
        }
        let large = matches!(kin, Kinematics::Large);
        if large && kinematic != 0.0 {
            return Err(self.err(
                format!("{key}.kinematic_hardening"),
                "kinematic hardening is available with kinematics = \"small\" only; under kinematics = \"large\" j2_plastic hardens isotropically (use isotropic_hardening)",
            ));
        }
        Ok(J2Plastic::new(
            e,
            nu,
            yield_stress,
            isotropic,
            kinematic,
            large,
        ))
    }
}
