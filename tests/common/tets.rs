//! A distorted mesh of ten-node tetrahedra built in the test (no mesh file): the unit cube
//! in n x n x n small cubes of six tetrahedra each, shared by the tet10 kernel and solver
//! tests.

use solver::fem::tet10;
use solver::math::Vec3;
use std::collections::HashMap;

/// A mesh of ten-node tetrahedra: node positions and each element's ten node ids.
pub struct Mesh {
    pub x: Vec<Vec3>,
    pub elements: Vec<[usize; 10]>,
}

/// The unit cube as n x n x n small cubes of six tetrahedra each (around the diagonal of
/// each small cube, so that the faces match), every vertex moved by a deterministic wobble
/// of up to 0.14 of the spacing, every midside node moved off its edge's midpoint by up to
/// 0.04 of the spacing (curved edges: the composite element's piecewise-linear map
/// reproduces a linear field on them too). Vertices come first, in lexicographic order.
pub fn distorted_cube(n: usize) -> Mesh {
    let h = 1.0 / n as f64;
    let id = |i: usize, j: usize, k: usize| i + (n + 1) * (j + (n + 1) * k);
    let mut x: Vec<Vec3> = Vec::new();
    for k in 0..=n {
        for j in 0..=n {
            for i in 0..=n {
                let m = x.len() as f64;
                let w = |c: f64| 0.14 * h * (1.7 * m + 2.3 * c).sin();
                x.push([
                    h * i as f64 + w(0.0),
                    h * j as f64 + w(1.0),
                    h * k as f64 + w(2.0),
                ]);
            }
        }
    }
    // The six tetrahedra of a small cube around its diagonal 000-111, each a path
    // 000 -> one axis -> two axes -> 111.
    let perms = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let mut corners = Vec::new();
    for c in 0..n * n * n {
        let (i, j, k) = (c % n, (c / n) % n, c / (n * n));
        for p in perms {
            let mut o = [i, j, k];
            let mut t = [id(o[0], o[1], o[2]); 4];
            for (s, &axis) in p.iter().enumerate() {
                o[axis] += 1;
                t[s + 1] = id(o[0], o[1], o[2]);
            }
            corners.push(t);
        }
    }
    let mut mids: HashMap<(usize, usize), usize> = HashMap::new();
    let mut elements = Vec::new();
    for mut t in corners {
        let vol = |t: &[usize; 4]| {
            let e = |a: usize| std::array::from_fn::<f64, 3, _>(|c| x[t[a]][c] - x[t[0]][c]);
            solver::math::det(&[e(1), e(2), e(3)])
        };
        if vol(&t) < 0.0 {
            t.swap(1, 2);
        }
        let mut el = [0; 10];
        el[..4].copy_from_slice(&t);
        for (m, &(a, b)) in tet10::MIDSIDE.iter().enumerate() {
            let key = (t[a].min(t[b]), t[a].max(t[b]));
            el[4 + m] = *mids.entry(key).or_insert_with(|| {
                let m = x.len() as f64;
                let bend = |c: f64| 0.04 * h * (0.9 * m + 1.3 * c).cos();
                x.push(std::array::from_fn(|c| {
                    0.5 * (x[key.0][c] + x[key.1][c]) + bend(c as f64)
                }));
                x.len() - 1
            });
        }
        elements.push(el);
    }
    Mesh { x, elements }
}

/// The nodes on the mesh's boundary: those of the faces only one element has.
pub fn boundary(mesh: &Mesh) -> Vec<bool> {
    let mut count: HashMap<[usize; 3], (usize, [usize; 6])> = HashMap::new();
    for el in &mesh.elements {
        for f in tet10::FACES {
            let mut key = [el[f[0]], el[f[1]], el[f[2]]];
            key.sort_unstable();
            let e = count.entry(key).or_insert((0, f.map(|a| el[a])));
            e.0 += 1;
        }
    }
    let mut on = vec![false; mesh.x.len()];
    for (n, nodes) in count.values() {
        if *n == 1 {
            for &a in nodes {
                on[a] = true;
            }
        }
    }
    on
}
