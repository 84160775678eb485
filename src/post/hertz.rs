//! `solver post hertz`: the contact pressure under a cylinder (axis along z) pressed onto a
//! flat body, against the Hertz line-contact (plane strain) solution
//!
//!   p(x) = p0 sqrt(1 - x^2 / a^2),  a = sqrt(4 P R / (pi E*)),  p0 = 2 P / (pi a),
//!   1 / E* = (1 - nu1^2) / E1 + (1 - nu2^2) / E2,
//!
//! with P the normal load per unit length. Everything is read from the result file: the
//! scene's one contact pair names the slave surface (the cylinder) and the master surface,
//! the scene's bodies give E and nu, a circle fitted to the slave nodes gives R and the axis,
//! the resultant contact force gives P and the normal direction. The nodal pressure is the
//! slave node's normal contact force over its tributary area (a quarter of each slave face
//! it belongs to). Further result files (`--overlay`, e.g. the same cylinder with the other
//! contact discretization or a finer mesh) are compared the same way and their pressures
//! drawn over the first file's.

use std::collections::HashMap;
use std::path::PathBuf;

use super::figures::{render_figure, Curve, Figure, LegendAt, Mark, Panel};
use super::plot::fonts_available;
use crate::fem::hex8::FACES;
use crate::math::{dot, Vec3};
use crate::output::{check_picture_output, write_picture, OutputError, OutputMesh, ResultFile};
use crate::scene::SceneFile;

/// Arguments of `solver post hertz`.
#[derive(clap::Args, Debug, Clone, PartialEq)]
pub struct HertzArgs {
    /// The result file (.h5) of a cylinder-on-flat scene with one contact pair.
    pub file: PathBuf,
    /// The plot to write (.png): pressure against position across the contact.
    #[arg(short = 'o', long)]
    pub output: PathBuf,
    /// Further result files of cylinder-on-flat scenes, each reported and its nodal
    /// pressures drawn over the first file's (the Hertz curve is the first file's).
    #[arg(long = "overlay", value_name = "FILE")]
    pub overlay: Vec<PathBuf>,
}

/// The Hertz line contact for a load per unit length, radius and contact modulus.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HertzLine {
    /// Contact half-width.
    pub a: f64,
    /// Peak pressure.
    pub p0: f64,
}

impl HertzLine {
    pub fn new(load_per_length: f64, radius: f64, e_star: f64) -> Self {
        let a = (4.0 * load_per_length * radius / (std::f64::consts::PI * e_star)).sqrt();
        HertzLine {
            a,
            p0: 2.0 * load_per_length / (std::f64::consts::PI * a),
        }
    }

    /// The pressure at distance `x` from the centre line of the contact.
    pub fn pressure(&self, x: f64) -> f64 {
        let r = x / self.a;
        if r.abs() >= 1.0 {
            0.0
        } else {
            self.p0 * (1.0 - r * r).sqrt()
        }
    }
}

/// The plane-strain contact modulus E* of two elastic bodies.
pub fn contact_modulus(e1: f64, nu1: f64, e2: f64, nu2: f64) -> f64 {
    1.0 / ((1.0 - nu1 * nu1) / e1 + (1.0 - nu2 * nu2) / e2)
}

