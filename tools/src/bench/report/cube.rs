//! The CG cube compression section.

use super::json::{Rec, J};
use super::markdown::fmt_stat;
use crate::cube::iteration_growth;
use crate::results::Results;
use std::fmt::Write as _;

pub fn json(r: &Results) -> J {
    J::Arr(
        r.cubes
            .iter()
            .map(|c| {
                Rec::default()
                    .put("divisions", c.n)
                    .put("elements", c.elements)
                    .put("nodes", c.nodes)
                    .put("unknowns", c.unknowns)
                    .put("cg_iterations", c.cg_iterations)
                    .put("cg_iterations_same_every_repeat", c.iterations_consistent)
                    .put(
                        "iterations_per_cbrt_unknowns",
                        c.iterations_per_cbrt_unknowns(),
                    )
                    .put("repeats", c.solve_wall.repeats)
                    .stat("run_wall_s", &c.run_wall)
                    .stat("solve_wall_s", &c.solve_wall)
                    .put("cpu_share", c.cpu_share)
                    .put("ms_per_iteration", c.ms_per_iteration())
                    .stat("force_call_s", &c.force_call)
                    .put("kernel_share", c.kernel_share())
                    .put("max_error_rel", c.max_error)
                    .json()
            })
            .collect(),
    )
}

pub fn markdown(r: &Results, w: &mut String) {
    let _ = writeln!(w, "\n## CG: cube compression\n");
    let _ = writeln!(
        w,
        "Unit cube, linear elastic E = 1e6, nu = 0.3; u_y = 0 at y = 0, symmetry u_x = 0 at \
         x = 0 and u_z = 0 at z = 0, u_y = -0.01 at y = 1; one load step, tolerance 1e-8, \
         nodal block-Jacobi PCG (`preconditioner = \"jacobi\"` on every size). \"solve\" is the load step's wall time, \"run\" adds \
         decomposition and set-up. \"kernel share\" = iterations x one `internal_force` \
         call on that mesh / solve time (fastest of each). \"error\" = max |u - u_exact| / 0.01 against the \
         exact uniaxial-stress field.\n"
    );
    let _ = writeln!(
        w,
        "| mesh | unknowns | CG iterations | iterations / unknowns^(1/3) | n | solve s | run s | CPU/wall | ms / iteration | kernel share | error |"
    );
    let _ = writeln!(w, "|---|---:|---:|---:|---:|---|---|---:|---:|---:|---:|");
    for c in &r.cubes {
        let _ = writeln!(
            w,
            "| {n}^3 | {} | {}{} | {:.2} | {} | {} | {} | {:.2} | {:.2} | {:.0} % | {:.1e} |",
            c.unknowns,
            c.cg_iterations,
            if c.iterations_consistent {
                ""
            } else {
                " (varied)"
            },
            c.iterations_per_cbrt_unknowns(),
            c.solve_wall.repeats,
            fmt_stat(&c.solve_wall, 3),
            fmt_stat(&c.run_wall, 3),
            c.cpu_share,
            c.ms_per_iteration(),
            100.0 * c.kernel_share(),
            c.max_error,
            n = c.n,
        );
    }
    if let [a, .., b] = r.cubes.as_slice() {
        let _ = writeln!(
            w,
            "\nTrend: iterations grow like unknowns^{:.2} from {}^3 to {}^3 \
             (unknowns^(1/3), i.e. 1/h, is what Jacobi-preconditioned CG is expected to show).",
            iteration_growth(a, b),
            a.n,
            b.n
        );
    }
}
