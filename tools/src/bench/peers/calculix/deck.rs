//! A CalculiX input deck as data, and its text. Only the cards the bench writes are
//! modelled; each is written as ccx reads it (at most 16 entries per data line).

use crate::api::Vec3;
use std::fmt::Write as _;

/// An input deck: written in the order of its fields.
#[derive(Default)]
pub struct Deck {
    /// Comment lines at the top (`** ...`).
    pub comments: Vec<String>,
    pub heading: String,
    /// Node coordinates; node ids are 1-based positions, all in the set NALL.
    pub nodes: Vec<Vec3>,
    /// Element blocks, each with its material and section.
    pub solids: Vec<Solid>,
    pub node_sets: Vec<NodeSet>,
    pub surfaces: Vec<Surface>,
    pub interactions: Vec<Interaction>,
    pub contact_pairs: Vec<ContactPair>,
    pub steps: Vec<Step>,
}

/// An element of ccx's.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ElementType {
    /// The hexahedron, 2x2x2 Gauss.
    #[default]
    C3D8,
    /// The hexahedron, 2x2x2 Gauss with incompatible modes (no shear or volumetric locking).
    C3D8I,
    /// The quadratic 10-node tetrahedron, 4 Gauss points.
    C3D10,
}

impl ElementType {
    pub fn label(self) -> &'static str {
        match self {
            ElementType::C3D8 => "C3D8",
            ElementType::C3D8I => "C3D8I",
            ElementType::C3D10 => "C3D10",
        }
    }
}

/// Elements of one type and material: `*ELEMENT`, `*MATERIAL`, `*SOLID SECTION`.
pub struct Solid {
    pub elset: String,
    pub element: ElementType,
    /// (element id, its node ids), 1-based, in ccx's (and our) node order: a C3D8's
    /// corners, a C3D10's corners and then its edge midpoints 1-2, 2-3, 3-1, 1-4, 2-4, 3-4.
    pub elements: Vec<(usize, Vec<usize>)>,
    pub material: Material,
}

pub struct Material {
    pub name: String,
    pub cards: Vec<MaterialCard>,
}

/// One card of a material definition.
pub enum MaterialCard {
    /// `*ELASTIC`: isotropic linear elasticity.
    Elastic { e: f64, nu: f64 },
    /// `*HYPERELASTIC, NEO HOOKE`: W = C10 (I1bar - 3) + (J - 1)^2 / D1.
    NeoHooke { c10: f64, d1: f64 },
    /// `*PLASTIC` (von Mises, isotropic hardening): (yield stress, equivalent plastic
    /// strain) points, constant beyond the last.
    Plastic { points: Vec<(f64, f64)> },
}

pub struct NodeSet {
    pub name: String,
    /// 1-based node ids.
    pub nodes: Vec<usize>,
}

/// An element-face surface: (1-based element id, ccx face label 1..6) per face.
pub struct Surface {
    pub name: String,
    pub faces: Vec<(usize, u8)>,
}