/// Least-squares circle through points of the plane: (centre, radius, largest distance of
/// a point from the circle). Fits x^2 + y^2 + D x + E y + F = 0 (linear in D, E, F).
pub fn fit_circle(points: &[[f64; 2]]) -> Option<([f64; 2], f64, f64)> {
    if points.len() < 3 {
        return None;
    }
    // Centred and scaled for conditioning.
    let n = points.len() as f64;
    let mx = points.iter().map(|p| p[0]).sum::<f64>() / n;
    let my = points.iter().map(|p| p[1]).sum::<f64>() / n;
    let scale = points
        .iter()
        .map(|p| (p[0] - mx).hypot(p[1] - my))
        .fold(0.0, f64::max);
    if !(scale > 0.0) {
        return None;
    }
    let mut m = [[0.0; 3]; 3];
    let mut r = [0.0; 3];
    for p in points {
        let (x, y) = ((p[0] - mx) / scale, (p[1] - my) / scale);
        let row = [x, y, 1.0];
        let rhs = -(x * x + y * y);
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] += row[i] * row[j];
            }
            r[i] += row[i] * rhs;
        }
    }
    let (inv, det) = crate::math::inverse(&m);
    if !(det.abs() > 1e-12 * n * n * n) {
        return None;
    }
    let s: [f64; 3] = std::array::from_fn(|i| (0..3).map(|j| inv[i][j] * r[j]).sum());
    let (cx, cy) = (-s[0] / 2.0, -s[1] / 2.0);
    let rr = cx * cx + cy * cy - s[2];
    if !(rr > 0.0) {
        return None;
    }
    let radius = rr.sqrt() * scale;
    let centre = [mx + cx * scale, my + cy * scale];
    let off = points
        .iter()
        .map(|p| ((p[0] - centre[0]).hypot(p[1] - centre[1]) - radius).abs())
        .fold(0.0, f64::max);
    Some((centre, radius, off))
}

/// The comparison: FE pressures at the slave nodes and the Hertz solution.
#[derive(Clone, Debug, PartialEq)]
pub struct HertzComparison {
    /// The scene's name and the pair's contact discretization, e.g. "cylinder (node_face)".
    pub label: String,
    pub radius: f64,
    pub e_star: f64,
    /// Resultant normal contact force per unit length.
    pub load_per_length: f64,
    pub hertz: HertzLine,
    /// (position across the contact, pressure) at every slave node, sorted by position.
    pub nodes: Vec<(f64, f64)>,
    /// Largest |position| of a node in contact.
    pub contact_edge: f64,
    /// Node spacing across the contact at its centre.
    pub spacing: f64,
    /// Node spacing at the Hertz edge: the distance between the node positions on either
    /// side of a.
    pub edge_spacing: f64,
    /// Largest FE pressure.
    pub peak: f64,
    /// RMS of FE minus Hertz pressure over the nodes within 1.5 a, over p0.
    pub rms_error: f64,
    /// (node index of the file, 0-based; position across the contact) of every slave
    /// node, by node index: where another code's pressures on the same mesh go
    /// (`errors_of`).
    pub slave: Vec<(usize, f64)>,
}

impl HertzComparison {
    /// (FE half-width - Hertz a) in node spacings at the edge.
    pub fn edge_error(&self) -> f64 {
        (self.contact_edge - self.hertz.a) / self.edge_spacing
    }

    /// Peak FE pressure over p0, minus 1.
    pub fn peak_error(&self) -> f64 {
        (self.peak - self.hertz.p0) / self.hertz.p0
    }

    /// (peak over p0 minus 1, RMS error within 1.5 a over p0) of other nodal pressures at
    /// the same slave nodes (another code's on the same mesh) against this comparison's
    /// Hertz solution (the load this file's contact carried): `pressure` of a slave node's
    /// index, None for no pressure there (a node out of contact). None when no slave node
    /// lies within 1.5 a.
    pub fn errors_of(&self, pressure: impl Fn(usize) -> Option<f64>) -> Option<(f64, f64)> {
        let nodes: Vec<(f64, f64)> = self
            .slave
            .iter()
            .map(|&(n, x)| (x, pressure(n).unwrap_or(0.0)))
            .collect();
        let peak = nodes.iter().map(|n| n.1).fold(f64::NEG_INFINITY, f64::max);
        let rms = rms_error(&nodes, &self.hertz)?;
        Some(((peak - self.hertz.p0) / self.hertz.p0, rms))
    }

