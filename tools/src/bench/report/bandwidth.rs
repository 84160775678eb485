//! The memory bandwidth section.

use super::json::{Rec, J};
use super::markdown::fmt_stat;
use crate::results::Results;
use std::fmt::Write as _;

pub fn json(r: &Results) -> J {
    J::Arr(
        r.stream
            .iter()
            .map(|s| {
                Rec::default()
                    .put("kernel", s.kernel)
                    .put("threads", s.threads)
                    .put("array_bytes", s.array_bytes)
                    .put("bytes_per_pass", s.bytes_per_pass)
                    .put("repeats", s.gbs.repeats)
                    .stat("gb_s", &s.gbs)
                    .json()
            })
            .collect(),
    )
}

pub fn markdown(r: &Results, w: &mut String) {
    let _ = writeln!(w, "## Memory bandwidth\n");
    let _ = writeln!(w, "| loop | threads | arrays x size | GB/s |");
    let _ = writeln!(w, "|---|---:|---|---|");
    for x in &r.stream {
        let _ = writeln!(
            w,
            "| {} | {} | {} x {:.0} MB | {} |",
            x.kernel,
            x.threads,
            x.bytes_per_pass / x.array_bytes,
            x.array_bytes as f64 / 1e6,
            fmt_stat(&x.gbs, 2)
        );
    }
}
