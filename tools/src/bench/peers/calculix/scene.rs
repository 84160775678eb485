//! A CalculiX deck of a scene as the solver loads it: the same nodes and elements (ids =
//! our 1-based ids), a material per body (linear elastic as *ELASTIC, neo-Hookean as NEO
//! HOOKE with the same initial shear and bulk moduli), one static step per segment of equal
//! load steps over which every load grows linearly (NLGEOM under large kinematics) in the
//! scene's increments with the prescribed displacements and the pressures (`*DLOAD`) at the
//! segment's end, every contact pair as node-to-surface penalty contact (with Coulomb
//! friction when the pair has it), and the total reaction force of every prescribed node
//! set printed to the .dat file at every increment. `deck_with` also writes scenes
//! without contact, J2 plasticity (`j2_plastic` without kinematic hardening as *PLASTIC),
//! another hexahedron (C3D8I) and fixed increments (`*STATIC, DIRECT`). What a scene holds
//! beyond that is refused with a message naming it; a new problem extends the translation
//! here.

use super::deck::{
    name, Boundary, CLoad, ContactPair, DLoad, Deck, ElementType, Interaction,
    Material as CcxMaterial, MaterialCard, NodePrint, NodeSet, PairType, Solid, Step, Surface,
};
use super::face_loads::shape_integrals;
use crate::api::{ElementKind, Formulation, Kinematics, Material, PiecewiseLinear, Problem, Vec3};
use std::collections::BTreeMap;

/// ccx's face label of each of our local faces 0 (-y), 1 (+x), 2 (+y), 3 (-x), 4 (-z),
/// 5 (+z): with our corner order a C3D8's face S1 is 1-2-3-4 (-z), S2 5-8-7-6 (+z), S3
/// 1-5-6-2 (-y), S4 2-6-7-3 (+x), S5 3-7-8-4 (+y), S6 4-8-5-1 (-x).
pub const CCX_FACE: [u8; 6] = [3, 4, 5, 6, 1, 2];

/// The same for a tet10's faces 0 (corners 0 1 3), 1 (1 2 3), 2 (0 3 2), 3 (0 2 1): a
/// C3D10's face S1 is 1-2-3, S2 1-4-2, S3 2-4-3, S4 3-4-1.
pub const CCX_TET_FACE: [u8; 4] = [2, 3, 4, 1];

/// ccx's label of local face `f` of element `e`.
fn ccx_face(problem: &Problem, e: u32, f: u8) -> u8 {
    match problem.mesh.kind(e as usize) {
        ElementKind::Hex8 => CCX_FACE[f as usize],
        ElementKind::Tet10 => CCX_TET_FACE[f as usize],
    }
}

/// The stick slope of Coulomb friction (shear stress per unit tangential displacement while
/// sticking) as a fraction of the normal penalty: a sticking point then moves about
/// 10 mu times the overclosure before it slips, a few overclosures, small against any slide.
const STICK_SLOPE: f64 = 0.1;

fn unsupported<T>(what: &str) -> Result<T, String> {
    Err(format!("the CalculiX deck does not support {what}"))
}

/// How `deck_with` writes a scene.
#[derive(Clone, Copy, Debug)]
pub struct Options {
    /// Slope of the linear pressure-overclosure law of every contact pair.
    pub penalty: f64,
    /// The hexahedron of every body: C3D8 stands for the scene's "full" only; C3D8I (no
    /// volumetric locking) also for "full" with mean dilatation.
    pub element: ElementType,
    /// Fixed increments, the scene's steps (`*STATIC, DIRECT`), instead of ccx's automatic
    /// incrementation starting from them.
    pub direct: bool,
    /// Whether a scene without contact pairs is written (refused by `deck`).
    pub without_contact: bool,
}

/// The deck of `problem`, contact by a linear pressure-overclosure law of slope `penalty`.
pub fn deck(problem: &Problem, penalty: f64) -> Result<Deck, String> {
    let options = Options {
        penalty,
        element: ElementType::C3D8,
        direct: false,
        without_contact: false,
    };
    deck_with(problem, &options)
}

