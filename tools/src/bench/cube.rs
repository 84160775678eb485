//! CG iterations and wall time of a cube compression solved through the library's
//! analysis driver on one rank, against the exact uniaxial-stress field.

use crate::api::{
    dot, local_mesh, norm, parse, run_analysis, scale, sub, Assembly, Plan, Problem, RunOptions,
    SerialComm, Vec3,
};
use crate::config::Config;
use crate::kernels::smooth_field;
use crate::stats::{measure, time_it, Stat};
use std::hint::black_box;
use std::time::Instant;

pub const CUBE_E: f64 = 1.0e6;
pub const CUBE_NU: f64 = 0.3;
pub const CUBE_DISPLACEMENT: f64 = -0.01;
pub const CUBE_TOLERANCE: f64 = 1e-8;

fn cube_scene(n: usize) -> String {
    format!(
        r#"name = "bench_cube_{n}"
kinematics = "small"

[[body]]
name = "cube"
box = {{ min = [0.0, 0.0, 0.0], max = [1.0, 1.0, 1.0] }}
divisions = [{n}, {n}, {n}]
material = {{ model = "linear_elastic", E = {CUBE_E:e}, nu = {CUBE_NU} }}

[[node_set]]
name = "bottom"
plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}

[[node_set]]
name = "top"
plane = {{ point = [0.0, 1.0, 0.0], normal = [0.0, 1.0, 0.0] }}

[[node_set]]
name = "x0"
plane = {{ point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}

[[node_set]]
name = "z0"
plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }}

[[displacement]]
node_set = "bottom"
components = ["y"]
value = 0.0

[[displacement]]
node_set = "x0"
components = ["x"]
value = 0.0

[[displacement]]
node_set = "z0"
components = ["z"]
value = 0.0

[[displacement]]
node_set = "top"
components = ["y"]
value = {CUBE_DISPLACEMENT:e}

[time]
segments = [{{ end = 1.0, steps = 1 }}]

[solver]
tolerance = {CUBE_TOLERANCE:e}
preconditioner = "jacobi"
"#
    )
}

/// The number of independent directions among `v` (Gram-Schmidt with a relative
/// tolerance), at most 3.
fn independent_directions(v: &[Vec3]) -> usize {
    let mut basis: Vec<Vec3> = Vec::new();
    for d in v {
        let mut w = *d;
        for b in &basis {
            let p = dot(&w, b);
            w = sub(&w, &scale(b, p));
        }
        let len = norm(&w);
        if len > 1e-10 * norm(d).max(f64::MIN_POSITIVE) {
            basis.push(scale(&w, 1.0 / len));
        }
    }
    basis.len().min(3)
}

/// Free degrees of freedom: 3 per node minus the rank of the prescribed directions there.
fn unknowns(problem: &Problem) -> usize {
    let mut dirs: Vec<Vec<Vec3>> = vec![Vec::new(); problem.mesh.num_nodes()];
    for d in &problem.dirichlet {
        for &n in &problem.node_sets[d.node_set].nodes {
            dirs[n as usize].push(d.direction);
        }
    }
    dirs.iter().map(|v| 3 - independent_directions(v)).sum()
}

pub struct CubeResult {
    pub n: usize,
    pub elements: usize,
    pub nodes: usize,
    pub unknowns: usize,
    pub cg_iterations: u64,
    pub iterations_consistent: bool,
    pub run_wall: Stat,
    pub solve_wall: Stat,
    /// CPU time / wall time of the runs (median).
    pub cpu_share: f64,
    /// One `internal_force` call on the same mesh (for the kernel share of the solve).
    pub force_call: Stat,
    /// max |u - u_exact| over the nodes, relative to |top displacement|.
    pub max_error: f64,
}

impl CubeResult {
    pub fn iterations_per_cbrt_unknowns(&self) -> f64 {
        self.cg_iterations as f64 / (self.unknowns as f64).cbrt()
    }

    pub fn ms_per_iteration(&self) -> f64 {
        1e3 * self.solve_wall.median / self.cg_iterations.max(1) as f64
    }

    /// The element loop's share of the solve: iterations x one `internal_force` call over
    /// the solve time, fastest of each (the least disturbed by other load).
    pub fn kernel_share(&self) -> f64 {
        self.cg_iterations as f64 * self.force_call.min / self.solve_wall.min
    }
}

/// The exponent p of iterations ~ unknowns^p from cube `a` to cube `b`.
pub fn iteration_growth(a: &CubeResult, b: &CubeResult) -> f64 {
    (b.cg_iterations as f64 / a.cg_iterations as f64).ln()
        / (b.unknowns as f64 / a.unknowns as f64).ln()
}

