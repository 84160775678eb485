//! The 10-node tetrahedron: its reference nodes, faces, edges and quadrature, and its
//! quadratic isoparametric map (the geometry the composite element's kernels start from).
//!
//! Reference tetrahedron: corners (0,0,0), (1,0,0), (0,1,0), (0,0,1). Node order as in
//! Exodus II TETRA10 and CalculiX C3D10: the four corners, then the midpoints of the edges
//! 0-1, 1-2, 2-0, 0-3, 1-3, 2-3. (Gmsh's 10-node tetrahedron swaps the last two; its
//! reader maps them.) Faces follow the Exodus side order (0-based), each listed corners
//! first, so that the corners' normal points out of the element, then the midpoints of its
//! edges in the same turn (corner 0-1, 1-2, 2-0 of the face).
//!
//! The element built on it is the composite tetrahedron: `composite` (its twelve linear
//! sub-tetrahedra, the projected gradient and the integration weights) and `kernel` (force,
//! tangent diagonal, stress, history).

mod composite;
mod kernel;
pub mod reference;
mod tangent;

pub use reference::{
    jacobian, min_jacobian_ratio, shape, shape_derivatives, EDGES, FACES, MIDSIDE, NODE_XI,
    QUADRATURE, WEIGHTS,
};

pub use composite::{geometry, nodal_volumes, volume, Geometry, SUB_TETS};
pub use kernel::{
    average_cauchy, diagonal_blocks, internal_force, mean_eqps, point_gradients, update_history,
    STABILIZATION, STRESS_POINTS,
};
pub use tangent::consistent_matrix;
