//! Scenes too big for the machine: the estimate before any allocation, the refusal with
//! what would fit, `--force`, and the estimate against measured peaks.

use solver::memory::estimate_run;
use solver::scene::counts::scene_size;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("memory-tests/{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// run/examples/bar.toml with `divisions` replaced.
fn bar(d: &Path, divisions: [u32; 3]) -> PathBuf {
    let text = std::fs::read_to_string(root().join("run/examples/bar.toml")).unwrap();
    let line = text
        .lines()
        .find(|l| l.starts_with("divisions"))
        .expect("bar.toml has divisions");
    let text = text.replace(line, &format!("divisions = {divisions:?}"));
    let p = d.join(format!("bar_{}.toml", divisions[0]));
    std::fs::write(&p, text).unwrap();
    p
}

fn text(o: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&o.stdout).to_string(),
        String::from_utf8_lossy(&o.stderr).to_string(),
    )
}

fn no_abort(o: &Output, what: &str) {
    let (_, err) = text(o);
    assert!(
        o.status.code().is_some(),
        "{what}: ended by a signal: {err}"
    );
    for bad in ["panicked", "backtrace", "memory allocation of"] {
        assert!(!err.contains(bad), "{what}: '{bad}' in:\n{err}");
    }
}

/// 5000^3 elements: `check` prints the counts and the estimate without building the mesh,
/// `run` exits 2 with the estimate, the memory available and what would fit, and also
/// names the divisions whose counts exceed the 32-bit ids. Run under a 2 GiB address space
/// limit, so that building any part of the 10^11-element mesh would fail loudly instead.
#[test]
fn a_scene_of_10_to_the_11_elements_is_refused_before_allocating() {
    let d = dir("huge");
    let scene = bar(&d, [5000, 5000, 5000]);
    let limited = |args: &[&str]| {
        Command::new("prlimit")
            .arg(format!("--as={}", 2u64 << 30))
            .arg(env!("CARGO_BIN_EXE_solver"))
            .args(args)
            .output()
            .expect("prlimit runs")
    };
    let check = limited(&["check", scene.to_str().unwrap()]);
    no_abort(&check, "check");
    let (out, err) = text(&check);
    assert_eq!(check.status.code(), Some(2), "{out}{err}");
    assert!(
        out.contains("125000000000 elements, 125075015001 nodes"),
        "{out}"
    );
    assert!(out.contains("memory: estimated peak"), "{out}");
    assert!(err.contains("body[0].divisions"), "{err}");

    let h5 = d.join("huge.h5");
    let run = limited(&["run", scene.to_str().unwrap(), "-o", h5.to_str().unwrap()]);
    no_abort(&run, "run");
    let (_, err) = text(&run);
    assert_eq!(run.status.code(), Some(2), "{err}");
    for needle in [
        "error: not enough memory: 125000000000 elements",
        "per rank on 1 rank(s)",
        "is available (",
        "no number of ranks fits it",
        "--force",
        "body[0].divisions: the mesh would have 125000000000 elements",
    ] {
        assert!(err.contains(needle), "'{needle}' not in:\n{err}");
    }
    assert!(!h5.exists() && !d.join("huge.h5.tmp").exists());
}

/// A scene that fits the machine but not an address space limit set for the process
/// (`prlimit --as`) is refused before it allocates: exit 2 naming the limit. With
/// `--force` it runs, and the allocation that then fails ends it with a one-line error and
/// exit 1, not an abort.
#[test]
fn an_address_space_limit_refuses_the_run_and_force_runs_it() {
    let d = dir("prlimit");
    // 120^3 = 1728000 fully integrated elements of one shape: about 1.6 GiB (estimate),
    // against 1 GiB of address space, of which the libraries take part before the scene
    // is read.
    let scene = bar(&d, [120, 120, 120]);
    let size = scene_size(&scene, 1).expect("counts from the divisions");
    let need = estimate_run(&size.counts, 1, false).per_rank();
    let limit: u64 = 1 << 30;
    assert!(
        need > 1.2 * limit as f64,
        "the scene must need more: {need}"
    );
    let h5 = d.join("bar.h5");
    let run = |force: bool| {
        let mut c = Command::new("prlimit");
        c.arg(format!("--as={limit}"))
            .arg(env!("CARGO_BIN_EXE_solver"))
            .args(["run", scene.to_str().unwrap(), "-o", h5.to_str().unwrap()]);
        if force {
            c.arg("--force");
        }
        c.output().expect("prlimit runs")
    };
    let refused = run(false);
    no_abort(&refused, "run");
    let (_, err) = text(&refused);
    assert_eq!(refused.status.code(), Some(2), "{err}");
    assert!(
        err.contains("error: not enough memory: 1728000 elements"),
        "{err}"
    );
    assert!(err.contains("(address space limit 1.0 GiB"), "{err}");
    assert!(err.contains("it would fit on"), "{err}");
    assert!(!h5.exists());

    let forced = run(true);
    no_abort(&forced, "run --force");
    let (_, err) = text(&forced);
    assert!(err.contains("warning: --force: not enough memory"), "{err}");
    assert_eq!(forced.status.code(), Some(1), "{err}");
    assert!(err.contains("error: out of memory"), "{err}");
    assert!(!h5.exists(), "no result file looking complete");
}

