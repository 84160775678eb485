//! The extreme suite's checks and reported values, and the checks several scenes share:
//! force balance (of the model and of one body), contact resultants, uniform uniaxial
//! stress and Coulomb's law, each computed by `solver::post::balance`.

use super::result::Res;
use crate::text::n;
use solver::fem::hex8::FACES;
use solver::post::balance::{coulomb_ratios, cross, norm, normal_tangential, scale, sub, sum, V3};

/// Force balance and contact resultants: a resultant differs from the load it carries by
/// the sum of the free residual components, at most sqrt(number of nodes) times the
/// residual norm, which the scenes' tolerances (1e-10 to 1e-12 of the reference force) keep
/// below 1e-9 of the load on these meshes.
pub const BALANCE: f64 = 1e-8;
/// Exact displacements and stresses: the condition number of the stiffness (1e2 to 1e3 on
/// these meshes) times the relative residual.
pub const EXACT: f64 = 1e-8;
/// Scale invariance: the scaled run differs from the unscaled one by the rounding of the
/// scaled input (1e-16) times the conditioning, with no absolute tolerance anywhere.
pub const SCALE: f64 = 1e-10;
/// Coulomb's law: |f_t| <= mu |f_n| to the relative slack the stick test allows (1e-9).
pub const COULOMB: f64 = 1e-8;

/// A reported value: a number or a few words.
#[derive(Clone, Debug, PartialEq)]
pub enum Val {
    Num(f64),
    Text(String),
}

impl Val {
    pub fn show(&self) -> String {
        match self {
            Val::Num(v) => n(*v),
            Val::Text(t) => t.clone(),
        }
    }
}

/// A check: name, value, limit, verdict (a value passes when finite and at most the limit).
#[derive(Clone, Debug, PartialEq)]
pub struct Check {
    pub name: String,
    pub value: f64,
    pub limit: f64,
    pub ok: bool,
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Checks {
    pub checks: Vec<Check>,
    pub reported: Vec<(String, Val)>,
    pub notes: Vec<String>,
}

impl Checks {
    pub fn check(&mut self, name: impl Into<String>, value: f64, limit: f64) {
        let ok = value.is_finite() && value <= limit;
        self.checks.push(Check {
            name: name.into(),
            value,
            limit,
            ok,
        });
    }

    pub fn report(&mut self, name: impl Into<String>, value: f64) {
        self.reported.push((name.into(), Val::Num(value)));
    }

    pub fn report_text(&mut self, name: impl Into<String>, value: String) {
        self.reported.push((name.into(), Val::Text(value)));
    }

    pub fn passed(&self) -> bool {
        self.checks.iter().all(|c| c.ok)
    }

