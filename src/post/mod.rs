//! `solver post`: tools working on result files (summary, comparison, plots).
//!
//! Embed [`PostCommand`] as a subcommand and call [`run_post`]; its `Ok` value is the process
//! exit code (0, or 1 when `compare` finds a difference beyond the tolerance). An `Err`
//! (missing or bad file, meshes or shapes that cannot be compared, bad arguments) should be
//! printed and end the process with exit code 2.

pub mod balance;
mod compare;
pub mod figures;
pub mod hertz;
mod info;
mod plot;
pub mod verify;

use std::path::PathBuf;

pub use compare::{compare_files, CompareReport, DatasetComparison};
pub use info::info_text;
pub use plot::{
    fonts_available, plot_data, render_plot, Axis, Component, PlotArgs, PlotData, Quantity, Series,
};

use crate::output::OutputError;

/// The `post` subcommands.
#[derive(clap::Subcommand, Debug, Clone, PartialEq)]
pub enum PostCommand {
    /// Summarise a result file: scene, ranks, steps, wall time, exit status and a per-step
    /// table of solver statistics.
    Info {
        /// The result file (.h5).
        file: PathBuf,
    },
    /// Compare two result files dataset by dataset. Exit code 0 when every counted dataset
    /// is within the tolerance, 1 when one is not, 2 when the files cannot be compared
    /// (different meshes or dataset shapes, unreadable file).
    Compare {
        /// The reference result file.
        a: PathBuf,
        /// The result file compared with it.
        b: PathBuf,
        /// Largest allowed relative difference (max |a-b| over max |a| of the dataset);
        /// 0 demands bitwise equality.
        #[arg(long, default_value_t = 0.0)]
        tol: f64,
        /// Compare only the datasets whose path starts with this (repeatable), e.g.
        /// `--only /results/displacement` for two runs whose contact pairs differ.
        #[arg(long)]
        only: Vec<String>,
    },
    /// Plot a nodal quantity along a node set (one line per step), or with --history
    /// through time.
    Plot(PlotArgs),
    /// Check a paper scene's result against the exact answers of the verification tests
    /// (exit code 1 when a check fails).
    Verify {
        /// The result file (.h5) of a paper scene.
        file: PathBuf,
        /// Print the checks as JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
    /// Draw one of the paper's figures (fig2, fig5, fig6, fig_smoothing) from the result
    /// file of its scene.
    Figure(figures::FigureArgs),
    /// Compare the contact pressure under a cylinder (axis z) pressed onto a flat body with
    /// the Hertz line-contact solution: prints the half-width, peak and RMS error, and
    /// plots pressure against position (e.g. run/examples/cylinder_on_block.toml).
    Hertz(hertz::HertzArgs),
    /// Write a result file (.h5) as an Exodus II file (.e) for Exodus tools (exodiff,
    /// ParaView's and VisIt's Exodus readers); `solver run -o NAME.e` does this itself.
    Exodus {
        /// The result file (.h5).
        file: PathBuf,
        /// The Exodus file to write (replaced if it is one already).
        #[arg(short, long)]
        output: PathBuf,
    },
}

/// Runs a `post` subcommand, printing its report to standard output; returns the exit code.
pub fn run_post(cmd: &PostCommand) -> Result<i32, OutputError> {
    match cmd {
        PostCommand::Info { file } => {
            print!("{}", info_text(file)?);
            Ok(0)
        }
        PostCommand::Compare { a, b, tol, only } => {
            let report = compare::compare_files_only(a, b, *tol, only)?;
            print!("{}", report.render());
            Ok(report.exit_code())
        }
        PostCommand::Verify { file, json } => {
            let v = verify::verify_file(file)?;
            if *json {
                println!(
                    "{}",
                    serde_json::to_string_pretty(&v).expect("plain data serialises")
                );
            } else {
                print!("{}", v.render());
            }
            Ok(if v.pass() { 0 } else { 1 })
        }
        PostCommand::Figure(args) => {
            println!("{}", figures::figure_command(args)?);
            Ok(0)
        }
        PostCommand::Exodus { file, output } => {
            let inputs = [(file.as_path(), "the result file")];
            crate::output::exodus::check_exodus_output(output, &inputs)?;
            crate::output::exodus::write_exodus(file, output)?;
            println!("wrote {}", output.display());
            Ok(0)
        }
        PostCommand::Hertz(args) => {
            println!("{}", hertz::hertz_command(args)?);
            Ok(0)
        }
        PostCommand::Plot(args) => {
            let inputs = [(args.file.as_path(), "the result file")];
            crate::output::check_picture_output(&args.output, &inputs)?;
            let data = plot_data(args)?;
            let text = fonts_available();
            if !text {
                eprintln!(
                    "warning: no usable system font (sans-serif); the plot is drawn without \
                     text (install fonts-dejavu-core for labels)"
                );
            }
            crate::output::write_picture(&args.output, &inputs, |tmp| {
                render_plot(&data, tmp, text)
            })?;
            println!(
                "wrote {} ({} line{}, {} points each)",
                args.output.display(),
                data.series.len(),
                if data.series.len() == 1 { "" } else { "s" },
                data.series.first().map_or(0, |s| s.points.len())
            );
            Ok(0)
        }
    }
}