/// The peak the solver reports ("peak memory X MiB per rank": the largest VmHWM over the
/// ranks) of the bench's block on block refined by `factor` on `ranks` ranks under mpirun,
/// with the scene's preconditioner or the one named.
fn measured_peak(d: &Path, factor: u32, ranks: usize, preconditioner: Option<&str>) -> f64 {
    let scene = root().join("run/scenes/bench/block_on_block.toml");
    let name = preconditioner.unwrap_or("default");
    let h5 = d.join(format!("n{}_np{ranks}_{name}.h5", 10 * factor));
    let mut args = vec!["--refine".to_string(), factor.to_string()];
    if let Some(p) = preconditioner {
        args.extend(["--preconditioner".to_string(), p.to_string()]);
    }
    run_under_mpirun(&scene, &args, ranks, &h5).1
}

/// Runs `scene` with `args` on `ranks` ranks under mpirun and returns the estimate and the
/// peak its done line prints ("peak memory X MiB per rank (estimated Y MiB)"), in bytes.
fn run_under_mpirun(scene: &Path, args: &[String], ranks: usize, h5: &Path) -> (f64, f64) {
    let o = Command::new(root().join("run/mpirun"))
        .args(["-np", &ranks.to_string()])
        .arg(env!("CARGO_BIN_EXE_solver"))
        .arg("run")
        .arg(scene)
        .args(args)
        .arg("-o")
        .arg(h5)
        .output()
        .expect("mpirun runs");
    let (_, err) = text(&o);
    assert!(o.status.success(), "{err}");
    let mib_after = |key: &str| -> f64 {
        let at = err.find(key).unwrap_or_else(|| panic!("'{key}' in {err}")) + key.len();
        let mib: f64 = err[at..]
            .split_whitespace()
            .next()
            .unwrap()
            .parse()
            .unwrap();
        mib * 1024.0 * 1024.0
    };
    (mib_after("(estimated "), mib_after("peak memory "))
}

/// The estimate is within 25% of the measured peak for the block on block at n = 10, 20,
/// 40 (the default preconditioner: Jacobi below 20000 nodes, multilevel at n = 40) on 1 and
/// 2 ranks. 25% is the issue's goal: the estimate decides whether a run may start, and a
/// quarter of margin either way still tells a run that fits from one that does not by far.
/// At the calibration the model was within -8% .. +14% of these peaks.
#[test]
fn the_estimate_is_within_25_percent_of_the_measured_peak() {
    let scene = root().join("run/scenes/bench/block_on_block.toml");
    let mut cases = Vec::new();
    for factor in [1, 2, 4] {
        let counts = scene_size(&scene, factor).expect("counts").counts;
        for ranks in [1, 2] {
            cases.push((factor, ranks, counts, None));
        }
    }
    estimates_within_25_percent("peaks", cases);
}

/// Runs each (refinement, ranks, counts, preconditioner by name) of the block on block and
/// asserts the model's estimate from the counts within 25% of the measured peak.
fn estimates_within_25_percent(
    name: &str,
    cases: Vec<(u32, usize, solver::memory::Counts, Option<&str>)>,
) {
    let d = dir(name);
    let mut lines = Vec::new();
    let mut worst: f64 = 0.0;
    for (factor, ranks, counts, preconditioner) in cases {
        let est = estimate_run(&counts, ranks, true).per_rank();
        let peak = measured_peak(&d, factor, ranks, preconditioner);
        let rel = est / peak - 1.0;
        worst = worst.max(rel.abs());
        lines.push(format!(
            "n = {}, {}, {ranks} rank(s): estimate {:.1} MiB, peak {:.1} MiB, {:+.1}%",
            10 * factor,
            preconditioner.unwrap_or("default"),
            est / 1048576.0,
            peak / 1048576.0,
            100.0 * rel
        ));
    }
    eprintln!("{}", lines.join("\n"));
    assert!(worst <= 0.25, "{}", lines.join("\n"));
}

