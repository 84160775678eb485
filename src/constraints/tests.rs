//! Tests of the constraint rows: projections, ties across ranks, the exchange plans.
use super::*;
use crate::comm::SerialComm;
use crate::mesh::{Connectivity, GlobalMesh};
use partition::Decomposition;

/// One element's eight nodes on one rank (node i is global and local i).
fn mesh() -> LocalMesh {
    let g = GlobalMesh {
        coords: (0..8)
            .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, (i >> 2) as f64])
            .collect(),
        elements: Connectivity::from_fixed(&[[0, 1, 3, 2, 4, 5, 7, 6]]),
        element_body: vec![0],
        bodies: vec![crate::mesh::Body {
            name: "b".into(),
            kind: crate::fem::ElementKind::Hex8,
            first_node: 0,
            num_nodes: 8,
            first_element: 0,
            num_elements: 1,
        }],
        freed: None,
    };
    let d = Decomposition::partition(8, &g.elements, 1).unwrap();
    LocalMesh::new(&g, &d, 0)
}

fn pad(v: Vec<Vec3>) -> Vec<Vec3> {
    let mut v = v;
    v.resize(8, [0.0; 3]);
    v
}

fn dirichlet(node: usize, dir: Vec3, value: f64, k: usize) -> RowSpec {
    RowSpec {
        node,
        row: Row {
            dir,
            value,
            masters: vec![],
            kind: RowKind::Dirichlet(k),
        },
    }
}

#[test]
fn skew_and_component_conditions_meet_at_their_intersection() {
    // u_x = 0 and u . n = -0.1 with n at 20 degrees from y: the node must satisfy both.
    let phi = 20f64.to_radians();
    let n = [-phi.sin(), phi.cos(), 0.0];
    let m = mesh();
    let c = Constraints::new(
        &SerialComm,
        &m,
        vec![
            dirichlet(0, [1.0, 0.0, 0.0], 0.0, 0),
            dirichlet(0, n, -0.1, 1),
        ],
    )
    .unwrap();
    let mut u = pad(vec![[0.3, 0.2, 0.1]]);
    c.impose(&SerialComm, &m, &mut u);
    assert!(u[0][0].abs() < 1e-15);
    assert!((dot(&u[0], &n) + 0.1).abs() < 1e-15);
    assert_eq!(u[0][2], 0.1);
}

#[test]
fn reduce_is_the_transpose_of_expand() {
    // Node 2 tied along n to nodes 0 and 1 with weights 0.25/0.75, node 3 tied to node 2
    // (a chain), node 2 also has a skew Dirichlet row.
    let n = [0.6, 0.8, 0.0];
    let specs = vec![
        RowSpec {
            node: 3,
            row: Row {
                dir: [0.0, 0.0, 1.0],
                value: 0.0,
                masters: vec![(2, 1.0)],
                kind: RowKind::Contact {
                    constraint: 1,
                    component: 0,
                },
            },
        },
        dirichlet(2, [1.0, 1.0, 0.0], 0.0, 0),
        RowSpec {
            node: 2,
            row: Row {
                dir: n,
                value: 0.0,
                masters: vec![(0, 0.25), (1, 0.75)],
                kind: RowKind::Contact {
                    constraint: 0,
                    component: 0,
                },
            },
        },
    ];
    let m = mesh();
    let c = Constraints::new(&SerialComm, &m, specs).unwrap();
    let v: Vec<Vec3> = pad(vec![
        [0.1, -0.2, 0.3],
        [0.5, 0.4, -0.6],
        [0.7, 0.1, 0.2],
        [-0.3, 0.9, 0.8],
    ]);
    let w: Vec<Vec3> = pad(vec![
        [0.2, 0.3, -0.1],
        [-0.4, 0.6, 0.5],
        [0.9, -0.8, 0.7],
        [0.1, 0.2, -0.3],
    ]);
    let mut tv = v.clone();
    c.expand(&SerialComm, &mut tv);
    let mut ttw = w.clone();
    c.reduce(&SerialComm, &mut ttw, None);
    let lhs: f64 = tv.iter().zip(&w).map(|(a, b)| dot(a, b)).sum();
    let rhs: f64 = v.iter().zip(&ttw).map(|(a, b)| dot(a, b)).sum();
    assert!((lhs - rhs).abs() < 1e-14, "{lhs} vs {rhs}");
    // The chain is resolved: node 3's z follows node 2's, which follows the masters, and
    // node 2 keeps its skew Dirichlet row. The rows (1,1,0)/sqrt(2) and (0.6,0.8,0) are
    // 8 degrees apart: the Gram system's condition number is about 200, so round-off is
    // bounded by about 200 eps |u| ~ 1e-13 |u|.
    let scale = tv.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    let tol = 1e-13 * scale;
    assert!((tv[3][2] - tv[2][2]).abs() < tol);
    assert!((dot(&tv[2], &n) - (0.25 * dot(&tv[0], &n) + 0.75 * dot(&tv[1], &n))).abs() < tol);
    assert!((tv[2][0] + tv[2][1]).abs() < tol, "{:?}", tv[2]);
}