    /// The check shown in the table: the first failing one, else the first.
    pub fn main(&self) -> Option<&Check> {
        self.checks.iter().find(|c| !c.ok).or(self.checks.first())
    }
}

/// max(|applied|, |sum of contact forces|): the force the balance is measured against.
fn reference_force(r: &Res, k: usize) -> Result<f64, String> {
    let fa = r.applied(k, None)?;
    let fc = sum(&r.contact_force(k)?);
    Ok(fa.map_or(0.0, norm).max(norm(fc)))
}

/// The sum of all reactions plus the applied loads (contact forces cancel in pairs).
pub fn balance(r: &Res, k: usize, c: &mut Checks, label: &str) -> Result<(), String> {
    let Some(fa) = r.applied(k, None)? else {
        c.notes
            .push("force balance not checked: the scene has body forces".into());
        return Ok(());
    };
    let reference = reference_force(r, k)?;
    let res = add3(sum(&r.reaction(k)?), fa);
    c.check(
        format!("force balance{label}: |sum R + loads| / F"),
        norm(res) / reference,
        BALANCE,
    );
    Ok(())
}

fn add3(a: V3, b: V3) -> V3 {
    solver::post::balance::add(a, b)
}

/// One body's equilibrium: its reactions, the contact force on its slave nodes and its
/// applied loads sum to zero.
pub fn body_balance(
    r: &Res,
    k: usize,
    body: &str,
    c: &mut Checks,
    label: &str,
) -> Result<(), String> {
    let b = r.body(body)?;
    let Some(fa) = r.applied(k, Some(b))? else {
        return Ok(());
    };
    let on = |v: &[V3]| -> V3 {
        sum(v
            .iter()
            .zip(&r.node_body)
            .filter(|(_, &nb)| nb == b)
            .map(|(x, _)| x))
    };
    let res = add3(add3(on(&r.reaction(k)?), on(&r.contact_force(k)?)), fa);
    c.check(
        format!("equilibrium of '{body}'{label}: |R + f_contact + loads| / F"),
        norm(res) / reference_force(r, k)?,
        BALANCE,
    );
    Ok(())
}

/// The sum of the contact forces against its exact value; returns the sum.
pub fn contact_resultant(
    r: &Res,
    k: usize,
    exact: V3,
    scale_: f64,
    c: &mut Checks,
    label: &str,
) -> Result<V3, String> {
    let fc = sum(&r.contact_force(k)?);
    let shown: Vec<String> = exact.iter().map(|&x| n(x)).collect();
    c.check(
        format!(
            "|sum f_contact - ({})|{label} / {}",
            shown.join(", "),
            n(scale_)
        ),
        norm(sub(fc, exact)) / scale_,
        BALANCE,
    );
    Ok(fc)
}

/// max |sigma - diag(0, sigma_yy, 0)| of the given elements (all when `None`).
fn uniaxial_error(s: &[[f64; 6]], sigma: f64, keep: &dyn Fn(usize) -> bool) -> f64 {
    s.iter()
        .enumerate()
        .filter(|(e, _)| keep(*e))
        .flat_map(|(_, s)| {
            let mut d = *s;
            d[1] -= sigma;
            d
        })
        .fold(f64::NEG_INFINITY, |m, x| np_max(m, x.abs()))
}

/// Uniform uniaxial stress sigma_yy = `sigma` in every element.
pub fn uniaxial(r: &Res, k: usize, sigma: f64, c: &mut Checks, label: &str) -> Result<(), String> {
    let s = r.stress(k)?;
    c.check(
        format!(
            "max |sigma - diag(0, {}, 0)|{label} / {}",
            n(sigma),
            n(sigma.abs())
        ),
        uniaxial_error(&s, sigma, &|_| true) / sigma.abs(),
        EXACT,
    );
    Ok(())
}

/// The same, reported per body.
pub fn uniaxial_by_body(r: &Res, k: usize, sigma: f64, c: &mut Checks) -> Result<(), String> {
    let s = r.stress(k)?;
    for (b, name) in r.bodies.iter().enumerate() {
        let err = uniaxial_error(&s, sigma, &|e| r.element_body[e] == b);
        c.report(
            format!(
                "max |sigma - diag(0, {}, 0)| / |sigma_yy| in '{name}'",
                n(sigma)
            ),
            err / sigma.abs(),
        );
    }
    Ok(())
}

/// Coulomb's law with a fixed unit normal over the nodes in contact (among `nodes`):
/// max |f_t| / (mu |f_n|) - 1, and the range over the slipping nodes.
pub fn coulomb(
    r: &Res,
    k: usize,
    normal: V3,
    mu: f64,
    c: &mut Checks,
    nodes: Option<&[usize]>,
    label: &str,
) -> Result<(), String> {
    let ratios = coulomb_ratios(&r.contact_force(k)?, &r.status(k)?, normal, mu, nodes);
    if ratios.is_empty() {
        return Ok(());
    }
    let max = ratios.iter().map(|x| x.1).fold(f64::NEG_INFINITY, np_max);
    c.check(
        format!("Coulomb{label}: max |f_t| / (mu |f_n|) - 1"),
        max - 1.0,
        COULOMB,
    );
    let slipping: Vec<f64> = ratios.iter().filter(|x| x.2 == 2).map(|x| x.1).collect();
    if !slipping.is_empty() {
        let lo = slipping.iter().copied().fold(f64::INFINITY, np_min);
        let hi = slipping.iter().copied().fold(f64::NEG_INFINITY, np_max);
        c.report(
            format!("slipping nodes{label}: |f_t| / (mu |f_n|) - 1 from"),
            lo - 1.0,
        );
        c.report(
            format!("slipping nodes{label}: |f_t| / (mu |f_n|) - 1 to"),
            hi - 1.0,
        );
    }
    Ok(())
}

/// numpy's max: NaN wins.
fn np_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

fn np_min(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.min(b)
    }
}

