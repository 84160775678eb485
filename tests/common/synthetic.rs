//! A synthetic result file (two bodies, node and side sets, contact fields), written
//! without a solve: shared by tests/output.rs and tests/output_post.rs.

use std::path::{Path, PathBuf};

use solver::output::{
    ElementNodes, OutputBody, OutputMesh, ResultWriter, RunInfo, StepOutput, StepStats,
};

/// A fresh, empty directory for one test.
#[track_caller]
pub fn test_dir(name: &str) -> PathBuf {
    super::fresh_dir(&format!("output-tests/{name}"))
}

/// Nodes and hexahedra of a structured box of `n` elements, node indices from `first`.
pub fn block(origin: [f64; 3], n: [usize; 3], first: u64) -> (Vec<[f64; 3]>, Vec<[u64; 8]>) {
    let mut coords = Vec::new();
    for k in 0..=n[2] {
        for j in 0..=n[1] {
            for i in 0..=n[0] {
                coords.push([
                    origin[0] + i as f64,
                    origin[1] + j as f64,
                    origin[2] + k as f64,
                ]);
            }
        }
    }
    let id = |i: usize, j: usize, k: usize| first + (i + (n[0] + 1) * (j + (n[1] + 1) * k)) as u64;
    let mut hexes = Vec::new();
    for k in 0..n[2] {
        for j in 0..n[1] {
            for i in 0..n[0] {
                hexes.push([
                    id(i, j, k),
                    id(i + 1, j, k),
                    id(i + 1, j + 1, k),
                    id(i, j + 1, k),
                    id(i, j, k + 1),
                    id(i + 1, j, k + 1),
                    id(i + 1, j + 1, k + 1),
                    id(i, j + 1, k + 1),
                ]);
            }
        }
    }
    (coords, hexes)
}

/// Two bodies: a unit cube ("base", 8 nodes, 1 element) and a 2x1x1 plate above it ("lid",
/// 12 nodes, 2 elements). Node ids are 2i+1, element ids 1..3.
pub fn synthetic_mesh() -> OutputMesh {
    let (mut coordinates, base) = block([0.0, 0.0, 0.0], [1, 1, 1], 0);
    let (lid_coords, lid) = block([0.0, 0.0, 1.25], [2, 1, 1], 8);
    coordinates.extend(lid_coords);
    let node_ids: Vec<u64> = (0..coordinates.len() as u64).map(|i| 2 * i + 1).collect();
    let top: Vec<u64> = coordinates
        .iter()
        .zip(&node_ids)
        .filter(|(c, _)| c[2] == 2.25)
        .map(|(_, &id)| id)
        .collect();
    let bottom: Vec<u64> = coordinates
        .iter()
        .zip(&node_ids)
        .filter(|(c, _)| c[2] == 0.0)
        .map(|(_, &id)| id)
        .collect();
    OutputMesh {
        coordinates,
        node_ids,
        bodies: vec![
            OutputBody {
                name: "base".into(),
                connectivity: ElementNodes::from_rows(&base),
                element_ids: vec![1],
            },
            OutputBody {
                name: "lid".into(),
                connectivity: ElementNodes::from_rows(&lid),
                element_ids: vec![2, 3],
            },
        ],
        node_sets: vec![("top".into(), top), ("bottom".into(), bottom)],
        side_sets: vec![
            ("contact_slave".into(), vec![(2, 4), (3, 4)]),
            ("contact_master".into(), vec![(1, 5)]),
        ],
    }
}

pub fn synthetic_info() -> RunInfo {
    RunInfo {
        solver_version: "0.1.0-test".into(),
        ranks: 2,
        scene_text: "[scene]\nname = \"two blocks\"\n# a comment with <xml> & \"quotes\"\n".into(),
        scene_name: "two blocks".into(),
        start_time: "2024-05-01T12:00:00Z".into(),
        element_rank: vec![0, 1, 1],
    }
}

/// Step `s` with values distinct per step, node, element and component.
pub fn synthetic_step(s: usize, mesh: &OutputMesh) -> StepOutput {
    let n = mesh.coordinates.len();
    let e = mesh.num_elements();
    let sf = s as f64 + 1.0;
    StepOutput {
        time: 0.25 * sf,
        displacement: (0..n)
            .map(|i| {
                let c = mesh.coordinates[i];
                [1e-3 * sf * c[0], -2e-3 * sf * c[2], 1e-4 * (i as f64) + sf]
            })
            .collect(),
        stress: (0..e)
            .map(|j| std::array::from_fn(|k| 1e6 * sf + 1e3 * j as f64 + k as f64))
            .collect(),
        reaction: (0..n)
            .map(|i| [sf, -(i as f64), 0.5 * sf * i as f64])
            .collect(),
        contact_force: (0..n)
            .map(|i| [0.0, 10.0 * sf + i as f64, -3.0 * sf])
            .collect(),
        contact_status: (0..n).map(|i| ((i + s) % 4) as u8).collect(),
        contact_gap: (0..n).map(|i| 1e-2 * (i as f64) - 1e-3 * sf).collect(),
        contact_pressure: (0..n).map(|i| 2.5 * sf * (i % 3) as f64).collect(),
        plastic_strain: Vec::new(),
        stats: StepStats {
            cg_iterations: 40 + s as u64,
            contact_updates: s as u64 % 2 + 1,
            residual: 1e-9 / sf,
            wall_time: 0.5 + 0.1 * sf,
            cutbacks: u64::from(s == 1),
            // Distinct per step and field; active = stick + slip as the solver reports.
            contact_active: 5 + 2 * s as u64,
            contact_stick: 3 + s as u64,
            contact_slip: 2 + s as u64,
            contact_released: s as u64 % 2,
            // Step 0 has no penetration (the value is 0 then, never negative).
            max_penetration: 2.5e-4 * s as f64,
        },
    }
}

/// Writes the synthetic result with `steps` steps to `<dir>/<name>.h5`, finished.
pub fn write_synthetic(dir: &Path, name: &str, steps: usize) -> PathBuf {
    let mesh = synthetic_mesh();
    let mut w =
        ResultWriter::create(&dir.join(format!("{name}.h5")), &synthetic_info(), &mesh).unwrap();
    for s in 0..steps {
        w.append_step(&synthetic_step(s, &mesh)).unwrap();
    }
    w.finish(12.5).unwrap()
}
