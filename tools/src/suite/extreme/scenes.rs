//! Each extreme scene's checks (`checks_of`), reading the last completed step unless said;
//! a scene without its own uses `generic` (force balance, and the slave body's); the
//! suite's scenes, in the report's order, and those that must stop.

use super::checks::*;
use super::result::Res;
use crate::text::n;
use solver::post::balance::V3;

pub const SCENE_DIR: &str = "run/scenes/extreme";
/// The suite's scenes in the report's order.
pub const ORDER: [&str; 16] = [
    "contrast_stiff_master",
    "contrast_soft_master",
    "contrast_stiff_on_soft",
    "incompressible_bbar",
    "incompressible_mean",
    "barrel",
    "drag",
    "drag_deformable",
    "bc_mu10",
    "bc_mu_tan_plus",
    "bc_mu_tan_minus",
    "penetration",
    "penetration_micro",
    "penetration_mega",
    "aspect100",
    "off_edge",
];
/// Scenes that cannot be solved: they must stop with a diagnosis.
pub const MUST_STOP: [&str; 1] = ["off_edge"];

/// The unscaled result a scaled scene is compared with.
pub type Base<'a> = Option<&'a Res>;

/// Runs the checks of scene `name` on its result.
pub fn checks_of(name: &str, r: &Res, c: &mut Checks, base: Base) -> Result<(), String> {
    match name {
        "contrast_stiff_master" | "contrast_soft_master" | "contrast_stiff_on_soft" => {
            contrast(r, c)
        }
        "incompressible_bbar" | "incompressible_mean" => confined(r, c),
        "barrel" => barrel(r, c),
        "drag" => drag(r, c),
        "drag_deformable" => drag_deformable(r, c),
        "bc_mu10" | "bc_mu_tan_plus" => bc(r, c, true),
        "bc_mu_tan_minus" => bc(r, c, false),
        "penetration" => penetration(r, c, 1.0, 1.0),
        "penetration_micro" => scaled(r, c, "penetration", 1e-6, 1e-6, base),
        "penetration_mega" => scaled(r, c, "penetration", 1e6, 1e6, base),
        "aspect100" => aspect(r, c),
        _ => generic(r, c),
    }
}

fn last(r: &Res) -> Result<usize, String> {
    r.n.checked_sub(1)
        .ok_or_else(|| "no step completed".to_string())
}

/// Force balance of the last completed step, and the slave body's when there is contact.
pub fn generic(r: &Res, c: &mut Checks) -> Result<(), String> {
    let k = last(r)?;
    balance(r, k, c, "")?;
    if r.contact("slave").is_some() {
        body_balance(r, k, &r.slave_body()?, c, "")?;
    }
    Ok(())
}

fn contrast(r: &Res, c: &mut Checks) -> Result<(), String> {
    let k = last(r)?;
    let p = r.pressure()?;
    balance(r, k, c, "")?;
    let sb = r.slave_body()?;
    body_balance(r, k, &sb, c, "")?;
    // The slave is the upper body (pushed up by the master) or the lower one (pushed down).
    let b = r.body(&sb)?;
    let min_y =
        r.x.iter()
            .zip(&r.node_body)
            .filter(|(_, &nb)| nb == b)
            .map(|(x, _)| x[1])
            .fold(f64::INFINITY, f64::min);
    let up = min_y >= 1.0 - 1e-12;
    contact_resultant(r, k, [0.0, if up { p } else { -p }, 0.0], p, c, "")?;
    uniaxial_by_body(r, k, -p, c)?;
    c.notes.push(
        "The stresses are reported, not checked: the bodies' Poisson expansions differ 1e6-fold, \
         so the slave nodes slide off the master nodes by nu p / E_soft = 3e-3 and node-to-face \
         contact loads the master between its nodes; the stiff body's stress is then uniform \
         only to O(slide / h)."
            .into(),
    );
    Ok(())
}

fn confined(r: &Res, c: &mut Checks) -> Result<(), String> {
    let k = last(r)?;
    balance(r, k, c, "")?;
    body_balance(r, k, &r.slave_body()?, c, "")?;
    let reaction = r.reaction(k)?;
    let top: Vec<V3> = r.node_set("top")?.iter().map(|&i| reaction[i]).collect();
    c.report(
        "total force on the top (y)",
        -solver::post::balance::sum(&top)[1],
    );
    Ok(())
}

