//! The block-on-block section: every run, two-level against Jacobi, 2 ranks against 1,
//! the coarse space.

use super::json::{Rec, J};
use super::markdown::{cell, fmt_opt, fmt_stat, identity_text};
use crate::block::{
    BlockCase, BlockSize, BLOCK_RANKS, BLOCK_SCENE, GOAL_ITERATION_RATIO, GOAL_N, GOAL_TIME_RATIO,
    PRECONDITIONERS,
};
use crate::results::Results;
use crate::runner::log::coarse_info;
use crate::runner::solver::Compare;
use std::fmt::Write as _;

pub fn json(r: &Results) -> J {
    let sizes = r
        .blocks
        .iter()
        .enumerate()
        .map(|(i, b)| size_json(r, i, b))
        .collect();
    Rec::default()
        .put("scene", BLOCK_SCENE)
        .put(
            "ranks",
            J::Arr(BLOCK_RANKS.iter().map(|&r| r.into()).collect()),
        )
        .put(
            "preconditioners",
            J::Arr(PRECONDITIONERS.iter().map(|p| p.arg().into()).collect()),
        )
        .put("tolerance", r.block_tolerance)
        .put(
            "goal",
            Rec::default()
                .put("n", GOAL_N)
                .put("iteration_ratio_at_most", GOAL_ITERATION_RATIO)
                .put("time_ratio_at_most", GOAL_TIME_RATIO)
                .json(),
        )
        .put("sizes", J::Arr(sizes))
        .json()
}

/// The record of one run (without the rank count, preconditioner and size); also the
/// large section's.
pub fn case_json(c: &BlockCase, marginal_bytes: Option<f64>) -> Rec {
    let l = &c.runs.log;
    let (force, force_error) = match &c.contact_force {
        Ok(f) => (J::Arr(f.iter().map(|&x| J::Num(x)).collect()), None),
        Err(e) => (J::Null, Some(e.clone())),
    };
    let coarse = c.coarse();
    Rec::default()
        .put("elements", l.elements)
        .put("nodes", l.nodes)
        .put("steps", l.steps)
        .put("cg_iterations", l.cg_iterations)
        .put("contact_updates", l.contact_updates)
        .put("counts_same_every_repeat", c.runs.consistent)
        .put("repeats", c.runs.wall.repeats)
        .stat("wall_s", &c.runs.wall)
        .stat("process_wall_s", &c.runs.process_wall)
        .stat("peak_mib_per_rank", &c.runs.peak_mib)
        .put("elements_per_rank", l.elements as f64 / c.ranks as f64)
        .put("bytes_per_element", c.bytes_per_element())
        .put("marginal_bytes_per_element", marginal_bytes)
        .put("contact_force", force)
        .put("contact_force_error", force_error)
        .put("preconditioner_line", c.preconditioner_line())
        .put("coarse_aggregates", coarse.map(|c| c.aggregates))
        .put("coarse_unknowns", coarse.map(|c| c.unknowns))
        .put("coarse_cell_size", coarse.map(|c| c.cell_size))
        .put("coarse_colours", coarse.map(|c| c.colours))
        .put("result_file", c.result.display().to_string())
}

/// `bitwise_identical` and what the comparison said, after `rec`.
fn compare_json(rec: Rec, compare: &Option<Result<Compare, String>>) -> Rec {
    match compare {
        Some(Ok(c)) => rec
            .put("bitwise_identical", c.identical())
            .put("compare_exit_code", c.code.map(|x| x as i64).map(J::Int))
            .put("compare_summary", c.summary.as_str()),
        Some(Err(e)) => rec
            .put("bitwise_identical", J::Null)
            .put("compare_error", e.as_str()),
        None => rec.put("bitwise_identical", J::Null),
    }
}

