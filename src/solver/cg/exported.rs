//! What the export of a model problem gives (`ModelExport`: the assembled operator, the
//! right-hand side and the rigid-body modes in the unknowns CG iterates on), where the
//! export stands, and the orthonormal free basis of a node those unknowns use.

use crate::math::{dot, Vec3};
use crate::precond::multilevel::sparse::Csr;

/// Free directions shorter than this after Gram-Schmidt are not free (P has entries of
/// order one; a projector's range vector keeps its length).
const RANK_TOLERANCE: f64 = 1e-6;

/// The assembled model problem.
#[derive(Clone, Debug, Default)]
pub struct ModelExport {
    /// Global node id of every unknown (0-based).
    pub node: Vec<u32>,
    /// The direction of every unknown (a unit vector).
    pub direction: Vec<Vec3>,
    /// The operator in these unknowns (square, measured: symmetric to round-off).
    pub matrix: Csr,
    /// The right-hand side: the starting residual T^T (f_ext - f_int) of the model problem.
    pub rhs: Vec<f64>,
    /// The six rigid-body modes (translations x, y, z; rotations about x, y, z through the
    /// centroid of the nodes), restricted to the free directions like every vector CG sees.
    pub modes: Vec<[f64; 6]>,
    /// max |A x - op(x)| / max |op(x)| for a pseudo-random x (the assembly's check).
    pub check_error: f64,
    /// The CG tolerance and the reference force at the start: CG stops when
    /// |r| <= tolerance * reference, the reference max(|f_ext|, |reaction|, floor)
    /// recomputed with the true residual.
    pub tolerance: f64,
    pub reference_start: f64,
    pub residual_start: f64,
    /// The load time of the model problem.
    pub time: f64,
    /// Constraint rows of the model problem: Dirichlet and contact.
    pub dirichlet_rows: usize,
    pub contact_rows: usize,
    /// Our CG on it: iterations, final residual and reference, or why it failed.
    pub iterations: Option<usize>,
    pub residual_end: f64,
    pub reference_end: f64,
    pub failure: Option<String>,
}

/// Where the export stands.
#[derive(Clone, Debug, Default)]
pub enum ExportState {
    #[default]
    Off,
    /// Asked for: taken at the next model problem that needs a CG iteration.
    Pending,
    /// Assembled; the outcome is filled in when CG finishes.
    Taken(Box<ModelExport>),
    /// Could not be taken (nonlinear bodies, several ranks).
    Refused(String),
}

/// An orthonormal basis of the range of the projector `p` (Gram-Schmidt of its columns).
pub fn free_basis(p: Option<&crate::math::Mat3>) -> Vec<Vec3> {
    let Some(p) = p else {
        return vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    };
    let mut basis: Vec<Vec3> = Vec::with_capacity(3);
    for j in 0..3 {
        let mut v: Vec3 = std::array::from_fn(|i| p[i][j]);
        // Twice: classical Gram-Schmidt loses orthogonality otherwise.
        for _ in 0..2 {
            for q in &basis {
                let c = dot(q, &v);
                for i in 0..3 {
                    v[i] -= c * q[i];
                }
            }
        }
        let n = dot(&v, &v).sqrt();
        if n > RANK_TOLERANCE {
            basis.push(std::array::from_fn(|i| v[i] / n));
        }
    }
    basis
}
