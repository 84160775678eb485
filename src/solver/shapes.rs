//! The reference geometry of the local elements, held per element shape. The elements of
//! a linear body whose mesh repeats a few shapes (a structured box, an extruded or
//! transfinite Gmsh mesh) are evaluated by the stiffness matrix of their shape
//! (`element::element_matrix`, one 24 x 24 product per evaluation instead of the
//! Gauss-point kernel) and hold an index each instead of about 1.9 kB of mean and
//! Gauss-point gradients; every other element keeps its own geometry, computed from its
//! coordinates as they are (bitwise as before).
//!
//! A shape is the element's coordinates relative to its first node after every coordinate
//! is rounded to one grid (`Plan`): a power of two 2^-GRID_BITS of the mesh's largest
//! coordinate's binade, 128 units in the last place of that coordinate. On the grid the
//! differences are exact, so a block's elements, whose coordinates min + i * h differ by
//! rounding, fall into a few shapes; the rounding moves a node by at most 64 units in the
//! last place of the largest coordinate, and the same for every element that holds it
//! (the geometry stays conforming). Which elements share a shape is not seen in any
//! result: each element's geometry is that of its own rounded shape.
//!
//! A composite tetrahedron (`fem::tet10`) keeps its own geometry (no two elements of a
//! tetrahedral mesh share a shape); its index is marked by `TET` so that it can never be
//! read as a hexahedron's (or a hexahedron's matrix).

use crate::fem::{element, tet10, ElementFailure, ElementKind};
use crate::math::{Mat3, Vec3};
use crate::memory::{try_with_capacity, AllocError};
use crate::mesh::GlobalMesh;
use crate::problem::{nearly_incompressible, BodyModel};
use std::collections::HashMap;

/// Bits of the largest coordinate's binade that the grid keeps.
const GRID_BITS: i64 = 46;

/// Elements per shape from which a linear body is evaluated by element matrices: a matrix
/// (4608 bytes) then costs at most 576 bytes per element, less than the geometry it
/// replaces in the kernel's reads (1904 bytes), and the product K u (576 multiply-adds)
/// is about a quarter of the Gauss-point kernel's work.
const ELEMENTS_PER_MATRIX: usize = 8;

/// Which bodies are evaluated by element matrices, and the grid their shapes are taken
/// on: a function of the whole mesh, made on rank 0 and given to every rank
/// (`solver::survey`), so the same elements use matrices on any number of ranks (a
/// matrix's force differs from the kernel's in rounding).
#[derive(Clone, Debug, Default)]
pub struct Plan {
    pub matrices: Vec<bool>,
    pub grid: f64,
    /// The number of shapes of each body evaluated by matrices (0 for the others).
    pub shapes: Vec<usize>,
}

impl Plan {
    /// Linear bodies (small kinematics, an elastic material: f = K u) that are not nearly
    /// incompressible and whose elements share shapes, on average at least
    /// ELEMENTS_PER_MATRIX elements to a shape. The shapes are
    /// counted by a 64-bit hash of their coordinates' bits (two shapes sharing a hash would
    /// count as one; the choice stays a function of the mesh); counting stops once a body
    /// has too many.
    pub fn new(mesh: &GlobalMesh, models: &[BodyModel]) -> Plan {
        use std::hash::{Hash, Hasher};
        let Some(grid) = grid(mesh) else {
            return Plan::default();
        };
        let shapes: Vec<usize> = mesh
            .bodies
            .iter()
            .zip(models)
            .map(|(b, m)| {
                if m.material.linear().is_none()
                    || b.num_elements == 0
                    || b.kind != ElementKind::Hex8
                {
                    return 0;
                }
                // K u sums the volumetric stiffness's large terms, which cancel for a
                // nearly isochoric field, so its rounding relative to the force grows
                // with K / G; the Gauss-point kernel forms the volumetric strain first
                // (incompressible_mean, nu = 0.4999: 65 CG iterations with the kernel,
                // 757 with matrices to the same residual; nu = 0.45 and 0.49 the same).
                if nearly_incompressible(&m.material) {
                    return 0;
                }
                let most = b.num_elements / ELEMENTS_PER_MATRIX;
                let mut seen = std::collections::HashSet::new();
                for e in b.first_element..b.first_element + b.num_elements {
                    let shape = shape_on_grid(&mesh.element_coords::<8>(e), grid);
                    let mut h = std::hash::DefaultHasher::new();
                    for v in shape[1..].as_flattened() {
                        v.to_bits().hash(&mut h);
                    }
                    seen.insert(h.finish());
                    if seen.len() > most {
                        return 0;
                    }
                }
                seen.len()
            })
            .collect();
        Plan {
            matrices: shapes.iter().map(|&k| k > 0).collect(),
            grid,
            shapes,
        }
    }