/// `*SURFACE INTERACTION` with a linear pressure-overclosure law, and `*FRICTION` when
/// there is friction.
pub struct Interaction {
    pub name: String,
    /// Pressure per unit overclosure.
    pub penalty: f64,
    /// Coulomb coefficient and stick slope (shear stress per unit tangential
    /// displacement while sticking).
    pub friction: Option<(f64, f64)>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PairType {
    NodeToSurface,
    /// ccx's penalty mortar: the pair's contact on the slave faces' integration points.
    SurfaceToSurface,
}

pub struct ContactPair {
    pub interaction: String,
    pub kind: PairType,
    pub slave: String,
    pub master: String,
}

/// `*STEP` ... `*END STEP`.
pub struct Step {
    pub nlgeom: bool,
    /// `*STATIC, DIRECT`: the increments fixed at the initial one (no cut-backs).
    pub direct: bool,
    /// `INC=`: the most increments ccx may take in the step (its default is 100).
    pub max_increments: usize,
    /// `*STATIC`: initial increment, step period, minimum and maximum increment.
    pub increments: [f64; 4],
    pub boundaries: Vec<Boundary>,
    /// `*DLOAD` pressures on element faces, at the step's end (ccx ramps them over the
    /// step from the previous step's values).
    pub dloads: Vec<DLoad>,
    /// `*CLOAD` nodal forces, at the step's end (ramped as the pressures are).
    pub cloads: Vec<CLoad>,
    pub node_prints: Vec<NodePrint>,
    /// `*CONTACT PRINT` of CSTR (the slave nodes' contact pressures) to the .dat file.
    pub contact_print: bool,
}

/// A pressure on one element face (`<element>, P<face>, <value>`): positive presses
/// against the face's outward normal.
pub struct DLoad {
    /// 1-based element id.
    pub element: usize,
    /// ccx face label 1..6.
    pub face: u8,
    pub value: f64,
}

/// A force on one degree of freedom of a node (`<node>, <dof>, <value>`).
pub struct CLoad {
    /// 1-based node id.
    pub node: usize,
    /// 1..3: x, y, z.
    pub dof: u8,
    pub value: f64,
}

/// `*BOUNDARY`: degrees of freedom `first..=last` of a node set set to `value`.
pub struct Boundary {
    pub node_set: String,
    pub first: u8,
    pub last: u8,
    pub value: f64,
}

/// `*NODE PRINT` of variables (e.g. `RF`) over a node set, to the .dat file.
pub struct NodePrint {
    pub node_set: String,
    pub variables: String,
    /// `TOTALS=ONLY`: the sum over the set, not node by node.
    pub totals_only: bool,
}

/// A name as ccx stores it (upper case; letters, digits and '_'), after `prefix`.
pub fn name(prefix: &str, name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_uppercase()
            } else {
                '_'
            }
        })
        .collect();
    format!("{prefix}{s}")
}

/// A real number as Fortran reads it back: the shortest round-trip digits, with a decimal
/// point in the mantissa (`1e-5` becomes `1.0e-5`); where those take more than the 20
/// characters ccx reads of a field, 13 significant digits.
pub fn real(x: f64) -> String {
    let s = format!("{x:?}");
    let s = match s.find('e') {
        Some(i) if !s[..i].contains('.') => format!("{}.0{}", &s[..i], &s[i..]),
        _ => s,
    };
    if s.len() <= 20 {
        s
    } else {
        format!("{x:.12e}")
    }
}

/// Comma-separated lines of at most 16 entries (ccx's limit per data line).
fn write_list(w: &mut String, items: &[String]) {
    for chunk in items.chunks(16) {
        let _ = writeln!(w, "{}", chunk.join(", "));
    }
}

impl Deck {
    /// The deck's text.
    pub fn text(&self) -> String {
        let mut s = String::new();
        let w = &mut s;
        for c in &self.comments {
            let _ = writeln!(w, "** {c}");
        }
        let _ = writeln!(w, "*HEADING\n{}", self.heading);
        let _ = writeln!(w, "*NODE, NSET=NALL");
        for (i, x) in self.nodes.iter().enumerate() {
            let _ = writeln!(
                w,
                "{}, {}, {}, {}",
                i + 1,
                real(x[0]),
                real(x[1]),
                real(x[2])
            );
        }
        for solid in &self.solids {
            solid.write(w);
        }
        for set in &self.node_sets {
            let _ = writeln!(w, "*NSET, NSET={}", set.name);
            let ids: Vec<String> = set.nodes.iter().map(usize::to_string).collect();
            write_list(w, &ids);
        }
        for surface in &self.surfaces {
            let _ = writeln!(w, "*SURFACE, NAME={}, TYPE=ELEMENT", surface.name);
            for &(e, f) in &surface.faces {
                let _ = writeln!(w, "{e}, S{f}");
            }
        }
        for i in &self.interactions {
            let _ = writeln!(
                w,
                "*SURFACE INTERACTION, NAME={}\n\
                 *SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n{}",
                i.name,
                real(i.penalty)
            );
            if let Some((mu, slope)) = i.friction {
                let _ = writeln!(w, "*FRICTION\n{}, {}", real(mu), real(slope));
            }
        }
        for p in &self.contact_pairs {
            let kind = match p.kind {
                PairType::NodeToSurface => "NODE TO SURFACE",
                PairType::SurfaceToSurface => "SURFACE TO SURFACE",
            };
            let _ = writeln!(
                w,
                "*CONTACT PAIR, INTERACTION={}, TYPE={kind}\n{}, {}",
                p.interaction, p.slave, p.master
            );
        }
        for step in &self.steps {
            step.write(w);
        }
        s
    }
}

