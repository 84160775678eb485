//! `solver post figure`: the paper's figures, redrawn from result files of the paper scenes
//! (scenes.md beside the paper fixes what each one shows).
//!
//! - `fig2`: U_x along the slave interface against s = x / cos(20 deg), last step
//!   (bc_interaction_frictionless, node set `interface`);
//! - `fig5`: the prescribed y-displacement of the top nodes (`upper_top`) and the total
//!   contact force on the slave nodes (`upper_bottom`, sum of y) through time
//!   (capture_release), with the springs-in-series answer;
//! - `fig6`: the cross-section average of u_x along the bar (body `bar`) at t = 1.25, 1.5,
//!   1.75, 2 (loading) and 2, 2.5, 3 (unloading) against the 1-D theory (stick_slip);
//! - `fig_smoothing`: u_x and u_y of the interface nodes against x, last step
//!   (normal_smoothing), with the master surface's u_y.
//!
//! Same look as `solver post plot` (white 1024-pixel-wide bitmap, sans-serif text, palette).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::plot::{fonts_available, number, padded_range};
use crate::output::{check_picture_output, write_picture, OutputError, OutputMesh, ResultFile};

/// The figures `solver post figure` draws.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum FigureName {
    /// Paper Figure 2: U_x along the slave interface against s (bc_interaction_frictionless).
    #[value(name = "fig2")]
    Fig2,
    /// Paper Figure 5: prescribed displacement and total contact force through time
    /// (capture_release).
    #[value(name = "fig5")]
    Fig5,
    /// Paper Figure 6: cross-section average of u_x along the bar against the 1-D theory
    /// (stick_slip).
    #[value(name = "fig6")]
    Fig6,
    /// u_x and u_y of the interface nodes against x (normal_smoothing).
    #[value(name = "fig_smoothing", alias = "fig-smoothing")]
    FigSmoothing,
}

/// Arguments of `solver post figure`.
#[derive(clap::Args, Debug, Clone, PartialEq)]
pub struct FigureArgs {
    /// Which figure.
    #[arg(value_enum)]
    pub name: FigureName,
    /// The result file (.h5) of the figure's scene.
    pub file: PathBuf,
    /// The image to write (.png).
    #[arg(short = 'o', long)]
    pub output: PathBuf,
}

/// How a curve is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mark {
    Line,
    Dashed,
    Points,
    LinePoints,
}

/// One curve of a panel.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    /// Legend entry; `None` for none.
    pub label: Option<String>,
    /// Palette index (curves sharing a colour belong together).
    pub color: usize,
    pub mark: Mark,
    /// What the legend glyph shows.
    pub legend: Mark,
    pub points: Vec<(f64, f64)>,
}

impl Curve {
    fn new(label: Option<String>, color: usize, mark: Mark, points: Vec<(f64, f64)>) -> Self {
        Curve {
            label,
            color,
            mark,
            legend: mark,
            points,
        }
    }
}

/// Where a panel's legend goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LegendAt {
    UpperLeft,
    UpperMiddle,
    UpperRight,
    LowerLeft,
    LowerRight,
}

/// One chart of a figure.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub curves: Vec<Curve>,
    pub legend: LegendAt,
}

/// A figure: panels stacked from top to bottom under one title.
#[derive(Clone, Debug, PartialEq)]
pub struct Figure {
    pub title: String,
    pub panels: Vec<Panel>,
}

/// Runs `solver post figure`: reads, draws, and returns a one-line summary.
pub fn figure_command(args: &FigureArgs) -> Result<String, OutputError> {
    let inputs = [(args.file.as_path(), "the result file")];
    check_picture_output(&args.output, &inputs)?;
    let f = ResultFile::open(&args.file)?;
    let fig = figure_data(args.name, &f)?;
    let text = fonts_available();
    if !text {
        eprintln!(
            "warning: no usable system font (sans-serif); the figure is drawn without text \
             (install fonts-dejavu-core for labels)"
        );
    }
    write_picture(&args.output, &inputs, |tmp| render_figure(&fig, tmp, text))?;
    let curves: usize = fig.panels.iter().map(|p| p.curves.len()).sum();
    Ok(format!(
        "wrote {}: {} ({} panel{}, {} curve{})",
        args.output.display(),
        fig.title,
        fig.panels.len(),
        if fig.panels.len() == 1 { "" } else { "s" },
        curves,
        if curves == 1 { "" } else { "s" }
    ))
}

