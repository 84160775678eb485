//! One run of the study as its row: what `mod.rs` measured, which `csv` and `report` read.

/// One scene at one refinement, tolerance and rank count.
pub struct Row {
    pub series: String,
    pub scene: String,
    pub factor: u32,
    pub tolerance: f64,
    pub ranks: usize,
    /// None when the run did not finish or the check is missing.
    pub error: Option<f64>,
    pub wall_time: Option<f64>,
    pub cg_iterations: Option<f64>,
    pub contact_updates: Option<f64>,
    /// Whether the 2-rank result equals the 1-rank one bitwise (None on 1 rank).
    pub identical: Option<bool>,
    pub status: String,
}

/// An optional figure in the files' number format (`-` when missing).
pub fn opt(v: Option<f64>) -> String {
    v.map_or("-".into(), |v| format!("{v:.3e}"))
}