/// The first node at `p` (to 1e-9 in each coordinate).
fn node_at(r: &Res, p: V3) -> Result<usize, String> {
    r.x.iter()
        .position(|x| (0..3).all(|i| (x[i] - p[i]).abs() < 1e-9))
        .ok_or_else(|| format!("no node at ({}, {}, {})", p[0], p[1], p[2]))
}

fn barrel(r: &Res, c: &mut Checks) -> Result<(), String> {
    let k = last(r)?;
    balance(r, k, c, "")?;
    body_balance(r, k, "block", c, "")?;
    coulomb(r, k, [0.0, -1.0, 0.0], r.mu()?, c, None, "")?;
    let u = r.displacement(k)?;
    let mid = node_at(r, [1.0, 0.0, 0.0])?;
    let top = node_at(r, [1.0, 0.5, 0.0])?;
    c.report("compression (height change / height)", -u[top][1] / 0.5);
    c.report("bulge: u_x of the mid-plane corner (1, 0, 0)", u[mid][0]);
    c.report(
        "u_x of the top corner (1, 0.5, 0), held by friction",
        u[top][0],
    );
    c.report_text(
        "slave nodes sticking / slipping at the end",
        stick_slip_counts(&r.status(k)?),
    );
    c.check(
        "barrelling (0: the mid-plane bulges more than the top edge)",
        if u[top][0] < u[mid][0] { 0.0 } else { 1.0 },
        0.0,
    );
    Ok(())
}

fn drag(r: &Res, c: &mut Checks) -> Result<(), String> {
    let k = last(r)?;
    let p = r.pressure()?;
    let mu = r.mu()?;
    balance(r, k, c, "")?;
    body_balance(r, k, "block", c, "")?;
    let fc = contact_resultant(r, k, [-mu * p, p, 0.0], p, c, "")?;
    c.report(
        "friction / normal force (sum over the slave nodes)",
        -fc[0] / fc[1],
    );
    coulomb(r, k, [0.0, 1.0, 0.0], mu, c, None, "")?;
    let st = r.status(k)?;
    c.report_text(
        "slave nodes sticking / slipping at the end",
        stick_slip_counts(&st),
    );
    // The friction direction of each slipping node against the direction of slip (+x).
    let f = r.contact_force(k)?;
    let cosines: Vec<f64> = (0..st.len())
        .filter(|&i| st[i] == 2)
        .map(|i| -f[i][0] / f[i][0].hypot(f[i][2]))
        .collect();
    if !cosines.is_empty() {
        c.report(
            "slipping nodes: smallest cosine between friction and -x (the slip opposes +x)",
            cosines.iter().copied().fold(f64::INFINITY, f64::min),
        );
    }
    Ok(())
}

fn drag_deformable(r: &Res, c: &mut Checks) -> Result<(), String> {
    let k = last(r)?;
    balance(r, k, c, "")?;
    body_balance(r, k, "block", c, "")
}