/// What a figure shows, read from a result file.
pub fn figure_data(name: FigureName, f: &ResultFile) -> Result<Figure, OutputError> {
    match name {
        FigureName::Fig2 => fig2(f),
        FigureName::Fig5 => fig5(f),
        FigureName::Fig6 => fig6(f),
        FigureName::FigSmoothing => fig_smoothing(f),
    }
}

fn usage(f: &ResultFile, message: String) -> OutputError {
    OutputError::Usage {
        file: f.path().to_path_buf(),
        message,
    }
}

/// 0-based node indices of a node set.
fn set_nodes(f: &ResultFile, mesh: &OutputMesh, name: &str) -> Result<Vec<usize>, OutputError> {
    let ids = f.node_set(name)?.ok_or_else(|| {
        usage(
            f,
            format!("this figure needs the node set '{name}', which the file lacks"),
        )
    })?;
    let index: HashMap<u64, usize> = mesh
        .node_ids
        .iter()
        .enumerate()
        .map(|(i, &id)| (id, i))
        .collect();
    let nodes: Vec<usize> = ids
        .iter()
        .map(|id| {
            index.get(id).copied().ok_or_else(|| {
                usage(
                    f,
                    format!("node set '{name}' names node id {id}, which the mesh lacks"),
                )
            })
        })
        .collect::<Result<_, _>>()?;
    if nodes.is_empty() {
        return Err(usage(f, format!("node set '{name}' is empty")));
    }
    Ok(nodes)
}

/// 0-based node indices of a body, sorted.
pub(crate) fn body_nodes(mesh: &OutputMesh, body: &str) -> Vec<usize> {
    let mut nodes: Vec<usize> = mesh
        .bodies
        .iter()
        .filter(|b| b.name == body)
        .flat_map(|b| b.connectivity.iter().flatten().map(|&n| n as usize))
        .collect();
    nodes.sort_unstable();
    nodes.dedup();
    nodes
}

/// Coordinates closer than this (1e-9 of the mesh's size) are the same.
fn tolerance(mesh: &OutputMesh) -> f64 {
    let (lo, hi) = mesh.coordinates.iter().fold(
        ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
        |(mut lo, mut hi), p| {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
            (lo, hi)
        },
    );
    let diag = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    1e-9 * diag.max(f64::MIN_POSITIVE)
}

/// Splits `nodes` into runs sharing coordinate `axis` (within `tol`), in increasing order.
fn groups(c: &[[f64; 3]], nodes: &[usize], axis: usize, tol: f64) -> Vec<(f64, Vec<usize>)> {
    let mut sorted = nodes.to_vec();
    sorted.sort_by(|&a, &b| c[a][axis].total_cmp(&c[b][axis]));
    let mut out: Vec<(f64, Vec<usize>)> = Vec::new();
    for n in sorted {
        match out.last_mut() {
            Some((x, members)) if (c[n][axis] - *x).abs() <= tol => members.push(n),
            _ => out.push((c[n][axis], vec![n])),
        }
    }
    out
}

/// (x, mean of `value` over the nodes at that x), increasing x.
fn mean_by_x(mesh: &OutputMesh, nodes: &[usize], value: impl Fn(usize) -> f64) -> Vec<(f64, f64)> {
    groups(&mesh.coordinates, nodes, 0, tolerance(mesh))
        .into_iter()
        .map(|(x, g)| (x, g.iter().map(|&n| value(n)).sum::<f64>() / g.len() as f64))
        .collect()
}