/// The same for the multilevel preconditioner asked for by name, on one rank at n = 20 and
/// 40 (18522 and 137842 nodes), and on 2 ranks at n = 40: each rank holds its rows of the
/// first coarse operator and the rest of the hierarchy whole, so one rank shows the whole
/// of it and two ranks the split. The build used to hold the old hierarchy and the
/// triplets of the first coarse operator and its transpose at once: at n = 40 849.4 MiB
/// under mpirun against the estimated 629.1 (-25.9%: this test failed; at n = 80 on 2
/// ranks, too big for it, 4760.6 against 3489.2); then 122.4 and 650.1 MiB against 108.0
/// and 629.1 (-11.8%, -3.2%; n = 80 on 2 ranks 3074.1, +13.5%). Since the first coarse
/// operator is written in place and the prolongator's products merged by rows (no
/// triplet lists): 99.2 and 557.7 MiB against 95.2 and 533.4 (-4.0%, -4.4%; n = 80 on 2
/// ranks 2509.8 against 2751.0, +9.6%). With element matrices (the blocks' elements share
/// a few shapes): 71.0 and 346.0 MiB against 66.1 and 301.0 (-6.9%, -13.0%; n = 80 on 2
/// ranks 1575.5 against 1798.4, +14.1%). Since each rank keeps only its rows of the first
/// coarse operator: see `memory::model` and docs/memory.md's table.
#[test]
fn the_multilevel_estimate_is_within_25_percent_of_the_measured_peak() {
    let scene = root().join("run/scenes/bench/block_on_block.toml");
    let mut cases = Vec::new();
    for (factor, ranks) in [(2, 1), (4, 1), (4, 2)] {
        let mut counts = scene_size(&scene, factor).expect("counts").counts;
        counts.two_level = false;
        counts.multilevel = true;
        cases.push((factor, ranks, counts, Some("multilevel")));
    }
    estimates_within_25_percent("peaks-multilevel", cases);
}

/// The estimate within 25% of the peak on unstructured Gmsh meshes, where the multilevel
/// hierarchy's first coarse level is counted on the mesh (`precond::multilevel::size`): the
/// plate with a hole (run/scenes/bench/plate_with_hole.toml: hexahedra split from
/// tetrahedra, 10.9 nodes per aggregate, its first coarse level slow, its factor of 1.5
/// million entries declined as too dear since 2026-12-01: `factor_choice`) on 1 and 2 ranks, and the Hertz example x2 (one element thick, 3.4 nodes per
/// aggregate, factored) on 1 and 2 ranks, each with the default preconditioner (multilevel
/// there). The same 25% as the generated blocks, for the same reason. Before the first
/// level was counted on the mesh: 66.1 and 51.6 MiB against 128.9 and 113.8 (-49%, -55%),
/// and 42.2 and 37.6 against 71.3 and 63.1 (-41%, -40%); since: -0.4%, -0.4%, -17.8%,
/// -20.4% (docs/memory.md's table). The x2 mesh comes from run/gmsh/make_examples 2 (Gmsh)
/// when missing. And on one rank tests/adjust.rs's two rings of 10-node tetrahedra (Gmsh,
/// 17064 nodes, 21.0 nodes per aggregate, factored): 36% low while 20 nodes per aggregate
/// was the threshold of a factored level, -7.3% since (`POOR_AGGREGATE_NODES`). Measured
/// 2026-11-30 with the constraint rows counted: +4.7%, +6.0%, -12.5%, -16.5%, +16.7%; the
/// rings +11.2% since a 10-node tetrahedron's geometry is counted as its own (1392 bytes,
/// not a hexahedron's 1904). With the plate's factor declined and the first coarse level's
/// build counted (13 bytes an entry): -1.2%, -1.5%, -12.7%, -16.3%, +13.7%.
#[test]
fn the_estimate_is_within_25_percent_on_gmsh_meshes() {
    let d = dir("gmsh");
    let x2 = root().join("run/examples/cylinder_on_block_x2.toml");
    if !x2.exists() || !root().join("run/gmsh/cylinder_on_block_x2.msh").exists() {
        let status = Command::new(root().join("run/gmsh/make_examples"))
            .arg("2")
            .status()
            .expect("run/gmsh/make_examples runs");
        assert!(status.success(), "run/gmsh/make_examples 2 failed");
    }
    let plate = root().join("run/scenes/bench/plate_with_hole.toml");
    let rings = d.join("rings.toml");
    let mesh = crate::common::gmsh(
        &root().join("run/tet/rings.geo"),
        &crate::adjust::FINE,
        d.join("rings.msh"),
    );
    std::fs::write(&rings, crate::adjust::scene(&mesh)).unwrap();
    let runs = [(&plate, 1), (&plate, 2), (&x2, 1), (&x2, 2), (&rings, 1)];
    scenes_within_25_percent(&d, &runs);
}

