//! Reference-configuration geometry of an element: the volume-averaged gradients, the
//! Gauss-point gradients and weights, the hourglass base vectors and stiffness, and the
//! helpers that move arrays of Gauss-point values (gather a gradient, scatter a force).

use super::ElementFailure;
use crate::fem::hex8::{gradients, jacobian, shape_derivatives, GAUSS, NODE_XI};
use crate::math::{Mat3, Vec3, ZERO33};

/// Reference-configuration data of one element that every formulation uses: computed once
/// per element and reused for every evaluation (see `Assembly`). 304 bytes.
#[derive(Clone, Debug)]
pub struct Geometry {
    /// Volume-averaged gradients (the uniform gradient of Flanagan and Belytschko),
    /// component-major: `bbar[k][a]` = d N_a / d X_k averaged over the element.
    pub(in crate::fem) bbar: [[f64; 8]; 3],
    pub(in crate::fem) volume: f64,
    /// volume * sum_a |bbar_a|^2, the scale of the hourglass stiffness.
    vbb: f64,
    /// Hourglass sums of the reference coordinates, hx_alpha = sum_a base_alpha,a x_a
    /// (kept so the one-point kernel need not gather the coordinates).
    hx: [Vec3; 4],
}

/// The gradients at the eight Gauss points, Gauss-point index innermost (`g[a][k][q]`)
/// so that loops over the Gauss points vectorise, and det J at each. 1600 bytes; needed
/// only by the fully integrated formulations.
#[derive(Clone, Debug, Default)]
pub struct GaussGeometry {
    g: [[[f64; 8]; 3]; 8],
    pub(in crate::fem) wdet: [f64; 8],
}

/// A 3x3 matrix at each of the eight Gauss points: `m[i][j][q]`.
pub(in crate::fem) type QMat = [[[f64; 8]; 3]; 3];
pub(super) const ZERO_Q: QMat = [[[0.0; 8]; 3]; 3];

/// The hourglass base vectors (xi eta, eta zeta, zeta xi, xi eta zeta at the nodes):
/// `HG_BASE[alpha][a]`, entries +-1.
pub(super) const HG_BASE: [[f64; 8]; 4] = hg_base();

const fn hg_base() -> [[f64; 8]; 4] {
    let mut b = [[0.0; 8]; 4];
    let mut a = 0;
    while a < 8 {
        let p = NODE_XI[a];
        b[0][a] = p[1] * p[2];
        b[1][a] = p[2] * p[0];
        b[2][a] = p[0] * p[1];
        b[3][a] = p[0] * p[1] * p[2];
        a += 1;
    }
    b
}

/// The element's shape: its coordinates relative to its first node. Elements that are
/// translated copies of each other have the same shape bit for bit when their coordinates
/// lie on one grid (`solver::shapes`: the differences of grid values are exact), so the
/// elements of a regular mesh (a structured box, an extruded or transfinite Gmsh mesh)
/// share a few shapes, and one computed geometry (`geometry` of the shape) serves each.
#[inline]
pub fn reference_shape(x: &[Vec3; 8]) -> [Vec3; 8] {
    let mut d = [[0.0; 3]; 8];
    for a in 1..8 {
        for i in 0..3 {
            d[a][i] = x[a][i] - x[0][i];
        }
    }
    d
}

#[inline]
pub fn geometry(x: &[Vec3; 8]) -> Result<(Geometry, GaussGeometry), ElementFailure> {
    let mut gauss = GaussGeometry::default();
    let mut volume = 0.0;
    let mut bbar = [[0.0; 8]; 3];
    for q in 0..8 {
        let (gq, d) = gradients(x, &GAUSS[q]).ok_or(ElementFailure::InvertedReference)?;
        gauss.wdet[q] = d;
        volume += d;
        for a in 0..8 {
            for k in 0..3 {
                gauss.g[a][k][q] = gq[a][k];
                bbar[k][a] += d * gq[a][k];
            }
        }
    }
    let mut bb = 0.0;
    for row in bbar.iter_mut() {
        for v in row.iter_mut() {
            *v /= volume;
            bb += *v * *v;
        }
    }
    let mut hx = [[0.0; 3]; 4];
    for (alpha, h) in hx.iter_mut().enumerate() {
        for a in 0..8 {
            for i in 0..3 {
                h[i] += HG_BASE[alpha][a] * x[a][i];
            }
        }
    }
    Ok((
        Geometry {
            bbar,
            volume,
            vbb: volume * bb,
            hx,
        },
        gauss,
    ))
}

impl Geometry {
    /// The root mean square of the nodes' mean gradients, sqrt(sum_a |bbar_a|^2 / 8).
    #[inline]
    pub(in crate::fem) fn rms_gradient(&self) -> f64 {
        (self.vbb / (8.0 * self.volume)).sqrt()
    }

    /// volume * sum_a |bbar_a|^2
    #[inline]
    pub(in crate::fem) fn vbb(&self) -> f64 {
        self.vbb
    }