fn size_json(r: &Results, i: usize, b: &BlockSize) -> J {
    let runs = b
        .runs
        .iter()
        .flat_map(|pr| {
            pr.cases
                .iter()
                .zip(BLOCK_RANKS)
                .map(|(c, ranks)| (pr.precond, ranks, c))
        })
        .map(|(p, ranks, c)| {
            let head = Rec::default()
                .put("preconditioner", p.arg())
                .put("ranks", ranks);
            match c {
                Err(e) => head.put("error", e.as_str()).json(),
                Ok(c) => head
                    .extend(case_json(c, r.marginal_bytes(i, p, ranks)))
                    .json(),
            }
        })
        .collect();
    let ranks_compared = b
        .runs
        .iter()
        .map(|pr| {
            let rec = Rec::default().put("preconditioner", pr.precond.arg());
            let rec = match pr.speedup() {
                Some(s) => rec.stat("speedup", &s),
                None => rec.put("speedup_median", J::Null),
            };
            compare_json(rec, &pr.compare).json()
        })
        .collect();
    let precond_compared = BLOCK_RANKS
        .iter()
        .map(|&ranks| precond_json(r, b, ranks))
        .collect();
    let coarse = b
        .coarse_lines()
        .into_iter()
        .map(|(ranks, line)| {
            Rec::default()
                .put("ranks", J::Arr(ranks.into_iter().map(J::from).collect()))
                .put("line", line)
                .json()
        })
        .collect();
    Rec::default()
        .put("n", b.n)
        .put("refine", b.refine)
        .put("elements", b.elements())
        .put("runs", J::Arr(runs))
        .put("two_level_over_jacobi", J::Arr(precond_compared))
        .put("one_against_two_ranks", J::Arr(ranks_compared))
        .put("coarse_space", J::Arr(coarse))
        .json()
}

/// Two-level against Jacobi on one rank count.
fn precond_json(r: &Results, b: &BlockSize, ranks: usize) -> J {
    let pair = b.pair(ranks);
    let it = b.iteration_ratio(ranks);
    let time = b.time_ratio(ranks);
    let df = b.force_difference(ranks);
    let rec = Rec::default()
        .put("ranks", ranks)
        .put("cg_iterations_jacobi", pair.map(|p| p.0.cg_iterations()))
        .put("cg_iterations_two_level", pair.map(|p| p.1.cg_iterations()))
        .put("wall_s_jacobi", pair.map(|p| p.0.runs.wall.median))
        .put("wall_s_two_level", pair.map(|p| p.1.runs.wall.median))
        .put("iteration_ratio", it);
    let rec = match &time {
        Some(t) => rec.stat("time_ratio", t),
        None => rec.put("time_ratio_median", J::Null),
    };
    rec.put("iteration_goal_met", it.map(|x| x <= GOAL_ITERATION_RATIO))
        .put("time_goal_met", time.map(|t| t.median <= GOAL_TIME_RATIO))
        .put("contact_force_relative_difference", df)
        .put(
            "contact_force_within_tolerance",
            df.zip(r.block_tolerance).map(|(d, t)| d <= t),
        )
        .json()
}

pub fn markdown(r: &Results, w: &mut String) {
    intro_markdown(r, w);
    runs_markdown(r, w);
    precond_markdown(r, w);
    ranks_markdown(r, w);
    coarse_markdown(r, w);
}

fn intro_markdown(r: &Results, w: &mut String) {
    let _ = writeln!(
        w,
        "\n## Block on block: the solver on 1 and 2 ranks, Jacobi and two-level\n"
    );
    let repeats: Vec<String> = r
        .blocks
        .iter()
        .map(|b| format!("n = {}: {}", b.n, b.repeats()))
        .collect();
    let tol = r
        .block_tolerance
        .map_or("unknown".to_string(), |t| format!("{t:e}"));
    let _ = writeln!(
        w,
        "`{BLOCK_SCENE}`: the upper block [0.05,0.95]x[1,1.9]x[0.05,0.95] pressed by u_y = \
         -0.009 at its top (x, z held) onto the lower block [0,1]^3 held at its bottom, both \
         linear elastic (E = 1000, nu = 0.3), n^3 hexahedra each with non-matching meshes, \
         frictionless contact, 2 load steps, tolerance {tol}. The solver refines it \
         (`solver run --refine F`) and runs as a subprocess under `run/mpirun -np R`, once \
         with `--preconditioner jacobi` (nodal block Jacobi) and once with `two_level` \
         (the same plus a coarse space of aggregate rigid-body modes). \
         Repeats per run: {}{}. \"time\" is the run time the solver prints (decomposition to result \
         file, without MPI start-up and scene loading), \"process\" the wall time of the \
         mpirun process. \"peak\" is the largest VmHWM over the ranks as the solver prints \
         it; \"B/element\" = peak / (elements / ranks), \"marginal\" = growth of the peak \
         over the next smaller size per element added per rank, same preconditioner (the \
         runtime's fixed cost cancels). \"contact force\" = sum of the y components of \
         `/results/contact/force` over all nodes at the last step.\n",
        repeats.join(", "),
        if r.blocks.iter().any(|b| b.n == GOAL_N) {
            " (one repeat on the largest size: its Jacobi run alone takes about 10 minutes \
             on one rank)"
        } else {
            ""
        }
    );
}