    /// The FE minus Hertz pressure at the nodes within a third of a of the centre, over p0:
    /// (their count, mean, standard deviation, largest). The mean is the discretization's
    /// error there, the deviation its node-by-node scatter (an unstructured surface's);
    /// the peak is the largest of those nodes' pressures, so it stands above Hertz's by
    /// the mean plus about the largest of as many draws of the scatter, and grows with
    /// their number at a given scatter. None when no node lies there.
    pub fn centre_errors(&self) -> Option<(usize, f64, f64, f64)> {
        let h = &self.hertz;
        let d: Vec<f64> = self
            .nodes
            .iter()
            .filter(|n| n.0.abs() <= h.a / 3.0)
            .map(|n| (n.1 - h.pressure(n.0)) / h.p0)
            .collect();
        if d.is_empty() {
            return None;
        }
        let n = d.len() as f64;
        let mean = d.iter().sum::<f64>() / n;
        let var = d.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / n;
        let largest = d.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        Some((d.len(), mean, var.sqrt(), largest))
    }

    pub fn render(&self) -> String {
        let h = &self.hertz;
        let in_window = self.nodes.iter().filter(|n| n.0.abs() <= 1.5 * h.a).count();
        let centre = self.centre_errors().map_or(String::new(), |(n, mean, sd, max)| {
            format!(
                "  FE - Hertz within |x| <= a / 3 ({n} nodes): mean {:+.2}%, scatter {:.2}% (standard deviation), largest {:+.2}% of p0\n",
                100.0 * mean,
                100.0 * sd,
                100.0 * max
            )
        });
        let text = format!(
            "Hertz line contact (plane strain): {}\n\
             \x20 radius R (fitted to the slave nodes)    {}\n\
             \x20 contact modulus E*                      {}\n\
             \x20 load per unit length P (contact force)  {}\n\
             \x20 half-width a: Hertz {}, FE outermost node in contact {} (node spacing {})\n\
             \x20 peak pressure: Hertz p0 {}, FE {} ({:+.1}%)\n\
             \x20 RMS error of the nodal pressure within |x| <= 1.5 a ({} nodes): {:.1}% of p0\n\
             \x20 half-width FE - Hertz: {:+.2} node spacings at the edge (spacing there {})\n\
             \x20 summary: peak/p0-1 {:+.4}, RMS/p0 {:.4}, (a_FE-a)/h {:+.3}\n",
            self.label,
            g(self.radius),
            g(self.e_star),
            g(self.load_per_length),
            g(h.a),
            g(self.contact_edge),
            g(self.spacing),
            g(h.p0),
            g(self.peak),
            100.0 * self.peak_error(),
            in_window,
            100.0 * self.rms_error,
            self.edge_error(),
            g(self.edge_spacing),
            self.peak_error(),
            self.rms_error,
            self.edge_error()
        );
        // The centre's line after the RMS error's.
        let at = text.find("  half-width FE - Hertz").unwrap_or(text.len());
        format!("{}{centre}{}", &text[..at], &text[at..]) + &self.table()
    }

    /// Position, FE and Hertz pressure within 1.5 a, nodes at one position (along the
    /// cylinder's length) averaged.
    fn table(&self) -> String {
        let mut rows: Vec<(f64, f64, usize)> = Vec::new();
        for &(x, p) in self
            .nodes
            .iter()
            .filter(|n| n.0.abs() <= 1.5 * self.hertz.a)
        {
            match rows.last_mut() {
                Some(r) if (x - r.0).abs() <= 1e-9 * self.radius => {
                    r.1 += p;
                    r.2 += 1;
                }
                _ => rows.push((x, p, 1)),
            }
        }
        let mut s = format!("  {:>10}  {:>10}  {:>10}\n", "x", "FE", "Hertz");
        for (x, p, n) in rows {
            s += &format!(
                "  {:>10}  {:>10}  {:>10}\n",
                g(x),
                g(p / n as f64),
                g(self.hertz.pressure(x))
            );
        }
        s
    }

    /// The plot: FE nodal pressures and the Hertz curve over [-2a, 2a].
    pub fn figure(&self) -> Figure {
        figure(std::slice::from_ref(self))
    }
}