    #[inline]
    pub(in crate::fem) fn bbar_at(&self, a: usize) -> Vec3 {
        [self.bbar[0][a], self.bbar[1][a], self.bbar[2][a]]
    }
}

#[inline(always)]
pub(in crate::fem) fn g_at(gauss: &GaussGeometry, a: usize, q: usize) -> Vec3 {
    [gauss.g[a][0][q], gauss.g[a][1][q], gauss.g[a][2][q]]
}

/// h_ij = sum_a u_a,i bbar_a,j (the element-mean displacement gradient)
#[inline]
pub(in crate::fem) fn mean_gradient(u: &[Vec3; 8], geo: &Geometry) -> Mat3 {
    let mut h = ZERO33;
    for a in 0..8 {
        for i in 0..3 {
            for j in 0..3 {
                h[i][j] += u[a][i] * geo.bbar[j][a];
            }
        }
    }
    h
}

/// h_ij(q) = sum_a u_a,i g_a,j(q) at every Gauss point.
#[inline(always)]
pub(in crate::fem) fn gauss_gradient(u: &[Vec3; 8], gauss: &GaussGeometry) -> QMat {
    let mut h = ZERO_Q;
    for j in 0..3 {
        let mut acc = [[0.0; 8]; 3];
        for a in 0..8 {
            let ga = &gauss.g[a][j];
            for i in 0..3 {
                let ua = u[a][i];
                for q in 0..8 {
                    acc[i][q] += ua * ga[q];
                }
            }
        }
        for i in 0..3 {
            h[i][j] = acc[i];
        }
    }
    h
}

/// f_a,i += sum_q sum_j t_ij(q) g_a,j(q)  (t already carries the quadrature weights).
#[inline(always)]
pub(super) fn gauss_scatter(t: &QMat, gauss: &GaussGeometry, f: &mut [Vec3; 8]) {
    for a in 0..8 {
        let ga = &gauss.g[a];
        for i in 0..3 {
            let mut acc = [0.0; 8];
            for j in 0..3 {
                for q in 0..8 {
                    acc[q] += t[i][j][q] * ga[j][q];
                }
            }
            f[a][i] += hsum(&acc);
        }
    }
}

/// Sum of eight values in a fixed order.
#[inline(always)]
fn hsum(v: &[f64; 8]) -> f64 {
    let s = [v[0] + v[4], v[1] + v[5], v[2] + v[6], v[3] + v[7]];
    (s[0] + s[2]) + (s[1] + s[3])
}

#[inline(always)]
pub(in crate::fem) fn at(m: &QMat, q: usize) -> Mat3 {
    std::array::from_fn(|i| std::array::from_fn(|j| m[i][j][q]))
}

/// t(q) = w m
#[inline(always)]
pub(super) fn put(t: &mut QMat, q: usize, m: &Mat3, w: f64) {
    for i in 0..3 {
        for j in 0..3 {
            t[i][j][q] = w * m[i][j];
        }
    }
}

/// Hourglass sums of the reference coordinates, hx_alpha = sum_a base_alpha,a x_a (from
/// the geometry): the hourglass vectors orthogonalised against linear fields are
/// gamma_alpha,a = base_alpha,a - bbar_a . hx_alpha, and f_a = sum_alpha gamma_alpha,a
/// Q_alpha with Q = K q (`stabilization`), q_alpha = sum_a gamma_alpha,a u_a.
#[inline]
pub(in crate::fem) fn hourglass(geo: &Geometry) -> [Vec3; 4] {
    geo.hx
}

/// Reference volume of the element.
pub fn volume(x: &[Vec3; 8]) -> Result<f64, ElementFailure> {
    // `geometry`'s volume, bit for bit (the same determinants summed in the same order),
    // without the gradients: a pass over every element of a mesh at set-up.
    let mut volume = 0.0;
    for xi in &GAUSS {
        let d = crate::math::det(&jacobian(x, &shape_derivatives(xi)));
        if !(d > 0.0) || !d.is_finite() {
            return Err(ElementFailure::InvertedReference);
        }
        volume += d;
    }
    Ok(volume)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn volume_is_the_geometry_volume_bit_for_bit() {
        // A distorted element (its nodes moved off the cube by up to 0.3), scaled so that
        // the determinants are not round numbers.
        let mut x: [Vec3; 8] = std::array::from_fn(|a| NODE_XI[a].map(|p| 0.37 * (1.0 + p)));
        for (a, v) in x.iter_mut().enumerate() {
            v[0] += 0.3 * ((a * 7 % 5) as f64 / 5.0 - 0.4) * 0.37;
            v[2] -= 0.2 * ((a * 3 % 4) as f64 / 4.0) * 0.37;
        }
        let g = geometry(&x).unwrap().0.volume;
        assert_eq!(volume(&x).unwrap().to_bits(), g.to_bits());
        // An inverted element: both refuse it.
        x.swap(0, 6);
        assert!(geometry(&x).is_err());
        assert!(matches!(volume(&x), Err(ElementFailure::InvertedReference)));
    }
}