    /// The log's line on the bodies evaluated by element matrices, when there are any.
    pub fn describe(&self, mesh: &GlobalMesh) -> Option<String> {
        let bodies: Vec<String> = mesh
            .bodies
            .iter()
            .zip(&self.shapes)
            .filter(|(_, &k)| k > 0)
            .map(|(b, k)| format!("'{}' ({} elements, {k} shapes)", b.name, b.num_elements))
            .collect();
        (!bodies.is_empty()).then(|| {
            format!(
                "element matrices (linear bodies of repeated element shapes, one stiffness \
                 matrix per shape): {}",
                bodies.join(", ")
            )
        })
    }

    fn matrix(&self, body: usize) -> bool {
        self.matrices.get(body) == Some(&true)
    }
}

/// The grid of the whole mesh: 2^(e - GRID_BITS) with the largest |coordinate| < 2^e.
/// None when there is no such normal number (no coordinate, all zero, one not finite).
fn grid(mesh: &GlobalMesh) -> Option<f64> {
    let largest = mesh
        .coords
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    if !largest.is_normal() {
        return None;
    }
    let e = ((largest.to_bits() >> 52) & 0x7ff) as i64 - 1022;
    let biased = e - GRID_BITS + 1023;
    (biased >= 1).then(|| f64::from_bits((biased as u64) << 52))
}

/// The element's shape on the grid: each coordinate rounded to a multiple of `grid`
/// (dividing and multiplying by a power of two is exact), then taken relative to the
/// first node (exact on the grid).
fn shape_on_grid(x: &[Vec3; 8], grid: f64) -> [Vec3; 8] {
    let mut y = *x;
    for v in y.as_flattened_mut() {
        *v = (*v / grid).round() * grid;
    }
    element::reference_shape(&y)
}

/// A shared shape's stiffness matrix and diagonal blocks (a linear body's: neither depends
/// on the displacement). A linear element's kernel does not fail on a valid geometry;
/// should it, the shape keeps neither and its elements their kernel (which reports).
fn shared_shape(
    g: &element::Geometry,
    gg: &element::GaussGeometry,
    m: &BodyModel,
) -> (Option<Box<element::ElementMatrix>>, Option<[Mat3; 8]>) {
    let k = element::element_matrix(g, Some(gg), &m.material, m.formulation).ok();
    let mut d = [[[0.0; 3]; 3]; 8];
    let blocks = element::diagonal_blocks_with(
        g,
        Some(gg),
        &[[0.0; 3]; 8],
        &m.material,
        m.formulation,
        &[],
        &mut d,
    );
    let d = (k.is_some() && blocks.is_ok()).then_some(d);
    (k, d)
}

/// The bit that marks an index into the composite tetrahedra's geometry.
const TET: u32 = 1 << 31;

pub struct Shapes {
    /// Per local element: its shape's index (a tetrahedron's with `TET` set), or why its
    /// reference geometry failed.
    index: Vec<Result<u32, ElementFailure>>,
    geometry: Vec<element::Geometry>,
    /// The Gauss-point gradients of each shape (empty when no body needs them).
    gauss: Vec<element::GaussGeometry>,
    /// The stiffness matrix of each shape of a body evaluated by matrices (shorter than
    /// the shapes when the last ones have none).
    matrix: Vec<Option<Box<element::ElementMatrix>>>,
    /// The diagonal 3 x 3 blocks of each shape that has a matrix: a linear body's tangent
    /// does not depend on the displacement, so every element of the shape has these
    /// blocks, the bits `element::diagonal_blocks_with` gives it.
    diagonal: Vec<Option<[Mat3; 8]>>,
    /// The geometry of each composite tetrahedron.
    tet: Vec<tet10::Geometry>,
}

/// The local elements as `Shapes` needs them: kind, coordinates and body of each (`coords`
/// of the hexahedra, `tet_coords` of the tetrahedra).
pub struct Elements<'a> {
    pub count: usize,
    pub kind: &'a dyn Fn(usize) -> ElementKind,
    pub coords: &'a dyn Fn(usize) -> [Vec3; 8],
    pub tet_coords: &'a dyn Fn(usize) -> [Vec3; 10],
    pub body: &'a dyn Fn(usize) -> usize,
}

