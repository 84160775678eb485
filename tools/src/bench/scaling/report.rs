//! `--scaling`'s report: report.md, results.json and scaling.png.

use super::measured::{Scaling, RUNTIME_RANKS, RUNTIME_SCENE};
use super::model::{Iteration, BANDWIDTH, LATENCY_S};
use crate::machine::load_average;
use plotters::prelude::*;
use std::fmt::Write;
use std::path::Path;

/// Rank counts of the prediction: powers of two to 1024.
fn predicted_ranks() -> Vec<f64> {
    (0..=10).map(|k| f64::from(1u32 << k)).collect()
}

pub fn write(dir: &Path, s: &Scaling) -> Result<(), String> {
    let put = |name: &str, text: String| {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))
    };
    put("report.md", markdown(s))?;
    put("results.json", json(s))?;
    if let Some(it) = &s.iteration {
        plot(&dir.join("scaling.png"), it)?;
    }
    Ok(())
}

pub fn markdown(s: &Scaling) -> String {
    let mut w = String::from("## Scaling: memory per rank and a model to 1024 ranks\n\n");
    let _ = writeln!(
        w,
        "The block on block at n = 40 (128000 elements), multilevel, on 1 to 16 ranks of this \
         machine (oversubscribed beyond its cores: the times beyond 2 ranks are not speed); \
         load average {}.\n",
        load_average().unwrap_or_else(|| "unknown".into())
    );
    let _ = writeln!(
        w,
        "| ranks | peak MiB per rank | CG iterations | wall (s) | ms / CG it. | messages / CG it. | bytes / CG it. | collectives / CG it. | received in collectives / CG it. |"
    );
    let _ = writeln!(w, "|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for p in &s.points {
        let dash = || "-".to_string();
        let (m, b, c, r) = p.sent.map_or((dash(), dash(), dash(), dash()), |x| {
            (
                format!("{:.2}", x.messages),
                format!("{:.0}", x.bytes),
                format!("{:.2}", x.collectives),
                format!("{:.0}", x.received),
            )
        });
        let _ = writeln!(
            w,
            "| {} | {:.1} | {} | {:.2} | {:.1} | {m} | {b} | {c} | {r} |",
            p.ranks(),
            p.peak_mib(),
            p.case.cg_iterations(),
            p.case.runs.wall.median,
            1e3 * p.seconds_per_iteration()
        );
    }
    let _ = writeln!(w);
    match (s.fit, s.runtime_mib) {
        (Some((a, b)), Some(rt)) => {
            let _ = writeln!(
                w,
                "Fit of the peak per rank: a + b / P with a = {a:.1} MiB, b = {b:.1} MiB. The \
                 runtime (`{RUNTIME_SCENE}` on {RUNTIME_RANKS} ranks) peaks at {rt:.1} MiB, so \
                 {:.1} MiB of a is replicated: {:.1}% of the 1-rank peak (the goal: at most 5%).\n",
                a - rt,
                100.0 * s.replicated_fraction().unwrap_or(f64::NAN)
            );
        }
        _ => {
            let _ = writeln!(w, "No fit (too few points or no runtime measurement).\n");
        }
    }
    if let Some(it) = &s.iteration {
        model_text(&mut w, it);
        let at = |r: usize| s.points.iter().find(|p| p.ranks() == r);
        if let (Some(one), Some(two)) = (at(1), at(2)) {
            if two.seconds_per_iteration() >= one.seconds_per_iteration() {
                let _ = writeln!(
                    w,
                    "The 2-rank run was not faster than the 1-rank run (a loaded machine): the \
                     replicated part of an iteration could not be measured and the model takes \
                     none, so the efficiencies above are upper bounds. Run on a quiet machine.\n"
                );
            }
        }
    }
    for f in &s.failures {
        let _ = writeln!(w, "- failed: {f}");
    }
    w
}

