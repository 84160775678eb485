//! What the plasticity section measured: its cases, ours and ccx's run of each. The runner
//! (`mod.rs`, `ours.rs`) produces it and the report (`report.rs`) reads it.

use crate::peers::calculix::deck::ElementType;

/// ccx's pressure-overclosure slope for the contact punch: about 30 times E over the
/// block's element size at n = 96, an overclosure of about 2.5e-5 at its pressure (0.04%
/// of the punch's depth).
pub const CONTACT_PENALTY: f64 = 3e7;

/// Ranks of our runs (beside ccx's 2 threads).
pub const RANKS: usize = 2;

/// What our run of one case measured.
#[derive(Clone, Debug)]
pub struct Ours {
    /// Wall time of the `run/mpirun` process (MPI start-up and scene loading included).
    pub wall: f64,
    /// The solver's own wall time (its `done:` line).
    pub solver_wall: f64,
    pub cg_total: u64,
    /// CG iterations of every increment, in order.
    pub cg_per_step: Vec<u64>,
    pub contact_updates: u64,
    /// The `preconditioner: ..` line without its prefix.
    pub preconditioner: String,
    /// The punch's mean pressure at the end.
    pub pressure: f64,
}

impl Ours {
    /// (largest CG iterations of one increment, that increment, 1-based).
    pub fn cg_max(&self) -> (u64, usize) {
        self.cg_per_step
            .iter()
            .enumerate()
            .fold((0, 0), |m, (k, &c)| if c > m.0 { (c, k + 1) } else { m })
    }
}

/// How the punch is pressed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// The block's top nodes under the punch moved down.
    Prescribed,
    /// A punch body through frictionless node-to-face contact.
    Contact,
}

/// One case of the section.
pub struct Case {
    pub name: &'static str,
    pub scene: &'static str,
    pub kind: Kind,
    /// Elements per edge of the block.
    pub n: usize,
}

/// The cases of a full run; `--quick` runs the first of each kind.
pub const CASES: [Case; 4] = [
    Case {
        name: "punch_40",
        scene: "run/scenes/plasticity/punch_40.toml",
        kind: Kind::Prescribed,
        n: 40,
    },
    Case {
        name: "punch_80",
        scene: "run/scenes/plasticity/punch_80.toml",
        kind: Kind::Prescribed,
        n: 80,
    },
    Case {
        name: "contact_punch_48",
        scene: "run/scenes/plasticity/contact_punch_48.toml",
        kind: Kind::Contact,
        n: 48,
    },
    Case {
        name: "contact_punch_96",
        scene: "run/scenes/plasticity/contact_punch_96.toml",
        kind: Kind::Contact,
        n: 96,
    },
];

/// ccx's run of a case.
#[derive(Clone, Debug)]
pub struct Ccx {
    pub wall: f64,
    pub newton_iterations: usize,
    /// Increments with a printed punch force.
    pub increments: usize,
    pub pressure: f64,
    pub element: ElementType,
}

/// One case's outcome.
pub struct Row {
    pub case: &'static Case,
    pub increments: usize,
    /// Prandtl's limit pressure (2 + pi) sigma_y / sqrt(3) of the block.
    pub prandtl: f64,
    pub ours: Result<Ours, String>,
    pub ccx: Result<Ccx, String>,
}
