//! `solver post plot`: a nodal quantity along a node set (one line per step) or through time.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use plotters::prelude::*;

use crate::output::{OutputError, OutputMesh, ResultFile};

/// A nodal result quantity.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    #[value(name = "displacement")]
    Displacement,
    #[value(name = "reaction")]
    Reaction,
    #[value(name = "contact_force", alias = "contact-force")]
    ContactForce,
    #[value(name = "contact_gap", alias = "contact-gap", alias = "gap")]
    ContactGap,
    #[value(name = "contact_status", alias = "contact-status", alias = "status")]
    ContactStatus,
    #[value(
        name = "contact_pressure",
        alias = "contact-pressure",
        alias = "pressure"
    )]
    ContactPressure,
}

impl Quantity {
    fn is_vector(self) -> bool {
        matches!(
            self,
            Quantity::Displacement | Quantity::Reaction | Quantity::ContactForce
        )
    }

    fn name(self) -> &'static str {
        match self {
            Quantity::Displacement => "displacement",
            Quantity::Reaction => "reaction",
            Quantity::ContactForce => "contact force",
            Quantity::ContactGap => "contact gap",
            Quantity::ContactStatus => "contact status",
            Quantity::ContactPressure => "contact pressure",
        }
    }
}

/// A component of a vector quantity.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Component {
    X,
    Y,
    Z,
    /// The Euclidean norm.
    #[value(alias = "mag")]
    Magnitude,
}

impl Component {
    fn of(self, v: [f64; 3]) -> f64 {
        match self {
            Component::X => v[0],
            Component::Y => v[1],
            Component::Z => v[2],
            Component::Magnitude => (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt(),
        }
    }

    fn name(self) -> &'static str {
        match self {
            Component::X => "x",
            Component::Y => "y",
            Component::Z => "z",
            Component::Magnitude => "magnitude",
        }
    }
}

/// The abscissa of a plot along a node set.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    X,
    Y,
    Z,
    /// Arc length along the set (nodes ordered along the set's longest extent).
    S,
}

/// Arguments of `solver post plot`.
#[derive(clap::Args, Debug, Clone, PartialEq)]
pub struct PlotArgs {
    /// The result file (.h5).
    pub file: PathBuf,
    /// The nodal quantity.
    #[arg(long, value_enum)]
    pub quantity: Quantity,
    /// Component of a vector quantity (displacement, reaction, contact_force).
    #[arg(long, value_enum)]
    pub component: Option<Component>,
    /// The node set (as named in the scene).
    #[arg(long)]
    pub node_set: String,
    /// Abscissa for a plot along the node set: an undeformed coordinate, or s, the arc
    /// length along the set with its nodes ordered along the set's longest extent.
    #[arg(long, value_enum, required_unless_present = "history")]
    pub against: Option<Axis>,
    /// Steps drawn along the set, one line each: all, last, or 0-based indices "0,4,9".
    #[arg(long, default_value = "last")]
    pub steps: String,
    /// Plot the quantity at the set's nodes against time instead.
    #[arg(long, conflicts_with_all = ["against", "steps"])]
    pub history: bool,
    /// With --history: one line for the sum over the set's nodes (for magnitude: the
    /// magnitude of the summed vector) instead of one line per node.
    #[arg(long, requires = "history")]
    pub sum: bool,
    /// The image to write (.png).
    #[arg(short = 'o', long)]
    pub output: PathBuf,
}

/// One line of a plot.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
}

/// What a plot shows.
#[derive(Clone, Debug, PartialEq)]
pub struct PlotData {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
}

/// Parses `all`, `last` or a comma-separated list of 0-based step indices.
fn parse_steps(file: &Path, spec: &str, steps: usize) -> Result<Vec<usize>, OutputError> {
    let usage = |message: String| OutputError::Usage {
        file: file.to_path_buf(),
        message,
    };
    if steps == 0 {
        return Err(usage("the file has no steps to plot".into()));
    }
    match spec.trim() {
        "all" => Ok((0..steps).collect()),
        "last" => Ok(vec![steps - 1]),
        list => list
            .split(',')
            .map(|t| {
                let i: usize = t.trim().parse().map_err(|_| {
                    usage(format!(
                        "--steps '{spec}': expected all, last or 0-based step indices like 0,3,7"
                    ))
                })?;
                if i < steps {
                    Ok(i)
                } else {
                    Err(usage(format!(
                        "--steps: step {i} out of range, the file has {steps} steps (0..{})",
                        steps - 1
                    )))
                }
            })
            .collect(),
    }
}