fn model_text(w: &mut String, it: &Iteration) {
    let _ = writeln!(
        w,
        "Model of one CG iteration ([model.rs](../../tools/src/bench/scaling/model.rs)): compute \
         {:.2} ms on one rank (the 1-rank run's time in its CG loops over their iterations), \
         of which {:.2} ms is repeated on every rank (estimated from the 2-rank run, t2 = (t1 - r) / 2 + r; 0 when that run was not faster); \
         {:.2} messages, {:.0} bytes (on {} ranks, scaled with the part's surface) and {:.2} \
         collectives per iteration, which bring each rank {:.0} bytes (what the coarse levels \
         still gather whole: taken as the same on any rank count of this mesh and growing with \
         the mesh in weak scaling), on a network of {:.1} us latency and {:.0} GB/s. Predicted \
         parallel efficiency (`scaling.png`):\n",
        1e3 * it.compute_s,
        1e3 * it.replicated_s,
        it.messages,
        it.bytes,
        it.bytes_ranks,
        it.collectives,
        it.received,
        LATENCY_S * 1e6,
        BANDWIDTH / 1e9
    );
    // The repeated part read from the 2-rank time moves with that time's noise (0 to 3.2 ms
    // in runs of the same binary) and takes in the two ranks' shared memory bandwidth: the
    // efficiencies with none of it bound the prediction from the other side.
    let none = Iteration {
        replicated_s: 0.0,
        ..*it
    };
    let _ = writeln!(
        w,
        "| ranks | strong (this mesh) | strong, none repeated | weak (this mesh per rank) | weak, none repeated |"
    );
    let _ = writeln!(w, "|---:|---:|---:|---:|---:|");
    for p in predicted_ranks() {
        let _ = writeln!(
            w,
            "| {p} | {:.3} | {:.3} | {:.3} | {:.3} |",
            it.strong_efficiency(p),
            none.strong_efficiency(p),
            it.weak_efficiency(p),
            none.weak_efficiency(p)
        );
    }
    let _ = writeln!(w);
}

fn json(s: &Scaling) -> String {
    let points: Vec<serde_json::Value> = s
        .points
        .iter()
        .map(|p| {
            serde_json::json!({
                "ranks": p.ranks(),
                "peak_mib": p.peak_mib(),
                "cg_iterations": p.case.cg_iterations(),
                "wall_s": p.case.runs.wall.median,
                "seconds_per_cg_iteration": p.seconds_per_iteration(),
                "messages_per_iteration": p.sent.map(|x| x.messages),
                "bytes_per_iteration": p.sent.map(|x| x.bytes),
                "collectives_per_iteration": p.sent.map(|x| x.collectives),
                "received_in_collectives_per_iteration": p.sent.map(|x| x.received),
            })
        })
        .collect();
    let prediction: Vec<serde_json::Value> = s
        .iteration
        .iter()
        .flat_map(|it| {
            predicted_ranks().into_iter().map(move |p| {
                let none = Iteration {
                    replicated_s: 0.0,
                    ..*it
                };
                serde_json::json!({
                    "ranks": p,
                    "strong_efficiency": it.strong_efficiency(p),
                    "weak_efficiency": it.weak_efficiency(p),
                    "strong_efficiency_none_repeated": none.strong_efficiency(p),
                    "weak_efficiency_none_repeated": none.weak_efficiency(p),
                })
            })
        })
        .collect();
    let v = serde_json::json!({
        "points": points,
        "runtime_mib": s.runtime_mib,
        "fit_a_mib": s.fit.map(|f| f.0),
        "fit_b_mib": s.fit.map(|f| f.1),
        "replicated_mib": s.replicated_mib(),
        "replicated_fraction": s.replicated_fraction(),
        "latency_s": LATENCY_S,
        "bandwidth_bytes_per_s": BANDWIDTH,
        "prediction": prediction,
        "failures": s.failures,
    });
    serde_json::to_string_pretty(&v).unwrap_or_default()
}

/// A line of the plot: its label, points and colour.
type Line = (&'static str, Vec<(f64, f64)>, RGBColor);

/// Predicted strong and weak efficiency against log2 of the rank count.
fn plot(path: &Path, it: &Iteration) -> Result<(), String> {
    let e = |e: &dyn std::fmt::Display| format!("cannot draw {}: {e}", path.display());
    let root = BitMapBackend::new(path, (900, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(|x| e(&x))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "block on block n = 40, multilevel: predicted parallel efficiency",
            ("sans-serif", 22),
        )
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..10.0, 0.0..1.05)
        .map_err(|x| e(&x))?;
    chart
        .configure_mesh()
        .x_desc("log2 (ranks)")
        .y_desc("efficiency")
        .draw()
        .map_err(|x| e(&x))?;
    let ranks = predicted_ranks();
    let lines: [Line; 2] = [
        (
            "strong (this mesh)",
            ranks
                .iter()
                .map(|&p| (p.log2(), it.strong_efficiency(p)))
                .collect(),
            BLUE,
        ),
        (
            "weak (this mesh per rank)",
            ranks
                .iter()
                .map(|&p| (p.log2(), it.weak_efficiency(p)))
                .collect(),
            RED,
        ),
    ];
    for (label, pts, colour) in lines {
        chart
            .draw_series(LineSeries::new(pts, colour.stroke_width(2)))
            .map_err(|x| e(&x))?
            .label(label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE)
        .border_style(BLACK)
        .position(SeriesLabelPosition::LowerLeft)
        .draw()
        .map_err(|x| e(&x))?;
    root.present().map_err(|x| e(&x))
}
