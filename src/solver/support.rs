//! Which bodies their supports hold: a diagnosis for a step that cannot be solved.
//!
//! A body is held against rigid motion when its prescribed directions and the contact ties
//! on its nodes block all six rigid-body motions. A support row (direction c at point x)
//! blocks the motions m = (t, w) with c . (t + w x x) != 0, i.e. the 6-vector
//! (c, x x c) . m; the body is held when those vectors span R^6. When a slave body has
//! been pushed off its master (every tie released), the rows left span fewer than six
//! motions and the model problem is singular: CG wanders instead of converging. Naming the
//! body and its free motions turns "CG did not converge" into a cause and a place.
//!
//! A contact tie counts as a support of both bodies it joins (optimistic when neither is
//! held otherwise: two free bodies touching each other are not reported). Reference
//! coordinates are used: the question is which motions are blocked, not by how much.

use super::cg::FreeBody;
use crate::contact::Enforcement;
use crate::math::{cross, Vec3};
use crate::problem::Problem;
use nalgebra::{Matrix6, SymmetricEigen, Vector6};

/// An eigenvalue of the support Gram matrix below this fraction of the largest one is a
/// free motion (the rows are unit directions and lever arms scaled by the body's size, so
/// the matrix is well scaled; round-off sits near 1e-16).
const FREE: f64 = 1e-10;

/// One line per body that is not held: "body 'name' ... (free: ...)". Deterministic and
/// the same on every rank (it reads only replicated data).
pub fn unheld_bodies(problem: &Problem, contact: &impl Enforcement) -> Vec<String> {
    unheld_with(&DirichletGrams::new(problem), problem, contact)
}

/// `unheld_bodies` with the prescribed directions' Gram matrices computed once.
pub fn unheld_with(
    dirichlet: &DirichletGrams,
    problem: &Problem,
    contact: &impl Enforcement,
) -> Vec<String> {
    freedom(problem, &dirichlet.with_ties(problem, contact))
        .into_iter()
        .map(|(b, eig, free)| unheld_line(problem, b, &eig, &free))
        .collect()
}

/// The Gram matrix of each body's prescribed directions (`support_gram`), computed once for
/// a run: the directions and the nodes they hold do not change. A model problem's adds its
/// contact ties' rows to them (a Gram matrix is a sum over its rows, taken in the same
/// order as over all the rows at once: the same bits).
pub struct DirichletGrams {
    grams: Vec<Matrix6<f64>>,
    /// Whether some body's prescribed directions alone leave a rigid-body motion free.
    contact_alone: bool,
}

impl DirichletGrams {
    pub fn new(problem: &Problem) -> Self {
        let rows = dirichlet_rows(problem);
        let grams: Vec<Matrix6<f64>> = (0..problem.mesh.bodies.len())
            .map(|b| support_gram(problem.body_frame(b), &rows[b]))
            .collect();
        let contact_alone = !held_by_contact_alone(problem).is_empty();
        DirichletGrams {
            grams,
            contact_alone,
        }
    }

    /// Each body's Gram matrix with the contact ties' rows added.
    fn with_ties(&self, problem: &Problem, contact: &impl Enforcement) -> Vec<Matrix6<f64>> {
        let body_of = |g: usize| problem.mesh.body_of_node(g);
        let frames: Vec<(Vec3, f64)> = (0..self.grams.len())
            .map(|b| problem.body_frame(b))
            .collect();
        let mut grams = self.grams.clone();
        for (slave, master, dirs) in contact.supports(problem) {
            let x = problem.reference_position(slave);
            for b in [body_of(slave as usize), body_of(master as usize)]
                .into_iter()
                .flatten()
            {
                for d in &dirs {
                    add_row(&mut grams[b], frames[b], &x, d);
                }
            }
        }
        grams
    }
}

/// The bodies a model problem's supports leave free, with their free motions, for
/// `Cg::check_equilibrium`: every free rigid-body motion of a body under small kinematics,
/// the free translations under large kinematics (where a rotation is not in the
/// operator's null space). Empty, without reading the contact ties, when every body's
/// prescribed directions hold it. Deterministic and the same on every rank.
pub fn free_bodies(
    dirichlet: &DirichletGrams,
    problem: &Problem,
    contact: &impl Enforcement,
) -> Vec<FreeBody> {
    if !dirichlet.contact_alone {
        return Vec::new();
    }
    let grams = dirichlet.with_ties(problem, contact);
    let mut out = Vec::new();
    for (b, eig, free) in freedom(problem, &grams) {
        let large = problem.body_models[b].material.is_large();
        let motions: Vec<[f64; 6]> = if large {
            free_translations(&grams[b], &eig)
        } else {
            free.iter()
                .map(|&k| std::array::from_fn(|i| eig.eigenvectors[(i, k)]))
                .collect()
        };
        if motions.is_empty() {
            continue;
        }
        let (centre, size) = problem.body_frame(b);
        out.push(FreeBody {
            body: b,
            centre,
            size,
            motions,
            line: unheld_line(problem, b, &eig, &free),
        });
    }
    out
}

