//! What the tetrahedra section measured: each mesh's run of ours and of ccx. The runner
//! (`mod.rs`) produces it and the report (`report.rs`) reads it.

use super::scenes::Case;

/// What one code measured on one mesh.
#[derive(Clone, Debug)]
pub struct Measured {
    pub wall: f64,
    /// Our CG iterations, or ccx's Newton iterations.
    pub iterations: u64,
    /// Cook: the tip's mean u_y; punch: the mean pressure at the end.
    pub value: f64,
}

/// One mesh: ours and ccx's (tetrahedral meshes only).
pub struct Row {
    pub case: Case,
    pub nodes: usize,
    pub ours: Result<Measured, String>,
    pub ccx: Option<Result<Measured, String>>,
}