/// The paper's bc_interaction with another mu: sticking (`stick`) or slipping everywhere it
/// can.
fn bc(r: &Res, c: &mut Checks, stick: bool) -> Result<(), String> {
    let (d, h, e) = (2e-3, 2.0, 10.0e6);
    let phi = 20f64.to_radians();
    let k = last(r)?;
    let mu = r.mu()?;
    c.report("mu - tan(20 deg)", mu - phi.tan());
    balance(r, k, c, "")?;
    body_balance(r, k, "block", c, "")?;
    // The nodes of local face 0 of the slave side set's elements, x > 0.
    let mut slaves: Vec<usize> = r
        .side_set("block_bottom")?
        .iter()
        .flat_map(|&(el, _)| [0, 1, 5, 4].map(|i| r.conn[el as usize - 1][i]))
        .collect();
    slaves.sort_unstable();
    slaves.dedup();
    let away: Vec<usize> = slaves.into_iter().filter(|&s| r.x[s][0] > 1e-9).collect();
    let normal = [-phi.sin(), phi.cos(), 0.0];
    coulomb(r, k, normal, mu, c, Some(&away), " (x > 0, incline normal)")?;
    coulomb_current(r, k, "wedge_top", mu, &away, c)?;
    let st = r.status(k)?;
    if stick {
        let u = r.displacement(k)?;
        let err =
            r.x.iter()
                .zip(&u)
                .flat_map(|(x, u)| [u[0], u[1] - -d / h * x[1], u[2]])
                .fold(f64::NEG_INFINITY, |m, v| m.max(v.abs()));
        c.check("max |u - exact| / d", err / d, EXACT);
        let s = r.stress(k)?;
        let serr = s
            .iter()
            .flat_map(|s| {
                let mut t = *s;
                t[1] += e * d / h;
                t
            })
            .fold(f64::NEG_INFINITY, |m, v| m.max(v.abs()));
        c.check("max |sigma - exact| / (E d / H)", serr / (e * d / h), EXACT);
        let mut not_stick = 0usize;
        for j in 0..r.n {
            not_stick += r.status(j)?.iter().filter(|&&s| s == 2 || s == 3).count();
        }
        c.check("slave node-steps not sticking", not_stick as f64, 0.0);
    } else {
        c.check(
            "slave nodes (x > 0) not slipping at the end (mu < tan(phi): must slip)",
            away.iter().filter(|&&s| st[s] != 2).count() as f64,
            0.0,
        );
    }
    c.report_text(
        "slave nodes sticking / slipping at the end",
        stick_slip_counts(&st),
    );
    Ok(())
}

/// Half an element of initial penetration, in units scaled by `l` (length) and `s`
/// (stress): the exact stress and contact force at t = 1 and 2, and no penetration left.
fn penetration(r: &Res, c: &mut Checks, l: f64, s: f64) -> Result<(), String> {
    let (h, e) = (0.25, 1.0e4);
    for (t, delta) in [(1.0, 0.125), (2.0, 0.175)] {
        let Some(k) = r.step(t) else {
            c.check(format!("step at t = {t:.1} present"), 1.0, 0.0);
            continue;
        };
        let label = format!(" at t = {}", n(t));
        let sig = -e * s * delta / 2.0;
        uniaxial(r, k, sig, c, &label)?;
        let f = e * s * l * l * delta / 2.0;
        contact_resultant(r, k, [0.0, f, 0.0], f, c, &label)?;
        balance(r, k, c, &label)?;
    }
    let pen = r.stats.first().map_or(f64::NAN, |s| s.max_penetration);
    c.check("penetration left after step 1 / h", pen / (h * l), 1e-10);
    Ok(())
}

/// max |a - b / unit| / max |a| over every value.
fn scaled_difference(a: &[f64], b: &[f64], unit: f64) -> f64 {
    let d = a
        .iter()
        .zip(b)
        .fold(f64::NEG_INFINITY, |m, (x, y)| m.max((x - y / unit).abs()));
    d / a.iter().fold(f64::NEG_INFINITY, |m, x| m.max(x.abs()))
}

/// Every step's values of a field, flattened.
fn all_steps<const W: usize>(
    r: &Res,
    read: &dyn Fn(usize) -> Result<Vec<[f64; W]>, String>,
) -> Result<Vec<f64>, String> {
    let mut out = Vec::new();
    for k in 0..r.n {
        out.extend(read(k)?.into_iter().flatten());
    }
    Ok(out)
}

/// The scaled penetration scene: its own checks, then the same answer as `base_name` in
/// scaled units.
fn scaled(
    r: &Res,
    c: &mut Checks,
    base_name: &str,
    l: f64,
    s: f64,
    base: Base,
) -> Result<(), String> {
    penetration(r, c, l, s)?;
    let Some(b) = scaled_base(r, c, base_name, base) else {
        return Ok(());
    };
    let (worst, place) = scaled_fields(r, b, c, base_name, l, s)?;
    scaled_gap(r, b, c, base_name, l)?;
    c.check(
        format!(
            "scale invariance: u / L, sigma / S, R and f_contact / (S L^2) against {base_name}'s, \
             max rel. difference (in {place})"
        ),
        worst,
        SCALE,
    );
    let counts = |x: &Res| -> Vec<(u64, u64, u64)> {
        x.stats
            .iter()
            .map(|s| (s.cg_iterations, s.contact_updates, s.cutbacks))
            .collect()
    };
    c.report_text(
        format!("CG iterations, contact updates and cut-backs identical to {base_name}'s"),
        if counts(b) == counts(r) { "yes" } else { "no" }.into(),
    );
    Ok(())
}