/// The deck of `problem` as `options` ask.
pub fn deck_with(problem: &Problem, options: &Options) -> Result<Deck, String> {
    if !problem.body_forces.is_empty() {
        return unsupported("body forces");
    }
    if problem.contacts.is_empty() && !options.without_contact {
        return unsupported("scenes without contact");
    }
    let friction = problem.contacts.iter().any(|p| p.mu > 0.0);
    let large = matches!(problem.kinematics, Kinematics::Large);
    let solids = solids(problem, options.element)?;
    let (node_sets, mut steps) = prescribed(problem, large)?;
    for step in &mut steps {
        step.direct = options.direct;
    }
    let mut element = match options.element {
        ElementType::C3D8 => "C3D8 (2x2x2 Gauss) as the scene's \"full\"".to_string(),
        ElementType::C3D8I => {
            "C3D8I (incompatible modes) for the scene's \"full\" (with or without mean dilatation)"
                .to_string()
        }
        ElementType::C3D10 => return unsupported("C3D10 for hexahedra"),
    };
    if problem
        .mesh
        .bodies
        .iter()
        .any(|b| b.kind == ElementKind::Tet10)
    {
        element.push_str(", C3D10 (4 Gauss points) for the tet10 bodies");
    }
    let mut deck = Deck {
        comments: vec![
            format!("{} written by the solver's bench: {element},", problem.name),
            format!(
                "{}, {}.",
                if problem.contacts.is_empty() {
                    "no contact"
                } else if friction {
                    "node-to-surface penalty contact with Coulomb friction"
                } else {
                    "node-to-surface penalty contact, frictionless"
                },
                if large {
                    "NLGEOM"
                } else {
                    "small strain (no NLGEOM)"
                }
            ),
        ],
        heading: problem.name.clone(),
        nodes: problem.mesh.coords.clone(),
        solids,
        node_sets,
        steps,
        ..Deck::default()
    };
    contact(problem, options.penalty, &mut deck)?;
    Ok(deck)
}

/// E and nu from the Lamé constants.
fn elastic(lambda: f64, mu: f64) -> MaterialCard {
    MaterialCard::Elastic {
        e: mu * (3.0 * lambda + 2.0 * mu) / (lambda + mu),
        nu: lambda / (2.0 * (lambda + mu)),
    }
}

/// Equivalent plastic strain of the second *PLASTIC point of a hardening J2 material (ccx
/// holds the yield stress constant beyond the last point): far beyond any strain a
/// bench problem reaches.
const HARDENING_STRAIN: f64 = 10.0;

/// The cards of a body's material.
fn material_cards(material: &Material) -> Result<Vec<MaterialCard>, String> {
    Ok(match material {
        Material::LinearElastic(m) => vec![elastic(m.lambda, m.mu)],
        // W = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2 and ccx's C10 (I1bar - 3) +
        // (J - 1)^2 / D1 agree to second order in the strain with C10 = mu / 2 and
        // D1 = 2 / K, K = lambda + 2 mu / 3; they differ at large strain.
        Material::NeoHookean(m) => vec![MaterialCard::NeoHooke {
            c10: m.mu / 2.0,
            d1: 2.0 / (m.lambda + 2.0 * m.mu / 3.0),
        }],
        // Linear isotropic hardening sigma_y + K alpha (alpha the equivalent plastic
        // strain) is ccx's *PLASTIC through two points; perfect plasticity is one.
        Material::J2Plastic(m) => {
            if m.kinematic != 0.0 {
                return unsupported("j2_plastic with kinematic hardening");
            }
            let mut points = vec![(m.yield_stress, 0.0)];
            if m.isotropic != 0.0 {
                points.push((
                    m.yield_stress + m.isotropic * HARDENING_STRAIN,
                    HARDENING_STRAIN,
                ));
            }
            vec![elastic(m.lambda, m.mu), MaterialCard::Plastic { points }]
        }
        other => return unsupported(other.name()),
    })
}

