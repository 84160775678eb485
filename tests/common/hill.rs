//! Hill's thick-walled sphere under internal pressure, elastic-perfectly plastic (Hill, The
//! Mathematical Theory of Plasticity, 1950, ch. V), on a thin sector around the x axis (a
//! gnomonic patch |y/x|, |z/x| <= W) whose flat sides pass through the centre and carry
//! u . n = 0: the closed form, and the sector's sets, constraints and load as scene text
//! shared by the hexahedral and the tetrahedral tests. With the plastic front at radius c,
//!
//!   p(c)  = 2 sigma_y ln(c/a) + (2 sigma_y / 3) (1 - c^3/b^3),
//!   u(b)  = sigma_y (1 - nu) c^3 / (E b^2),
//!
//! and the limit pressure 2 sigma_y ln(b/a) when the front reaches b.

pub const E: f64 = 200e3;
pub const NU: f64 = 0.3;
pub const SY: f64 = 250.0;
pub const A: f64 = 1.0;
pub const B: f64 = 2.0;
pub const W: f64 = 0.05;

/// Front radii the convergence tests choose their pressures for.
pub const FRONTS: [f64; 3] = [1.25, 1.5, 1.75];

pub fn p_of_c(c: f64) -> f64 {
    2.0 * SY * (c / A).ln() + 2.0 * SY / 3.0 * (1.0 - (c / B).powi(3))
}

pub fn ub_of_c(c: f64) -> f64 {
    SY * (1.0 - NU) * c.powi(3) / (E * B * B)
}

/// The material line of the sphere's body.
pub fn material() -> String {
    format!("material = {{ model = \"j2_plastic\", E = {E}, nu = {NU}, yield_stress = {SY} }}")
}

/// The sector's sides (in the box [a, b] x [-W, W]^2 before `to_sector`) held along their
/// normals, the inner sphere pressed with the pressure reaching each of `pressures` at
/// t = 1, 2, ... in two steps each, and the time segments.
pub fn sides_and_load(pressures: &[f64]) -> String {
    let k = 1.0 / (1.0 + W * W).sqrt();
    let mut func = String::from("[0.0, 0.0]");
    let mut segs = Vec::new();
    for (i, p) in pressures.iter().enumerate() {
        func += &format!(", [{}.0, {p}]", i + 1);
        segs.push(format!("{{ end = {}.0, steps = 2 }}", i + 1));
    }
    let (mw, wk, mwk) = (-W, W * k, -W * k);
    let mut text = String::new();
    for (name, axis, at) in [("ym", 1, mw), ("yp", 1, W), ("zm", 2, mw), ("zp", 2, W)] {
        let mut point = [0.0; 3];
        let mut normal = [0.0; 3];
        point[axis] = at;
        normal[axis] = 1.0;
        let mut dir = [if at < 0.0 { wk } else { mwk }, 0.0, 0.0];
        dir[axis] = k;
        text += &format!(
            "[[node_set]]\nname = \"{name}\"\nplane = {{ point = {point:?}, normal = {normal:?} }}\n\
             [[displacement]]\nnode_set = \"{name}\"\ndirection = {dir:?}\nvalue = 0.0\n"
        );
    }
    text += &format!(
        "[[side_set]]\nname = \"inner\"\nplane = {{ point = [{A}, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}\n\
         [[pressure]]\nside_set = \"inner\"\nfunction = [{func}]\n\
         [time]\nsegments = [{}]\n",
        segs.join(", ")
    );
    text
}

/// The box [a, b] x [-W, W]^2 onto the sector: (x, y, z) -> x (1, y, z) / |(1, y, z)|.
pub fn to_sector(coords: &mut [[f64; 3]]) {
    for c in coords.iter_mut() {
        let s = c[0] / (1.0 + c[1] * c[1] + c[2] * c[2]).sqrt();
        *c = [s, s * c[1], s * c[2]];
    }
}