impl Shapes {
    /// The geometry of the local elements: shared shapes and their stiffness matrices for
    /// the bodies `plan` evaluates by matrices, one geometry per element otherwise;
    /// Gauss-point gradients kept when `gauss` is set. Fails only when memory is refused.
    pub fn new(
        el: &Elements,
        models: &[BodyModel],
        gauss: bool,
        plan: &Plan,
    ) -> Result<Self, AllocError> {
        // Each element's shape number, and the first element of each shape.
        let mut number: Vec<u32> = try_with_capacity(el.count, "the element geometry")?;
        let mut first = Vec::new();
        let mut seen: HashMap<[u64; 22], u32> = HashMap::new();
        let mut tets = Vec::new();
        for e in 0..el.count {
            if (el.kind)(e) == ElementKind::Tet10 {
                number.push(TET);
                tets.push(e);
                continue;
            }
            let b = (el.body)(e);
            if !plan.matrix(b) {
                number.push(first.len() as u32);
                first.push(e);
                continue;
            }
            let shape = shape_on_grid(&(el.coords)(e), plan.grid);
            let mut key = [0u64; 22];
            key[21] = b as u64;
            for (k, v) in key.iter_mut().zip(shape[1..].as_flattened()) {
                *k = v.to_bits();
            }
            let s = *seen.entry(key).or_insert_with(|| {
                first.push(e);
                first.len() as u32 - 1
            });
            number.push(s);
        }
        drop(seen);
        let mut geometry = try_with_capacity(first.len(), "the element geometry")?;
        let mut gauss_table = try_with_capacity(
            if gauss { first.len() } else { 0 },
            "the Gauss-point gradients",
        )?;
        let mut matrix = Vec::new();
        let mut diagonal = Vec::new();
        // Shape number -> its index among the shapes whose geometry did not fail.
        let mut kept = Vec::with_capacity(first.len());
        for &e in &first {
            let b = (el.body)(e);
            let x = (el.coords)(e);
            let shared = plan.matrix(b);
            let x = if shared {
                shape_on_grid(&x, plan.grid)
            } else {
                x
            };
            match element::geometry(&x) {
                Ok((g, gg)) => {
                    if shared {
                        let (k, d) = shared_shape(&g, &gg, &models[b]);
                        matrix.resize(geometry.len(), None);
                        matrix.push(k);
                        diagonal.resize(geometry.len(), None);
                        diagonal.push(d);
                    }
                    kept.push(Ok(geometry.len() as u32));
                    geometry.push(g);
                    if gauss {
                        gauss_table.push(gg);
                    }
                }
                Err(k) => kept.push(Err(k)),
            }
        }
        let mut index = try_with_capacity(el.count, "the element geometry")?;
        index.extend(
            number
                .iter()
                .map(|&s| if s == TET { Ok(TET) } else { kept[s as usize] }),
        );
        let mut tet = try_with_capacity(tets.len(), "the tetrahedra's geometry")?;
        for e in tets {
            index[e] = tet10::geometry(&(el.tet_coords)(e)).map(|g| {
                tet.push(g);
                TET | (tet.len() as u32 - 1)
            });
        }
        Ok(Shapes {
            index,
            geometry,
            gauss: gauss_table,
            matrix,
            diagonal,
            tet,
        })
    }

    /// The reference geometry of local element `e`, a composite tetrahedron, or why it
    /// failed. Panics if `e` is a hexahedron.
    #[inline]
    pub fn tet(&self, e: usize) -> Result<&tet10::Geometry, ElementFailure> {
        let s = self.index[e]?;
        assert!(s & TET != 0, "element {e} is not a tetrahedron");
        Ok(&self.tet[(s & !TET) as usize])
    }

    /// The reference geometry of local element `e` and its Gauss-point gradients (when
    /// kept), or why it failed.
    #[inline(always)]
    pub fn get(
        &self,
        e: usize,
    ) -> Result<(&element::Geometry, Option<&element::GaussGeometry>), ElementFailure> {
        let s = self.index[e]? as usize;
        Ok((&self.geometry[s], self.gauss.get(s)))
    }

