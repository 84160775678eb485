//! A CalculiX deck of a scene as the solver loads it: the same nodes and elements (ids =
//! our 1-based ids), a linear elastic material per body, the prescribed displacements at
//! the last step's time applied over one static step (ramped), the contact pair as
//! frictionless node-to-surface penalty contact, and the total reaction force of every
//! prescribed node set printed to the .dat file. What a scene holds beyond that is refused
//! with a message naming it; a new problem extends the translation here.

use super::deck::{
    name, Boundary, ContactPair, Deck, Interaction, Material as CcxMaterial, MaterialCard,
    NodePrint, NodeSet, PairType, Solid, Step, Surface,
};
use crate::api::{Formulation, Kinematics, Material, Problem, HEX8_FACES};

/// ccx's face label of each of our local faces 0 (-y), 1 (+x), 2 (+y), 3 (-x), 4 (-z),
/// 5 (+z): with our corner order a C3D8's face S1 is 1-2-3-4 (-z), S2 5-8-7-6 (+z), S3
/// 1-5-6-2 (-y), S4 2-6-7-3 (+x), S5 3-7-8-4 (+y), S6 4-8-5-1 (-x).
pub const CCX_FACE: [u8; 6] = [3, 4, 5, 6, 1, 2];

fn unsupported<T>(what: &str) -> Result<T, String> {
    Err(format!("the CalculiX deck does not support {what}"))
}

/// The deck of `problem`, contact by a linear pressure-overclosure law of slope `penalty`.
pub fn deck(problem: &Problem, penalty: f64) -> Result<Deck, String> {
    if !matches!(problem.kinematics, Kinematics::Small) {
        return unsupported("large kinematics");
    }
    if !problem.pressures.is_empty()
        || !problem.tractions.is_empty()
        || !problem.body_forces.is_empty()
    {
        return unsupported("pressures, tractions or body forces");
    }
    let [pair] = problem.contacts.as_slice() else {
        return unsupported("other than one contact pair");
    };
    if pair.mu != 0.0 {
        return unsupported("friction");
    }
    let solids = solids(problem)?;
    let (node_sets, step) = prescribed(problem)?;
    let mut deck = Deck {
        comments: vec![
            format!(
                "{} written by the solver's bench: C3D8 (2x2x2 Gauss) as the scene's \"full\",",
                problem.name
            ),
            "frictionless node-to-surface penalty contact, linear static (no NLGEOM).".into(),
        ],
        heading: problem.name.clone(),
        nodes: problem.mesh.coords.clone(),
        solids,
        node_sets,
        steps: vec![step],
        ..Deck::default()
    };
    contact(problem, penalty, &mut deck)?;
    Ok(deck)
}

/// One element block per body, with its material (E and nu from the scene's Lamé
/// constants) and section.
fn solids(problem: &Problem) -> Result<Vec<Solid>, String> {
    let mesh = &problem.mesh;
    let mut solids = Vec::new();
    for (b, body) in mesh.bodies.iter().enumerate() {
        let model = &problem.body_models[b];
        let Material::LinearElastic(m) = &model.material else {
            return unsupported("materials other than linear elastic");
        };
        if !matches!(model.formulation, Formulation::Full) {
            return unsupported("formulations other than \"full\"");
        }
        let (lambda, mu) = (m.lambda, m.mu);
        let e = mu * (3.0 * lambda + 2.0 * mu) / (lambda + mu);
        let nu = lambda / (2.0 * (lambda + mu));
        let elements = (body.first_element..body.first_element + body.num_elements)
            .map(|k| (k + 1, mesh.elements[k].map(|n| n as usize + 1)))
            .collect();
        solids.push(Solid {
            elset: name("E_", &body.name),
            elements,
            material: CcxMaterial {
                name: name("M_", &body.name),
                cards: vec![MaterialCard::Elastic { e, nu }],
            },
        });
    }
    Ok(solids)
}

/// The prescribed node sets and the one step: each prescribed displacement along one axis
/// at the final time, and the total reaction force of every prescribed set printed.
fn prescribed(problem: &Problem) -> Result<(Vec<NodeSet>, Step), String> {
    let t_end = problem
        .step_times
        .last()
        .copied()
        .ok_or("the scene has no load steps")?;
    let mut boundaries = Vec::new();
    let mut sets: Vec<usize> = Vec::new();
    for dc in &problem.dirichlet {
        let axis = (0..3).find(|&i| {
            (dc.direction[i].abs() - 1.0).abs() < 1e-12
                && (0..3).all(|j| j == i || dc.direction[j].abs() < 1e-12)
        });
        let Some(i) = axis else {
            return unsupported("prescribed directions other than x, y or z");
        };
        let dof = i as u8 + 1;
        boundaries.push(Boundary {
            node_set: name("N_", &problem.node_sets[dc.node_set].name),
            first: dof,
            last: dof,
            value: dc.function.eval(t_end) / dc.direction[i],
        });
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
    let node_prints = node_sets
        .iter()
        .map(|s| NodePrint {
            node_set: s.name.clone(),
            variables: "RF".into(),
            totals_only: true,
        })
        .collect();
    let step = Step {
        nlgeom: false,
        increments: [1.0, 1.0, 1.0e-5, 1.0],
        boundaries,
        node_prints,
    };
    Ok((node_sets, step))
}

/// The pair's master faces, the slave faces from the side set whose nodes are the pair's
/// slave nodes, and frictionless node-to-surface penalty contact between them.
fn contact(problem: &Problem, penalty: f64, deck: &mut Deck) -> Result<(), String> {
    let mesh = &problem.mesh;
    let pair = &problem.contacts[0];
    let face_nodes = |e: u32, f: u8| -> [u32; 4] {
        let c = mesh.elements[e as usize];
        HEX8_FACES[f as usize].map(|a| c[a])
    };
    let slave_set = problem
        .side_sets
        .iter()
        .find(|s| {
            let mut nodes: Vec<u32> = s
                .faces
                .iter()
                .flat_map(|&(e, f)| face_nodes(e, f))
                .collect();
            nodes.sort_unstable();
            nodes.dedup();
            nodes == pair.slave_nodes
        })
        .ok_or("no side set has exactly the contact pair's slave nodes")?;
    let surface = |name: &str, faces: &[(u32, u8)]| Surface {
        name: name.into(),
        faces: faces
            .iter()
            .map(|&(e, f)| (e as usize + 1, CCX_FACE[f as usize]))
            .collect(),
    };
    deck.surfaces = vec![
        surface("S_MASTER", &pair.master_faces),
        surface("S_SLAVE", &slave_set.faces),
    ];
    deck.interactions = vec![Interaction {
        name: "FRICTIONLESS".into(),
        penalty,
    }];
    deck.contact_pairs = vec![ContactPair {
        interaction: "FRICTIONLESS".into(),
        kind: PairType::NodeToSurface,
        slave: "S_SLAVE".into(),
        master: "S_MASTER".into(),
    }];
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

    /// A scene beyond the translation is refused, naming what it holds.
    #[test]
    fn friction_is_refused() {
        let text = std::fs::read_to_string(repo_root().join(BLOCK_SCENE)).unwrap();
        let text = text.replacen(
            "friction = \"frictionless\"",
            "friction = \"coulomb\"\nmu = 0.3",
            1,
        );
        let problem = crate::api::parse(&text).unwrap();
        let e = deck(&problem, 1e7).err().unwrap();
        assert_eq!(e, "the CalculiX deck does not support friction");
    }
}
