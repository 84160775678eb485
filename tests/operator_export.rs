//! `--export-operator`: the first model problem assembled by probing the matrix-free
//! constrained operator (Dirichlet rows and contact ties) equals that operator on a
//! pseudo-random vector to round-off, is symmetric, and its right-hand side is CG's
//! starting residual.

use crate::common;
use solver::comm::SerialComm;
use solver::run::{run, RunOptions};
use std::path::Path;

/// The data of a little-endian `.npy` file written by `output::npy` (f8, i8 or i4) as f64.
fn read_npy(path: &Path) -> Vec<f64> {
    let b = std::fs::read(path).unwrap();
    assert_eq!(&b[..6], b"\x93NUMPY");
    let hlen = u16::from_le_bytes([b[8], b[9]]) as usize;
    let header = std::str::from_utf8(&b[10..10 + hlen]).unwrap();
    let data = &b[10 + hlen..];
    if header.contains("'<f8'") {
        data.chunks(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect()
    } else if header.contains("'<i8'") {
        data.chunks(8)
            .map(|c| i64::from_le_bytes(c.try_into().unwrap()) as f64)
            .collect()
    } else {
        assert!(header.contains("'<i4'"), "{header}");
        data.chunks(4)
            .map(|c| i32::from_le_bytes(c.try_into().unwrap()) as f64)
            .collect()
    }
}

#[test]
fn exported_operator_is_the_matrix_free_operator() {
    let text = std::fs::read_to_string(common::repo("run/scenes/bench/block_on_block.toml"))
        .unwrap()
        .replace("divisions = [10, 10, 10]", "divisions = [4, 4, 4]")
        .replace(
            "tolerance = 1e-8",
            "tolerance = 1e-8\npreconditioner = \"multilevel\"",
        );
    let p = common::problem(&text);
    let dir = common::fresh_dir("operator_export");
    let (summary, _) = run(
        &SerialComm,
        &p,
        &RunOptions {
            output: None,
            verbosity: 0,
            export_operator: Some(dir.clone()),
            final_state: true,
            partition: Default::default(),
        },
    )
    .unwrap();
    assert!(summary.failure.is_none(), "{:?}", summary.failure);
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("model.json")).unwrap()).unwrap();
    let check = meta["assembly_check"].as_f64().unwrap();
    assert!(
        check < 1e-12,
        "assembled A x differs from the operator by {check:e}"
    );
    assert!(
        meta["contact_rows"].as_u64().unwrap() > 0,
        "no contact ties: {meta}"
    );
    assert!(meta["cg_iterations"].as_u64().unwrap() > 0);
    let m = meta["unknowns"].as_u64().unwrap() as usize;

    let ptr: Vec<usize> = read_npy(&dir.join("A_indptr.npy"))
        .iter()
        .map(|&v| v as usize)
        .collect();
    let idx: Vec<usize> = read_npy(&dir.join("A_indices.npy"))
        .iter()
        .map(|&v| v as usize)
        .collect();
    let val = read_npy(&dir.join("A_data.npy"));
    assert_eq!(ptr.len(), m + 1);
    let mut dense = vec![0.0; m * m];
    for i in 0..m {
        for k in ptr[i]..ptr[i + 1] {
            dense[i * m + idx[k]] = val[k];
        }
    }
    let amax = val.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    for i in 0..m {
        assert!(dense[i * m + i] > 0.0, "diagonal {i} not positive");
        for j in 0..i {
            let d = (dense[i * m + j] - dense[j * m + i]).abs();
            assert!(d <= 1e-12 * amax, "A not symmetric at ({i}, {j}): {d:e}");
        }
    }
    // The right-hand side is CG's starting residual, whose norm the summary gives.
    let b = read_npy(&dir.join("b.npy"));
    let bn = b.iter().map(|v| v * v).sum::<f64>().sqrt();
    let r0 = meta["residual_start"].as_f64().unwrap();
    assert!(
        (bn - r0).abs() <= 1e-12 * r0,
        "|b| = {bn}, CG's |r0| = {r0}"
    );
    // Unit directions and six modes per unknown.
    let dir3 = read_npy(&dir.join("direction.npy"));
    assert_eq!(dir3.len(), 3 * m);
    for d in dir3.chunks(3) {
        assert!((d.iter().map(|v| v * v).sum::<f64>() - 1.0).abs() < 1e-14);
    }
    assert_eq!(read_npy(&dir.join("B.npy")).len(), 6 * m);
}
