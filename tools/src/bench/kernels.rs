//! The element kernels (`Assembly::internal_force` and `Assembly::diagonal`) on one core
//! for every integration / material combination on a structured cube mesh of hexahedra,
//! and the composite tet10's on the same cube split into tetrahedra (`tet_cube`), with a
//! memory-traffic model.

use crate::api::{local_mesh, parse, Assembly, LocalMesh, Mat3, Vec3, ZERO33};
use crate::config::Config;
use crate::stats::{time_it, Stat, Timing};
use std::hint::black_box;
use std::time::Instant;

/// Bytes per hexahedron the memory-traffic model charges, with no reuse of shared nodes:
/// coordinates 8 x 3 x 8 B, displacements 8 x 3 x 8 B read, result 8 x k x 8 B read and
/// written (k = 3 for the force, 9 for the 3x3 diagonal blocks), connectivity 8 x 4 B.
pub fn model_bytes(result_width: usize) -> f64 {
    model_bytes_of(8, result_width)
}

/// `model_bytes` for an element of `nodes` nodes (10 for the tetrahedron).
pub fn model_bytes_of(nodes: usize, result_width: usize) -> f64 {
    (nodes * 3 * 8 + nodes * 3 * 8 + 2 * nodes * result_width * 8 + nodes * 4) as f64
}

#[derive(Clone, Copy)]
pub struct Case {
    pub label: &'static str,
    pub integration: &'static str,
    pub volumetric: &'static str,
    pub large: bool,
    /// The composite tet10 on the cube split into tetrahedra.
    pub tet: bool,
}

impl Case {
    pub fn material(&self) -> &'static str {
        if self.large {
            "neo_hookean"
        } else {
            "linear_elastic"
        }
    }

    pub fn kinematics(&self) -> &'static str {
        if self.large {
            "large"
        } else {
            "small"
        }
    }
}

const CASES: [Case; 9] = [
    Case {
        label: "full, linear elastic (small)",
        integration: "full",
        volumetric: "standard",
        large: false,
        tet: false,
    },
    Case {
        label: "full + B-bar, linear elastic (small)",
        integration: "full",
        volumetric: "mean_dilatation",
        large: false,
        tet: false,
    },
    Case {
        label: "mean + hourglass, linear elastic (small)",
        integration: "mean",
        volumetric: "standard",
        large: false,
        tet: false,
    },
    Case {
        label: "full, neo-Hookean (large)",
        integration: "full",
        volumetric: "standard",
        large: true,
        tet: false,
    },
    Case {
        label: "full + F-bar, neo-Hookean (large)",
        integration: "full",
        volumetric: "mean_dilatation",
        large: true,
        tet: false,
    },
    Case {
        label: "mean + hourglass, neo-Hookean (large)",
        integration: "mean",
        volumetric: "standard",
        large: true,
        tet: false,
    },
    Case {
        label: "tet10 composite, linear elastic (small)",
        integration: "full",
        volumetric: "standard",
        large: false,
        tet: true,
    },
    Case {
        label: "tet10 + mean dilatation, linear elastic (small)",
        integration: "full",
        volumetric: "mean_dilatation",
        large: false,
        tet: true,
    },
    Case {
        label: "tet10 composite, neo-Hookean (large)",
        integration: "full",
        volumetric: "standard",
        large: true,
        tet: true,
    },
];

/// The tetrahedral cases' scene: the cube of `tet_cube` (its file `msh`), whose n / 2 cells
/// a side give 0.75 as many elements as the hexahedral cube of n.
fn tet_scene(msh: &std::path::Path, case: &Case) -> String {
    format!(
        r#"name = "bench_kernel_tet"
kinematics = "{kinematics}"

[gmsh]
file = "{msh}"

[[body]]
name = "cube"
gmsh_volume = "cube"
material = {{ model = "{model}", E = 1.0e6, nu = 0.3 }}
volumetric = "{volumetric}"

[time]
segments = [{{ end = 1.0, steps = 1 }}]
"#,
        kinematics = case.kinematics(),
        model = case.material(),
        volumetric = case.volumetric,
        msh = msh.display(),
    )
}

fn kernel_scene(n: usize, case: &Case) -> String {
    format!(
        r#"name = "bench_kernel"
kinematics = "{kinematics}"

[[body]]
name = "cube"
box = {{ min = [0.0, 0.0, 0.0], max = [1.0, 1.0, 1.0] }}
divisions = [{n}, {n}, {n}]
material = {{ model = "{model}", E = 1.0e6, nu = 0.3 }}
integration = "{integration}"
volumetric = "{volumetric}"

[time]
segments = [{{ end = 1.0, steps = 1 }}]
"#,
        kinematics = case.kinematics(),
        model = case.material(),
        integration = case.integration,
        volumetric = case.volumetric,
    )
}

/// A smooth displacement field with strains of order 1e-3 in every component.
pub fn smooth_field(coords: &[Vec3]) -> Vec<Vec3> {
    let a = 1e-3;
    coords
        .iter()
        .map(|x| {
            let (s0, c0) = (2.0 * x[0] + 0.3).sin_cos();
            let (s1, c1) = (1.5 * x[1] - 0.2).sin_cos();
            let (s2, c2) = (2.5 * x[2] + 0.1).sin_cos();
            [
                a * (s0 * c1 + 0.5 * s2),
                a * (c0 * s1 - 0.3 * c2 * s0),
                a * (s2 * c1 + 0.4 * s1 * c0),
            ]
        })
        .collect()
}

