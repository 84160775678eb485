//! Structured hexahedral blocks: a box or a general hexahedron given by 8 corners, meshed
//! nx x ny x nz. Nodes are numbered with z fastest, then x, then y (the paper numbering);
//! elements likewise.

use crate::fem::hex8;
use crate::math::Vec3;
use crate::memory::{try_with_capacity, AllocError};

/// Node positions and element connectivity (0-based, local to the block).
pub struct Block {
    pub coords: Vec<Vec3>,
    pub elements: Vec<[u32; 8]>,
}

/// Corner points of an axis-aligned box in hexahedron node order.
pub fn box_corners(min: &Vec3, max: &Vec3) -> [Vec3; 8] {
    let mut c = [[0.0; 3]; 8];
    for (a, ca) in c.iter_mut().enumerate() {
        for i in 0..3 {
            ca[i] = if hex8::NODE_XI[a][i] < 0.0 {
                min[i]
            } else {
                max[i]
            };
        }
    }
    c
}

/// Fails only when the memory for it is refused.
pub fn generate(corners: &[Vec3; 8], nx: usize, ny: usize, nz: usize) -> Result<Block, AllocError> {
    let node = |i: usize, j: usize, k: usize| -> u32 { ((j * (nx + 1) + i) * (nz + 1) + k) as u32 };
    let mut coords =
        try_with_capacity((nx + 1) * (ny + 1) * (nz + 1), "a block's node coordinates")?;
    for j in 0..=ny {
        for i in 0..=nx {
            for k in 0..=nz {
                let xi = [
                    -1.0 + 2.0 * i as f64 / nx as f64,
                    -1.0 + 2.0 * j as f64 / ny as f64,
                    -1.0 + 2.0 * k as f64 / nz as f64,
                ];
                let n = hex8::shape(&xi);
                let mut x = [0.0; 3];
                for a in 0..8 {
                    for d in 0..3 {
                        x[d] += n[a] * corners[a][d];
                    }
                }
                // Snap exact corner values so faces on coordinate planes are exactly planar.
                for d in 0..3 {
                    for a in 0..8 {
                        if (x[d] - corners[a][d]).abs() <= 1e-15 * corners[a][d].abs() {
                            x[d] = corners[a][d];
                        }
                    }
                }
                coords.push(x);
            }
        }
    }
    let mut elements = try_with_capacity(nx * ny * nz, "a block's element connectivity")?;
    for j in 0..ny {
        for i in 0..nx {
            for k in 0..nz {
                elements.push([
                    node(i, j, k),
                    node(i + 1, j, k),
                    node(i + 1, j + 1, k),
                    node(i, j + 1, k),
                    node(i, j, k + 1),
                    node(i + 1, j, k + 1),
                    node(i + 1, j + 1, k + 1),
                    node(i, j + 1, k + 1),
                ]);
            }
        }
    }
    Ok(Block { coords, elements })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_numbering_of_a_two_element_block() {
        // Normal-smoothing scene, upper body: [0,2]x[1,2]x[0,1], 2x1x1. With 12 nodes before
        // it, its bottom centre nodes (x = 1, y = 1) are 15 and 16 (1-based).
        let b = generate(&box_corners(&[0.0, 1.0, 0.0], &[2.0, 2.0, 1.0]), 2, 1, 1).unwrap();
        assert_eq!(b.coords.len(), 12);
        assert_eq!(b.coords[2], [1.0, 1.0, 0.0]);
        assert_eq!(b.coords[3], [1.0, 1.0, 1.0]);
        assert_eq!(b.elements.len(), 2);
        for el in &b.elements {
            let x: Vec<Vec3> = el.iter().map(|&n| b.coords[n as usize]).collect();
            let x: [Vec3; 8] = x.try_into().unwrap();
            assert!(hex8::min_jacobian_ratio(&x) > 0.99);
        }
    }
}