/// Reports max |f_t| / (mu |f_n|) - 1 over `nodes` with the normal of the deformed master
/// face whose centre is nearest each node (the normal the solver's contact search uses).
pub fn coulomb_current(
    r: &Res,
    k: usize,
    master: &str,
    mu: f64,
    nodes: &[usize],
    c: &mut Checks,
) -> Result<(), String> {
    let u = r.displacement(k)?;
    let x: Vec<V3> =
        r.x.iter()
            .zip(&u)
            .map(|(a, b)| [a[0] + b[0], a[1] + b[1], a[2] + b[2]])
            .collect();
    let mut faces: Vec<(V3, V3)> = Vec::new();
    for &(e, lf) in r.side_set(master)? {
        // The corners from the one the reports have always started face 2 (+y) at: the
        // order of the centre's sum decides between faces at the same distance.
        let f = FACES[lf as usize];
        let cycle = if lf == 2 { [f[1], f[2], f[3], f[0]] } else { f };
        let p: Vec<V3> = cycle
            .iter()
            .map(|&i| x[r.conn[e as usize - 1][i]])
            .collect();
        let a = cross(sub(p[2], p[0]), sub(p[3], p[1]));
        let len = norm(a);
        faces.push((scale(0.25, sum(&p)), a.map(|v| v / len)));
    }
    let fc = r.contact_force(k)?;
    let mut worst = f64::NEG_INFINITY;
    for &s in nodes {
        let mut best: Option<(f64, V3)> = None;
        for (centre, normal) in &faces {
            let d = norm(sub(*centre, x[s]));
            if best.is_none_or(|b| d < b.0) {
                best = Some((d, *normal));
            }
        }
        let Some((_, nrm)) = best else { continue };
        let (fn_, ft) = normal_tangential(fc[s], nrm);
        let ratio = ft / (mu * fn_.abs()) - 1.0;
        if ratio > worst {
            worst = ratio;
        }
    }
    c.report(
        "Coulomb with the deformed master normal (the one the solver uses): max |f_t| / (mu |f_n|) - 1",
        worst,
    );
    Ok(())
}

/// `sticking / slipping` counts of a step's status.
pub fn stick_slip_counts(st: &[u8]) -> String {
    let count = |v: u8| st.iter().filter(|&&s| s == v).count();
    format!("{} / {}", count(1), count(2))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_check_passes_only_when_finite_and_within_its_limit() {
        let mut c = Checks::default();
        c.check("a", 1e-9, BALANCE);
        assert!(c.passed());
        assert_eq!(c.main().unwrap().name, "a");
        c.check("b", f64::NAN, BALANCE);
        c.check("c", 2e-8, BALANCE);
        assert!(!c.passed());
        assert_eq!(
            c.main().unwrap().name,
            "b",
            "the first failing check is shown"
        );
        c.report_text("s", "1 / 2".into());
        assert_eq!(c.reported[0].1.show(), "1 / 2");
    }

    /// A stress field off the uniaxial one by 1e-3 of sigma in one component.
    #[test]
    fn uniaxial_error_is_the_largest_component_difference() {
        let s = vec![
            [0.0, -10.0, 0.0, 0.0, 0.0, 0.0],
            [0.0, -10.0, 0.01, 0.0, 0.0, 0.0],
        ];
        assert_eq!(uniaxial_error(&s, -10.0, &|_| true), 0.01);
        assert_eq!(uniaxial_error(&s, -10.0, &|e| e == 0), 0.0);
    }

    #[test]
    fn numpy_extrema_propagate_nan() {
        assert!(np_max(1.0, f64::NAN).is_nan());
        assert_eq!(np_min(1.0, 2.0), 1.0);
        assert_eq!(stick_slip_counts(&[0, 1, 2, 2]), "1 / 2");
    }
}