/// (x, cross-section average of u_x at x): mean over z at each y, trapezoidal in y.
pub(crate) fn section_average(
    mesh: &OutputMesh,
    nodes: &[usize],
    u: &[[f64; 3]],
) -> Vec<(f64, f64)> {
    let c = &mesh.coordinates;
    let tol = tolerance(mesh);
    groups(c, nodes, 0, tol)
        .into_iter()
        .map(|(x, at_x)| {
            let rows: Vec<(f64, f64)> = groups(c, &at_x, 1, tol)
                .into_iter()
                .map(|(y, g)| (y, g.iter().map(|&n| u[n][0]).sum::<f64>() / g.len() as f64))
                .collect();
            let height = rows[rows.len() - 1].0 - rows[0].0;
            let mean = if rows.len() < 2 || height <= 0.0 {
                rows.iter().map(|r| r.1).sum::<f64>() / rows.len() as f64
            } else {
                rows.windows(2)
                    .map(|w| 0.5 * (w[0].1 + w[1].1) * (w[1].0 - w[0].0))
                    .sum::<f64>()
                    / height
            };
            (x, mean)
        })
        .collect()
}

/// The stored step at time `t`, if any.
fn step_at(times: &[f64], t: f64) -> Option<usize> {
    times
        .iter()
        .position(|&x| (x - t).abs() <= 1e-9 * t.abs().max(1.0))
}

fn last_step(f: &ResultFile) -> Result<(usize, f64), OutputError> {
    let times = f.time()?;
    match times.last() {
        Some(&t) => Ok((times.len() - 1, t)),
        None => Err(usage(f, "the file has no steps to draw".into())),
    }
}

/// Paper Figure 2: U_x along the slave interface against s = x / cos(20 deg).
fn fig2(f: &ResultFile) -> Result<Figure, OutputError> {
    let mesh = f.mesh()?;
    let nodes = set_nodes(f, &mesh, "interface")?;
    let (k, t) = last_step(f)?;
    let u = f.displacement(k)?;
    let cos = 20f64.to_radians().cos();
    let points: Vec<(f64, f64)> = mean_by_x(&mesh, &nodes, |n| u[n][0])
        .into_iter()
        .map(|(x, v)| (x / cos, v))
        .collect();
    Ok(Figure {
        title: "Figure 2: contact / boundary-condition interaction, frictionless".into(),
        panels: vec![Panel {
            title: format!("U_x of the slave interface nodes at t = {}", number(t)),
            x_label: "s = x / cos(20 deg), distance from x = 0 along the incline".into(),
            y_label: "U_x".into(),
            curves: vec![Curve::new(
                Some("computed (mean over z); U_x(0) = 0 is the Dirichlet condition".into()),
                0,
                Mark::LinePoints,
                points,
            )],
            legend: LegendAt::UpperRight,
        }],
    })
}

/// Paper Figure 5: prescribed displacement and total contact force through time.
fn fig5(f: &ResultFile) -> Result<Figure, OutputError> {
    let mesh = f.mesh()?;
    let top = set_nodes(f, &mesh, "upper_top")?;
    let slaves = set_nodes(f, &mesh, "upper_bottom")?;
    let times = f.time()?;
    if times.is_empty() {
        return Err(usage(f, "the file has no steps to draw".into()));
    }
    // Springs in series: each unit cube has stiffness E (unit area and length), the pair E/2.
    let e = 10.0e6;
    let mut prescribed = Vec::with_capacity(times.len());
    let mut force = Vec::with_capacity(times.len());
    let mut exact = Vec::with_capacity(times.len());
    for (k, &t) in times.iter().enumerate() {
        let u = f.displacement(k)?;
        let fc = f.contact_force(k)?;
        let uy = top.iter().map(|&n| u[n][1]).sum::<f64>() / top.len() as f64;
        prescribed.push((t, uy));
        force.push((t, slaves.iter().map(|&n| fc[n][1]).sum::<f64>()));
        exact.push((t, 0.5 * e * (-uy).max(0.0)));
    }
    Ok(Figure {
        title: "Figure 5: capture and release".into(),
        panels: vec![
            Panel {
                title: "prescribed y-displacement of the top nodes (node set upper_top)".into(),
                x_label: "time t".into(),
                y_label: "u_y".into(),
                curves: vec![Curve::new(
                    Some("u_y of nodes 13-16".into()),
                    0,
                    Mark::LinePoints,
                    prescribed,
                )],
                legend: LegendAt::UpperLeft,
            },
            Panel {
                title: "total contact force on the slave nodes (sum of f_y over upper_bottom)"
                    .into(),
                x_label: "time t".into(),
                y_label: "contact force, y".into(),
                curves: vec![
                    Curve::new(
                        Some("exact: springs in series, (E/2) max(0, -u_y), E = 1e7".into()),
                        1,
                        Mark::Line,
                        exact,
                    ),
                    Curve::new(Some("computed".into()), 0, Mark::Points, force),
                ],
                legend: LegendAt::UpperMiddle,
            },
        ],
    })
}

