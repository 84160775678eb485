//! The report's sections, one per paper test (4.1-4.5), the Gmsh example and any other
//! scene: fixed text (`texts`), the scenes' blocks, the figures and the pictures.

use super::results::{
    hertz_half, hertz_peak, hertz_rms, Paper, Render, PLASTIC_EXAMPLE, TET_EXAMPLE,
};
use super::texts::*;
use super::verdicts::cycle_updates;
use crate::text::Doc;
use crate::text::{code, num};

/// A scene of a section and its title in the report.
type Titled = (&'static str, Option<&'static str>);

/// The paper's sections: (heading, scenes with their titles).
const SECTIONS: [(&str, &[Titled]); 5] = [
    (
        "4.1",
        &[
            ("bc_interaction", Some("stick, mu = 0.5")),
            (
                "bc_interaction_mu037",
                Some("mu = 0.37, just above tan(phi): sticks"),
            ),
            (
                "bc_interaction_mu036",
                Some("mu = 0.36, just below tan(phi): slips"),
            ),
            (
                "bc_interaction_frictionless",
                Some("frictionless, Figure 2"),
            ),
        ],
    ),
    (
        "4.2",
        &[
            ("normal_smoothing", Some("smoothing on")),
            (
                "normal_smoothing_off",
                Some("smoothing off (held at the fold)"),
            ),
        ],
    ),
    ("4.3", &[("capture_release", None)]),
    ("4.4", &[("stick_slip", None)]),
    (
        "4.5",
        &[
            ("multi_constraint", Some("matching meshes")),
            (
                "multi_constraint_nonmatching",
                Some("non-matching shaded block (reported)"),
            ),
        ],
    ),
];

impl Paper {
    fn blocks(&self, d: &mut Doc, section: usize) {
        for (n, t) in SECTIONS[section].1 {
            if self.runs.iter().any(|r| r.0 == *n) {
                self.scene_block(d, n, *t);
            }
        }
    }

    pub fn sections(&self, d: &mut Doc, render: &Render) {
        d.w("## 4.1 Contact / boundary-condition interaction\n");
        d.w(S41_SETUP);
        d.w(S41_EXACT);
        self.blocks(d, 0);
        self.figure(d, "fig2", FIG2);
        d.w("## 4.2 Normal smoothing\n");
        d.w(S42_SETUP);
        d.w(S42_EXACT);
        self.smoothing_updates(d);
        self.blocks(d, 1);
        self.figure(d, "fig_smoothing", FIG_SMOOTHING);
        d.w("## 4.3 Capture and release\n");
        d.w(S43_SETUP);
        d.w(S43_EXACT);
        self.blocks(d, 2);
        self.figure(d, "fig5", FIG5);
        self.pictures(d, "capture_release", render);
        d.w("## 4.4 Stick / slip bar\n");
        d.w(S44_SETUP);
        d.w(S44_EXACT);
        d.w(S44_NOT_3D);
        self.blocks(d, 3);
        if let Some(ss) = self
            .runs
            .iter()
            .find(|r| r.0 == "stick_slip")
            .map(|r| &r.1 .0)
        {
            if let Some(diff) = ss.reported("difference from the 1-D formula at t = 2, / u_max") {
                d.w(format!(
                    "At full load (t = 2) the computed cross-section average differs from the 1-D \
                     formula by {:.2}% of u_max, the size the 3-D effect described above leads one \
                     to expect; Figure 6's lowest panel shows the difference along the bar at every \
                     drawn time.\n",
                    diff * 100.0
                ));
            }
        }
        self.figure(d, "fig6", FIG6);
        self.pictures(d, "stick_slip", render);
        d.w("## 4.5 Multiple contact constraints (patch test)\n");
        d.w(S45_SETUP);
        d.w(S45_EXACT);
        self.blocks(d, 4);
        self.pictures(d, "multi_constraint", render);
        self.example_section(d, render);
        self.plastic_section(d, render);
        self.tet_section(d, render);
        let known: Vec<&str> = SECTIONS
            .iter()
            .flat_map(|s| s.1.iter().map(|x| x.0))
            .collect();
        let extra: Vec<&String> = self
            .scenes
            .iter()
            .filter(|n| !known.contains(&n.as_str()))
            .collect();
        if !extra.is_empty() {
            d.w("## Other scenes in run/scenes/paper\n");
            for n in extra {
                self.scene_block(d, n, None);
            }
        }
    }