/// The estimate within 25% of the peak on generated blocks of elongated elements, whose
/// multilevel aggregates are not the cubes' 27 nodes (weakly coupled diagonal neighbours
/// are not aggregated: `preflight::aggregated_as_counted`), so the first coarse level
/// is counted on the mesh once it is built: a block of 24^3 elements of 0.083 x 0.042 x
/// 0.083 (4.5 nodes an aggregate, its first coarse level slow; its factor, too dear, is
/// declined since 2026-12-01), estimated
/// 33.1 MiB from its divisions alone against a peak of 193.6 (-83%), and one of 40 x 20 x
/// 20 elements of 0.1 x 0.05 x 0.05 (10.2 nodes an aggregate, not factored), -27% from
/// its divisions; measured since: +16%, -18% and -18% (2 ranks); with the factor
/// declined and the level's build counted: +3.1%, -2.0%, -9.7%. The same 25% as above.
#[test]
fn the_estimate_is_within_25_percent_on_elongated_blocks() {
    let d = dir("elongated");
    let scene = |name: &str, max: [f64; 3], divisions: [u32; 3]| {
        let path = d.join(format!("{name}.toml"));
        let text = format!(
            "name = \"{name}\"\n\
             [[body]]\nname = \"block\"\n\
             box = {{ min = [0.0, 0.0, 0.0], max = [{}, {}, {}] }}\n\
             divisions = [{}, {}, {}]\n\
             material = {{ model = \"linear_elastic\", E = 1000.0, nu = 0.3 }}\n\
             [[node_set]]\nname = \"bottom\"\nbody = \"block\"\n\
             plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}\n\
             [[node_set]]\nname = \"top\"\nbody = \"block\"\n\
             plane = {{ point = [0.0, {}, 0.0], normal = [0.0, 1.0, 0.0] }}\n\
             [[displacement]]\nnode_set = \"bottom\"\ncomponents = [\"x\", \"y\", \"z\"]\nvalue = 0.0\n\
             [[displacement]]\nnode_set = \"top\"\ncomponents = [\"y\"]\n\
             function = [[0.0, 0.0], [1.0, -0.01]]\n\
             [time]\nsegments = [{{ end = 1.0, steps = 1 }}]\n\
             [solver]\ntolerance = 1e-8\npreconditioner = \"multilevel\"\n",
            max[0], max[1], max[2], divisions[0], divisions[1], divisions[2], max[1]
        );
        std::fs::write(&path, text).unwrap();
        path
    };
    let slow = scene("flat_cells", [2.0, 1.0, 2.0], [24, 24, 24]);
    let long = scene("long_cells", [4.0, 1.0, 1.0], [40, 20, 20]);
    for path in [&slow, &long] {
        let size = scene_size(path, 1).expect("counted from the divisions");
        assert!(
            !solver::preflight::aggregated_as_counted(&size),
            "{}: elongated",
            path.display()
        );
    }
    // Blocks of cubes aggregate as counted (the model's calibration).
    let cubes = scene_size(&root().join("run/scenes/bench/block_on_block.toml"), 1);
    assert!(solver::preflight::aggregated_as_counted(
        &cubes.expect("counted")
    ));
    scenes_within_25_percent(&d, &[(&slow, 1), (&long, 1), (&long, 2)]);
}