/// The plot of several comparisons: the first's Hertz curve over [-2a, 2a] and every
/// comparison's FE nodal pressures (one colour each, labelled when there are several).
pub fn figure(comparisons: &[HertzComparison]) -> Figure {
    let first = &comparisons[0];
    let a = first.hertz.a;
    let mut curves = vec![Curve {
        label: Some("Hertz".into()),
        color: 0,
        mark: Mark::Line,
        legend: Mark::Line,
        points: (0..=400)
            .map(|i| {
                let x = -2.0 * a + 4.0 * a * i as f64 / 400.0;
                (x, first.hertz.pressure(x))
            })
            .collect(),
    }];
    for (i, c) in comparisons.iter().enumerate() {
        let label = if comparisons.len() == 1 {
            "FE: nodal force / tributary area".to_string()
        } else {
            format!("FE {}: RMS {:.1}% of p0", c.label, 100.0 * c.rms_error)
        };
        curves.push(Curve {
            label: Some(label),
            color: i + 1,
            mark: Mark::Points,
            legend: Mark::Points,
            points: c
                .nodes
                .iter()
                .copied()
                .filter(|n| n.0.abs() <= 2.0 * a)
                .collect(),
        });
    }
    Figure {
        title: format!(
            "Cylinder on block: contact pressure against Hertz (R = {}, P = {} per unit length)",
            g(first.radius),
            g(first.load_per_length)
        ),
        panels: vec![Panel {
            title: format!(
                "a = {}, p0 = {}; RMS error {:.1}% of p0 within 1.5 a",
                g(a),
                g(first.hertz.p0),
                100.0 * first.rms_error
            ),
            x_label: "position across the contact (from the cylinder's centre line)".into(),
            y_label: "contact pressure".into(),
            curves,
            legend: LegendAt::UpperRight,
        }],
    }
}

/// Four significant digits, plain for moderate magnitudes.
fn g(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if (1e-3..1e6).contains(&a) {
        let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
        format!("{v:.decimals$}")
    } else {
        format!("{v:.3e}")
    }
}

/// Runs `solver post hertz`: compares, draws, and returns the report.
pub fn hertz_command(args: &HertzArgs) -> Result<String, OutputError> {
    let mut inputs = vec![(args.file.as_path(), "the result file")];
    inputs.extend(
        args.overlay
            .iter()
            .map(|f| (f.as_path(), "a result file (--overlay)")),
    );
    check_picture_output(&args.output, &inputs)?;
    let comparisons = inputs
        .iter()
        .map(|(f, _)| compare(&ResultFile::open(f)?))
        .collect::<Result<Vec<_>, _>>()?;
    let text = fonts_available();
    if !text {
        eprintln!(
            "warning: no usable system font (sans-serif); the plot is drawn without text \
             (install fonts-dejavu-core for labels)"
        );
    }
    write_picture(&args.output, &inputs, |tmp| {
        render_figure(&figure(&comparisons), tmp, text)
    })?;
    let reports: Vec<String> = comparisons.iter().map(|c| c.render()).collect();
    Ok(format!(
        "{}wrote {}",
        reports.join("\n"),
        args.output.display()
    ))
}