/// One element block per body, with its material and section.
fn solids(problem: &Problem, element: ElementType) -> Result<Vec<Solid>, String> {
    let mesh = &problem.mesh;
    let mut solids = Vec::new();
    for (b, body) in mesh.bodies.iter().enumerate() {
        let model = &problem.body_models[b];
        let cards = material_cards(&model.material)?;
        let element = match (body.kind, model.formulation, element) {
            (ElementKind::Hex8, Formulation::Full, _)
            | (ElementKind::Hex8, Formulation::FullBar, ElementType::C3D8I) => element,
            (ElementKind::Hex8, Formulation::FullBar, _) => {
                return unsupported("mean dilatation with C3D8 (C3D8I instead)")
            }
            (ElementKind::Tet10, Formulation::Mean { .. }, _) => {
                return unsupported("one-point tetrahedra")
            }
            // ccx's own quadratic tetrahedron beside our composite one, on the same nodes.
            (ElementKind::Tet10, _, _) => ElementType::C3D10,
            _ => return unsupported("formulations other than \"full\""),
        };
        let elements = (body.first_element..body.first_element + body.num_elements)
            .map(|k| {
                let nodes = mesh.elements.element(k).iter();
                (k + 1, nodes.map(|&n| n as usize + 1).collect())
            })
            .collect();
        solids.push(Solid {
            elset: name("E_", &body.name),
            element,
            elements,
            material: CcxMaterial {
                name: name("M_", &body.name),
                cards,
            },
        });
    }
    Ok(solids)
}

/// The prescribed node sets and the steps: one per segment of load steps of equal length
/// (its increments those steps), each prescribed displacement along one axis at the
/// segment's end (ccx ramps it linearly over the step, as the scene's piecewise-linear
/// functions do between the segment ends), the total reaction force of every prescribed
/// set printed at every increment.
fn prescribed(problem: &Problem, large: bool) -> Result<(Vec<NodeSet>, Vec<Step>), String> {
    let mut axes = Vec::new();
    let mut sets: Vec<usize> = Vec::new();
    for dc in &problem.dirichlet {
        let axis = (0..3).find(|&i| {
            (dc.direction[i].abs() - 1.0).abs() < 1e-12
                && (0..3).all(|j| j == i || dc.direction[j].abs() < 1e-12)
        });
        let Some(i) = axis else {
            return unsupported("prescribed directions other than x, y or z");
        };
        axes.push(i);
        if !sets.contains(&dc.node_set) {
            sets.push(dc.node_set);
        }
    }
    let node_sets: Vec<NodeSet> = sets
        .iter()
        .map(|&s| {
            let set = &problem.node_sets[s];
            NodeSet {
                name: name("N_", &set.name),
                nodes: set.nodes.iter().map(|&n| n as usize + 1).collect(),
            }
        })
        .collect();
    let node_prints: Vec<NodePrint> = node_sets
        .iter()
        .map(|s| NodePrint {
            node_set: s.name.clone(),
            variables: "RF".into(),
            totals_only: true,
        })
        .collect();
    let steps = segments(problem)?
        .into_iter()
        .map(|(start, end, dt)| {
            Ok(Step {
                nlgeom: large,
                direct: false,
                max_increments: 10_000,
                increments: [dt, end - start, 1.0e-5 * (end - start), dt],
                boundaries: problem
                    .dirichlet
                    .iter()
                    .zip(&axes)
                    .map(|(dc, &i)| Boundary {
                        node_set: name("N_", &problem.node_sets[dc.node_set].name),
                        first: i as u8 + 1,
                        last: i as u8 + 1,
                        value: dc.function.eval(end) / dc.direction[i],
                    })
                    .collect(),
                dloads: problem
                    .pressures
                    .iter()
                    .flat_map(|p| {
                        let value = p.function.eval(end);
                        problem.side_sets[p.side_set]
                            .faces
                            .iter()
                            .map(move |&(e, f)| DLoad {
                                element: e as usize + 1,
                                face: ccx_face(problem, e, f),
                                value,
                            })
                    })
                    .collect(),
                cloads: traction_forces(problem, end)?,
                node_prints: node_prints
                    .iter()
                    .map(|p| NodePrint {
                        node_set: p.node_set.clone(),
                        variables: p.variables.clone(),
                        totals_only: p.totals_only,
                    })
                    .collect(),
                contact_print: false,
            })
        })
        .collect::<Result<_, String>>()?;
    Ok((node_sets, steps))
}