/// Runs each scene on its ranks under mpirun; every estimate within 25% of the run's peak.
fn scenes_within_25_percent(d: &Path, runs: &[(&PathBuf, usize)]) {
    let mut lines = Vec::new();
    let mut worst: f64 = 0.0;
    for &(scene, ranks) in runs {
        let name = scene.file_stem().unwrap().to_string_lossy().to_string();
        let h5 = d.join(format!("{name}_np{ranks}.h5"));
        let (est, peak) = run_under_mpirun(scene, &[], ranks, &h5);
        let rel = est / peak - 1.0;
        worst = worst.max(rel.abs());
        lines.push(format!(
            "{name}, {ranks} rank(s): estimate {:.1} MiB, peak {:.1} MiB, {:+.1}%",
            est / 1048576.0,
            peak / 1048576.0,
            100.0 * rel
        ));
    }
    eprintln!("{}", lines.join("\n"));
    assert!(worst <= 0.25, "{}", lines.join("\n"));
}

/// The estimate within 25% of the peak on plastic runs on one rank, whose integration-point
/// states (two of 13 values per point) the estimate counts: the plane-strain punch at 48 x
/// 48 pressed by a die (run/scenes/plasticity/contact_punch_48.toml, the full tangent under
/// `auto`) and a cube of 10-node tetrahedra stretched past yield (run/tet/cube.geo at
/// h = 0.125, 4679 nodes, the full tangent). Measured: +3.5% and -6.2% (the punch +20.4%
/// while the tangent's entries were taken as a hexahedral interior's 243 per node, where a
/// slab one element thick has 162). At h = 0.08
/// (16194 nodes; `auto` refuses the tangent's factor and runs multilevel: a 29 s run, not
/// repeated here) `solver run` estimated 307.1 MiB (the tangent, as if taken) against a
/// peak of 86.2; then 79.2 against 82.3 (the hierarchy with its factored first level, and
/// the states, which the restart file now takes a round at a time); since the factor's
/// work is bounded (`factor_choice`: 45 V-cycles there, declined) 59.6 against 65.2, in
/// 18.2 s against 15.7 with the factor (636 and 633 CG iterations).
#[test]
fn the_estimate_is_within_25_percent_on_plastic_runs() {
    let d = dir("plastic");
    let plastic = r#"{ model = "j2_plastic", E = 1000.0, nu = 0.3, yield_stress = 1.0, isotropic_hardening = 10.0 }"#;
    let mesh = crate::tet_gmsh_solve::cube_mesh(&d, 0.125, 1);
    let cube = d.join("cube.toml");
    std::fs::write(
        &cube,
        crate::tet_gmsh_solve::scene(&mesh, "small", plastic, 0.01, 1),
    )
    .unwrap();
    let punch = root().join("run/scenes/plasticity/contact_punch_48.toml");
    scenes_within_25_percent(&d, &[(&punch, 1), (&cube, 1)]);
}

/// The full tangent on more ranks than one: every rank gathers the tangent's triplets, and
/// its peak is the model's 40 bytes an entry (the gathered triplets and their u32 copy) as
/// on one rank. An L-bracket meshed all-hexahedral by Gmsh (tests/fixtures/gmsh/l_bracket.geo
/// at h = 5.4: 13910 nodes), J2 plastic, its arm pushed past yield: `auto` factors the full
/// tangent (41190 unknowns, 7.2 million entries in the factor). Measured before a rank freed
/// its own triplets once gathered and the gather was kept in one buffer: 313.4 MiB per rank
/// on 2 ranks, higher than 1 rank's 304.8, against 226.5 estimated (-27.7%); since, with the
/// factor counted on the mesh and the old factor's pages given back before a rebuild
/// (`memory::guard::give_back_freed`): +20.0% (1 rank) and +16.4% (2 ranks). The same 25% as above.
#[test]
fn the_estimate_is_within_25_percent_on_the_full_tangent_over_two_ranks() {
    let d = dir("full_tangent");
    let mesh = crate::common::gmsh(
        &root().join("tests/fixtures/gmsh/l_bracket.geo"),
        &["-setnumber", "h", "5.4", "-setnumber", "hex", "1"],
        d.join("l_bracket.msh"),
    );
    let scene = d.join("l_bracket.toml");
    std::fs::write(
        &scene,
        format!(
            "name = \"l_bracket\"\nkinematics = \"small\"\n\
             [gmsh]\nfile = \"{}\"\n\
             [[body]]\nname = \"bracket\"\ngmsh_volume = \"bracket\"\n\
             material = {{ model = \"j2_plastic\", E = 200e3, nu = 0.3, yield_stress = 250.0, isotropic_hardening = 2e3 }}\n\
             volumetric = \"mean_dilatation\"\n\
             [[node_set]]\nname = \"foot_end\"\ngmsh_group = \"foot_end\"\n\
             [[node_set]]\nname = \"arm_top\"\ngmsh_group = \"arm_top\"\n\
             [[displacement]]\nnode_set = \"foot_end\"\ncomponents = [\"x\", \"y\", \"z\"]\nvalue = 0.0\n\
             [[displacement]]\nnode_set = \"arm_top\"\ncomponents = [\"x\"]\n\
             function = [[0.0, 0.0], [1.0, 1.0]]\n\
             [time]\nsegments = [{{ end = 1.0, steps = 4 }}]\n",
            mesh.display()
        ),
    )
    .unwrap();
    scenes_within_25_percent(&d, &[(&scene, 1), (&scene, 2)]);
}