/// The comparison at the last step of a result file: the pair's contact modulus, the
/// slave nodes' tributary areas, the cylinder they lie on, the resultant contact force,
/// then the pressure profile against Hertz's.
pub fn compare(f: &ResultFile) -> Result<HertzComparison, OutputError> {
    let usage = |message: String| OutputError::Usage {
        file: f.path().to_path_buf(),
        message,
    };
    let steps = f.num_steps();
    if steps == 0 {
        return Err(usage("the file has no completed step".into()));
    }
    let attrs = f.attributes()?;
    let scene: SceneFile = toml::from_str(&attrs.scene_text)
        .map_err(|e| usage(format!("the scene stored in the file does not parse: {e}")))?;
    let [contact] = scene.contact.as_slice() else {
        return Err(usage(format!(
            "expected a scene with one [[contact]] pair, found {}",
            scene.contact.len()
        )));
    };
    let mesh = f.mesh()?;
    let elements = element_table(&mesh);
    let faces = |name: &str| -> Result<&Vec<(u64, u8)>, OutputError> {
        mesh.side_sets
            .iter()
            .find(|s| s.0 == name)
            .map(|s| &s.1)
            .ok_or_else(|| usage(format!("the file has no side set '{name}'")))
    };
    let material = |set: &str| -> Result<(f64, f64), OutputError> {
        let body = side_set_body(&elements, faces(set)?)
            .ok_or_else(|| usage(format!("side set '{set}' is not on exactly one body")))?;
        elastic_constants(&scene, body)
            .ok_or_else(|| usage(format!("the scene has no body '{body}'")))
    };
    let (e1, nu1) = material(&contact.slave)?;
    let (e2, nu2) = material(&contact.master)?;
    let e_star = contact_modulus(e1, nu1, e2, nu2);
    let area = tributary_areas(&mesh, &elements, faces(&contact.slave)?).map_err(usage)?;
    let mut slave: Vec<usize> = area.keys().copied().collect();
    slave.sort_unstable();
    let (centre, radius, length) = cylinder(&mesh, &slave, &contact.slave).map_err(usage)?;
    let force = f.contact_force(steps - 1)?;
    let status = f.contact_status(steps - 1)?;
    let (normal, magnitude) = resultant(&force, &slave).map_err(usage)?;
    let across = [normal[1], -normal[0], 0.0];
    let position = |n: usize| {
        let x = mesh.coordinates[n];
        dot(&[x[0] - centre[0], x[1] - centre[1], 0.0], &across)
    };
    let load_per_length = magnitude / length;
    let hertz = HertzLine::new(load_per_length, radius, e_star);
    let mut nodes: Vec<(f64, f64)> = slave
        .iter()
        .map(|&n| (position(n), dot(&force[n], &normal) / area[&n]))
        .collect();
    nodes.sort_by(|a, b| a.0.total_cmp(&b.0));
    let contact_edge = slave
        .iter()
        .filter(|&&n| status[n] == 1 || status[n] == 2)
        .map(|&n| position(n).abs())
        .fold(0.0, f64::max);
    let peak = nodes.iter().map(|n| n.1).fold(f64::NEG_INFINITY, f64::max);
    let discretization = contact.discretization.as_deref().unwrap_or("node_face");
    let rms_error = rms_error(&nodes, &hertz)
        .ok_or_else(|| usage("no slave node lies within 1.5 a of the contact".into()))?;
    Ok(HertzComparison {
        label: format!("{} ({discretization})", attrs.scene_name),
        radius,
        e_star,
        load_per_length,
        hertz,
        spacing: spacing(&nodes, radius),
        edge_spacing: edge_spacing(&nodes, radius, hertz.a),
        nodes,
        contact_edge,
        peak,
        rms_error,
        slave: slave.iter().map(|&n| (n, position(n))).collect(),
    })
}

/// RMS of the pressure error within 1.5 a of the centre, over p0; None when no node
/// lies there.
fn rms_error(nodes: &[(f64, f64)], hertz: &HertzLine) -> Option<f64> {
    let window: Vec<f64> = nodes
        .iter()
        .filter(|n| n.0.abs() <= 1.5 * hertz.a)
        .map(|n| n.1 - hertz.pressure(n.0))
        .collect();
    if window.is_empty() {
        return None;
    }
    Some((window.iter().map(|d| d * d).sum::<f64>() / window.len() as f64).sqrt() / hertz.p0)
}

/// E and nu of a body of the scene. Hertz's solution is elastic: a plastic body is
/// compared by its elastic constants, valid while it has not yielded.
fn elastic_constants(scene: &SceneFile, body: &str) -> Option<(f64, f64)> {
    let def = scene.body.iter().find(|b| b.name == body)?;
    Some(def.material.params().young_poisson())
}