/// The 1-D theory of the stick/slip bar at time t (scenes.md, paper 4.4).
pub(crate) fn stick_slip_exact(t: f64, x: f64) -> f64 {
    let (mu, delta, h, e, pmax) = (0.5, 1.0e-4, 0.1, 10.0e6, 5.0e4);
    let sq = |a: f64| if a > 0.0 { a * a } else { 0.0 };
    if t <= 1.0 {
        return 0.0;
    }
    let p = pmax * (t.min(2.0) - 1.0);
    let l = p * h * h / (2.0 * mu * delta * e);
    let loaded = sq(l - x);
    if t <= 2.0 {
        return mu * delta * loaded / (h * h);
    }
    let dp = pmax * (t.min(3.0) - 2.0);
    let lp = dp * h * h / (4.0 * mu * delta * e);
    mu * delta * (loaded - 2.0 * sq(lp - x)) / (h * h)
}

/// Paper Figure 6: the stick/slip bar, 3-D cross-section averages against the 1-D theory,
/// and their difference.
fn fig6(f: &ResultFile) -> Result<Figure, OutputError> {
    // The times drawn; a time's colour is its position here.
    const TIMES: [f64; 6] = [1.25, 1.5, 1.75, 2.0, 2.5, 3.0];
    let (mu, delta, h, e, pmax) = (0.5, 1.0e-4, 0.1, 10.0e6, 5.0e4);
    let l_max = pmax * h * h / (2.0 * mu * delta * e);
    let u_max = mu * delta * l_max * l_max / (h * h);
    let mesh = f.mesh()?;
    let bar = body_nodes(&mesh, "bar");
    if bar.is_empty() {
        return Err(usage(f, "this figure needs the body 'bar'".into()));
    }
    let times = f.time()?;
    let x0 = bar
        .iter()
        .map(|&n| mesh.coordinates[n][0])
        .fold(f64::INFINITY, f64::min);
    let x1 = bar
        .iter()
        .map(|&n| mesh.coordinates[n][0])
        .fold(f64::NEG_INFINITY, f64::max);
    // Beyond the largest slip zone the bar sticks (u_x = 0): show a little of it only.
    let x_end = x1.min(x0 + 1.3 * l_max);
    let shown = |pts: Vec<(f64, f64)>| -> Vec<(f64, f64)> {
        pts.into_iter()
            .filter(|p| p.0 <= x_end + 1e-9 * (x1 - x0))
            .collect()
    };
    let mut averages = Vec::new();
    for (i, &t) in TIMES.iter().enumerate() {
        if let Some(k) = step_at(&times, t) {
            let u = f.displacement(k)?;
            averages.push((i, t, shown(section_average(&mesh, &bar, &u))));
        }
    }
    if averages.is_empty() {
        return Err(usage(
            f,
            format!(
                "no step at t = {} (the stick/slip scene's times)",
                TIMES.map(number).join(", ")
            ),
        ));
    }
    let mut panels = fig6_theory_panels(&averages, x0, x_end);
    panels.push(fig6_difference_panel(&averages, u_max));
    Ok(Figure {
        title: "Figure 6: stick/slip bar; points: 3-D solution, lines: 1-D theory".into(),
        panels,
    })
}

/// Figure 6's averages: (the time's index, the time, the points).
type Fig6Averages = [(usize, f64, Vec<(f64, f64)>)];