/// A total contact force's y component, or why it could not be read.
pub fn force_cell(c: &BlockCase) -> String {
    match &c.contact_force {
        Ok(f) => format!("{:.6}", f[1]),
        Err(e) => format!("unreadable: {}", cell(e)),
    }
}

fn runs_markdown(r: &Results, w: &mut String) {
    let _ = writeln!(
        w,
        "| n | elements | preconditioner | ranks | CG iterations | contact updates | n runs | time s | process s | peak MiB/rank | B/element | marginal B/element | contact force y |"
    );
    let _ = writeln!(
        w,
        "|---:|---:|---|---:|---:|---:|---:|---|---|---|---:|---:|---:|"
    );
    for (i, b) in r.blocks.iter().enumerate() {
        for pr in &b.runs {
            let p = pr.precond;
            for (c, ranks) in pr.cases.iter().zip(BLOCK_RANKS) {
                let _ = match c {
                    Err(e) => writeln!(
                        w,
                        "| {} | {} | {} | {ranks} | failed: {} |||||||||",
                        b.n,
                        b.elements().map_or("-".into(), |e| e.to_string()),
                        p.label(),
                        cell(e)
                    ),
                    Ok(c) => writeln!(
                        w,
                        "| {} | {} | {} | {ranks} | {}{} | {} | {} | {} | {} | {} | {:.0} | {} | {} |",
                        b.n,
                        c.elements(),
                        p.label(),
                        c.cg_iterations(),
                        if c.runs.consistent { "" } else { " (varied)" },
                        c.runs.log.contact_updates,
                        c.runs.wall.repeats,
                        fmt_stat(&c.runs.wall, 2),
                        fmt_stat(&c.runs.process_wall, 2),
                        fmt_stat(&c.runs.peak_mib, 1),
                        c.bytes_per_element(),
                        fmt_opt(r.marginal_bytes(i, p, ranks), 0),
                        force_cell(c)
                    ),
                };
            }
        }
    }
}

fn precond_markdown(r: &Results, w: &mut String) {
    let tol = r
        .block_tolerance
        .map_or("unknown".to_string(), |t| format!("{t:e}"));
    let _ = writeln!(w, "\n### Two-level against Jacobi\n");
    let _ = writeln!(
        w,
        "Ratios are two-level over Jacobi on the same rank count: CG iterations, and the \
         solver's run time (median [min, max], the extremes from the fastest over the \
         slowest repeat). The goal on n = {GOAL_N} is a CG ratio of at most {:.2} and a \
         time ratio of at most {:.2}. \"force difference\" = |F_two-level - F_Jacobi| / \
         |F_Jacobi| of the total contact force vectors; both solves stop at the relative \
         residual {tol}, and the forces should agree to about that.\n",
        GOAL_ITERATION_RATIO, GOAL_TIME_RATIO
    );
    let _ = writeln!(
        w,
        "| n | ranks | CG Jacobi | CG two-level | CG ratio | time Jacobi s | time two-level s | time ratio | force difference |"
    );
    let _ = writeln!(w, "|---:|---:|---:|---:|---:|---:|---:|---|---:|");
    for b in &r.blocks {
        for ranks in BLOCK_RANKS {
            let Some((j, t)) = b.pair(ranks) else {
                let _ = writeln!(
                    w,
                    "| {} | {ranks} | not compared (a run failed) ||||||||",
                    b.n
                );
                continue;
            };
            let _ = writeln!(
                w,
                "| {} | {ranks} | {} | {} | {} | {:.2} | {:.2} | {} | {} |",
                b.n,
                j.cg_iterations(),
                t.cg_iterations(),
                fmt_opt(b.iteration_ratio(ranks), 3),
                j.runs.wall.median,
                t.runs.wall.median,
                b.time_ratio(ranks).map_or("-".into(), |s| fmt_stat(&s, 3)),
                b.force_difference(ranks)
                    .map_or("-".into(), |d| format!("{d:.1e}")),
            );
        }
    }
    let _ = writeln!(w, "{}", goal_text(r.blocks.iter().find(|b| b.n == GOAL_N)));
}