/// The quantity (component) of every node at one step.
fn nodal_values(
    f: &ResultFile,
    q: Quantity,
    c: Option<Component>,
    step: usize,
) -> Result<Vec<f64>, OutputError> {
    Ok(match q {
        Quantity::ContactGap => f.gap(step)?,
        Quantity::ContactStatus => f.contact_status(step)?.into_iter().map(f64::from).collect(),
        Quantity::ContactPressure => {
            f.contact_pressure(step)?
                .ok_or_else(|| OutputError::Usage {
                    file: f.path().to_path_buf(),
                    message: format!(
                "no {} in this file (written before the solver recorded the contact pressure); \
                 plot contact_force, or run the scene again",
                crate::output::layout::CONTACT_PRESSURE
            ),
                })?
        }
        _ => {
            let c = c.unwrap_or(Component::X);
            nodal_vectors(f, q, step)?
                .into_iter()
                .map(|v| c.of(v))
                .collect()
        }
    })
}

fn nodal_vectors(f: &ResultFile, q: Quantity, step: usize) -> Result<Vec<[f64; 3]>, OutputError> {
    match q {
        Quantity::Displacement => f.displacement(step),
        Quantity::Reaction => f.reaction(step),
        _ => f.contact_force(step),
    }
}

/// Reads what a plot shows, without drawing it: checks the request, finds the node set's
/// nodes, then gathers the values through time (`--history`) or along the set.
pub fn plot_data(args: &PlotArgs) -> Result<PlotData, OutputError> {
    let file = args.file.as_path();
    let f = ResultFile::open(file)?;
    check_component(args)?;
    let mesh = f.mesh()?;
    let nodes = set_nodes(args, &f, &mesh)?;
    let y_label = match args.component {
        Some(c) => format!("{} {}", args.quantity.name(), c.name()),
        None => args.quantity.name().to_string(),
    };
    if args.history {
        history_plot(args, &f, &mesh, &nodes, y_label)
    } else {
        along_plot(args, &f, &mesh, &nodes, y_label)
    }
}

fn usage(args: &PlotArgs, message: String) -> OutputError {
    OutputError::Usage {
        file: args.file.clone(),
        message,
    }
}

/// A vector quantity needs a component, a scalar takes none.
fn check_component(args: &PlotArgs) -> Result<(), OutputError> {
    let q = args.quantity;
    if q.is_vector() && args.component.is_none() {
        return Err(usage(
            args,
            format!(
                "--quantity {} needs --component x, y, z or magnitude",
                q.name()
            ),
        ));
    }
    if !q.is_vector() && args.component.is_some() {
        return Err(usage(
            args,
            format!("--quantity {} is a scalar; leave out --component", q.name()),
        ));
    }
    Ok(())
}

/// The mesh indices of the node set's nodes, in the set's order.
fn set_nodes(
    args: &PlotArgs,
    f: &ResultFile,
    mesh: &OutputMesh,
) -> Result<Vec<usize>, OutputError> {
    let Some(ids) = f.node_set(&args.node_set)? else {
        let names = f.node_set_names()?;
        return Err(usage(
            args,
            format!(
                "no node set '{}' (the file has: {})",
                args.node_set,
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            ),
        ));
    };
    if ids.is_empty() {
        return Err(usage(
            args,
            format!("node set '{}' is empty", args.node_set),
        ));
    }
    let index: HashMap<u64, usize> = mesh
        .node_ids
        .iter()
        .enumerate()
        .map(|(i, &id)| (id, i))
        .collect();
    ids.iter()
        .map(|id| {
            index.get(id).copied().ok_or_else(|| {
                usage(
                    args,
                    format!(
                        "node set '{}' names node id {id}, which the mesh lacks",
                        args.node_set
                    ),
                )
            })
        })
        .collect()
}