/// The x axis of Figure 6's panels.
const FIG6_X: &str = "x, distance from the loaded end (the paper plots against s = L - x)";

/// Figure 6's loading and unloading panels: the averages (time's index, time, points)
/// against the 1-D theory drawn from `x0` to `x_end`.
fn fig6_theory_panels(averages: &Fig6Averages, x0: f64, x_end: f64) -> Vec<Panel> {
    let (x_label, y_label) = (FIG6_X, "cross-section average of u_x");
    let mut panels = Vec::new();
    for (title, range) in [
        (
            "loading: p = p_max (t - 1), slip zone x < L = p h^2 / (2 mu delta E)",
            1.0..=2.0,
        ),
        (
            "unloading: dp = p_max (t - 2), reverse slip for x < L' = dp h^2 / (4 mu delta E)",
            2.0..=3.0,
        ),
    ] {
        let mut curves = Vec::new();
        for (i, t, avg) in averages.iter().filter(|a| range.contains(&a.1)) {
            let exact: Vec<(f64, f64)> = (0..=400)
                .map(|j| {
                    let x = x0 + (x_end - x0) * f64::from(j) / 400.0;
                    (x, stick_slip_exact(*t, x))
                })
                .collect();
            curves.push(Curve::new(None, *i, Mark::Line, exact));
            let mut computed = Curve::new(
                Some(format!("t = {}", number(*t))),
                *i,
                Mark::Points,
                avg.clone(),
            );
            computed.legend = Mark::LinePoints;
            curves.push(computed);
        }
        if !curves.is_empty() {
            panels.push(Panel {
                title: title.into(),
                x_label: x_label.into(),
                y_label: y_label.into(),
                curves,
                legend: LegendAt::UpperRight,
            });
        }
    }
    panels
}

/// Figure 6's last panel: the averages minus the 1-D theory, over u_max.
fn fig6_difference_panel(averages: &Fig6Averages, u_max: f64) -> Panel {
    let x_label = FIG6_X;
    Panel {
        title: format!(
            "3-D average minus 1-D theory, over u_max = mu delta L^2 / h^2 = {}",
            number(u_max)
        ),
        x_label: x_label.into(),
        y_label: "(average u_x - theory) / u_max".into(),
        curves: averages
            .iter()
            .map(|(i, t, avg)| {
                Curve::new(
                    Some(format!("t = {}", number(*t))),
                    *i,
                    Mark::LinePoints,
                    avg.iter()
                        .map(|&(x, v)| (x, (v - stick_slip_exact(*t, x)) / u_max))
                        .collect(),
                )
            })
            .collect(),
        legend: LegendAt::UpperRight,
    }
}

/// u_x and u_y of the normal smoothing interface against x.
fn fig_smoothing(f: &ResultFile) -> Result<Figure, OutputError> {
    let mesh = f.mesh()?;
    let slaves = set_nodes(f, &mesh, "interface")?;
    let (k, t) = last_step(f)?;
    let u = f.displacement(k)?;
    let tol = tolerance(&mesh);
    // The master surface: the lower body's top nodes (its largest y).
    let lower = body_nodes(&mesh, "lower");
    let top_y = lower
        .iter()
        .map(|&n| mesh.coordinates[n][1])
        .fold(f64::NEG_INFINITY, f64::max);
    let master: Vec<usize> = lower
        .into_iter()
        .filter(|&n| (mesh.coordinates[n][1] - top_y).abs() <= tol)
        .collect();
    let mut panels = Vec::new();
    for (c, name) in [(0, "u_x"), (1, "u_y")] {
        let mut curves = vec![Curve::new(
            Some(format!(
                "{name}, slave nodes (upper body bottom, node set interface)"
            )),
            0,
            Mark::LinePoints,
            mean_by_x(&mesh, &slaves, |n| u[n][c]),
        )];
        if !master.is_empty() {
            curves.push(Curve::new(
                Some(format!("{name}, master nodes (lower body top)")),
                1,
                Mark::LinePoints,
                mean_by_x(&mesh, &master, |n| u[n][c]),
            ));
        }
        panels.push(Panel {
            title: format!("{name} along the interface at t = {}", number(t)),
            x_label: "x".into(),
            y_label: name.into(),
            curves,
            legend: if c == 0 {
                LegendAt::UpperLeft
            } else {
                LegendAt::UpperMiddle
            },
        });
    }
    Ok(Figure {
        title: "Normal smoothing: the interface (mean over z); nodes at x = 1 move only in y"
            .into(),
        panels,
    })
}