/// Every traction at time `t` as the nodal forces ccx's element takes from it
/// (`face_loads`), summed per node and direction, in node order.
fn traction_forces(problem: &Problem, t: f64) -> Result<Vec<CLoad>, String> {
    let mut forces: BTreeMap<(usize, u8), f64> = BTreeMap::new();
    for traction in &problem.tractions {
        let scale = traction.function.eval(t);
        for &(e, f) in &problem.side_sets[traction.side_set].faces {
            let nodes: Vec<u32> = problem.mesh.face_nodes(e, f).collect();
            let x: Vec<Vec3> = nodes
                .iter()
                .map(|&n| problem.mesh.coords[n as usize])
                .collect();
            let Some(shares) = shape_integrals(&x) else {
                return unsupported(&format!("tractions on faces of {} nodes", x.len()));
            };
            for (&n, share) in nodes.iter().zip(shares) {
                for (i, t) in traction.vector.iter().enumerate() {
                    *forces.entry((n as usize + 1, i as u8 + 1)).or_default() += scale * t * share;
                }
            }
        }
    }
    Ok(forces
        .into_iter()
        .filter(|&(_, v)| v != 0.0)
        .map(|((node, dof), value)| CLoad { node, dof, value })
        .collect())
}

/// The load steps as segments of equal steps over which every load function (prescribed
/// displacements and pressures) grows by the same amount per step: (start, end, step
/// length). ccx ramps a step's loads linearly, so a segment must end wherever a function
/// changes its slope (the stick/slip bar's pressure rises from t = 1 to 2 and falls from
/// 2 to 3 in steps of the same length).
fn segments(problem: &Problem) -> Result<Vec<(f64, f64, f64)>, String> {
    let functions: Vec<&PiecewiseLinear> = problem
        .dirichlet
        .iter()
        .map(|d| &d.function)
        .chain(problem.pressures.iter().map(|p| &p.function))
        .chain(problem.tractions.iter().map(|t| &t.function))
        .collect();
    let increments =
        |a: f64, b: f64| -> Vec<f64> { functions.iter().map(|f| f.eval(b) - f.eval(a)).collect() };
    let same = |x: f64, y: f64| (x - y).abs() <= 1e-9 * x.abs().max(y.abs());
    let mut out: Vec<(f64, f64, f64)> = Vec::new();
    let mut t0 = problem.start_time;
    for &t in &problem.step_times {
        let dt = t - t0;
        match out.last_mut() {
            Some(seg)
                if same(dt, seg.2)
                    && increments(t0, t)
                        .iter()
                        .zip(increments(seg.1 - seg.2, seg.1))
                        .all(|(a, b)| same(*a, b)) =>
            {
                seg.1 = t
            }
            _ => out.push((t0, t, dt)),
        }
        t0 = t;
    }
    if out.is_empty() {
        return Err("the scene has no load steps".into());
    }
    Ok(out)
}