/// The quantity at the set's nodes through time: one line per node, or their sum.
fn history_plot(
    args: &PlotArgs,
    f: &ResultFile,
    mesh: &OutputMesh,
    nodes: &[usize],
    y_label: String,
) -> Result<PlotData, OutputError> {
    let (q, c) = (args.quantity, args.component);
    let time = f.time()?;
    if time.is_empty() {
        return Err(usage(args, "the file has no steps to plot".into()));
    }
    let mut per_node = vec![Vec::with_capacity(time.len()); nodes.len()];
    let mut sums = Vec::with_capacity(time.len());
    for (step, &t) in time.iter().enumerate() {
        if args.sum && q.is_vector() {
            let v = nodal_vectors(f, q, step)?;
            let mut total = [0.0; 3];
            for &n in nodes {
                for k in 0..3 {
                    total[k] += v[n][k];
                }
            }
            sums.push((t, c.unwrap_or(Component::X).of(total)));
        } else {
            let v = nodal_values(f, q, c, step)?;
            if args.sum {
                sums.push((t, nodes.iter().map(|&n| v[n]).sum()));
            } else {
                for (line, &n) in per_node.iter_mut().zip(nodes) {
                    line.push((t, v[n]));
                }
            }
        }
    }
    let series = if args.sum {
        vec![Series {
            label: format!("sum over '{}'", args.node_set),
            points: sums,
        }]
    } else {
        per_node
            .into_iter()
            .zip(nodes)
            .map(|(points, &n)| Series {
                label: format!("node {}", mesh.node_ids[n]),
                points,
            })
            .collect()
    };
    Ok(PlotData {
        title: format!(
            "{y_label}{} at node set '{}'",
            if args.sum { " (sum)" } else { "" },
            args.node_set
        ),
        x_label: "time".into(),
        y_label,
        series,
    })
}

/// The order of the points along the set and their abscissae: sorted by the chosen
/// coordinate (then the next two), `s` the arc length along the set's longest extent.
fn abscissae(coords: &[[f64; 3]], against: Axis) -> (Vec<usize>, Vec<f64>) {
    let axis = match against {
        Axis::X => 0,
        Axis::Y => 1,
        Axis::Z => 2,
        Axis::S => (0..3)
            .max_by(|&a, &b| {
                let extent = |k: usize| {
                    let (lo, hi) = coords.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| {
                        (lo.min(p[k]), hi.max(p[k]))
                    });
                    hi - lo
                };
                extent(a).total_cmp(&extent(b)).then(b.cmp(&a))
            })
            .unwrap_or(0),
    };
    let mut order: Vec<usize> = (0..coords.len()).collect();
    order.sort_by(|&a, &b| {
        coords[a][axis]
            .total_cmp(&coords[b][axis])
            .then_with(|| coords[a][(axis + 1) % 3].total_cmp(&coords[b][(axis + 1) % 3]))
            .then_with(|| coords[a][(axis + 2) % 3].total_cmp(&coords[b][(axis + 2) % 3]))
    });
    let abscissa: Vec<f64> = if against == Axis::S {
        let mut s = 0.0;
        let mut prev: Option<[f64; 3]> = None;
        order
            .iter()
            .map(|&i| {
                let p = coords[i];
                if let Some(q) = prev {
                    s += ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2))
                        .sqrt();
                }
                prev = Some(p);
                s
            })
            .collect()
    } else {
        order.iter().map(|&i| coords[i][axis]).collect()
    };
    (order, abscissa)
}

/// The quantity along the set, one line per chosen step.
fn along_plot(
    args: &PlotArgs,
    f: &ResultFile,
    mesh: &OutputMesh,
    nodes: &[usize],
    y_label: String,
) -> Result<PlotData, OutputError> {
    let against = args.against.ok_or_else(|| {
        usage(
            args,
            "--against x|y|z|s is needed unless --history is given".into(),
        )
    })?;
    let steps = parse_steps(&args.file, &args.steps, f.num_steps())?;
    let coords: Vec<[f64; 3]> = nodes.iter().map(|&n| mesh.coordinates[n]).collect();
    let (order, abscissa) = abscissae(&coords, against);
    let time = f.time()?;
    let mut series = Vec::new();
    for step in steps {
        let v = nodal_values(f, args.quantity, args.component, step)?;
        series.push(Series {
            label: format!("step {step}, t = {}", number(time[step])),
            points: order
                .iter()
                .zip(&abscissa)
                .map(|(&i, &x)| (x, v[nodes[i]]))
                .collect(),
        });
    }
    let x_label = match against {
        Axis::X => "x",
        Axis::Y => "y",
        Axis::Z => "z",
        Axis::S => "arc length s",
    };
    Ok(PlotData {
        title: format!("{y_label} along node set '{}'", args.node_set),
        x_label: x_label.into(),
        y_label,
        series,
    })
}