/// A slender cantilever of cubic elements (a generated block of 120 x 12 x 12, 20449 nodes:
/// multilevel under `auto`), clamped at one end and loaded at the other: its first coarse
/// level's V-cycle reduces the error by 0.61 a cycle, where the blocks of cubes the model
/// counts from their divisions give 0.56. While a rate above 0.6 had the level factored
/// (1.49 million entries) the peak was 68.7 MiB against 47.0 estimated (-32%), and at
/// 240 x 24 x 24 391.6 against 156.9 (-60%, a factor of 22.2 million entries, the run
/// twice as long as without it); no factor below 0.63 (`cycle::SLOW_RATE`): -4% on 1
/// and 2 ranks. The same 25% as above.
#[test]
fn the_estimate_is_within_25_percent_on_a_slender_cantilever() {
    let d = dir("cantilever");
    let scene = cantilever(&d, "cantilever", [120, 12, 12]);
    scenes_within_25_percent(&d, &[(&scene, 1), (&scene, 2)]);
}

/// A cantilever of 60 x 6 x 6 clamped at x = 0, a downward traction on its tip, in
/// `divisions` elements.
fn cantilever(d: &Path, name: &str, divisions: [u32; 3]) -> PathBuf {
    let scene = d.join(format!("{name}.toml"));
    std::fs::write(
        &scene,
        format!(
            "name = \"{name}\"\nkinematics = \"small\"\n\
             [[body]]\nname = \"beam\"\n\
             box = {{ min = [0.0, 0.0, 0.0], max = [60.0, 6.0, 6.0] }}\n\
             divisions = [{}, {}, {}]\n\
             material = {{ model = \"linear_elastic\", E = 200e3, nu = 0.3 }}\n\
             [[node_set]]\nname = \"root\"\n\
             plane = {{ point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}\n\
             [[side_set]]\nname = \"tip\"\n\
             plane = {{ point = [60.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}\n\
             [[displacement]]\nnode_set = \"root\"\ncomponents = [\"x\", \"y\", \"z\"]\nvalue = 0.0\n\
             [[traction]]\nside_set = \"tip\"\nvector = [0.0, -10.0, 0.0]\n\
             [time]\nsegments = [{{ end = 1.0, steps = 1 }}]\n",
            divisions[0], divisions[1], divisions[2]
        ),
    )
    .unwrap();
    scene
}

/// A cantilever of 1 x 0.25 x 0.25 elements (60 x 24 x 24, 38125 nodes): its first coarse
/// level's V-cycle is slow (rate 0.86), and its factor would cost the work of 169 V-cycles
/// (`factor_choice::FACTOR_WORK` allows 30), so the run declines it and says so. With the
/// factor (16.2 million entries) it took 30 CG iterations, 3.25 s and 275 MiB against 34,
/// 1.19 s and 82 MiB without, and the estimate, which did not foresee it, was 74% low.
/// The estimate counts the same work on the mesh (`multilevel::size`): within the same 25%
/// as above on 1 and 2 ranks (+14.6% and +5.6% measured).
#[test]
fn a_cantilever_of_elongated_elements_declines_its_coarse_factor() {
    let d = dir("elongated-cantilever");
    let scene = cantilever(&d, "elongated", [60, 24, 24]);
    let o = Command::new(env!("CARGO_BIN_EXE_solver"))
        .args(["run", "-v"])
        .arg(&scene)
        .arg("-o")
        .arg(d.join("verbose.h5"))
        .output()
        .expect("solver runs");
    let (_, err) = text(&o);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("(its factor not formed: the work of "),
        "{err}"
    );
    assert!(!err.contains("factored sparse"), "{err}");
    scenes_within_25_percent(&d, &[(&scene, 1), (&scene, 2)]);
}

