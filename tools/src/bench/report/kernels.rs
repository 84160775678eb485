//! The element kernels section.

use super::json::{Rec, J};
use super::markdown::{fmt_rate, fmt_stat};
use crate::kernels::model_bytes;
use crate::results::Results;
use std::fmt::Write as _;

pub fn json(r: &Results) -> J {
    let triad = r.triad_1core();
    J::Arr(
        r.kernels
            .iter()
            .map(|k| {
                let model_gbs = k.model_gbs();
                Rec::default()
                    .put("case", k.case.label)
                    .put("operation", k.operation)
                    .put("integration", k.case.integration)
                    .put("volumetric", k.case.volumetric)
                    .put("material", k.case.material())
                    .put("kinematics", k.case.kinematics())
                    .put("mesh", format!("{n}x{n}x{n}", n = r.kernel_n))
                    .put("elements", k.elements)
                    .put("nodes", k.nodes)
                    .put("repeats", k.seconds.repeats)
                    .stat("seconds", &k.seconds)
                    .stat("elements_per_s", &k.rate())
                    .stat("ns_per_element", &k.ns_per_element())
                    .put("cpu_share", k.cpu_share)
                    .put("model_bytes_per_element", k.model_bytes)
                    .put("model_gb_s", model_gbs)
                    .put("fraction_of_triad_1core", triad.map(|t| model_gbs / t))
                    .put("checksum", k.checksum)
                    .json()
            })
            .collect(),
    )
}

pub fn markdown(r: &Results, w: &mut String) {
    let triad = r.triad_1core();
    let _ = writeln!(w, "\n## Element kernels (one core)\n");
    let _ = writeln!(
        w,
        "Traffic model, no reuse of nodes shared between elements: coordinates 8 x 3 x 8 B \
         + displacements 8 x 3 x 8 B read + result 8 x k x 8 B read and written (k = 3 \
         force, 9 diagonal 3x3 block) + connectivity 8 x 4 B = {} B/element for \
         `internal_force`, {} B/element for `diagonal`. \"% of triad\" is the model's \
         bandwidth at the median rate over the one-core triad bandwidth{}. With perfect \
         cache reuse on this structured mesh each element brings only about one new node \
         (about 130 B), so the real DRAM traffic is lower still. The tet10 rows run on the \
         same cube cut into n/2 cells a side, each split into six tetrahedra (the Kuhn \
         split; 0.75 times as many elements, the same node count once the edges' \
         midpoints are added), their model with 10 nodes per element.\n",
        model_bytes(3),
        model_bytes(9),
        triad.map_or(String::new(), |t| format!(" ({t:.2} GB/s)"))
    );
    let _ = writeln!(
        w,
        "| case | operation | n | elements/s | ns/element | CPU/wall | model GB/s | % of triad |"
    );
    let _ = writeln!(w, "|---|---|---:|---|---|---:|---:|---:|");
    for k in &r.kernels {
        let gbs = k.model_gbs();
        let _ = writeln!(
            w,
            "| {} | `{}` | {} | {} | {} | {:.2} | {:.2} | {} |",
            k.case.label,
            k.operation,
            k.seconds.repeats,
            fmt_rate(&k.rate()),
            fmt_stat(&k.ns_per_element(), 0),
            k.cpu_share,
            gbs,
            triad.map_or("-".into(), |t| format!("{:.1} %", 100.0 * gbs / t))
        );
    }
}