/// Every cube size of the configuration.
pub fn run(cfg: &Config) -> Result<Vec<CubeResult>, String> {
    let mut cubes = Vec::new();
    for &(n, repeats) in &cfg.cube {
        let t = Instant::now();
        let c = cube(n, repeats)?;
        eprintln!(
            "bench: cube {n}^3: {} CG iterations, solve {:.3} s (median of {}), {:.1} s in all",
            c.cg_iterations,
            c.solve_wall.median,
            c.solve_wall.repeats,
            t.elapsed().as_secs_f64()
        );
        cubes.push(c);
    }
    Ok(cubes)
}

/// max |u - u_exact| / |d| against uniaxial stress: u_y = d y, u_x = -nu d x,
/// u_z = -nu d z (exact for trilinear hexes).
fn max_error(problem: &Problem, displacement: &[Vec3]) -> f64 {
    let d = CUBE_DISPLACEMENT;
    let mut max_error = 0.0f64;
    for (x, u) in problem.mesh.coords.iter().zip(displacement) {
        let exact = [-CUBE_NU * d * x[0], d * x[1], -CUBE_NU * d * x[2]];
        for i in 0..3 {
            max_error = max_error.max((u[i] - exact[i]).abs() / d.abs());
        }
    }
    max_error
}

fn cube(n: usize, repeats: usize) -> Result<CubeResult, String> {
    let problem = parse(&cube_scene(n))?;
    let opts = RunOptions {
        output: None,
        verbosity: 0,
        export_operator: None,
        final_state: true,
        partition: Default::default(),
    };
    let mut run_wall = Vec::new();
    let mut solve_wall = Vec::new();
    let mut iterations = Vec::new();
    let mut shares = Vec::new();
    let mut error = 0.0f64;
    for _ in 0..repeats.max(1) {
        let mut result = None;
        let (wall, cpu) = measure(&mut || {
            result = Some(run_analysis(&SerialComm, &problem, &opts));
        });
        shares.push(cpu / wall);
        let (summary, state) = result.expect("set by the closure")?;
        if let Some(f) = summary.failure {
            return Err(format!("cube {n}^3 failed: {f}"));
        }
        run_wall.push(summary.wall_time);
        solve_wall.push(summary.steps.iter().map(|s| s.wall_time).sum());
        iterations.push(summary.steps.iter().map(|s| s.cg_iterations).sum::<u64>());
        error = max_error(&problem, &state.displacement);
    }
    Ok(CubeResult {
        n,
        elements: problem.mesh.num_elements(),
        nodes: problem.mesh.num_nodes(),
        unknowns: unknowns(&problem),
        cg_iterations: iterations[0],
        iterations_consistent: iterations.iter().all(|&k| k == iterations[0]),
        run_wall: Stat::of(&run_wall),
        solve_wall: Stat::of(&solve_wall),
        cpu_share: Stat::of(&shares).median,
        force_call: force_call(&problem)?,
        max_error: error,
    })
}

/// The cost of one element loop on the problem's mesh, for the kernel's share of a CG
/// iteration.
fn force_call(problem: &Problem) -> Result<Stat, String> {
    let local = local_mesh(problem)?;
    // The element loop as the solver runs it (element matrices for linear bodies whose
    // elements share shapes).
    let plan = Plan::new(&problem.mesh, &problem.body_models);
    let asm = Assembly::new(&local, &problem.body_models, &plan)?;
    let u = smooth_field(&local.coords);
    let mut f = vec![[0.0; 3]; local.num_nodes()];
    Ok(time_it(5, || {
        let _ = asm.internal_force(black_box(&u), black_box(&mut f));
    })
    .wall)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 2^3 cube: 27 nodes, 81 directions; held are y on the 9 bottom and 9 top nodes,
    /// x on the 9 nodes at x = 0 and z on the 9 at z = 0: 36 directions, 45 unknowns.
    #[test]
    fn unknowns_of_a_small_cube() {
        let p = parse(&cube_scene(2)).unwrap();
        assert_eq!(unknowns(&p), 81 - 36);
        assert_eq!(
            independent_directions(&[[1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]),
            1
        );
        let skew = [
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 1.0],
            [1.0, 1.0, 1.0],
        ];
        assert_eq!(independent_directions(&skew), 3);
    }

    /// Iterations that double while the unknowns grow eightfold grow like unknowns^(1/3).
    #[test]
    fn growth_exponent() {
        let cube = |unknowns, cg_iterations| CubeResult {
            n: 0,
            elements: 0,
            nodes: 0,
            unknowns,
            cg_iterations,
            iterations_consistent: true,
            run_wall: Stat::of(&[1.0]),
            solve_wall: Stat::of(&[0.5, 1.0]),
            cpu_share: 1.0,
            force_call: Stat::of(&[0.001]),
            max_error: 0.0,
        };
        let (a, b) = (cube(1000, 100), cube(8000, 200));
        assert!((iteration_growth(&a, &b) - 1.0 / 3.0).abs() < 1e-15);
        // 200 iterations x 1 ms over the fastest solve of 0.5 s.
        assert!((b.kernel_share() - 0.4).abs() < 1e-15);
        assert!((b.ms_per_iteration() - 3.75).abs() < 1e-15);
    }
}
