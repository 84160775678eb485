//! The contact search section.

use super::json::{Rec, J};
use super::markdown::{fmt_rate, fmt_stat};
use crate::results::Results;
use crate::search::CONTACT_GAP_FRACTION;
use std::fmt::Write as _;

pub fn json(r: &Results) -> J {
    let c = &r.contact;
    let ns = c.slave_nodes as f64;
    Rec::default()
        .put("master_divisions", format!("{m}x1x{m}", m = c.m))
        .put("slave_divisions", format!("{k}x1x{k}", k = c.m - 1))
        .put("master_faces", c.master_faces)
        .put("slave_nodes", c.slave_nodes)
        .put("face_size", c.face_size)
        .put("normal_tolerance", c.normal_tolerance)
        .put("tangential_tolerance", c.tangential_tolerance)
        .put("max_abs_offset", c.max_offset)
        .put("threads", 1usize)
        .put("parse_s", c.parse_s)
        .put("perturb_s", c.perturb_s)
        .put("repeats", c.total.repeats)
        .stat("build_s", &c.build)
        .stat("search_s", &c.search)
        .stat("total_s", &c.total)
        .put("cpu_share", c.cpu_share)
        .stat("slave_nodes_per_s", &c.search_rate())
        .stat("us_per_query", &c.us_per_query())
        .stat("total_slave_nodes_per_s", &c.total.rate(ns))
        .put("interactions_found", c.found)
        .put("interactions_same_every_repeat", c.consistent)
        .put("expected", c.expected)
        .put("expected_found", c.expected_found)
        .put("all_expected_found", c.expected_found == c.expected)
        .put("max_gap_error", c.max_gap_error)
        .put("max_point_error", c.max_point_error)
        .stat("mortar_s", &c.mortar)
        .stat("mortar_slave_nodes_per_s", &c.mortar.rate(ns))
        .put("mortar_ties", c.mortar_ties)
        .put("mortar_max_weight_sum_error", c.mortar_weight_error)
        .json()
}

pub fn markdown(r: &Results, w: &mut String) {
    let c = &r.contact;
    let _ = writeln!(w, "\n## Contact search\n");
    let _ = writeln!(
        w,
        "Two blocks stacked at y = 0.1 with non-matching meshes: the master surface is the \
         top of the lower block ({m}x1x{m} elements, {mf} faces of size {fs:.3e}), the \
         slave nodes the bottom of the upper block ({k}x1x{k} elements, {sn} nodes), each \
         offset along y by a pseudo-random gap uniform in ±{a:.3e} ({fr} x the normal \
         tolerance {nt:.3e}; largest |offset| {mo:.3e}; tangential tolerance {tt:.3e}). One thread. \"build\" is \
         `MasterSurface::new` (face corners and the BVH of the inflated face boxes), \
         \"search\" is `MasterSurface::search` of every slave node, \"total\" both; \
         after one untimed warm-up round. Not timed: scene generation and `parse_scene` \
         {ps:.2} s, slave offsets {pt:.2} ms. \"found / expected\": slave nodes with an \
         interaction / slave nodes over the master surface within the normal tolerance \
         ({ef} of the {ex} expected found{cons}); over the interactions, max |gap - offset| \
         = {ge:.1e} and max distance of the contact point from the node's foot on the \
         plane = {pe:.1e}.\n",
        m = c.m,
        k = c.m - 1,
        mf = c.master_faces,
        fs = c.face_size,
        sn = c.slave_nodes,
        a = CONTACT_GAP_FRACTION * c.normal_tolerance,
        fr = CONTACT_GAP_FRACTION,
        mo = c.max_offset,
        nt = c.normal_tolerance,
        tt = c.tangential_tolerance,
        ps = c.parse_s,
        pt = 1e3 * c.perturb_s,
        ef = c.expected_found,
        ex = c.expected,
        cons = if c.consistent {
            ", the same count every repeat"
        } else {
            "; **the count varied between repeats**"
        },
        ge = c.max_gap_error,
        pe = c.max_point_error,
    );
    let _ = writeln!(
        w,
        "| master faces | slave nodes | n | build ms | search ms | total ms | slave nodes/s (search) | µs / query | CPU/wall | found / expected |"
    );
    let _ = writeln!(w, "|---:|---:|---:|---|---|---|---|---|---:|---:|");
    let _ = writeln!(
        w,
        "| {} | {} | {} | {} | {} | {} | {} | {} | {:.2} | {} / {} |",
        c.master_faces,
        c.slave_nodes,
        c.total.repeats,
        fmt_stat(&c.build.scaled(1e3), 2),
        fmt_stat(&c.search.scaled(1e3), 2),
        fmt_stat(&c.total.scaled(1e3), 2),
        fmt_rate(&c.search_rate()),
        fmt_stat(&c.us_per_query(), 3),
        c.cpu_share,
        c.found,
        c.expected,
    );
    let _ = writeln!(
        w,
        "\nThe mortar integration of the same pair at the same positions, per contact update \
         (`contact::mortar::ties` of every slave node: each slave face against the master faces \
         its box meets, projected on its plane, clipped, integrated with the 7-point triangle \
         rule; the dual basis; the ties), one thread, after one untimed warm-up: {} ms \
         (median of {}), {} slave nodes/s, {:.1} x the node-to-face build and search; {} of \
         the {} slave nodes tied, max |sum of weights - 1| = {:.1e}.",
        fmt_stat(&c.mortar.scaled(1e3), 2),
        c.mortar.repeats,
        fmt_rate(&c.mortar.rate(c.slave_nodes as f64)),
        c.mortar.median / c.total.median,
        c.mortar_ties,
        c.slave_nodes,
        c.mortar_weight_error,
    );
}