/// Each slave node's tributary area: a quarter of each of its faces of hexahedra; on a
/// tet10's 6-node face, a third of each of the face's four sub-triangles the node is a
/// corner of (the facets contact takes, `FaceKind::contact_facets`).
fn tributary_areas(
    mesh: &OutputMesh,
    elements: &HashMap<u64, (&str, &[u64])>,
    faces: &[(u64, u8)],
) -> Result<HashMap<usize, f64>, String> {
    let mut area: HashMap<usize, f64> = HashMap::new();
    for &(id, face) in faces {
        let conn = elements
            .get(&id)
            .ok_or_else(|| format!("side set names element {id}, which the mesh lacks"))?
            .1;
        if conn.len() == 10 {
            let local = crate::fem::tet10::FACES[face as usize];
            for f in crate::fem::FaceKind::Tri6.contact_facets() {
                let nodes: [usize; 3] = std::array::from_fn(|a| conn[local[f[a]]] as usize);
                let x = nodes.map(|n| mesh.coordinates[n]);
                let third = crate::fem::face::triangle_area(&x) / 3.0;
                for n in nodes {
                    *area.entry(n).or_insert(0.0) += third;
                }
            }
            continue;
        }
        if conn.len() != 8 {
            return Err(format!(
                "side set names element {id} of {} nodes; the Hertz comparison reads faces of hexahedra and tet10s only",
                conn.len()
            ));
        }
        let nodes = FACES[face as usize].map(|a| conn[a] as usize);
        let x: [Vec3; 4] = nodes.map(|n| mesh.coordinates[n]);
        let quarter = crate::fem::face::area(&x) / 4.0;
        for n in nodes {
            *area.entry(n).or_insert(0.0) += quarter;
        }
    }
    Ok(area)
}

/// The circle about a z axis the slave nodes lie on, and the cylinder's length along z:
/// (centre, radius, length).
fn cylinder(
    mesh: &OutputMesh,
    slave: &[usize],
    name: &str,
) -> Result<([f64; 2], f64, f64), String> {
    let plane: Vec<[f64; 2]> = slave
        .iter()
        .map(|&n| [mesh.coordinates[n][0], mesh.coordinates[n][1]])
        .collect();
    let (centre, radius, off) = fit_circle(&plane)
        .ok_or_else(|| "the slave nodes do not lie on a circle about a z axis".to_string())?;
    if off > 1e-3 * radius {
        return Err(format!(
            "the slave surface '{name}' is not a cylinder about a z axis (a node lies {off:.3e} off the best circle of radius {radius:.4e})"
        ));
    }
    let zs = slave.iter().map(|&n| mesh.coordinates[n][2]);
    let length = zs.clone().fold(f64::NEG_INFINITY, f64::max) - zs.fold(f64::INFINITY, f64::min);
    if !(length > 0.0) {
        return Err("the slave surface has no length along z".into());
    }
    Ok((centre, radius, length))
}

/// The direction and magnitude of the total contact force on the slave nodes, which must
/// be perpendicular to the cylinder's axis.
fn resultant(force: &[Vec3], slave: &[usize]) -> Result<(Vec3, f64), String> {
    let mut total = [0.0; 3];
    for &n in slave {
        for i in 0..3 {
            total[i] += force[n][i];
        }
    }
    let magnitude = crate::math::norm(&total);
    if !(magnitude > 0.0) {
        return Err("there is no contact force at the last step".into());
    }
    let normal = total.map(|v| v / magnitude);
    if normal[2].abs() > 1e-6 {
        return Err(format!(
            "the resultant contact force {total:?} is not perpendicular to the cylinder's axis (z)"
        ));
    }
    Ok((normal, magnitude))
}

