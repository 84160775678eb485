//! What an Exodus file of a result holds besides the mesh: which of the optional variables
//! (contact pressure, equivalent plastic strain) and how many steps.

use super::names as n;
use crate::output::{OutputError, OutputMesh, ResultFile};

/// What the file holds besides the mesh: which optional variables, how many steps.
pub(super) struct Shape {
    pub nodal: Vec<&'static str>,
    pub element: Vec<&'static str>,
    pub steps: usize,
}

impl Shape {
    pub(super) fn of(f: &ResultFile, mesh: &OutputMesh) -> Result<Self, OutputError> {
        let nodal = n::NODAL_VARIABLES
            .iter()
            .copied()
            .filter(|v| *v != "contact_pressure" || f.has_contact_pressure())
            .collect();
        let plastic = f.num_steps() > 0 && f.plastic_strain(0)?.is_some();
        let element = n::ELEMENT_VARIABLES
            .iter()
            .copied()
            .filter(|v| *v != "eqps" || plastic)
            .collect();
        // Ids are written as netCDF `int` (32-bit), which every Exodus reader takes.
        let too_big = mesh.node_ids.iter().any(|&i| i > i32::MAX as u64)
            || mesh
                .bodies
                .iter()
                .any(|b| b.element_ids.iter().any(|&i| i > i32::MAX as u64));
        if too_big {
            return Err(OutputError::Invalid {
                file: f.path().to_path_buf(),
                dataset: "node_num_map".into(),
                message: "an id beyond 2^31 - 1 does not fit Exodus's 32-bit ids".into(),
            });
        }
        Ok(Shape {
            nodal,
            element,
            steps: f.num_steps(),
        })
    }
}