/// The palette of `solver post plot` without its yellow, which is hard to see on white.
fn color(i: usize) -> RGBAColor {
    const ORDER: [usize; 8] = [0, 3, 1, 4, 5, 6, 7, 9];
    Palette99::pick(ORDER[i % ORDER.len()]).to_rgba()
}

/// Draws a figure into a bitmap file (format from the extension, e.g. `.png`). With
/// `text == false` nothing needing a font is drawn.
pub fn render_figure(fig: &Figure, output: &Path, text: bool) -> Result<(), OutputError> {
    let err = |e: &dyn std::fmt::Display| OutputError::Plot {
        file: output.to_path_buf(),
        message: e.to_string(),
    };
    let n = fig.panels.len().max(1);
    let height = if n == 1 { 768 } else { 60 + 520 * n as u32 };
    let root = BitMapBackend::new(output, (1024, height)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let area = if text {
        root.titled(&fig.title, ("sans-serif", 26))
            .map_err(|e| err(&e))?
    } else {
        root.clone()
    };
    for (panel, area) in fig.panels.iter().zip(area.split_evenly((n, 1))) {
        draw_panel(panel, &area, text).map_err(|e| err(&e))?;
    }
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;
type DrawResult<'a> =
    Result<(), DrawingAreaErrorKind<<BitMapBackend<'a> as DrawingBackend>::ErrorType>>;

/// The chart of one panel: x and y in f64.
type Chart<'b, 'a> = ChartContext<
    'b,
    BitMapBackend<'a>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// Draws one panel of a figure into its area: axes, curves and legend.
fn draw_panel<'a>(panel: &Panel, area: &Area<'a>, text: bool) -> DrawResult<'a> {
    let all = || panel.curves.iter().flat_map(|c| c.points.iter());
    let xr = padded_range(all().map(|p| p.0), 0.02);
    let yr = padded_range(all().map(|p| p.1), 0.08);
    let mut builder = ChartBuilder::on(area);
    builder.margin(20);
    if text {
        builder
            .caption(&panel.title, ("sans-serif", 20))
            .x_label_area_size(50)
            .y_label_area_size(90);
    }
    let mut chart = builder.build_cartesian_2d(xr.clone(), yr.clone())?;
    draw_panel_axes(&mut chart, panel, &xr, &yr, text)?;
    if draw_curves(&mut chart, panel, text)? {
        draw_panel_legend(&mut chart, panel.legend)?;
    }
    Ok(())
}

/// The panel's axes: the mesh with ticks and labels, or without text only a frame.
fn draw_panel_axes<'b, 'a: 'b>(
    chart: &mut Chart<'b, 'a>,
    panel: &Panel,
    xr: &std::ops::Range<f64>,
    yr: &std::ops::Range<f64>,
    text: bool,
) -> DrawResult<'a> {
    if text {
        // A tick at rounding noise around zero reads 0.
        let (xs, ys) = (xr.end - xr.start, yr.end - yr.start);
        let x_fmt = move |v: &f64| number(if v.abs() < 1e-9 * xs { 0.0 } else { *v });
        let y_fmt = move |v: &f64| number(if v.abs() < 1e-9 * ys { 0.0 } else { *v });
        chart
            .configure_mesh()
            .x_desc(panel.x_label.as_str())
            .y_desc(panel.y_label.as_str())
            .x_label_formatter(&x_fmt)
            .y_label_formatter(&y_fmt)
            .draw()?;
    } else {
        chart.draw_series(std::iter::once(Rectangle::new(
            [(xr.start, yr.start), (xr.end, yr.end)],
            BLACK,
        )))?;
    }
    Ok(())
}