impl Solid {
    fn write(&self, w: &mut String) {
        let _ = writeln!(
            w,
            "*ELEMENT, TYPE={}, ELSET={}",
            self.element.label(),
            self.elset
        );
        for (id, nodes) in &self.elements {
            let _ = write!(w, "{id}");
            for n in nodes {
                let _ = write!(w, ", {n}");
            }
            let _ = writeln!(w);
        }
        let m = &self.material;
        let _ = writeln!(w, "*MATERIAL, NAME={}", m.name);
        for card in &m.cards {
            match card {
                MaterialCard::Elastic { e, nu } => {
                    let _ = writeln!(w, "*ELASTIC\n{}, {}", real(*e), real(*nu));
                }
                MaterialCard::NeoHooke { c10, d1 } => {
                    let _ = writeln!(w, "*HYPERELASTIC, NEO HOOKE\n{}, {}", real(*c10), real(*d1));
                }
                MaterialCard::Plastic { points } => {
                    let _ = writeln!(w, "*PLASTIC");
                    for &(stress, strain) in points {
                        let _ = writeln!(w, "{}, {}", real(stress), real(strain));
                    }
                }
            }
        }
        let _ = writeln!(
            w,
            "*SOLID SECTION, ELSET={}, MATERIAL={}",
            self.elset, m.name
        );
    }
}