/// Every pair's master and slave faces and node-to-surface penalty contact between them
/// (one pair keeps the names S_MASTER, S_SLAVE and CONTACT; more are numbered from 1).
fn contact(problem: &Problem, penalty: f64, deck: &mut Deck) -> Result<(), String> {
    let surface = |name: String, faces: &[(u32, u8)]| Surface {
        name,
        faces: faces
            .iter()
            .map(|&(e, f)| (e as usize + 1, ccx_face(problem, e, f)))
            .collect(),
    };
    let several = problem.contacts.len() > 1;
    for (k, pair) in problem.contacts.iter().enumerate() {
        if pair.slave_faces.is_empty() {
            return unsupported(&format!("contact pair '{}' without slave faces", pair.name));
        }
        let suffix = if several {
            format!("_{}", k + 1)
        } else {
            String::new()
        };
        let (master, slave, interaction) = (
            format!("S_MASTER{suffix}"),
            format!("S_SLAVE{suffix}"),
            format!("CONTACT{suffix}"),
        );
        deck.surfaces
            .push(surface(master.clone(), &pair.master_faces));
        deck.surfaces
            .push(surface(slave.clone(), &pair.slave_faces));
        deck.interactions.push(Interaction {
            name: interaction.clone(),
            penalty,
            friction: (pair.mu > 0.0).then_some((pair.mu, STICK_SLOPE * penalty)),
        });
        deck.contact_pairs.push(ContactPair {
            interaction,
            kind: PairType::NodeToSurface,
            slave,
            master,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::api::load_scene_refined;
    use crate::block::BLOCK_SCENE;
    use crate::runner::solver::repo_root;

    /// The deck of the bench scene: every node and element, the master faces on the lower
    /// block's top (+y: S5), the slave faces on the upper block's bottom (-y: S3).
    #[test]
    fn deck_of_the_bench_scene() {
        let problem = load_scene_refined(&repo_root().join(BLOCK_SCENE), 1).unwrap();
        let deck = deck(&problem, 1e7).unwrap().text();
        let block = |start: &str| -> Vec<&str> {
            deck.lines()
                .skip_while(|l| !l.starts_with(start))
                .skip(1)
                .take_while(|l| !l.starts_with('*'))
                .collect()
        };
        assert_eq!(block("*NODE").len(), 2 * 11 * 11 * 11);
        assert_eq!(block("*ELEMENT, TYPE=C3D8, ELSET=E_LOWER").len(), 1000);
        let master = block("*SURFACE, NAME=S_MASTER");
        let slave = block("*SURFACE, NAME=S_SLAVE");
        assert_eq!(master.len(), 100);
        assert_eq!(slave.len(), 100);
        assert!(master.iter().all(|l| l.ends_with(", S5")));
        assert!(slave.iter().all(|l| l.ends_with(", S3")));
        // E and nu back from the Lamé constants, to a few roundings.
        let elastic: Vec<f64> = block("*ELASTIC")[0]
            .split(", ")
            .map(|x| x.parse().unwrap())
            .collect();
        assert!((elastic[0] - 1000.0).abs() < 1e-9 && (elastic[1] - 0.3).abs() < 1e-12);
        assert!(deck.contains("N_UPPER_TOP, 2, 2, -0.009\n"));
        assert!(deck.contains("*NODE PRINT, NSET=N_UPPER_TOP, TOTALS=ONLY\nRF\n"));
        assert!(deck.contains("*NODE PRINT, NSET=N_LOWER_BOTTOM, TOTALS=ONLY\nRF\n"));
    }

    /// Friction becomes *FRICTION (mu and a stick slope a tenth of the penalty); a scene
    /// beyond the translation is refused, naming what it holds.
    #[test]
    fn friction_and_a_refusal() {
        let text = std::fs::read_to_string(repo_root().join(BLOCK_SCENE)).unwrap();
        let text = text.replacen(
            "friction = \"frictionless\"",
            "friction = \"coulomb\"\nmu = 0.3",
            1,
        );
        let problem = crate::api::parse(&text).unwrap();
        let text_of = deck(&problem, 1e7).unwrap().text();
        assert!(text_of.contains("*FRICTION\n0.3, 1000000.0\n"), "{text_of}");
        // On the held bottom: the skew row repeats what x and y prescribe there (a skew
        // row with other values is refused by the scene itself).
        let skew = format!(
            "{text}\n[[displacement]]\nnode_set = \"lower_bottom\"\ndirection = [1.0, 1.0, 0.0]\nvalue = 0.0\n"
        );
        let problem = crate::api::parse(&skew).unwrap();
        let e = deck(&problem, 1e7).err().unwrap();
        assert_eq!(
            e,
            "the CalculiX deck does not support prescribed directions other than x, y or z"
        );
    }

    /// The plastic punch: no contact, C3D8I for "full" with mean dilatation, *ELASTIC and
    /// *PLASTIC (perfect: one point), 50 fixed increments; C3D8 and contact-less scenes
    /// are refused unless asked for.
    #[test]
    fn deck_of_the_plastic_punch() {
        let scene = repo_root().join("run/scenes/plasticity/punch_40.toml");
        let problem = load_scene_refined(&scene, 1).unwrap();
        let mut options = Options {
            penalty: 1e7,
            element: ElementType::C3D8I,
            direct: true,
            without_contact: true,
        };
        let text = deck_with(&problem, &options).unwrap().text();
        assert!(
            text.contains("*ELEMENT, TYPE=C3D8I, ELSET=E_BLOCK\n"),
            "{text}"
        );
        let material = "*MATERIAL, NAME=M_BLOCK\n*ELASTIC\n";
        let i = text.find(material).unwrap() + material.len();
        let cards: Vec<&str> = text[i..].lines().take(3).collect();
        let elastic: Vec<f64> = cards[0].split(", ").map(|x| x.parse().unwrap()).collect();
        assert!((elastic[0] - 200e3).abs() < 1e-6 && (elastic[1] - 0.3).abs() < 1e-12);
        assert_eq!(cards[1..], ["*PLASTIC", "100.0, 0.0"]);
        assert!(
            text.contains("*STATIC, DIRECT\n0.02, 1.0, 1.0e-5, 0.02\n"),
            "{text}"
        );
        assert!(text.contains("N_PUNCH, 2, 2, -0.1\n"));
        assert!(!text.contains("*CONTACT PAIR"));
        options.element = ElementType::C3D8;
        assert_eq!(
            deck_with(&problem, &options).err().unwrap(),
            "the CalculiX deck does not support mean dilatation with C3D8 (C3D8I instead)"
        );
        assert_eq!(
            deck(&problem, 1e7).err().unwrap(),
            "the CalculiX deck does not support scenes without contact"
        );
    }

    /// A traction becomes *CLOAD: the consistent nodal forces of ccx's element (a quarter
    /// of the force at each corner of a flat square face; `face_loads` tests the 6-node
    /// triangle), scaled by the traction's function at each step's end (to 1e-12: a few
    /// roundings).
    #[test]
    fn a_traction_becomes_nodal_forces() {
        let text = r#"
name = "traction"
kinematics = "small"
[[body]]
name = "bar"
box = { min = [0.0, 0.0, 0.0], max = [2.0, 1.0, 1.0] }
divisions = [2, 1, 1]
material = { model = "linear_elastic", E = 1000.0, nu = 0.3 }
[[node_set]]
name = "fixed"
plane = { point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }
[[side_set]]
name = "end"
body = "bar"
plane = { point = [2.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }
[[displacement]]
node_set = "fixed"
components = ["x", "y", "z"]
value = 0.0
[[traction]]
side_set = "end"
vector = [0.0, 3.0, 0.0]
function = [[0.0, 0.0], [1.0, 1.0], [2.0, 0.5]]
[time]
segments = [{ end = 1.0, steps = 2 }, { end = 2.0, steps = 1 }]
"#;
        let problem = crate::api::parse(text).unwrap();
        let options = Options {
            penalty: 0.0,
            element: ElementType::C3D8,
            direct: false,
            without_contact: true,
        };
        let deck = deck_with(&problem, &options).unwrap();
        // The traction's slope changes at t = 1: two steps, loads at 1.0 and 0.5.
        assert_eq!(deck.steps.len(), 2);
        for (step, scale) in deck.steps.iter().zip([1.0, 0.5]) {
            assert_eq!(step.cloads.len(), 4);
            for c in &step.cloads {
                assert_eq!(c.dof, 2);
                assert!((c.value - 0.75 * scale).abs() < 1e-12, "{}", c.value);
                assert!((problem.mesh.coords[c.node - 1][0] - 2.0).abs() < 1e-12);
            }
        }
        assert!(deck.text().contains("*CLOAD\n"));
    }

    /// The ironing example: NLGEOM, the slab's neo-Hookean solid as NEO HOOKE, two steps
    /// (pressing in 5 increments of 0.2, dragging in 30 of 1/30), the die's final position.
    #[test]
    fn deck_of_the_ironing_example() {
        let problem =
            load_scene_refined(&repo_root().join("run/examples/ironing.toml"), 1).unwrap();
        let deck = deck(&problem, 2e5).unwrap().text();
        assert_eq!(
            deck.matches("*STEP, NLGEOM, INC=10000\n").count(),
            2,
            "{deck}"
        );
        // E = 1000, nu = 0.3: mu = 384.6..., C10 = mu / 2, K = 833.3..., D1 = 2 / K.
        let c10 = 1000.0 / (2.0 * 1.3) / 2.0;
        let d1 = 2.0 / (1000.0 / (3.0 * 0.4));
        let line = deck
            .lines()
            .skip_while(|l| !l.starts_with("*MATERIAL, NAME=M_SLAB"))
            .nth(2)
            .unwrap();
        let v: Vec<f64> = line.split(", ").map(|x| x.parse().unwrap()).collect();
        assert!(
            (v[0] - c10).abs() < 1e-12 * c10 && (v[1] - d1).abs() < 1e-12 * d1,
            "{line}"
        );
        assert!(deck.contains("*STATIC\n0.2, 1.0, 1.0e-5, 0.2\n"), "{deck}");
        assert!(deck.contains("N_DIE, 1, 1, 3.0\n"), "{deck}");
        assert!(deck.contains("*FRICTION\n0.3, 20000.0\n"), "{deck}");
    }
}
