//! The CalculiX section: ccx on the block-on-block problem beside our two-level 2-rank
//! run.

use super::json::{Rec, J};
use super::markdown::{cell, fmt_opt, fmt_stat};
use crate::block::BLOCK_RANKS;
use crate::peers::calculix::block::{CcxSize, CCX_PENALTY, CCX_THREADS, CCX_TIMEOUT_S};
use crate::peers::calculix::run::Outcome;
use crate::results::{relative_difference, Results};
use crate::runner::solver::Precond;
use std::fmt::Write as _;

pub fn json(r: &Results) -> J {
    let c = &r.calculix;
    let sizes = c.sizes.iter().map(|s| size_json(r, s)).collect();
    Rec::default()
        .put("available", c.version.is_some())
        .put("version", c.version.clone())
        .put("threads", CCX_THREADS)
        .put("timeout_s", CCX_TIMEOUT_S)
        .put("penalty_slope", CCX_PENALTY)
        .put("sizes", J::Arr(sizes))
        .json()
}

fn size_json(r: &Results, s: &CcxSize) -> J {
    let ours = r.our_force(s.n);
    let ours_2 = r.our_case(s.n);
    let rec = Rec::default()
        .put("n", s.n)
        .put("elements", s.elements)
        .put("nodes", s.nodes)
        .put("deck", s.deck.display().to_string())
        .put("threads", CCX_THREADS)
        .put("our_preconditioner", Precond::TwoLevel.arg())
        .put("our_ranks", BLOCK_RANKS[1])
        .put("our_contact_force_y", ours)
        .put(
            "our_process_wall_s",
            ours_2.map(|b| b.runs.process_wall.median),
        )
        .put("our_wall_s", ours_2.map(|b| b.runs.wall.median));
    match &s.outcome {
        Outcome::Finished { timed, values } => rec
            .put("status", "finished")
            .put("repeats", timed.wall.repeats)
            .stat("wall_s", &timed.wall)
            .put("ccx_time_s", timed.own_time)
            .put("peak_mib", timed.peak_mib)
            .put("iterations", timed.iterations)
            .put("total_force", -values.top[1])
            .put("bottom_force", values.bottom[1])
            .put(
                "relative_difference",
                ours.map(|o| relative_difference(-values.top[1], o)),
            ),
        Outcome::Stopped(why) => rec.put("status", "stopped").put("reason", why.as_str()),
        Outcome::Failed(e) => rec.put("status", "failed").put("reason", e.as_str()),
        Outcome::Skipped(why) => rec.put("status", "skipped").put("reason", why.as_str()),
    }
    .json()
}

pub fn markdown(r: &Results, w: &mut String) {
    let c = &r.calculix;
    let _ = writeln!(w, "## CalculiX beside us\n");
    let Some(version) = &c.version else {
        let _ = writeln!(
            w,
            "CalculiX not available (no `ccx` on PATH; `run/setup --calculix` installs \
             Debian's calculix-ccx)."
        );
        return;
    };
    let _ = writeln!(
        w,
        "CalculiX {version} (`ccx`) on the same problem, from an input deck the bench writes \
         from the scene as the solver loads it: the same nodes and elements (C3D8, 2x2x2 \
         Gauss like the scene's full integration), E and nu, the prescribed displacements \
         at the final time over one static step (no NLGEOM), and frictionless \
         node-to-surface penalty contact of the slave faces on the master faces with a \
         linear pressure-overclosure law of slope {CCX_PENALTY:e} (overclosure about 1e-6 \
         at these pressures). `OMP_NUM_THREADS={CCX_THREADS}`, direct solver (SPOOLES as \
         Debian builds it), at most {CCX_TIMEOUT_S:.0} s per size (larger sizes are \
         skipped after one that does not finish). \"ccx force\" = -(sum of RF_y over the \
         upper block's top), \"bottom\" = sum of RF_y over the lower block's bottom; \
         \"ours\" = our total contact force (two-level preconditioner, 2 ranks). Times are \
         process wall times on both sides (ours: `run/mpirun -np 2 ... --preconditioner \
         two_level`, medians; the repeats are those of the table above). \
         Decks and logs in `out/bench/calculix/`.\n"
    );
    let _ = writeln!(
        w,
        "| n | elements | our two-level 2-rank process s | ccx s (2 threads) | ccx / ours | ccx peak MiB | ccx iterations | our force | ccx force | bottom | relative difference |"
    );
    let _ = writeln!(w, "|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|");
    for s in &c.sizes {
        size_markdown(r, s, w);
    }
}

fn size_markdown(r: &Results, s: &CcxSize, w: &mut String) {
    let ours = r.our_force(s.n);
    let our_t = r.our_case(s.n).map(|b| b.runs.process_wall.median);
    let head = format!(
        "| {} | {} | {} |",
        s.n,
        if s.elements > 0 {
            s.elements.to_string()
        } else {
            "-".into()
        },
        fmt_opt(our_t, 2)
    );
    let our_f = fmt_opt(ours, 6);
    let _ = match &s.outcome {
        Outcome::Finished { timed, values } => writeln!(
            w,
            "{head} {} | {} | {} | {} | {our_f} | {:.6} | {:.6} | {} |",
            fmt_stat(&timed.wall, 2),
            fmt_opt(our_t.map(|t| timed.wall.median / t), 2),
            fmt_opt(timed.peak_mib, 0),
            timed.iterations,
            -values.top[1],
            values.bottom[1],
            ours.map_or("-".into(), |o| format!(
                "{:+.2e}",
                relative_difference(-values.top[1], o)
            )),
        ),
        Outcome::Stopped(why) => writeln!(w, "{head} {why} |||| {our_f} ||||"),
        Outcome::Failed(e) => writeln!(w, "{head} failed: {} |||| {our_f} ||||", cell(e)),
        Outcome::Skipped(why) => writeln!(w, "{head} not run: {why} |||| {our_f} ||||"),
    };
}
