//! Equilibrium and Coulomb's law read from a result file: the resultant of the applied
//! pressures and tractions (from the scene's text and the faces' vector areas), the force
//! balance of the whole model and of one body, contact resultants, and the ratio
//! |f_t| / (mu |f_n|) of each node in contact. Used by `solver post verify` (the tangential
//! split of a contact force) and by the extreme suite's checks (`suite extreme`).
//!
//! Sums run over nodes or faces in their stored order, one after the other, so a value is
//! the same bitwise wherever it is computed.

use crate::fem::hex8::FACES;

pub type V3 = [f64; 3];

/// A function of time: (t, value) points, linear between them.
pub type Function = Vec<(f64, f64)>;

/// Component-wise sum of vectors, in order.
pub fn sum<'a>(v: impl IntoIterator<Item = &'a V3>) -> V3 {
    v.into_iter()
        .fold([0.0; 3], |s, x| [s[0] + x[0], s[1] + x[1], s[2] + x[2]])
}

pub fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

pub fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub fn scale(s: f64, a: V3) -> V3 {
    [s * a[0], s * a[1], s * a[2]]
}

pub fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}

pub fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// A piecewise-linear function of time through `points`, held beyond its ends.
pub fn piecewise(points: &[(f64, f64)], t: f64) -> f64 {
    let Some(&(t_first, v_first)) = points.first() else {
        return 0.0;
    };
    if t <= t_first {
        return v_first;
    }
    for w in points.windows(2) {
        let ((t0, v0), (t1, v1)) = (w[0], w[1]);
        if t <= t1 {
            return if t1 > t0 {
                v0 + (v1 - v0) * (t - t0) / (t1 - t0)
            } else {
                v1
            };
        }
    }
    points.last().map_or(0.0, |p| p.1)
}

/// The outward vector area of local face `face` of a hexahedron with corners `x` (exact for
/// a bilinear face: half the cross product of its diagonals, turned away from the element's
/// centre).
pub fn face_vector_area(x: &[V3; 8], face: usize) -> V3 {
    let p: Vec<V3> = FACES[face].iter().map(|&c| x[c]).collect();
    let a = scale(0.5, cross(sub(p[2], p[0]), sub(p[3], p[1])));
    let outward = sub(sum(&p).map(|v| v / 4.0), sum(x.iter()).map(|v| v / 8.0));
    if dot(a, outward) < 0.0 {
        scale(-1.0, a)
    } else {
        a
    }
}

/// Normal and tangential parts of a force against a unit normal: (f . n, |f - (f . n) n|).
pub fn normal_tangential(f: V3, n: V3) -> (f64, f64) {
    let fn_ = dot(f, n);
    (fn_, norm(sub(f, scale(fn_, n))))
}

/// The Coulomb ratio |f_t| / (mu |f_n|) of each node in contact (status 1 stick or 2
/// slip) among `nodes` (all nodes when `None`), in increasing node order: (node, ratio,
/// status).
pub fn coulomb_ratios(
    force: &[V3],
    status: &[u8],
    normal: V3,
    mu: f64,
    nodes: Option<&[usize]>,
) -> Vec<(usize, f64, u8)> {
    let in_contact = |i: usize| status[i] == 1 || status[i] == 2;
    let mut chosen: Vec<usize> = match nodes {
        Some(n) => n.iter().copied().filter(|&i| in_contact(i)).collect(),
        None => (0..status.len()).filter(|&i| in_contact(i)).collect(),
    };
    chosen.sort_unstable();
    chosen.dedup();
    chosen
        .into_iter()
        .map(|i| {
            let (fn_, ft) = normal_tangential(force[i], normal);
            (i, ft / (mu * fn_.abs()), status[i])
        })
        .collect()
}

/// The loads a scene applies that this module sums: pressures and tractions on side sets,
/// each with its function of time; whether the scene has body forces (not summed).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneLoads {
    /// (side set, pressure function).
    pub pressures: Vec<(String, Function)>,
    /// (side set, traction vector, scale function if any).
    pub tractions: Vec<(String, V3, Option<Function>)>,
    pub body_force: bool,
}

fn number(x: &toml::Value) -> Option<f64> {
    x.as_float().or_else(|| x.as_integer().map(|i| i as f64))
}

/// A function of time as the scene writes it: `[[t, value], ...]`.
fn function(v: Option<&toml::Value>) -> Option<Function> {
    v?.as_array()?
        .iter()
        .map(|p| {
            let p = p.as_array()?;
            Some((number(p.first()?)?, number(p.get(1)?)?))
        })
        .collect()
}

impl SceneLoads {
    /// The loads of a scene's TOML text; an error names what cannot be read.
    pub fn from_scene(doc: &toml::Table) -> Result<SceneLoads, String> {
        let list = |key: &str| {
            doc.get(key)
                .and_then(|v| v.as_array())
                .cloned()
                .unwrap_or_default()
        };
        let mut loads = SceneLoads {
            body_force: doc.get("body_force").is_some_and(|v| match v {
                toml::Value::Array(a) => !a.is_empty(),
                toml::Value::Table(t) => !t.is_empty(),
                _ => true,
            }),
            ..SceneLoads::default()
        };
        for (i, p) in list("pressure").iter().enumerate() {
            let side = p
                .get("side_set")
                .and_then(|s| s.as_str())
                .ok_or(format!("pressure[{i}].side_set"))?;
            let f = function(p.get("function")).ok_or(format!("pressure[{i}].function"))?;
            loads.pressures.push((side.into(), f));
        }
        for (i, t) in list("traction").iter().enumerate() {
            let side = t
                .get("side_set")
                .and_then(|s| s.as_str())
                .ok_or(format!("traction[{i}].side_set"))?;
            let v: Vec<f64> = t
                .get("vector")
                .and_then(|v| v.as_array())
                .and_then(|a| a.iter().map(number).collect::<Option<Vec<f64>>>())
                .filter(|c| c.len() == 3)
                .ok_or(format!("traction[{i}].vector"))?;
            let f = match t.get("function") {
                Some(f) => Some(function(Some(f)).ok_or(format!("traction[{i}].function"))?),
                None => None,
            };
            loads.tractions.push((side.into(), [v[0], v[1], v[2]], f));
        }
        Ok(loads)
    }
}