/// The bodies whose supports (Gram matrices `grams`) leave a rigid-body motion free:
/// (body, the eigen decomposition of its Gram matrix, the indices of its free
/// eigenvectors).
fn freedom(
    problem: &Problem,
    grams: &[Matrix6<f64>],
) -> Vec<(usize, SymmetricEigen<f64, nalgebra::U6>, Vec<usize>)> {
    let mut out = Vec::new();
    for (b, body) in problem.mesh.bodies.iter().enumerate() {
        if body.num_nodes == 0 {
            continue;
        }
        let eig = SymmetricEigen::new(grams[b]);
        let largest = eig.eigenvalues.iter().fold(0.0f64, |m, &v| m.max(v));
        let free: Vec<usize> = (0..6)
            .filter(|&k| eig.eigenvalues[k] <= FREE * largest || largest == 0.0)
            .collect();
        if !free.is_empty() {
            out.push((b, eig, free));
        }
    }
    out
}

/// The translations no support row has a component along: the null space of the rows'
/// sum of c c^T (the Gram matrix's translation block), judged against the Gram matrix's
/// largest eigenvalue, as (t, 0).
fn free_translations(
    gram: &Matrix6<f64>,
    eig: &SymmetricEigen<f64, nalgebra::U6>,
) -> Vec<[f64; 6]> {
    let largest = eig.eigenvalues.iter().fold(0.0f64, |m, &v| m.max(v));
    let t = SymmetricEigen::new(gram.fixed_view::<3, 3>(0, 0).into_owned());
    (0..3)
        .filter(|&k| t.eigenvalues[k] <= FREE * largest || largest == 0.0)
        .map(|k| {
            let v = t.eigenvectors.column(k);
            [v[0], v[1], v[2], 0.0, 0.0, 0.0]
        })
        .collect()
}

/// "body 'name' is not held: ... (free: ...)".
fn unheld_line(
    problem: &Problem,
    b: usize,
    eig: &SymmetricEigen<f64, nalgebra::U6>,
    free: &[usize],
) -> String {
    format!(
        "body '{}' is not held: its prescribed displacements and contact ties block {} of its 6 rigid-body motions (free: {})",
        problem.mesh.bodies[b].name,
        6 - free.len(),
        free_motions(eig, free).join(", ")
    )
}

/// The names of the bodies whose prescribed displacements alone leave a rigid-body motion
/// free: what holds them there is contact (a cylinder pressed onto a block, a body between
/// two dies). Their model problems are badly conditioned for a one-level preconditioner:
/// the free motion's stiffness comes through the contact patch only, far below the
/// element stiffness the nodal blocks see (the Hertz example remeshed twice as fine: 300
/// Jacobi CG iterations reduce its first model problem's residual by less than 10).
/// Deterministic and the same on every rank (replicated data only).
pub fn held_by_contact_alone(problem: &Problem) -> Vec<String> {
    let mesh = &problem.mesh;
    let rows = dirichlet_rows(problem);
    let mut out = Vec::new();
    for (b, body) in mesh.bodies.iter().enumerate() {
        if body.num_nodes == 0 {
            continue;
        }
        let eig = SymmetricEigen::new(support_gram(problem.body_frame(b), &rows[b]));
        let largest = eig.eigenvalues.iter().fold(0.0f64, |m, &v| m.max(v));
        if largest == 0.0 || eig.eigenvalues.iter().any(|&v| v <= FREE * largest) {
            out.push(body.name.clone());
        }
    }
    out
}

/// The prescribed directions of each body as (point, direction).
fn dirichlet_rows(problem: &Problem) -> Vec<Vec<(Vec3, Vec3)>> {
    let mesh = &problem.mesh;
    let mut rows: Vec<Vec<(Vec3, Vec3)>> = vec![Vec::new(); mesh.bodies.len()];
    for bc in &problem.dirichlet {
        for &g in &problem.node_sets[bc.node_set].nodes {
            if let Some(b) = problem.mesh.body_of_node(g as usize) {
                rows[b].push((problem.reference_position(g), bc.direction));
            }
        }
    }
    rows
}