/// The completed result of `base_name` with as many steps as `r`; without one, a failed
/// check saying why.
fn scaled_base<'a>(r: &Res, c: &mut Checks, base_name: &str, base: Base<'a>) -> Base<'a> {
    let Some(b) = base.filter(|b| {
        b.path
            .to_string_lossy()
            .ends_with(&format!("{base_name}.h5"))
    }) else {
        c.check(
            format!("scale invariance against {base_name} (no completed result of it)"),
            1.0,
            0.0,
        );
        return None;
    };
    if b.n != r.n {
        c.check(format!("as many steps as {base_name}"), 1.0, 0.0);
        return None;
    }
    Some(b)
}

/// Reports each field's scaled difference from the base's; returns the worst and its field.
fn scaled_fields(
    r: &Res,
    b: &Res,
    c: &mut Checks,
    base_name: &str,
    l: f64,
    s: f64,
) -> Result<(f64, &'static str), String> {
    let (mut worst, mut place) = (0.0, "");
    let force = s * l * l;
    let fields: [(&'static str, f64, Vec<f64>, Vec<f64>); 4] = [
        (
            "displacement",
            l,
            all_steps(b, &|k| b.displacement(k))?,
            all_steps(r, &|k| r.displacement(k))?,
        ),
        (
            "stress",
            s,
            all_steps(b, &|k| b.stress(k))?,
            all_steps(r, &|k| r.stress(k))?,
        ),
        (
            "reaction",
            force,
            all_steps(b, &|k| b.reaction(k))?,
            all_steps(r, &|k| r.reaction(k))?,
        ),
        (
            "contact/force",
            force,
            all_steps(b, &|k| b.contact_force(k))?,
            all_steps(r, &|k| r.contact_force(k))?,
        ),
    ];
    for (name, unit, a, v) in &fields {
        let d = scaled_difference(a, v, *unit);
        c.report(
            format!(
                "max |{name} / {} - {base_name}'s| / max |{base_name}'s|",
                n(*unit)
            ),
            d,
        );
        if d >= worst {
            (worst, place) = (d, *name);
        }
    }
    Ok((worst, place))
}

/// Reports the gaps' difference from the base's; gaps are round-off around zero, so it is
/// measured against the element size.
fn scaled_gap(r: &Res, b: &Res, c: &mut Checks, base_name: &str, l: f64) -> Result<(), String> {
    let mut gap = f64::NEG_INFINITY;
    for k in 0..r.n {
        for (x, y) in b.gap(k)?.iter().zip(&r.gap(k)?) {
            gap = gap.max((x - y / l).abs());
        }
    }
    c.report(format!("max |gap / L - {base_name}'s| / h"), gap / 0.25);
    Ok(())
}

fn aspect(r: &Res, c: &mut Checks) -> Result<(), String> {
    let k = last(r)?;
    let p = r.pressure()?;
    balance(r, k, c, "")?;
    body_balance(r, k, "upper", c, "")?;
    contact_resultant(r, k, [0.0, p, 0.0], p, c, "")?;
    uniaxial(r, k, -p, c, "")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A field scaled by exactly 2 has no difference; one value off by 1e-3 of the largest
    /// shows as 1e-3.
    #[test]
    fn scaled_difference_is_relative_to_the_largest_value() {
        let a = [1.0, -4.0, 2.0];
        assert_eq!(scaled_difference(&a, &[2.0, -8.0, 4.0], 2.0), 0.0);
        let d = scaled_difference(&a, &[2.0, -8.0, 4.008], 2.0);
        assert_eq!(d, (2.0f64 - 4.008 / 2.0).abs() / 4.0);
        assert!((d - 1e-3).abs() < 1e-15, "{d}");
    }
}