/// The node spacing at the contact's centre (between the two nodes nearest it, or from
/// a node on it to the next).
fn spacing(nodes: &[(f64, f64)], radius: f64) -> f64 {
    let mut distinct: Vec<f64> = nodes.iter().map(|n| n.0.abs()).collect();
    distinct.sort_by(f64::total_cmp);
    distinct.dedup_by(|a, b| (*a - *b).abs() <= 1e-9 * radius);
    match distinct.as_slice() {
        [a, b, ..] if *a <= 1e-9 * radius => *b,
        [a, b, ..] => a + b,
        _ => 0.0,
    }
}

/// The node spacing at distance `a` from the centre: between the nearest distinct node
/// positions (|x|) below and above a, or the last spacing when no node lies beyond a.
fn edge_spacing(nodes: &[(f64, f64)], radius: f64, a: f64) -> f64 {
    let mut distinct: Vec<f64> = nodes.iter().map(|n| n.0.abs()).collect();
    distinct.sort_by(f64::total_cmp);
    distinct.dedup_by(|x, y| (*x - *y).abs() <= 1e-9 * radius);
    let gaps: Vec<(f64, f64)> = distinct.windows(2).map(|w| (w[0], w[1])).collect();
    gaps.iter()
        .find(|(lo, hi)| *lo <= a && a < *hi)
        .or(gaps.last())
        .map_or(0.0, |(lo, hi)| hi - lo)
}

/// Element id -> (body name, connectivity).
fn element_table(mesh: &OutputMesh) -> HashMap<u64, (&str, &[u64])> {
    let mut out = HashMap::new();
    for b in &mesh.bodies {
        for (id, conn) in b.element_ids.iter().zip(&b.connectivity) {
            out.insert(*id, (b.name.as_str(), conn));
        }
    }
    out
}