/// A short label for a number: plain for moderate magnitudes, scientific otherwise.
pub(crate) fn number(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if (1e-3..1e5).contains(&a) {
        let s = format!("{v:.6}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" {
            "0".into()
        } else {
            s.into()
        }
    } else {
        format!("{v:.3e}")
    }
}

/// Whether a sans-serif system font can be loaded (plotters' `ttf` feature, via fontconfig).
pub fn fonts_available() -> bool {
    ("sans-serif", 16.0).into_font().box_size("Ag0.").is_ok()
}

/// A range covering `values` with a little room, never empty.
pub(crate) fn padded_range(values: impl Iterator<Item = f64>, pad: f64) -> std::ops::Range<f64> {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    if !lo.is_finite() || !hi.is_finite() {
        return 0.0..1.0;
    }
    let span = hi - lo;
    if span <= f64::EPSILON * hi.abs().max(lo.abs()) || span == 0.0 {
        let d = if hi == 0.0 { 1.0 } else { 0.05 * hi.abs() };
        return lo - d..hi + d;
    }
    lo - pad * span..hi + pad * span
}

/// Draws a plot into a bitmap file (format from the extension, e.g. `.png`). With
/// `text == false` nothing needing a font is drawn: no title, tick labels or legend.
pub fn render_plot(data: &PlotData, output: &Path, text: bool) -> Result<(), OutputError> {
    let err = |e: &dyn std::fmt::Display| OutputError::Plot {
        file: output.to_path_buf(),
        message: e.to_string(),
    };
    let xr = padded_range(
        data.series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.0)),
        0.0,
    );
    let yr = padded_range(
        data.series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.1)),
        0.05,
    );
    let root = BitMapBackend::new(output, (1024, 768)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut builder = ChartBuilder::on(&root);
    builder.margin(24);
    if text {
        builder
            .caption(&data.title, ("sans-serif", 24))
            .x_label_area_size(50)
            .y_label_area_size(90);
    }
    let mut chart = builder
        .build_cartesian_2d(xr.clone(), yr.clone())
        .map_err(|e| err(&e))?;
    draw_plot_axes(&mut chart, data, &xr, &yr, text).map_err(|e| err(&e))?;
    draw_plot_series(&mut chart, data, text).map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

/// The chart of a plot: x and y in f64.
type PlotChart<'b, 'a> = ChartContext<
    'b,
    BitMapBackend<'a>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;
/// What drawing into a bitmap can fail with.
type PlotResult<'a> =
    Result<(), DrawingAreaErrorKind<<BitMapBackend<'a> as DrawingBackend>::ErrorType>>;

/// The plot's axes: the mesh with ticks and labels, or without text a frame and a grid.
fn draw_plot_axes<'b, 'a: 'b>(
    chart: &mut PlotChart<'b, 'a>,
    data: &PlotData,
    xr: &std::ops::Range<f64>,
    yr: &std::ops::Range<f64>,
    text: bool,
) -> PlotResult<'a> {
    if text {
        chart
            .configure_mesh()
            .x_desc(data.x_label.as_str())
            .y_desc(data.y_label.as_str())
            .x_label_formatter(&|v| number(*v))
            .y_label_formatter(&|v| number(*v))
            .draw()?;
    } else {
        // Frame and a 10 x 10 grid, drawn by hand: the mesh drawing would need a font.
        let grey = RGBColor(220, 220, 220);
        for k in 0..=10 {
            let x = xr.start + (xr.end - xr.start) * f64::from(k) / 10.0;
            let y = yr.start + (yr.end - yr.start) * f64::from(k) / 10.0;
            let style = if k == 0 || k == 10 { BLACK } else { grey };
            chart.draw_series(std::iter::once(PathElement::new(
                vec![(x, yr.start), (x, yr.end)],
                style,
            )))?;
            chart.draw_series(std::iter::once(PathElement::new(
                vec![(xr.start, y), (xr.end, y)],
                style,
            )))?;
        }
    }
    Ok(())
}

/// Draws every series (points too when there are few) and, with text, the legend.
fn draw_plot_series<'b, 'a: 'b>(
    chart: &mut PlotChart<'b, 'a>,
    data: &PlotData,
    text: bool,
) -> PlotResult<'a> {
    let legend = text && data.series.len() <= 12;
    for (i, s) in data.series.iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        let style = ShapeStyle::from(color).stroke_width(2);
        if s.points.len() <= 64 {
            chart.draw_series(
                s.points
                    .iter()
                    .map(|&p| Circle::new(p, 3, ShapeStyle::from(color).filled())),
            )?;
        }
        let anno = chart.draw_series(LineSeries::new(s.points.iter().copied(), style))?;
        if legend {
            anno.label(s.label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
        }
    }
    if legend {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 16))
            .draw()?;
    }
    Ok(())
}