/// The goal on n = GOAL_N, judged per rank count.
fn goal_text(goal: Option<&BlockSize>) -> String {
    let Some(b) = goal else {
        return format!("\nGoal: n = {GOAL_N} was not run.");
    };
    let met = |ok: bool| if ok { "met" } else { "**not met**" };
    let parts: Vec<String> = BLOCK_RANKS
        .iter()
        .filter_map(|&r| {
            let it = b.iteration_ratio(r)?;
            let t = b.time_ratio(r)?.median;
            Some(format!(
                "{r} rank(s): CG ratio {it:.3} ({}), time ratio {t:.3} ({})",
                met(it <= GOAL_ITERATION_RATIO),
                met(t <= GOAL_TIME_RATIO)
            ))
        })
        .collect();
    if parts.is_empty() {
        format!("\nGoal on n = {GOAL_N}: not judged (a run failed).")
    } else {
        format!("\nGoal on n = {GOAL_N}: {}.", parts.join("; "))
    }
}

fn ranks_markdown(r: &Results, w: &mut String) {
    let _ = writeln!(w, "\n### 2 ranks against 1\n");
    let _ = writeln!(
        w,
        "| n | preconditioner | 1-rank time s | 2-rank time s | speed-up | 1 and 2 ranks bitwise identical |"
    );
    let _ = writeln!(w, "|---:|---|---:|---:|---|---|");
    for b in &r.blocks {
        for pr in &b.runs {
            let t = |ranks: usize| fmt_opt(pr.case(ranks).map(|c| c.runs.wall.median), 2);
            let _ = writeln!(
                w,
                "| {} | {} | {} | {} | {} | {} |",
                b.n,
                pr.precond.label(),
                t(BLOCK_RANKS[0]),
                t(BLOCK_RANKS[1]),
                pr.speedup().map_or("-".into(), |s| fmt_stat(&s, 2)),
                identity_text(&pr.compare)
            );
        }
    }
}

fn coarse_markdown(r: &Results, w: &mut String) {
    let _ = writeln!(w, "\n### Coarse space\n");
    let _ = writeln!(
        w,
        "The two-level runs' `preconditioner:` line (`solver -vv`): aggregates are the nodes \
         of one body in one cell of a uniform grid, 6 rigid-body modes each.\n"
    );
    let _ = writeln!(
        w,
        "| n | ranks | aggregates | coarse unknowns | cell size | colours | line |"
    );
    let _ = writeln!(w, "|---:|---|---:|---:|---:|---:|---|");
    for b in &r.blocks {
        for (ranks, line) in b.coarse_lines() {
            let ranks: Vec<String> = ranks.iter().map(usize::to_string).collect();
            let c = coarse_info(&line);
            let _ = writeln!(
                w,
                "| {} | {} | {} | {} | {} | {} | {} |",
                b.n,
                ranks.join(", "),
                c.map_or("-".into(), |c| c.aggregates.to_string()),
                c.map_or("-".into(), |c| c.unknowns.to_string()),
                c.map_or("-".into(), |c| format!("{:.4e}", c.cell_size)),
                c.map_or("-".into(), |c| c.colours.to_string()),
                cell(&line)
            );
        }
    }
}
