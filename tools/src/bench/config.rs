//! Sizes and repeat counts of a normal run (`--quick` or full).

use std::path::PathBuf;

/// Sizes and repeat counts of one benchmark run.
pub struct Config {
    pub quick: bool,
    pub out: PathBuf,
    /// f64 entries per STREAM array.
    pub stream_len: usize,
    pub stream_repeats: usize,
    /// Elements per edge of the kernel mesh.
    pub kernel_n: usize,
    pub force_repeats: usize,
    pub diagonal_repeats: usize,
    /// (elements per edge, repeats) of the CG cube compressions.
    pub cube: Vec<(usize, usize)>,
    /// (master faces per edge, repeats) of the contact search: m^2 master faces, m^2
    /// slave nodes.
    pub contact: (usize, usize),
    /// (refinement factor, repeats) of the block-on-block solver runs.
    pub block: Vec<(usize, usize)>,
    /// Refinement factor whose decomposition over `block::PARTITION_RANKS` is reported.
    pub partition_refine: usize,
    /// Refinement factors CalculiX runs at (with the repeats of `block`).
    pub calculix: Vec<usize>,
}

impl Config {
    pub fn new(quick: bool, out: PathBuf) -> Self {
        if quick {
            Config {
                quick,
                out,
                stream_len: 8 << 20, // 64 MiB per array
                stream_repeats: 3,
                kernel_n: 30,
                force_repeats: 5,
                diagonal_repeats: 3,
                cube: vec![(10, 3), (20, 3)],
                contact: (100, 5),
                block: vec![(1, 1)],
                partition_refine: 1,
                calculix: vec![1],
            }
        } else {
            Config {
                quick,
                out,
                stream_len: 25_000_000, // 200 MB per array
                stream_repeats: 10,
                kernel_n: 50,
                force_repeats: 7,
                diagonal_repeats: 5,
                cube: vec![(10, 5), (20, 3), (40, 3)],
                contact: (316, 7),
                // n = 40 with Jacobi takes about 10 minutes on one rank: one repeat.
                block: vec![(1, 3), (2, 3), (4, 1)],
                partition_refine: 4,
                calculix: vec![1, 2, 4],
            }
        }
    }

    /// The repeats of the block-on-block size with this refinement factor (1 when it is
    /// not run).
    pub fn block_repeats(&self, refine: usize) -> usize {
        self.block.iter().find(|b| b.0 == refine).map_or(1, |b| b.1)
    }
}