impl Step {
    fn write(&self, w: &mut String) {
        let _ = writeln!(
            w,
            "*STEP{}, INC={}",
            if self.nlgeom { ", NLGEOM" } else { "" },
            self.max_increments
        );
        let inc: Vec<String> = self.increments.iter().map(|&x| real(x)).collect();
        let direct = if self.direct { ", DIRECT" } else { "" };
        let _ = writeln!(w, "*STATIC{direct}\n{}", inc.join(", "));
        if !self.boundaries.is_empty() {
            let _ = writeln!(w, "*BOUNDARY");
        }
        for b in &self.boundaries {
            let _ = writeln!(
                w,
                "{}, {}, {}, {}",
                b.node_set,
                b.first,
                b.last,
                real(b.value)
            );
        }
        if !self.dloads.is_empty() {
            let _ = writeln!(w, "*DLOAD");
        }
        for d in &self.dloads {
            let _ = writeln!(w, "{}, P{}, {}", d.element, d.face, real(d.value));
        }
        if !self.cloads.is_empty() {
            let _ = writeln!(w, "*CLOAD");
        }
        for c in &self.cloads {
            let _ = writeln!(w, "{}, {}, {}", c.node, c.dof, real(c.value));
        }
        for p in &self.node_prints {
            let totals = if p.totals_only { ", TOTALS=ONLY" } else { "" };
            let _ = writeln!(
                w,
                "*NODE PRINT, NSET={}{totals}\n{}",
                p.node_set, p.variables
            );
        }
        if self.contact_print {
            let _ = writeln!(w, "*CONTACT PRINT\nCSTR");
        }
        let _ = writeln!(w, "*END STEP");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reals_keep_every_digit_and_a_decimal_point() {
        assert_eq!(real(1.0), "1.0");
        assert_eq!(real(1e-5), "1.0e-5");
        assert_eq!(real(-0.009), "-0.009");
        assert_eq!(real(1e7), "10000000.0");
        assert_eq!(real(2.5e-7), "2.5e-7");
        assert_eq!(real(0.1 + 0.2), "0.30000000000000004");
        // Longer than a ccx field: 13 significant digits.
        assert_eq!(real(-2.220446049250313e-16), "-2.220446049250e-16");
        assert_eq!(real(-1.0 / 3.0), "-0.3333333333333333");
        assert_eq!(name("N_", "upper top-1"), "N_UPPER_TOP_1");
    }

    /// The deck of `one_element_deck`, as ccx reads it.
    const ONE_ELEMENT: &str = "\
** a test
*HEADING
cube
*NODE, NSET=NALL
1, 0.0, 0.0, 0.0
2, 1.0, 0.0, 0.0
3, 1.0, 1.0, 0.0
4, 0.0, 1.0, 0.0
5, 0.0, 0.0, 1.0
6, 1.0, 0.0, 1.0
7, 1.0, 1.0, 1.0
8, 0.0, 1.0, 1.0
*ELEMENT, TYPE=C3D8, ELSET=E_CUBE
1, 1, 2, 3, 4, 5, 6, 7, 8
*MATERIAL, NAME=M_CUBE
*ELASTIC
210000.0, 0.3
*SOLID SECTION, ELSET=E_CUBE, MATERIAL=M_CUBE
*NSET, NSET=N_TOP
1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16
17, 18
*SURFACE, NAME=S_TOP, TYPE=ELEMENT
1, S5
*SURFACE INTERACTION, NAME=I
*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR
10000000.0
*CONTACT PAIR, INTERACTION=I, TYPE=NODE TO SURFACE
S_TOP, S_TOP
*STEP, NLGEOM, INC=100
*STATIC
0.1, 1.0, 1.0e-5, 0.5
*BOUNDARY
N_TOP, 2, 2, -0.01
*DLOAD
1, P2, 5.0
*CLOAD
7, 1, 0.25
*NODE PRINT, NSET=N_TOP, TOTALS=ONLY
RF
*END STEP
";

    /// One element pressed on its top, the whole deck as ccx gets it.
    #[test]
    fn one_element_deck() {
        let corners = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
            [0.0, 1.0, 1.0],
        ];
        let deck = Deck {
            comments: vec!["a test".into()],
            heading: "cube".into(),
            nodes: corners.to_vec(),
            solids: vec![Solid {
                elset: "E_CUBE".into(),
                element: ElementType::C3D8,
                elements: vec![(1, vec![1, 2, 3, 4, 5, 6, 7, 8])],
                material: Material {
                    name: "M_CUBE".into(),
                    cards: vec![MaterialCard::Elastic { e: 210e3, nu: 0.3 }],
                },
            }],
            node_sets: vec![NodeSet {
                name: "N_TOP".into(),
                nodes: (1..=18).collect(),
            }],
            surfaces: vec![Surface {
                name: "S_TOP".into(),
                faces: vec![(1, 5)],
            }],
            interactions: vec![Interaction {
                name: "I".into(),
                penalty: 1e7,
                friction: None,
            }],
            contact_pairs: vec![ContactPair {
                interaction: "I".into(),
                kind: PairType::NodeToSurface,
                slave: "S_TOP".into(),
                master: "S_TOP".into(),
            }],
            steps: vec![Step {
                nlgeom: true,
                direct: false,
                max_increments: 100,
                increments: [0.1, 1.0, 1e-5, 0.5],
                boundaries: vec![Boundary {
                    node_set: "N_TOP".into(),
                    first: 2,
                    last: 2,
                    value: -0.01,
                }],
                dloads: vec![DLoad {
                    element: 1,
                    face: 2,
                    value: 5.0,
                }],
                cloads: vec![CLoad {
                    node: 7,
                    dof: 1,
                    value: 0.25,
                }],
                node_prints: vec![NodePrint {
                    node_set: "N_TOP".into(),
                    variables: "RF".into(),
                    totals_only: true,
                }],
                contact_print: false,
            }],
        };
        assert_eq!(deck.text(), ONE_ELEMENT);
    }
}
