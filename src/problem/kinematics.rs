//! Small or large kinematics: the strain measure and the configuration the equations are
//! written in.

use serde::Deserialize;

/// `small`: linearised strain, equations on the undeformed configuration; `large`: the
/// deformation gradient, equilibrium on the deformed configuration.
#[derive(serde::Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum Kinematics {
    #[default]
    Small,
    Large,
}