    /// 4.2: the contact updates with smoothing on and off.
    fn smoothing_updates(&self, d: &mut Doc) {
        let find = |n: &str| self.runs.iter().find(|r| r.0 == n).map(|r| &r.1 .0);
        let (Some(on), Some(off)) = (find("normal_smoothing"), find("normal_smoothing_off")) else {
            return;
        };
        d.w("**Contact updates, smoothing on and off:**\n");
        let ups = on.per_step_updates();
        let per_step = if ups.is_empty() {
            String::new()
        } else {
            let v: Vec<String> = ups.iter().map(u64::to_string).collect();
            format!("; per step: {}", v.join(", "))
        };
        let steps = |r: &super::model::PaperRun| r.steps().map_or("None".into(), |s| s.to_string());
        d.w(format!(
            "- smoothing on (`normal_smoothing`): {} contact updates over {} load steps, {} CG \
             iterations{per_step}.",
            num(on.reported("contact updates (total)")),
            steps(on),
            num(on.reported("CG iterations (total)"))
        ));
        if off.completed() {
            d.w(format!(
                "- smoothing off (`normal_smoothing_off`): {} contact updates over {} load \
                 steps, {} CG iterations. The paper's node at the V flips between the two \
                 facets without smoothing; here, back on the facet it left, it is held at \
                 their shared edge by both (a fold), and the answer is the symmetric one \
                 of smoothing on.",
                num(off.reported("contact updates (total)")),
                steps(off),
                num(off.reported("CG iterations (total)"))
            ));
        } else {
            let msg = off.message();
            let count = off.steps().unwrap_or(0);
            d.w(format!(
                "- smoothing off (`normal_smoothing_off`): {count} load step{} completed ({} \
                 contact updates in them); the next load step did not converge even after its \
                 cut-backs, its last attempt stopping with the contact set cycling{} (exit code \
                 {}). The diagnosis, quoted from the run:\n",
                if count == 1 { "" } else { "s" },
                num(off.reported("contact updates (total)")),
                cycle_updates(&msg)
                    .map_or(String::new(), |n| format!(" after {n} contact updates")),
                off.rec.rc.as_deref().unwrap_or("None")
            ));
            d.w(format!("  > {}\n", msg.replace('\n', "\n  > ")));
        }
        d.w("");
    }

    /// The Gmsh example: the cylinder on a block against Hertz.
    fn example_section(&self, d: &mut Doc, render: &Render) {
        let (ex1, ex2) = self.pair(&self.example);
        d.w("## Gmsh example: a cylinder on a block (Hertz line contact)\n");
        d.w(format!(
            "Not one of the paper's tests: `{}` presses a steel half-cylinder (R = 10 mm, \
             E = 210000 MPa, nu = 0.3) onto an aluminium block (E = 70000 MPa, nu = 0.33), \
             frictionless, in plane strain (one element through the thickness, u_z = 0 on both \
             faces), with 500 MPa on the cylinder's flat top (P = 10000 N per mm of length). Both \
             bodies come from the Gmsh mesh `run/gmsh/cylinder_on_block.msh` (hexahedra). `solver \
             post hertz` compares the nodal contact pressure (normal contact force over the \
             tributary area) with the Hertz line-contact solution p(x) = p0 sqrt(1 - x^2/a^2); no \
             limit is set (a coarse mesh, node-to-surface contact).\n",
            self.example_scene
        ));
        if ex1.rec.not_run() {
            d.w(format!("Not run: {}\n", ex1.message()));
        } else {
            let rc = ex1.rec.rc.as_deref().unwrap_or("");
            let mut line = format!("- 1 rank: exit code {rc}");
            if let Some(t) = ex1.rec.time {
                line += &format!(", wall time {t:.2} s (process)");
            }
            if let Some(steps) = ex1.steps() {
                line += &format!(
                    "; {steps} load step{} completed",
                    if steps == 1 { "" } else { "s" }
                );
            }
            let stopped = if rc != "0" {
                format!(" The run stopped: {}", code(&ex1.message()))
            } else {
                String::new()
            };
            d.w(format!("{line}.{stopped}"));
            let wall2 = match ex2.rec.time {
                Some(t) if ex2.completed() => format!(" (wall time {t:.2} s)"),
                _ => String::new(),
            };
            let result = ex1
                .result
                .as_ref()
                .map_or("missing".into(), |r| format!("[`{r}`]({r})"));
            d.w(format!(
                "- 2 ranks: {}{wall2} (`solver post compare`, every dataset; the 1-rank result is \
                 {result}).\n",
                self.two_ranks(&self.example)
            ));
            self.hertz_lines(d, ex1.result.as_deref());
        }
        self.pictures(d, &self.example, render);
    }

