//! The `material` table of a body: the model under the scene's kinematics, its parameters
//! checked by the model (`material::Parameters`), errors named by the table's key.

use super::error::{Builder, SceneError};
use crate::material::Material;
use crate::problem::Kinematics;
use crate::scene::types::MaterialDef;

impl Builder {
    pub(super) fn material(
        &self,
        key: &str,
        m: &MaterialDef,
        kin: Kinematics,
    ) -> Result<(Material, f64), SceneError> {
        let params = m.params();
        let material = params
            .build(matches!(kin, Kinematics::Large))
            .map_err(|e| self.err(format!("{key}.{}", e.key), e.message))?;
        Ok((material, params.density()))
    }
}