pub struct KernelResult {
    pub case: Case,
    pub operation: &'static str,
    pub elements: usize,
    pub nodes: usize,
    pub seconds: Stat,
    /// CPU time / wall time (median over the repeats).
    pub cpu_share: f64,
    pub model_bytes: f64,
    /// A checksum of the output, to show the result is not trivial.
    pub checksum: f64,
}

impl KernelResult {
    fn new(case: &Case, operation: &'static str, local: &LocalMesh, t: Timing) -> Self {
        KernelResult {
            case: *case,
            operation,
            elements: local.elements.len(),
            nodes: local.num_nodes(),
            seconds: t.wall,
            cpu_share: t.cpu_share,
            model_bytes: model_bytes_of(
                if case.tet { 10 } else { 8 },
                if operation == "diagonal" { 9 } else { 3 },
            ),
            checksum: 0.0,
        }
    }

    /// Elements per second.
    pub fn rate(&self) -> Stat {
        self.seconds.rate(self.elements as f64)
    }

    /// Nanoseconds per element.
    pub fn ns_per_element(&self) -> Stat {
        self.seconds.scaled(1e9 / self.elements as f64)
    }

    /// The traffic model's bandwidth at the median rate, GB/s.
    pub fn model_gbs(&self) -> f64 {
        self.model_bytes * self.rate().median / 1e9
    }
}

/// Every case of CASES, each operation timed on the same mesh.
pub fn run(cfg: &Config) -> Result<Vec<KernelResult>, String> {
    eprintln!(
        "bench: element kernels on {n}x{n}x{n} ({} / {} repeats)",
        cfg.force_repeats,
        cfg.diagonal_repeats,
        n = cfg.kernel_n
    );
    let mut out = Vec::new();
    let (mut hex, mut tet): (Option<LocalMesh>, Option<LocalMesh>) = (None, None);
    let msh = crate::tet_cube::write(
        &std::env::temp_dir().join("solver-bench-kernels"),
        (cfg.kernel_n / 2).max(1),
    )?;
    for case in CASES.iter() {
        let t = Instant::now();
        let problem = if case.tet {
            parse(&tet_scene(&msh, case))?
        } else {
            parse(&kernel_scene(cfg.kernel_n, case))?
        };
        // Every case of a kind has the same mesh: decompose it once.
        let slot = if case.tet { &mut tet } else { &mut hex };
        if slot.is_none() {
            *slot = Some(local_mesh(&problem)?);
        }
        let local = slot.as_ref().expect("built above");
        let setup = t.elapsed().as_secs_f64();
        // The Gauss-point kernels themselves: no body evaluated by element matrices.
        let asm = Assembly::new(local, &problem.body_models, &Default::default())?;
        let [force, diagonal] = time_case(cfg, case, &asm, local)?;
        eprintln!(
            "bench: kernel {:<42} internal_force {:7.1} ns/el, diagonal {:7.1} ns/el (setup {:.1} s)",
            case.label,
            force.ns_per_element().median,
            diagonal.ns_per_element().median,
            setup
        );
        out.extend([force, diagonal]);
    }
    Ok(out)
}

/// `internal_force` and `diagonal` of one case.
fn time_case(
    cfg: &Config,
    case: &Case,
    asm: &Assembly,
    local: &LocalMesh,
) -> Result<[KernelResult; 2], String> {
    let u = smooth_field(&local.coords);
    let nn = local.num_nodes();
    let mut failure = None;

    let mut f = vec![[0.0; 3]; nn];
    let timing = time_it(cfg.force_repeats, || {
        if let Err(e) = asm.internal_force(black_box(&u), black_box(&mut f)) {
            failure = Some(e.to_string());
        }
    });
    if let Some(e) = failure.take() {
        return Err(format!("{}: internal_force failed: {e}", case.label));
    }
    let mut force = KernelResult::new(case, "internal_force", local, timing);
    force.checksum = f.iter().flatten().map(|v| v.abs()).sum::<f64>();

    let mut d: Vec<Mat3> = vec![ZERO33; nn];
    let timing = time_it(cfg.diagonal_repeats, || {
        if let Err(e) = asm.diagonal(black_box(&u), black_box(&mut d)) {
            failure = Some(e.to_string());
        }
    });
    if let Some(e) = failure {
        return Err(format!("{}: diagonal failed: {e}", case.label));
    }
    let mut diagonal = KernelResult::new(case, "diagonal", local, timing);
    diagonal.checksum = d.iter().flatten().flatten().map(|v| v.abs()).sum::<f64>();
    Ok([force, diagonal])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The traffic model's totals as the report states them: 800 B for the force, 1568 B
    /// for the diagonal blocks.
    #[test]
    fn traffic_model() {
        assert_eq!(model_bytes(3), 800.0);
        assert_eq!(model_bytes(9), 1568.0);
    }

    /// Every case's scene is accepted by the solver's parser; the tetrahedral ones read
    /// six tet10 elements per cell.
    #[test]
    fn every_case_scene_parses() {
        let msh =
            crate::tet_cube::write(&std::env::temp_dir().join("solver-bench-kernels-test"), 2)
                .unwrap();
        for case in &CASES {
            let p = if case.tet {
                parse(&tet_scene(&msh, case)).unwrap()
            } else {
                parse(&kernel_scene(2, case)).unwrap()
            };
            let want = if case.tet { 48 } else { 8 };
            assert_eq!(p.mesh.num_elements(), want, "{}", case.label);
        }
    }
}