    /// The plastic example: a bolted clamp of two J2 plates with friction.
    fn plastic_section(&self, d: &mut Doc, render: &Render) {
        let name = PLASTIC_EXAMPLE;
        if !self.runs.iter().any(|r| r.0 == name) {
            return;
        }
        d.w("## Plastic example: a bolted clamp (J2 plasticity with friction)\n");
        d.w(
            "Not one of the paper's tests: `run/examples/bolted_clamp.toml` presses a stiff bolt \
             head onto two elastic-plastic plates (j2_plastic, small kinematics, yield stress 250, \
             linear isotropic hardening) until the upper plate yields under the head's edges, \
             then pulls the lower plate along x while the upper plate is held: the plate \
             interface (Coulomb) first sticks, then slips. A starting point for plastic contact \
             analyses; no exact answer is checked here (the J2 model is verified in \
             tests/plastic_*.rs).\n",
        );
        if self.run_lines(d, name) {
            self.pictures(d, name, render);
        }
    }

    /// The tetrahedral example: a bracket made with Gmsh's OpenCASCADE kernel.
    fn tet_section(&self, d: &mut Doc, render: &Render) {
        let name = TET_EXAMPLE;
        if !self.runs.iter().any(|r| r.0 == name) {
            return;
        }
        d.w(
            "## Tetrahedral example: a bracket bolted to a plate (OpenCASCADE part, J2, contact)\n",
        );
        d.w(
            "Not one of the paper's tests: `run/examples/bracket.toml` is a part an analyst \
             would bring from CAD: an L-shaped steel bracket built with Gmsh's OpenCASCADE kernel \
             (`run/gmsh/bracket.geo`: two boxes joined, the inner corner filleted, a bolt hole \
             drilled through the foot, the bolt head's bearing ring split off), meshed with \
             tetrahedra by `run/gmsh/make_examples` and read as composite 10-node tetrahedra \
             (j2_plastic, yield stress 250, 1% hardening, mean dilatation), resting on a base \
             plate of hexahedra (mortar contact, the foot's tet10 faces the slave). The bolt \
             holds its bearing ring; the top of the arm is pushed 1.6 mm sideways, toward the \
             foot's free end. The bend and the foot between it and the bolt yield (the section's \
             fully plastic moment sigma_y b t^2 / 4 = 31.3 N m is a push of about 830 N); the \
             foot's heel lifts off the plate while its toe, beyond the bolt, is pressed into it. \
             `tests/bracket.rs` checks the equilibrium of the reactions (1e-8 of the push), the \
             plastic zone (at the bend, none in the arm's upper half), the heel's lift and that \
             no slave node penetrates.\n",
        );
        if self.run_lines(d, name) {
            self.pictures(d, name, render);
        }
    }

    /// The 1- and 2-rank lines of an example; false when it was not run.
    fn run_lines(&self, d: &mut Doc, name: &str) -> bool {
        let (r1, r2) = self.pair(name);
        if r1.rec.not_run() {
            d.w(format!("Not run: {}\n", r1.message()));
            return false;
        }
        let rc = r1.rec.rc.as_deref().unwrap_or("");
        let mut line = format!("- 1 rank: exit code {rc}");
        if let Some(t) = r1.rec.time {
            line += &format!(", wall time {t:.2} s (process)");
        }
        if let Some(steps) = r1.steps() {
            line += &format!("; {steps} load steps completed");
        }
        d.w(format!("{line}."));
        let wall2 = match r2.rec.time {
            Some(t) if r2.completed() => format!(" (wall time {t:.2} s)"),
            _ => String::new(),
        };
        d.w(format!(
            "- 2 ranks: {}{wall2} (`solver post compare`, every dataset, plastic strain and \
             history included).\n",
            self.two_ranks(name)
        ));
        true
    }

    fn hertz_lines(&self, d: &mut Doc, result: Option<&str>) {
        let txt = &self.hertz_txt;
        if let (true, Some(rms), Some((p0, fe, pct))) =
            (self.hertz_rc == "0", hertz_rms(txt), hertz_peak(txt))
        {
            let half = hertz_half(txt).map_or(String::new(), |(a, b, c)| {
                format!("; half-width a = {a}, outermost node in contact at {b}, nodes {c} apart")
            });
            d.w(format!(
                "**Against Hertz:** RMS error of the nodal pressure {rms}% of p0 (nodes within \
                 1.5 a); peak pressure {fe} against p0 = {p0} ({pct}%){half}.\n"
            ));
        }
        d.w(format!(
            "`solver post hertz {}/{} -o {}/hertz.png`{}:\n",
            self.out.display(),
            result.unwrap_or("?"),
            self.out.display(),
            if self.hertz_rc == "0" {
                String::new()
            } else {
                format!(" (exit {})", self.hertz_rc)
            }
        ));
        d.w(format!(
            "```\n{}\n```\n",
            if txt.is_empty() { "(no output)" } else { txt }
        ));
        if self.out.join("hertz.png").exists() {
            d.w("![Hertz line contact: FE nodal pressure against Hertz](hertz.png)\n");
            d.w(HERTZ_CAPTION);
        }
    }
}
