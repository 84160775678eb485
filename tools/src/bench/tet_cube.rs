//! A unit cube of n^3 cells, each split into six tetrahedra along its main diagonal (the
//! Kuhn split: conforming across cells), written as a Gmsh 4.1 file of 4-node tetrahedra
//! in the physical volume "cube" (the solver's reader completes them to 10 nodes): the
//! tetrahedral kernels' mesh, made without Gmsh.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The six tetrahedra of a cell as paths from corner 0 to corner 7 (corner bits x, y, z),
/// one per order of the three axes.
const PATHS: [[usize; 3]; 6] = [
    [0, 1, 2],
    [0, 2, 1],
    [1, 0, 2],
    [1, 2, 0],
    [2, 0, 1],
    [2, 1, 0],
];

/// The nodes (x, y, z) and the positively oriented tetrahedra (0-based) of the cube.
pub fn tetrahedra(n: usize) -> (Vec<[f64; 3]>, Vec<[usize; 4]>) {
    let id = |i: usize, j: usize, k: usize| i + (n + 1) * (j + (n + 1) * k);
    let h = 1.0 / n as f64;
    let mut x = Vec::with_capacity((n + 1).pow(3));
    for k in 0..=n {
        for j in 0..=n {
            for i in 0..=n {
                x.push([i as f64 * h, j as f64 * h, k as f64 * h]);
            }
        }
    }
    let mut tets = Vec::with_capacity(6 * n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                for path in PATHS {
                    let mut c = [i, j, k];
                    let mut t = [id(c[0], c[1], c[2]); 4];
                    for (s, &axis) in path.iter().enumerate() {
                        c[axis] += 1;
                        t[s + 1] = id(c[0], c[1], c[2]);
                    }
                    if volume6(&x, &t) < 0.0 {
                        t.swap(2, 3);
                    }
                    tets.push(t);
                }
            }
        }
    }
    (x, tets)
}

/// Six times the signed volume of tetrahedron `t`.
fn volume6(x: &[[f64; 3]], t: &[usize; 4]) -> f64 {
    let d = |a: usize| -> [f64; 3] { std::array::from_fn(|r| x[t[a]][r] - x[t[0]][r]) };
    let (a, b, c) = (d(1), d(2), d(3));
    a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
        + a[2] * (b[0] * c[1] - b[1] * c[0])
}

/// The Gmsh 4.1 text of the cube.
pub fn msh(n: usize) -> String {
    let (x, tets) = tetrahedra(n);
    let mut s = String::new();
    s.push_str("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n");
    s.push_str("$PhysicalNames\n1\n3 1 \"cube\"\n$EndPhysicalNames\n");
    s.push_str("$Entities\n0 0 0 1\n1 0 0 0 1 1 1 1 1 0\n$EndEntities\n");
    let _ = write!(s, "$Nodes\n1 {0} 1 {0}\n3 1 0 {0}\n", x.len());
    for k in 1..=x.len() {
        let _ = writeln!(s, "{k}");
    }
    for p in &x {
        let _ = writeln!(s, "{} {} {}", p[0], p[1], p[2]);
    }
    s.push_str("$EndNodes\n");
    let _ = write!(s, "$Elements\n1 {0} 1 {0}\n3 1 4 {0}\n", tets.len());
    for (e, t) in tets.iter().enumerate() {
        let _ = writeln!(
            s,
            "{} {} {} {} {}",
            e + 1,
            t[0] + 1,
            t[1] + 1,
            t[2] + 1,
            t[3] + 1
        );
    }
    s.push_str("$EndElements\n");
    s
}

/// Writes the cube's file into `dir` (created) and returns its path.
pub fn write(dir: &Path, n: usize) -> Result<PathBuf, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let path = dir.join(format!("tet_cube_{n}.msh"));
    std::fs::write(&path, msh(n)).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Six positive tetrahedra per cell filling the cube: volumes sum to 1, none inverted,
    /// every node used.
    #[test]
    fn the_tetrahedra_fill_the_cube() {
        let (x, t) = tetrahedra(3);
        assert_eq!(t.len(), 6 * 27);
        let v: f64 = t.iter().map(|t| volume6(&x, t) / 6.0).sum();
        assert!((v - 1.0).abs() < 1e-12, "{v}");
        assert!(t.iter().all(|t| volume6(&x, t) > 0.0));
        let mut used = vec![false; x.len()];
        t.iter().flatten().for_each(|&k| used[k] = true);
        assert!(used.iter().all(|&u| u));
    }
}