/// The one body all faces of a side set belong to.
fn side_set_body<'a>(
    elements: &HashMap<u64, (&'a str, &'a [u64])>,
    faces: &[(u64, u8)],
) -> Option<&'a str> {
    let mut body = None;
    for (id, _) in faces {
        let b = elements.get(id)?.0;
        match body {
            None => body = Some(b),
            Some(o) if o != b => return None,
            _ => {}
        }
    }
    body
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hertz_half_width_and_peak() {
        // P = pi E* a^2 / (4 R): with E* = 1, R = 1, P = pi / 4 gives a = 1 and p0 = 1/2.
        let h = HertzLine::new(std::f64::consts::PI / 4.0, 1.0, 1.0);
        assert!((h.a - 1.0).abs() < 1e-15);
        assert!((h.p0 - 0.5).abs() < 1e-15);
        assert_eq!(h.pressure(1.5), 0.0);
        // The pressure integrates to P: p0 pi a / 2.
        let n = 200_000;
        let sum: f64 = (0..n)
            .map(|i| h.pressure(-1.0 + 2.0 * (i as f64 + 0.5) / n as f64) * 2.0 / n as f64)
            .sum();
        assert!((sum - std::f64::consts::PI / 4.0).abs() < 1e-6, "{sum}");
        // Two equal bodies: E* = E / (2 (1 - nu^2)).
        assert!((contact_modulus(2.0, 0.5, 2.0, 0.5) - 1.0 / 0.75).abs() < 1e-15);
    }

    /// A comparison of R = 1, E* = 1, P = pi / 4 (a = 1) with the given nodes and slave nodes.
    fn comparison(
        hertz: HertzLine,
        nodes: Vec<(f64, f64)>,
        slave: Vec<(usize, f64)>,
    ) -> HertzComparison {
        HertzComparison {
            label: String::new(),
            radius: 1.0,
            e_star: 1.0,
            load_per_length: std::f64::consts::PI / 4.0,
            hertz,
            nodes,
            contact_edge: 1.0,
            spacing: 0.2,
            edge_spacing: 0.2,
            peak: hertz.p0,
            rms_error: 0.0,
            slave,
        }
    }

    /// Another code's pressures at the slave nodes: Hertz's own give no error; Hertz's
    /// plus 1% of p0 inside the contact give +1% at the peak and, with the nodes out of
    /// contact (none given: zero pressure) exact, an RMS of 1% times the root of the share
    /// of the window's nodes that are inside (exact arithmetic on these sums: 1e-12).
    #[test]
    fn other_pressures_are_compared_with_the_same_hertz_solution() {
        let hertz = HertzLine::new(std::f64::consts::PI / 4.0, 1.0, 1.0);
        // Nodes at -1.4, -1.2, ..., 1.4 (15, 9 strictly inside |x| < 1), shuffled ids.
        let slave: Vec<(usize, f64)> = (0..15)
            .map(|i| ((i * 7) % 15, -1.4 + 0.2 * i as f64))
            .collect();
        let position = |n: usize| slave.iter().find(|s| s.0 == n).unwrap().1;
        let c = comparison(hertz, Vec::new(), slave.clone());
        let (peak, rms) = c.errors_of(|n| Some(hertz.pressure(position(n)))).unwrap();
        assert!(peak.abs() < 1e-12 && rms < 1e-12, "{peak} {rms}");
        let inside = |x: f64| x.abs() < 1.0 - 1e-9;
        let shifted = |n: usize| {
            let x = position(n);
            inside(x).then(|| hertz.pressure(x) + 0.01 * hertz.p0)
        };
        let (peak, rms) = c.errors_of(shifted).unwrap();
        let share = slave.iter().filter(|s| inside(s.1)).count() as f64 / 15.0;
        assert!((peak - 0.01).abs() < 1e-12, "{peak}");
        assert!((rms - 0.01 * share.sqrt()).abs() < 1e-12, "{rms}");
    }

    /// The centre's statistics: Hertz's pressure plus 0.5% of p0, plus and minus 2% in
    /// turn at the nodes within a / 3 (x = -0.3, -0.2, ..., 0.3: seven nodes, three at +2%),
    /// give a mean of 0.5% - 2% / 7, a deviation of 2% sqrt(1 - 1 / 49) and a largest of
    /// 2.5%; the nodes beyond a / 3 (x = 0.4, with +10%) do not count (exact arithmetic up
    /// to round-off: 1e-12).
    #[test]
    fn the_centre_s_mean_and_scatter_are_those_of_the_nodes_within_a_third_of_a() {
        let hertz = HertzLine::new(std::f64::consts::PI / 4.0, 1.0, 1.0);
        let mut nodes: Vec<(f64, f64)> = (-3..=3)
            .map(|i| {
                let x = 0.1 * f64::from(i);
                let wobble = if i % 2 == 0 { 0.02 } else { -0.02 };
                (x, hertz.pressure(x) + (0.005 + wobble) * hertz.p0)
            })
            .collect();
        nodes.push((0.4, hertz.pressure(0.4) + 0.1 * hertz.p0));
        let c = comparison(hertz, nodes, Vec::new());
        let (n, mean, sd, largest) = c.centre_errors().unwrap();
        assert_eq!(n, 7);
        assert!((mean - (0.005 - 0.02 / 7.0)).abs() < 1e-12, "{mean}");
        assert!(
            (sd - 0.02 * (1.0f64 - 1.0 / 49.0).sqrt()).abs() < 1e-12,
            "{sd}"
        );
        assert!((largest - 0.025).abs() < 1e-12, "{largest}");
    }

    #[test]
    fn circle_fit_is_exact_on_a_circle() {
        let pts: Vec<[f64; 2]> = (0..7)
            .map(|i| {
                let t = std::f64::consts::PI * (1.0 + i as f64 / 6.0);
                [3.0 + 10.0 * t.cos(), 10.0 + 10.0 * t.sin()]
            })
            .collect();
        let (c, r, off) = fit_circle(&pts).unwrap();
        assert!(
            (c[0] - 3.0).abs() < 1e-9 && (c[1] - 10.0).abs() < 1e-9,
            "{c:?}"
        );
        assert!((r - 10.0).abs() < 1e-9 && off < 1e-9);
        assert!(fit_circle(&[[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]).is_none());
    }
}
