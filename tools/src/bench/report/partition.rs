//! The partition section: `solver check --ranks` of the block scene.

use super::json::{Rec, J};
use crate::block::BLOCK_SCENE;
use crate::results::Results;
use std::fmt::Write as _;

pub fn json(r: &Results) -> J {
    J::Arr(
        r.partitions
            .iter()
            .map(|p| match p {
                Ok(p) => Rec::default()
                    .put("n", p.n)
                    .put("ranks", p.ranks)
                    .put("element_imbalance", p.imbalance)
                    .put("edge_cut", p.edge_cut)
                    .put("text", p.text.as_str())
                    .json(),
                Err(e) => Rec::default().put("error", e.as_str()).json(),
            })
            .collect(),
    )
}

pub fn markdown(r: &Results, w: &mut String) {
    let _ = writeln!(w, "\n## Partition\n");
    let _ = writeln!(
        w,
        "`solver check {BLOCK_SCENE} --refine F --ranks R`: how the mesh splits (METIS), \
         and the master faces each rank owns / holds for its slave nodes.\n"
    );
    for p in &r.partitions {
        let _ = match p {
            Ok(p) => writeln!(
                w,
                "n = {}, {} ranks:\n\n```\n{}\n```\n",
                p.n, p.ranks, p.text
            ),
            Err(e) => writeln!(w, "{e}\n"),
        };
    }
}