/// The Gram matrix of a body's supports as rigid-body motions (direction, and moment
/// about the body's centre with lever arms scaled by the body's size: its frame,
/// `problem::frame_of`).
fn support_gram(frame: (Vec3, f64), rows: &[(Vec3, Vec3)]) -> Matrix6<f64> {
    let mut gram = Matrix6::<f64>::zeros();
    for (x, c) in rows {
        add_row(&mut gram, frame, x, c);
    }
    gram
}

/// Adds the row of direction `c` at `x` to `gram`.
fn add_row(gram: &mut Matrix6<f64>, (centre, size): (Vec3, f64), x: &Vec3, c: &Vec3) {
    let arm = [0, 1, 2].map(|i| (x[i] - centre[i]) / size);
    let m = cross(&arm, c);
    let r = Vector6::new(c[0], c[1], c[2], m[0], m[1], m[2]);
    *gram += r * r.transpose();
}

/// The free motions (eigenvectors `free` of the Gram matrix) named: as a projector (the
/// eigenvectors of a repeated zero eigenvalue are any basis of its space), first the axis
/// motions lying wholly in it, then the rest of the space, described by its basis vectors.
fn free_motions(eig: &SymmetricEigen<f64, nalgebra::U6>, free: &[usize]) -> Vec<String> {
    let mut projector = Matrix6::<f64>::zeros();
    for &k in free {
        let v = eig.eigenvectors.column(k).into_owned();
        projector += v * v.transpose();
    }
    const AXIS: [&str; 6] = [
        "translation along x",
        "translation along y",
        "translation along z",
        "rotation about x",
        "rotation about y",
        "rotation about z",
    ];
    let mut motions: Vec<String> = Vec::new();
    for (i, name) in AXIS.iter().enumerate() {
        if projector[(i, i)] >= 1.0 - 1e-8 {
            motions.push(name.to_string());
            let e = Vector6::from_fn(|r, _| if r == i { 1.0 } else { 0.0 });
            projector -= e * e.transpose();
        }
    }
    let rest = SymmetricEigen::new(projector);
    let mut order: Vec<usize> = (0..6).filter(|&k| rest.eigenvalues[k] > 0.5).collect();
    order.sort_by(|&i, &j| rest.eigenvalues[j].total_cmp(&rest.eigenvalues[i]));
    for k in order {
        motions.push(describe(&rest.eigenvectors.column(k).into_owned()));
    }
    motions
}

/// "translation along (a, b, c)" or "rotation about (a, b, c)" (rotations about the body's
/// centre), whichever part dominates, the direction rounded to two decimals with a
/// positive first non-zero component.
fn describe(v: &Vector6<f64>) -> String {
    let t = [v[0], v[1], v[2]];
    let w = [v[3], v[4], v[5]];
    let norm = |a: &Vec3| (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    let (kind, d) = if norm(&t) >= norm(&w) {
        ("translation along", t)
    } else {
        ("rotation about", w)
    };
    let l = norm(&d);
    let mut d = d.map(|x| x / l);
    if let Some(first) = d.iter().find(|x| x.abs() >= 5e-3) {
        if *first < 0.0 {
            d = d.map(|x| -x);
        }
    }
    let f = |x: f64| {
        let r = (x * 100.0).round() / 100.0;
        if r == 0.0 {
            "0".to_string()
        } else {
            format!("{r}")
        }
    };
    format!("{kind} ({}, {}, {})", f(d[0]), f(d[1]), f(d[2]))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(path: &str) -> Problem {
        let file = format!("{}/{path}", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(&file).unwrap();
        crate::scene::parse_scene(&text, &file, "scene").unwrap()
    }

    #[test]
    fn bodies_held_by_contact_alone_are_named() {
        // The stick/slip bar: z fixed on every node, x and y held only by the plates.
        let p = scene("run/scenes/paper/stick_slip.toml");
        assert_eq!(held_by_contact_alone(&p), vec!["bar".to_string()]);
        // The Hertz example: the cylinder's symmetry planes leave its vertical motion free.
        let p = scene("run/examples/cylinder_on_block.toml");
        assert_eq!(held_by_contact_alone(&p), vec!["cylinder".to_string()]);
        // The bar of the boundary-condition interaction test is fixed by its own supports.
        let p = scene("run/scenes/paper/bc_interaction.toml");
        assert!(held_by_contact_alone(&p).is_empty());
    }

    #[test]
    fn describe_names_the_dominant_part() {
        let v = Vector6::new(0.0, -1.0, 0.0, 0.0, 0.0, 0.0);
        assert_eq!(describe(&v), "translation along (0, 1, 0)");
        let v = Vector6::new(0.1, 0.0, 0.0, 0.0, 0.0, 0.9);
        assert_eq!(describe(&v), "rotation about (0, 0, 1)");
    }
}