/// Draws every curve of the panel with its legend entry; returns whether any has one.
fn draw_curves<'b, 'a: 'b>(
    chart: &mut Chart<'b, 'a>,
    panel: &Panel,
    text: bool,
) -> Result<bool, DrawingAreaErrorKind<<BitMapBackend<'a> as DrawingBackend>::ErrorType>> {
    let mut legend = false;
    for c in &panel.curves {
        let color = color(c.color);
        let line = ShapeStyle::from(color).stroke_width(2);
        let dot = ShapeStyle::from(color).filled();
        let pts = c.points.iter().copied();
        let anno = match c.mark {
            Mark::Line => chart.draw_series(LineSeries::new(pts, line))?,
            Mark::Dashed => chart.draw_series(DashedLineSeries::new(pts, 10, 6, line))?,
            Mark::Points => chart.draw_series(pts.map(|p| Circle::new(p, 4, dot)))?,
            Mark::LinePoints => {
                chart.draw_series(pts.clone().map(|p| Circle::new(p, 3, dot)))?;
                chart.draw_series(LineSeries::new(pts, line))?
            }
        };
        if let (true, Some(label)) = (text, &c.label) {
            legend = true;
            let glyph = c.legend;
            let show_line = glyph != Mark::Points;
            let show_dot = matches!(glyph, Mark::Points | Mark::LinePoints);
            let glyph_line = if show_line {
                line
            } else {
                ShapeStyle::from(TRANSPARENT)
            };
            let glyph_dot = if show_dot {
                dot
            } else {
                ShapeStyle::from(TRANSPARENT)
            };
            anno.label(label.as_str()).legend(move |(x, y)| {
                EmptyElement::at((x, y))
                    + PathElement::new(vec![(0, 0), (20, 0)], glyph_line)
                    + Circle::new((10, 0), 4, glyph_dot)
            });
        }
    }
    Ok(legend)
}

/// The legend box, where the panel asks for it.
fn draw_panel_legend<'b, 'a: 'b>(chart: &mut Chart<'b, 'a>, at: LegendAt) -> DrawResult<'a> {
    let position = match at {
        LegendAt::UpperLeft => SeriesLabelPosition::UpperLeft,
        LegendAt::UpperMiddle => SeriesLabelPosition::UpperMiddle,
        LegendAt::UpperRight => SeriesLabelPosition::UpperRight,
        LegendAt::LowerLeft => SeriesLabelPosition::LowerLeft,
        LegendAt::LowerRight => SeriesLabelPosition::LowerRight,
    };
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 16))
        .draw()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stick_slip_theory() {
        // u_max = mu delta L^2 / h^2 = 1.25e-3 at full load, half of it after unloading.
        assert!((stick_slip_exact(2.0, 0.0) - 1.25e-3).abs() < 1e-15);
        assert!((stick_slip_exact(3.0, 0.0) - 0.625e-3).abs() < 1e-15);
        assert_eq!(stick_slip_exact(1.5, 0.3), 0.0);
        // Beyond L' the unloading leaves the loaded profile.
        assert_eq!(stick_slip_exact(2.5, 0.3), stick_slip_exact(2.0, 0.3));
    }

    #[test]
    fn renders_with_and_without_text() {
        let fig = Figure {
            title: "test".into(),
            panels: vec![Panel {
                title: "panel".into(),
                x_label: "x".into(),
                y_label: "y".into(),
                curves: vec![
                    Curve::new(
                        Some("a".into()),
                        0,
                        Mark::Dashed,
                        vec![(0.0, 0.0), (1.0, 1.0)],
                    ),
                    Curve::new(None, 1, Mark::Points, vec![(0.5, 0.4)]),
                ],
                legend: LegendAt::LowerRight,
            }],
        };
        let dir = std::env::temp_dir();
        for text in [false, fonts_available()] {
            let out = dir.join(format!(
                "solver-figure-test-{}-{text}.png",
                std::process::id()
            ));
            render_figure(&fig, &out, text).expect("renders");
            assert!(std::fs::metadata(&out).expect("written").len() > 0);
            let _ = std::fs::remove_file(&out);
        }
    }
}