/// A stack of 24 blocks (20 x 20 x 1 elements each, 21168 nodes: `auto` builds the
/// multilevel hierarchy from its node count) whose coarse cells each hold several bodies,
/// where a two-level coarse space would be refused: `solver check` estimates the
/// multilevel hierarchy counted from the divisions; counted on the loaded mesh (its first
/// coarse level poorly aggregated, factored) the estimate is larger, and that is the one a
/// Gmsh mesh gets. (When `auto` took two-level at this size and passed it over for
/// multilevel here, the estimate had been the two-level one at first: a stack of 128
/// blocks, 146112 nodes, 139.8 MiB estimated against 1549 MiB measured on 2 ranks.)
#[test]
fn a_stack_of_bodies_sharing_coarse_cells_is_estimated_as_the_multilevel_run() {
    let d = dir("stack");
    let mut s = String::from("name = \"stack24\"\nkinematics = \"small\"\n");
    for i in 0..24 {
        let (z0, z1) = (0.05 * i as f64, 0.05 * (i + 1) as f64);
        s += &format!(
            "[[body]]\nname = \"b{i}\"\nbox = {{ min = [0.0, 0.0, {z0}], max = [1.0, 1.0, {z1}] }}\n\
             divisions = [20, 20, 1]\nmaterial = {{ model = \"linear_elastic\", E = 1.0e6, nu = 0.3 }}\n\
             [[side_set]]\nname = \"b{i}_top\"\nbody = \"b{i}\"\nplane = {{ point = [0.0, 0.0, {z1}], normal = [0.0, 0.0, 1.0] }}\n\
             [[side_set]]\nname = \"b{i}_bottom\"\nbody = \"b{i}\"\nplane = {{ point = [0.0, 0.0, {z0}], normal = [0.0, 0.0, 1.0] }}\n"
        );
        if i > 0 {
            s += &format!(
                "[[contact]]\nmaster = \"b{}_top\"\nslave = \"b{i}_bottom\"\n",
                i - 1
            );
        }
    }
    s += "[[node_set]]\nname = \"base\"\nbody = \"b0\"\nplane = { point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }\n\
          [[displacement]]\nnode_set = \"base\"\ncomponents = [\"x\", \"y\", \"z\"]\nvalue = 0.0\n\
          [[pressure]]\nside_set = \"b23_top\"\nvalue = 1.0e3\n\
          [time]\nsegments = [{ end = 1.0, steps = 1 }]\n";
    let scene = d.join("stack24.toml");
    std::fs::write(&scene, s).unwrap();
    let size = scene_size(&scene, 1).expect("counted from the divisions");
    assert_eq!(size.counts.nodes, 24 * 21 * 21 * 2);
    assert!(!size.counts.two_level && size.counts.multilevel);
    let p = solver::scene::load_scene(&scene).unwrap();
    assert!(solver::precond::coarse::refusal(&p).is_some());
    let loaded = solver::preflight::loaded_size(&p);
    assert!(loaded.counts.multilevel && !loaded.counts.two_level);
    let mut two_level = size.counts;
    (two_level.two_level, two_level.multilevel) = (true, false);
    let (two, multi) = (
        estimate_run(&two_level, 2, true).per_rank(),
        estimate_run(&loaded.counts, 2, true).per_rank(),
    );
    assert!(multi > two, "multilevel {multi} against two-level {two}");
    let o = Command::new(env!("CARGO_BIN_EXE_solver"))
        .args(["check", scene.to_str().unwrap(), "--ranks", "2"])
        .output()
        .unwrap();
    let (out, err) = text(&o);
    assert_eq!(o.status.code(), Some(0), "{out}{err}");
    let counted = estimate_run(&size.counts, 2, true).per_rank();
    assert!(multi > counted, "loaded {multi} against counted {counted}");
    let mib = format!(
        "estimated peak {:.1} MiB per rank",
        counted / (1024.0 * 1024.0)
    );
    assert!(out.contains(&mib), "{mib} not in:\n{out}");
}