/// The faces of a side set as outward vector areas, with the body of each face.
pub struct Faces {
    pub areas: Vec<V3>,
    pub bodies: Vec<usize>,
}

/// The resultant of the applied pressures and tractions at time `t` on the faces `faces`
/// gives for each side set (on one body, or all); `None` when the scene has body forces.
pub fn applied_resultant(
    loads: &SceneLoads,
    t: f64,
    body: Option<usize>,
    faces: &dyn Fn(&str) -> Result<Faces, String>,
) -> Result<Option<V3>, String> {
    if loads.body_force {
        return Ok(None);
    }
    let mut total = [0.0; 3];
    let on = |f: &Faces| -> Vec<V3> {
        f.areas
            .iter()
            .zip(&f.bodies)
            .filter(|(_, &b)| body.is_none_or(|want| b == want))
            .map(|(a, _)| *a)
            .collect()
    };
    for (side, function) in &loads.pressures {
        let a = on(&faces(side)?);
        total = sub(total, scale(piecewise(function, t), sum(&a)));
    }
    for (side, vector, function) in &loads.tractions {
        let a = on(&faces(side)?);
        let s = function.as_ref().map_or(1.0, |f| piecewise(f, t));
        let area: f64 = a.iter().map(|x| norm(*x)).sum();
        total = add(total, scale(s * area, *vector));
    }
    Ok(Some(total))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_cube() -> [V3; 8] {
        [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
            [0.0, 1.0, 1.0],
        ]
    }

    /// Each face of a unit cube has unit area along its outward axis (exact in binary).
    #[test]
    fn vector_areas_of_a_unit_cube_point_outward() {
        let x = unit_cube();
        let expect = [
            [0.0, -1.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 0.0, -1.0],
            [0.0, 0.0, 1.0],
        ];
        for (f, e) in expect.iter().enumerate() {
            assert_eq!(face_vector_area(&x, f), *e, "face {f}");
        }
    }

    #[test]
    fn piecewise_functions_hold_beyond_their_ends() {
        let f = [(0.0, 0.0), (1.0, 100.0), (1.0, 50.0), (2.0, 0.0)];
        assert_eq!(piecewise(&f, -1.0), 0.0);
        assert_eq!(piecewise(&f, 0.5), 50.0);
        assert_eq!(piecewise(&f, 1.5), 25.0);
        assert_eq!(piecewise(&f, 3.0), 0.0);
    }

    /// A force at exactly mu |f_n| has ratio 1; a sticking node below; nodes out of
    /// contact are left out.
    #[test]
    fn coulomb_ratios_of_nodes_in_contact() {
        let f = [[3.0, 10.0, 0.0], [1.0, 10.0, 0.0], [5.0, 0.0, 0.0]];
        let r = coulomb_ratios(&f, &[2, 1, 0], [0.0, 1.0, 0.0], 0.3, None);
        assert_eq!(r.len(), 2);
        assert!((r[0].1 - 1.0).abs() <= 4.0 * f64::EPSILON);
        assert!((r[1].1 - 1.0 / 3.0).abs() <= 4.0 * f64::EPSILON);
        assert_eq!(
            coulomb_ratios(&f, &[2, 1, 0], [0.0, 1.0, 0.0], 0.3, Some(&[1, 2])).len(),
            1
        );
    }

    /// A pressure p on the top of a unit cube pushes down by p; a traction of magnitude 1
    /// along x on the same face by its area; body forces leave the sum undefined.
    #[test]
    fn applied_resultant_of_pressure_and_traction() {
        let x = unit_cube();
        let top = Faces {
            areas: vec![face_vector_area(&x, 2)],
            bodies: vec![0],
        };
        let faces = |_: &str| {
            Ok(Faces {
                areas: top.areas.clone(),
                bodies: top.bodies.clone(),
            })
        };
        let doc: toml::Table =
            "[[pressure]]\nside_set = \"top\"\nfunction = [[0.0, 0.0], [1, 100.0]]\n\
                                [[traction]]\nside_set = \"top\"\nvector = [2.0, 0, 0]\n"
                .parse()
                .unwrap();
        let loads = SceneLoads::from_scene(&doc).unwrap();
        let r = applied_resultant(&loads, 0.5, None, &faces)
            .unwrap()
            .unwrap();
        assert_eq!(r, [2.0, -50.0, 0.0]);
        assert_eq!(
            applied_resultant(&loads, 0.5, Some(1), &faces).unwrap(),
            Some([0.0, 0.0, 0.0])
        );
        let mut bf = loads.clone();
        bf.body_force = true;
        assert_eq!(applied_resultant(&bf, 0.5, None, &faces).unwrap(), None);
        let bad: toml::Table = "[[pressure]]\nside_set = \"top\"\n".parse().unwrap();
        assert_eq!(
            SceneLoads::from_scene(&bad).unwrap_err(),
            "pressure[0].function"
        );
    }
}