    /// The stiffness matrix of local element `e`, when its body is evaluated by matrices.
    #[inline(always)]
    pub fn matrix(&self, e: usize) -> Option<&element::ElementMatrix> {
        let s = *self.index[e].as_ref().ok()? as usize;
        self.matrix.get(s)?.as_deref()
    }

    /// The diagonal blocks of local element `e`, when its body is evaluated by matrices.
    #[inline(always)]
    pub fn diagonal(&self, e: usize) -> Option<&[Mat3; 8]> {
        let s = *self.index[e].as_ref().ok()? as usize;
        self.diagonal.get(s)?.as_ref()
    }

    /// How many distinct hexahedral shapes are kept.
    pub fn count(&self) -> usize {
        self.geometry.len()
    }

    /// How many composite tetrahedra keep a geometry.
    pub fn tets(&self) -> usize {
        self.tet.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::Formulation;
    use crate::material::{LinearElastic, Material};
    use crate::mesh::{block, Body};

    /// A generated block (coordinates min + i * h, which differ by rounding) keeps a few
    /// shapes on the grid, one per element off it; every element's geometry is the one
    /// computed from its own coordinates (on the grid when shared), and a linear body's
    /// elements get the matrix of their own geometry.
    #[test]
    fn a_snapped_block_keeps_few_shapes_and_each_element_its_own_geometry() {
        let n = 12;
        let corners = block::box_corners(&[0.05, 1.0, 0.05], &[0.95, 1.9, 0.95]);
        let b = block::generate(&corners, n, n + 1, n).unwrap();
        let ne = b.elements.len();
        let mesh = GlobalMesh {
            coords: b.coords,
            elements: crate::mesh::Connectivity::from_fixed(&b.elements),
            element_body: vec![0; ne],
            bodies: vec![Body {
                name: "block".into(),
                kind: crate::fem::ElementKind::Hex8,
                first_node: 0,
                num_nodes: (n + 1) * (n + 2) * (n + 1),
                first_element: 0,
                num_elements: ne,
            }],
            freed: None,
        };
        let models = [BodyModel {
            material: Material::LinearElastic(LinearElastic::new(1000.0, 0.3)),
            formulation: Formulation::Full,
            density: 0.0,
        }];
        let shapes = |plan: &Plan| {
            let el = Elements {
                count: ne,
                kind: &|_| ElementKind::Hex8,
                coords: &|e| mesh.element_coords(e),
                tet_coords: &|_| unreachable!("no tetrahedra here"),
                body: &|_| 0,
            };
            Shapes::new(&el, &models, true, plan).unwrap()
        };
        let plan = Plan::new(&mesh, &models);
        assert_eq!(plan.matrices, [true]);
        let rubber = [BodyModel {
            material: Material::LinearElastic(LinearElastic::new(1000.0, 0.4999)),
            ..models[0].clone()
        }];
        assert_eq!(
            Plan::new(&mesh, &rubber).matrices,
            [false],
            "nearly incompressible"
        );
        assert!(plan
            .describe(&mesh)
            .unwrap()
            .contains("'block' (1872 elements, "));
        let raw = shapes(&Plan::default());
        let snapped = shapes(&plan);
        // At most 4 spacings per direction on the grid (the grid's spacing and the
        // rounding of the generated coordinates, one unit each way): at most 64 shapes.
        assert!(snapped.count() <= 64, "{} shapes", snapped.count());
        assert_eq!(raw.count(), ne, "one shape per element off the grid");
        assert!(raw.matrix(0).is_none());
        for e in 0..ne {
            let (geo, gauss) = raw.get(e).unwrap();
            let (own, own_gauss) = element::geometry(&mesh.element_coords(e)).unwrap();
            assert_eq!(format!("{geo:?}"), format!("{own:?}"));
            assert_eq!(format!("{:?}", gauss.unwrap()), format!("{own_gauss:?}"));
            let (geo, gauss) = snapped.get(e).unwrap();
            let x = shape_on_grid(&mesh.element_coords(e), plan.grid);
            let (own, own_gauss) = element::geometry(&x).unwrap();
            assert_eq!(format!("{geo:?}"), format!("{own:?}"));
            assert_eq!(format!("{:?}", gauss.unwrap()), format!("{own_gauss:?}"));
            let k = element::element_matrix(
                &own,
                Some(&own_gauss),
                &models[0].material,
                Formulation::Full,
            )
            .unwrap();
            assert_eq!(snapped.matrix(e).unwrap()[..], k[..]);
        }
    }
}
