//! `solver run --export-operator DIR`: the first model problem that needs a CG iteration,
//! assembled (`solver::cg::ModelExport`), written as NumPy arrays and a JSON summary for
//! other solvers (`run/pyamg_peer.py`):
//!
//! - `A_indptr.npy` (int64), `A_indices.npy` (int32), `A_data.npy` (float64): the operator
//!   in CSR form, rows and columns the unknowns;
//! - `b.npy`: the right-hand side; `B.npy` (unknowns x 6): the rigid-body modes;
//! - `node_id.npy` (int64, 1-based global node ids as in the result file) and
//!   `direction.npy` (unknowns x 3): what each unknown is;
//! - `model.json`: sizes, the stopping rule and our CG's outcome on the same problem.

use crate::output::npy::write_npy;
use crate::solver::cg::ModelExport;
use std::path::Path;

/// The stopping rule of our CG, in words, for the summary.
const STOPPING_RULE: &str = "|r| <= tolerance * reference, r = b - A x (2-norm over the unknowns), reference = max(|f_ext|, |reaction force|, floor) recomputed with every true residual (every 50 iterations and at convergence); x starts at 0";

/// Writes the export into `dir` (created if missing); the error names the file.
pub fn write_export(dir: &Path, scene: &str, e: &ModelExport) -> Result<(), String> {
    std::fs::create_dir_all(dir)
        .map_err(|err| format!("cannot create {}: {err}", dir.display()))?;
    let m = e.rhs.len();
    let a = &e.matrix;
    let ptr: Vec<i64> = a.ptr.iter().map(|&p| p as i64).collect();
    let idx: Vec<i32> = a.idx.iter().map(|&j| j as i32).collect();
    write_npy(&dir.join("A_indptr.npy"), &ptr, &[ptr.len()])?;
    write_npy(&dir.join("A_indices.npy"), &idx, &[idx.len()])?;
    write_npy(&dir.join("A_data.npy"), &a.val, &[a.val.len()])?;
    write_npy(&dir.join("b.npy"), &e.rhs, &[m])?;
    write_npy(&dir.join("B.npy"), e.modes.as_flattened(), &[m, 6])?;
    let ids: Vec<i64> = e.node.iter().map(|&g| g as i64 + 1).collect();
    write_npy(&dir.join("node_id.npy"), &ids, &[m])?;
    write_npy(
        &dir.join("direction.npy"),
        e.direction.as_flattened(),
        &[m, 3],
    )?;
    let mut nodes = e.node.clone();
    nodes.dedup();
    let summary = serde_json::json!({
        "scene": scene,
        "unknowns": m,
        "nodes": nodes.len(),
        "nonzeros": a.nnz(),
        "time": e.time,
        "dirichlet_rows": e.dirichlet_rows,
        "contact_rows": e.contact_rows,
        "assembly_check": e.check_error,
        "stopping_rule": STOPPING_RULE,
        "tolerance": e.tolerance,
        "residual_start": e.residual_start,
        "reference_start": e.reference_start,
        "cg_iterations": e.iterations,
        "residual_end": e.residual_end,
        "reference_end": e.reference_end,
        "failure": e.failure,
    });
    let path = dir.join("model.json");
    let text = serde_json::to_string_pretty(&summary).map_err(|err| err.to_string())?;
    std::fs::write(&path, text + "\n")
        .map_err(|err| format!("cannot write {}: {err}", path.display()))
}
