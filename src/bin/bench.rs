//! `bench`: the performance benchmark (reported, never asserted).
//!
//! Measures, on this machine:
//! 1. STREAM-like memory bandwidth (copy and triad over arrays much larger than the caches),
//! 2. the element kernels (`Assembly::internal_force` and `Assembly::diagonal`) on one
//!    core for every integration / material combination on a structured cube mesh, with a
//!    memory-traffic model and the fraction of the measured bandwidth it implies,
//! 3. CG iterations and wall time of a cube compression solved through `run::run`,
//! 4. the contact search (`MasterSurface::new`, the BVH of master faces, and
//!    `MasterSurface::search` of every slave node) on two stacked blocks with non-matching
//!    meshes, about 1e5 slave nodes against 1e5 master faces (1e4 in quick mode),
//! 5. the block-on-block scene (`run/scenes/bench/block_on_block.toml`) refined to n = 10,
//!    20, 40 elements per edge (n = 10 in quick mode), run by `target/release/solver` under
//!    `run/mpirun` on 1 and 2 ranks with each preconditioner (`--preconditioner jacobi` and
//!    `two_level`): CG iterations, contact updates, wall time, peak memory, total contact
//!    force, the coarse space, the two-level / Jacobi ratios of iterations and time, the
//!    difference of the contact forces, the 2-rank speed-up and whether the 1- and 2-rank
//!    result files are bitwise identical; and `solver check --ranks 2, 3` of the largest size
//!    (the partition),
//! 6. CalculiX (`ccx`, when installed) on the same problem, from an input deck written here,
//!    on 2 threads within 5 minutes per size: its wall time and total force beside ours.
//!
//! Writes `<out>/results.json` and `<out>/report.md` (default `out/bench`) and prints the
//! report. Usage: `bench [--quick] [--out DIR]`. Normally started by `run/bench`.
//!
//! `bench --large [--ranks 2|1|1,2] [--out DIR]` runs only the block on block at n = 80
//! (about 10^6 elements) with the two-level preconditioner, after a memory estimate from
//! n = 20 and 40 on the same rank count, and puts it into the same two files as a section
//! of its own (the other sections are left as they are; a later normal run keeps it).

use partition::Decomposition;
use serde::de::{Deserialize, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::ser::{SerializeMap, SerializeSeq};
use serde::{Serialize, Serializer};
use solver::comm::SerialComm;
use solver::math::{Mat3, Vec3, ZERO33};
use solver::mesh::local::LocalMesh;
use solver::output::ResultFile;
use solver::problem::Problem;
use solver::run::{run, RunOptions};
use solver::scene::{load_scene_refined, parse_scene};
use solver::solver::assembly::Assembly;
use std::fmt::Write as _;
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitCode, Stdio};
use std::time::{Duration, Instant};

// ---------------------------------------------------------------------------------------
// Settings
// ---------------------------------------------------------------------------------------

/// Sizes and repeat counts of one benchmark run.
struct Config {
    quick: bool,
    out: PathBuf,
    /// f64 entries per STREAM array.
    stream_len: usize,
    stream_repeats: usize,
    /// Elements per edge of the kernel mesh.
    kernel_n: usize,
    force_repeats: usize,
    diagonal_repeats: usize,
    /// (elements per edge, repeats) of the CG cube compressions.
    cube: Vec<(usize, usize)>,
    /// (master faces per edge, repeats) of the contact search: m^2 master faces, m^2
    /// slave nodes.
    contact: (usize, usize),
    /// (refinement factor, repeats) of the block-on-block solver runs.
    block: Vec<(usize, usize)>,
    /// Refinement factor whose decomposition over PARTITION_RANKS is reported.
    partition_refine: usize,
    /// Refinement factors CalculiX runs at (with the repeats of `block`).
    calculix: Vec<usize>,
}

impl Config {
    fn new(quick: bool, out: PathBuf) -> Self {
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
}

/// Bytes per element the memory-traffic model charges, with no reuse of shared nodes:
/// coordinates 8 x 3 x 8 B, displacements 8 x 3 x 8 B read, result 8 x k x 8 B read and
/// written (k = 3 for the force, 9 for the 3x3 diagonal blocks), connectivity 8 x 4 B.
fn model_bytes(result_width: usize) -> f64 {
    (8 * 3 * 8 + 8 * 3 * 8 + 2 * 8 * result_width * 8 + 8 * 4) as f64
}

// ---------------------------------------------------------------------------------------
// Statistics and a small ordered JSON value
// ---------------------------------------------------------------------------------------

/// Median, minimum and maximum of repeated measurements.
#[derive(Clone, Copy, Debug)]
struct Stat {
    median: f64,
    min: f64,
    max: f64,
    repeats: usize,
}

impl Stat {
    fn of(samples: &[f64]) -> Stat {
        let mut s = samples.to_vec();
        s.sort_by(f64::total_cmp);
        let n = s.len();
        let median = if n == 0 {
            f64::NAN
        } else if n % 2 == 1 {
            s[n / 2]
        } else {
            0.5 * (s[n / 2 - 1] + s[n / 2])
        };
        Stat {
            median,
            min: s.first().copied().unwrap_or(f64::NAN),
            max: s.last().copied().unwrap_or(f64::NAN),
            repeats: n,
        }
    }

    /// `k / t` of a time statistic (the minimum rate comes from the maximum time).
    fn rate(&self, k: f64) -> Stat {
        Stat {
            median: k / self.median,
            min: k / self.max,
            max: k / self.min,
            repeats: self.repeats,
        }
    }

    /// `k * t`.
    fn scaled(&self, k: f64) -> Stat {
        Stat {
            median: k * self.median,
            min: k * self.min,
            max: k * self.max,
            repeats: self.repeats,
        }
    }
}

/// A JSON value whose objects keep their keys in insertion order.
#[derive(Clone)]
enum J {
    Null,
    Bool(bool),
    Int(i64),
    Num(f64),
    Str(String),
    Arr(Vec<J>),
    Obj(Vec<(String, J)>),
}

impl Serialize for J {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            J::Null => s.serialize_unit(),
            J::Bool(b) => s.serialize_bool(*b),
            J::Int(i) => s.serialize_i64(*i),
            J::Num(x) if x.is_finite() => s.serialize_f64(*x),
            J::Num(_) => s.serialize_unit(),
            J::Str(t) => s.serialize_str(t),
            J::Arr(v) => {
                let mut seq = s.serialize_seq(Some(v.len()))?;
                for x in v {
                    seq.serialize_element(x)?;
                }
                seq.end()
            }
            J::Obj(kv) => {
                let mut map = s.serialize_map(Some(kv.len()))?;
                for (k, v) in kv {
                    map.serialize_entry(k, v)?;
                }
                map.end()
            }
        }
    }
}

/// JSON read back in document order (the large section is merged into an earlier
/// results.json and carried over by a later run without reordering the file).
impl<'de> Deserialize<'de> for J {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<J, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = J;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a JSON value")
            }
            fn visit_unit<E>(self) -> Result<J, E> {
                Ok(J::Null)
            }
            fn visit_none<E>(self) -> Result<J, E> {
                Ok(J::Null)
            }
            fn visit_bool<E>(self, b: bool) -> Result<J, E> {
                Ok(J::Bool(b))
            }
            fn visit_i64<E>(self, i: i64) -> Result<J, E> {
                Ok(J::Int(i))
            }
            fn visit_u64<E>(self, u: u64) -> Result<J, E> {
                Ok(i64::try_from(u).map_or(J::Num(u as f64), J::Int))
            }
            fn visit_f64<E>(self, x: f64) -> Result<J, E> {
                Ok(J::Num(x))
            }
            fn visit_str<E>(self, t: &str) -> Result<J, E> {
                Ok(J::Str(t.to_string()))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut a: A) -> Result<J, A::Error> {
                let mut v = Vec::new();
                while let Some(x) = a.next_element()? {
                    v.push(x);
                }
                Ok(J::Arr(v))
            }
            fn visit_map<A: MapAccess<'de>>(self, mut a: A) -> Result<J, A::Error> {
                let mut kv = Vec::new();
                while let Some(entry) = a.next_entry::<String, J>()? {
                    kv.push(entry);
                }
                Ok(J::Obj(kv))
            }
        }
        d.deserialize_any(V)
    }
}

impl J {
    /// The value of `key` in an object.
    fn get(&self, key: &str) -> Option<&J> {
        match self {
            J::Obj(kv) => kv.iter().find(|(k, _)| k == key).map(|(_, v)| v),
            _ => None,
        }
    }

    /// Sets `key` of an object (in place when present, else at the end).
    fn set(&mut self, key: &str, v: J) {
        if let J::Obj(kv) = self {
            match kv.iter_mut().find(|(k, _)| k == key) {
                Some(e) => e.1 = v,
                None => kv.push((key.to_string(), v)),
            }
        }
    }
}

impl From<f64> for J {
    fn from(x: f64) -> J {
        J::Num(x)
    }
}
impl From<usize> for J {
    fn from(x: usize) -> J {
        J::Int(x as i64)
    }
}
impl From<u64> for J {
    fn from(x: u64) -> J {
        J::Int(x as i64)
    }
}
impl From<bool> for J {
    fn from(x: bool) -> J {
        J::Bool(x)
    }
}
impl From<&str> for J {
    fn from(x: &str) -> J {
        J::Str(x.to_string())
    }
}
impl From<String> for J {
    fn from(x: String) -> J {
        J::Str(x)
    }
}
impl<T: Into<J>> From<Option<T>> for J {
    fn from(x: Option<T>) -> J {
        x.map_or(J::Null, Into::into)
    }
}

/// Builder of a flat JSON record.
#[derive(Default)]
struct Rec(Vec<(String, J)>);

impl Rec {
    fn put(mut self, key: &str, v: impl Into<J>) -> Self {
        self.0.push((key.to_string(), v.into()));
        self
    }

    /// `<prefix>_median`, `<prefix>_min`, `<prefix>_max`.
    fn stat(mut self, prefix: &str, s: &Stat) -> Self {
        self.0.push((format!("{prefix}_median"), J::Num(s.median)));
        self.0.push((format!("{prefix}_min"), J::Num(s.min)));
        self.0.push((format!("{prefix}_max"), J::Num(s.max)));
        self
    }

    /// Appends the fields of `other`.
    fn extend(mut self, other: Rec) -> Self {
        self.0.extend(other.0);
        self
    }

    fn json(self) -> J {
        J::Obj(self.0)
    }
}

/// Wall time per call, and the calling thread's CPU time over wall time.
#[derive(Clone, Copy, Debug)]
struct Timing {
    wall: Stat,
    /// Median of CPU time / wall time over the samples: about 1 when the core was ours,
    /// lower when other processes took it (the wall time is then inflated).
    cpu_share: f64,
}

impl Timing {
    fn of(samples: &[(f64, f64)]) -> Timing {
        let wall: Vec<f64> = samples.iter().map(|s| s.0).collect();
        let share: Vec<f64> = samples.iter().map(|s| s.1 / s.0).collect();
        Timing {
            wall: Stat::of(&wall),
            cpu_share: Stat::of(&share).median,
        }
    }
}

/// Times `f` `repeats` times after one untimed warm-up call.
fn time_it(repeats: usize, mut f: impl FnMut()) -> Timing {
    f();
    let samples: Vec<(f64, f64)> = (0..repeats).map(|_| measure(&mut f)).collect();
    Timing::of(&samples)
}

/// (wall seconds, thread CPU seconds) of one call.
fn measure(f: &mut impl FnMut()) -> (f64, f64) {
    let c = thread_cpu_time();
    let t = Instant::now();
    f();
    (t.elapsed().as_secs_f64(), thread_cpu_time() - c)
}

/// CPU time of the calling thread in seconds (`CLOCK_THREAD_CPUTIME_ID`); NaN elsewhere
/// than on Linux or when the call fails.
#[cfg(target_os = "linux")]
fn thread_cpu_time() -> f64 {
    use std::ffi::{c_int, c_long};
    #[repr(C)]
    struct Timespec {
        tv_sec: c_long,
        tv_nsec: c_long,
    }
    extern "C" {
        fn clock_gettime(clock: c_int, ts: *mut Timespec) -> c_int;
    }
    const CLOCK_THREAD_CPUTIME_ID: c_int = 3;
    let mut ts = Timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime only writes the timespec it is given, which lives on our stack
    // and has the C layout of `struct timespec` on 64-bit Linux (two longs).
    let rc = unsafe { clock_gettime(CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    if rc == 0 {
        ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
    } else {
        f64::NAN
    }
}

#[cfg(not(target_os = "linux"))]
fn thread_cpu_time() -> f64 {
    f64::NAN
}

/// (all, steal) jiffies of the whole machine from the `cpu` line of /proc/stat: time the
/// hypervisor gave to other guests shows as steal, which thread CPU clocks do not see.
fn cpu_jiffies() -> Option<(u64, u64)> {
    let s = std::fs::read_to_string("/proc/stat").ok()?;
    let line = s.lines().find(|l| l.starts_with("cpu "))?;
    let v: Vec<u64> = line
        .split_whitespace()
        .skip(1)
        .filter_map(|x| x.parse().ok())
        .collect();
    // user nice system idle iowait irq softirq steal [guest guest_nice, included in user]
    let all: u64 = v.iter().take(8).sum();
    Some((all, v.get(7).copied().unwrap_or(0)))
}

/// The 1-, 5- and 15-minute load averages, as /proc/loadavg gives them.
fn load_average() -> Option<String> {
    let s = std::fs::read_to_string("/proc/loadavg").ok()?;
    Some(s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
}

// ---------------------------------------------------------------------------------------
// Machine description
// ---------------------------------------------------------------------------------------

struct Machine {
    cpu_model: String,
    cache: String,
    logical_cpus: usize,
    physical_cores: Option<usize>,
    date: String,
    git_commit: Option<String>,
    git_dirty: Option<bool>,
    load_start: Option<String>,
    jiffies_start: Option<(u64, u64)>,
}

fn command_output(cmd: &str, args: &[&str]) -> Option<String> {
    let out = std::process::Command::new(cmd).args(args).output().ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

fn machine() -> Machine {
    let info = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    let field = |name: &str| -> Option<String> {
        info.lines()
            .filter_map(|l| l.split_once(':'))
            .find(|(k, _)| k.trim() == name)
            .map(|(_, v)| v.trim().to_string())
    };
    let processors = info
        .lines()
        .filter(|l| l.split(':').next().map(str::trim) == Some("processor"))
        .count();
    let logical_cpus = if processors > 0 {
        processors
    } else {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    };
    // Physical cores: distinct (physical id, core id) pairs, when the kernel reports them.
    let mut cores = std::collections::BTreeSet::new();
    let mut phys = String::new();
    for l in info.lines() {
        if let Some((k, v)) = l.split_once(':') {
            match k.trim() {
                "physical id" => phys = v.trim().to_string(),
                "core id" => {
                    cores.insert((phys.clone(), v.trim().to_string()));
                }
                _ => {}
            }
        }
    }
    let git_commit = command_output("git", &["rev-parse", "--short", "HEAD"]);
    let git_dirty = git_commit
        .as_ref()
        .and_then(|_| command_output("git", &["status", "--porcelain", "--untracked-files=no"]))
        .map(|s| !s.is_empty());
    Machine {
        cpu_model: field("model name").unwrap_or_else(|| "unknown".into()),
        cache: field("cache size").unwrap_or_else(|| "unknown".into()),
        logical_cpus,
        physical_cores: (!cores.is_empty()).then_some(cores.len()),
        date: solver::output::rfc3339_now(),
        git_commit,
        git_dirty,
        load_start: load_average(),
        jiffies_start: cpu_jiffies(),
    }
}

// ---------------------------------------------------------------------------------------
// 1a. Memory bandwidth
// ---------------------------------------------------------------------------------------

struct Stream {
    kernel: &'static str,
    threads: usize,
    array_bytes: usize,
    /// Bytes counted per pass (STREAM convention: no write-allocate traffic).
    bytes_per_pass: usize,
    gbs: Stat,
}

fn copy(dst: &mut [f64], src: &[f64]) {
    for (d, s) in dst.iter_mut().zip(src) {
        *d = *s;
    }
}

fn triad(a: &mut [f64], b: &[f64], c: &[f64], s: f64) {
    for ((a, b), c) in a.iter_mut().zip(b).zip(c) {
        *a = b + s * c;
    }
}

fn triad_threads(a: &mut [f64], b: &[f64], c: &[f64], s: f64, threads: usize) {
    let chunk = a.len().div_ceil(threads);
    std::thread::scope(|scope| {
        for ((a, b), c) in a
            .chunks_mut(chunk)
            .zip(b.chunks(chunk))
            .zip(c.chunks(chunk))
        {
            scope.spawn(move || triad(a, b, c, s));
        }
    });
}

fn memory_bandwidth(cfg: &Config, threads: usize) -> Vec<Stream> {
    let n = cfg.stream_len;
    let mut a = vec![1.0f64; n];
    let mut b = vec![2.0f64; n];
    let c = vec![0.5f64; n];
    let bytes = n * 8;
    let mut out = Vec::new();
    let mut record = |kernel, threads, arrays: usize, t: Stat| {
        out.push(Stream {
            kernel,
            threads,
            array_bytes: bytes,
            bytes_per_pass: arrays * bytes,
            gbs: t.rate(arrays as f64 * bytes as f64 / 1e9),
        })
    };
    let t = time_it(cfg.stream_repeats, || {
        copy(black_box(&mut b), black_box(&a));
    })
    .wall;
    record("copy", 1, 2, t);
    let t = time_it(cfg.stream_repeats, || {
        triad(black_box(&mut a), black_box(&b), black_box(&c), 3.0);
    })
    .wall;
    record("triad", 1, 3, t);
    if threads > 1 {
        let t = time_it(cfg.stream_repeats, || {
            triad_threads(
                black_box(&mut a),
                black_box(&b),
                black_box(&c),
                3.0,
                threads,
            );
        })
        .wall;
        record("triad", threads, 3, t);
    }
    black_box((&a, &b));
    out
}

// ---------------------------------------------------------------------------------------
// 1b. Element kernels
// ---------------------------------------------------------------------------------------

#[derive(Clone, Copy)]
struct Case {
    label: &'static str,
    integration: &'static str,
    volumetric: &'static str,
    large: bool,
}

const CASES: [Case; 6] = [
    Case {
        label: "full, linear elastic (small)",
        integration: "full",
        volumetric: "standard",
        large: false,
    },
    Case {
        label: "full + B-bar, linear elastic (small)",
        integration: "full",
        volumetric: "mean_dilatation",
        large: false,
    },
    Case {
        label: "mean + hourglass, linear elastic (small)",
        integration: "mean",
        volumetric: "standard",
        large: false,
    },
    Case {
        label: "full, neo-Hookean (large)",
        integration: "full",
        volumetric: "standard",
        large: true,
    },
    Case {
        label: "full + F-bar, neo-Hookean (large)",
        integration: "full",
        volumetric: "mean_dilatation",
        large: true,
    },
    Case {
        label: "mean + hourglass, neo-Hookean (large)",
        integration: "mean",
        volumetric: "standard",
        large: true,
    },
];

fn kernel_scene(n: usize, case: &Case) -> String {
    let (kinematics, model) = if case.large {
        ("large", "neo_hookean")
    } else {
        ("small", "linear_elastic")
    };
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
        integration = case.integration,
        volumetric = case.volumetric,
    )
}

fn parse(text: &str) -> Result<Problem, String> {
    parse_scene(text, "bench", "bench").map_err(|e| format!("generated scene rejected: {e}"))
}

fn local_mesh(problem: &Problem) -> Result<LocalMesh, String> {
    let mesh = &problem.mesh;
    let d = Decomposition::partition(mesh.num_nodes(), &mesh.elements, 1)
        .map_err(|e| format!("partition failed: {e}"))?;
    Ok(LocalMesh::new(mesh, &d, 0))
}

/// A smooth displacement field with strains of order 1e-3 in every component.
fn smooth_field(coords: &[Vec3]) -> Vec<Vec3> {
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

struct KernelResult {
    case: Case,
    operation: &'static str,
    elements: usize,
    nodes: usize,
    seconds: Stat,
    /// CPU time / wall time (median over the repeats).
    cpu_share: f64,
    model_bytes: f64,
    /// A checksum of the output, to show the result is not trivial.
    checksum: f64,
}

fn kernels(cfg: &Config) -> Result<Vec<KernelResult>, String> {
    let mut out = Vec::new();
    let mut local: Option<LocalMesh> = None;
    for case in CASES.iter() {
        let t = Instant::now();
        let problem = parse(&kernel_scene(cfg.kernel_n, case))?;
        // Every case has the same mesh: decompose it once.
        if local.is_none() {
            local = Some(local_mesh(&problem)?);
        }
        let local = local.as_ref().expect("built above");
        let setup = t.elapsed().as_secs_f64();
        let asm = Assembly::new(local, &problem.body_models);
        let u = smooth_field(&local.coords);
        let nn = local.num_nodes();
        let ne = local.elements.len();

        let mut f = vec![[0.0; 3]; nn];
        let mut failure = None;
        let timing = time_it(cfg.force_repeats, || {
            if let Err(e) = asm.internal_force(black_box(&u), black_box(&mut f)) {
                failure = Some(e.to_string());
            }
        });
        if let Some(e) = failure.take() {
            return Err(format!("{}: internal_force failed: {e}", case.label));
        }
        let checksum = f.iter().flatten().map(|v| v.abs()).sum::<f64>();
        out.push(KernelResult {
            case: *case,
            operation: "internal_force",
            elements: ne,
            nodes: nn,
            seconds: timing.wall,
            cpu_share: timing.cpu_share,
            model_bytes: model_bytes(3),
            checksum,
        });

        let mut d: Vec<Mat3> = vec![ZERO33; nn];
        let dtiming = time_it(cfg.diagonal_repeats, || {
            if let Err(e) = asm.diagonal(black_box(&u), black_box(&mut d)) {
                failure = Some(e.to_string());
            }
        });
        if let Some(e) = failure {
            return Err(format!("{}: diagonal failed: {e}", case.label));
        }
        let dsum = d.iter().flatten().flatten().map(|v| v.abs()).sum::<f64>();
        out.push(KernelResult {
            case: *case,
            operation: "diagonal",
            elements: ne,
            nodes: nn,
            seconds: dtiming.wall,
            cpu_share: dtiming.cpu_share,
            model_bytes: model_bytes(9),
            checksum: dsum,
        });
        eprintln!(
            "bench: kernel {:<42} internal_force {:7.1} ns/el, diagonal {:7.1} ns/el (setup {:.1} s)",
            case.label,
            timing.wall.median / ne as f64 * 1e9,
            dtiming.wall.median / ne as f64 * 1e9,
            setup
        );
    }
    Ok(out)
}

// ---------------------------------------------------------------------------------------
// 2. CG on a cube compression
// ---------------------------------------------------------------------------------------

const CUBE_E: f64 = 1.0e6;
const CUBE_NU: f64 = 0.3;
const CUBE_DISPLACEMENT: f64 = -0.01;
const CUBE_TOLERANCE: f64 = 1e-8;

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

/// Free degrees of freedom: 3 per node minus the rank of the prescribed directions there.
fn unknowns(problem: &Problem) -> usize {
    let mut dirs: Vec<Vec<Vec3>> = vec![Vec::new(); problem.mesh.num_nodes()];
    for d in &problem.dirichlet {
        for &n in &problem.node_sets[d.node_set].nodes {
            dirs[n as usize].push(d.direction);
        }
    }
    let rank = |v: &[Vec3]| -> usize {
        // Gram-Schmidt with a relative tolerance.
        let mut basis: Vec<Vec3> = Vec::new();
        for d in v {
            let mut w = *d;
            for b in &basis {
                let p = solver::math::dot(&w, b);
                w = solver::math::sub(&w, &solver::math::scale(b, p));
            }
            let len = solver::math::norm(&w);
            if len > 1e-10 * solver::math::norm(d).max(f64::MIN_POSITIVE) {
                basis.push(solver::math::scale(&w, 1.0 / len));
            }
        }
        basis.len()
    };
    dirs.iter().map(|v| 3 - rank(v).min(3)).sum()
}

struct CubeResult {
    n: usize,
    elements: usize,
    nodes: usize,
    unknowns: usize,
    cg_iterations: u64,
    iterations_consistent: bool,
    run_wall: Stat,
    solve_wall: Stat,
    /// CPU time / wall time of the runs (median).
    cpu_share: f64,
    /// One `internal_force` call on the same mesh (for the kernel share of the solve).
    force_call: Stat,
    /// max |u - u_exact| over the nodes, relative to |top displacement|.
    max_error: f64,
}

fn cube(n: usize, repeats: usize) -> Result<CubeResult, String> {
    let problem = parse(&cube_scene(n))?;
    let opts = RunOptions {
        output: None,
        verbosity: 0,
    };
    let mut run_wall = Vec::new();
    let mut solve_wall = Vec::new();
    let mut iterations = Vec::new();
    let mut shares = Vec::new();
    let mut max_error = 0.0f64;
    for _ in 0..repeats.max(1) {
        let mut result = None;
        let (wall, cpu) = measure(&mut || result = Some(run(&SerialComm, &problem, &opts)));
        shares.push(cpu / wall);
        let (summary, state) = result.expect("set by the closure")?;
        if let Some(f) = summary.failure {
            return Err(format!("cube {n}^3 failed: {f}"));
        }
        run_wall.push(summary.wall_time);
        solve_wall.push(summary.steps.iter().map(|s| s.wall_time).sum());
        iterations.push(summary.steps.iter().map(|s| s.cg_iterations).sum::<u64>());
        // Uniaxial stress: u_y = d y, u_x = -nu d x, u_z = -nu d z (exact for trilinear hexes).
        let d = CUBE_DISPLACEMENT;
        max_error = 0.0;
        for (x, u) in problem.mesh.coords.iter().zip(&state.displacement) {
            let exact = [-CUBE_NU * d * x[0], d * x[1], -CUBE_NU * d * x[2]];
            for i in 0..3 {
                max_error = max_error.max((u[i] - exact[i]).abs() / d.abs());
            }
        }
    }
    // The cost of one element loop on this mesh, for the kernel's share of a CG iteration.
    let local = local_mesh(&problem)?;
    let asm = Assembly::new(&local, &problem.body_models);
    let u = smooth_field(&local.coords);
    let mut f = vec![[0.0; 3]; local.num_nodes()];
    let force_call = time_it(5, || {
        let _ = asm.internal_force(black_box(&u), black_box(&mut f));
    })
    .wall;
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
        force_call,
        max_error,
    })
}

// ---------------------------------------------------------------------------------------
// 3. Contact search
// ---------------------------------------------------------------------------------------

/// Height of each block of the contact-search scene; the interface is at y = CONTACT_H.
const CONTACT_H: f64 = 0.1;
/// Amplitude of the pseudo-random normal offset of the slave nodes, as a fraction of the
/// pair's normal search tolerance (offsets are uniform in [-a, a] times the tolerance).
const CONTACT_GAP_FRACTION: f64 = 0.5;

/// Two blocks stacked at y = CONTACT_H: the lower block's top (m x m faces) is the master
/// surface, the upper block's bottom ((m - 1) x (m - 1) elements, m^2 nodes, so the meshes
/// do not match) gives the slave nodes.
fn contact_scene(m: usize) -> String {
    let k = m - 1;
    let h = CONTACT_H;
    let h2 = 2.0 * CONTACT_H;
    format!(
        r#"name = "bench_contact_{m}"
kinematics = "small"

[[body]]
name = "lower"
box = {{ min = [0.0, 0.0, 0.0], max = [1.0, {h:?}, 1.0] }}
divisions = [{m}, 1, {m}]
material = {{ model = "linear_elastic", E = 1.0e6, nu = 0.3 }}

[[body]]
name = "upper"
box = {{ min = [0.0, {h:?}, 0.0], max = [1.0, {h2:?}, 1.0] }}
divisions = [{k}, 1, {k}]
material = {{ model = "linear_elastic", E = 1.0e6, nu = 0.3 }}

[[side_set]]
name = "lower_top"
body = "lower"
plane = {{ point = [0.0, {h:?}, 0.0], normal = [0.0, 1.0, 0.0] }}

[[side_set]]
name = "upper_bottom"
body = "upper"
plane = {{ point = [0.0, {h:?}, 0.0], normal = [0.0, 1.0, 0.0] }}

[[contact]]
master = "lower_top"
slave = "upper_bottom"

[time]
segments = [{{ end = 1.0, steps = 1 }}]
"#
    )
}

/// A uniform pseudo-random number in [0, 1) from an integer (splitmix64), so the slave
/// offsets are the same on every run and machine.
fn unit_hash(i: u64) -> f64 {
    let mut z = i.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

struct ContactResult {
    /// Master faces per edge (the slave block has one division fewer).
    m: usize,
    master_faces: usize,
    slave_nodes: usize,
    face_size: f64,
    normal_tolerance: f64,
    tangential_tolerance: f64,
    /// Largest |normal offset| given to a slave node.
    max_offset: f64,
    /// Scene generation + parse_scene (mesh, side sets, pair), once.
    parse_s: f64,
    /// Current slave positions (the offsets), once.
    perturb_s: f64,
    build: Stat,
    search: Stat,
    total: Stat,
    cpu_share: f64,
    /// Interactions found (the same in every repeat, else `consistent` is false).
    found: usize,
    /// Slave nodes inside the master surface's extent and within the normal tolerance.
    expected: usize,
    /// Of the expected nodes, how many found a face.
    expected_found: usize,
    consistent: bool,
    /// max |gap - offset| over the interactions found.
    max_gap_error: f64,
    /// max distance of the contact point from the slave node's foot on the plane.
    max_point_error: f64,
}

fn contact_search(m: usize, repeats: usize) -> Result<ContactResult, String> {
    use solver::contact::search::{Interaction, MasterSurface};
    let t = Instant::now();
    let problem = parse(&contact_scene(m))?;
    let parse_s = t.elapsed().as_secs_f64();
    let pair = problem
        .contacts
        .first()
        .ok_or("the contact scene has no contact pair")?;

    // Current positions: master nodes where the mesh has them, slave nodes offset along y
    // by a pseudo-random gap (both penetration and separation) within the normal tolerance.
    let t = Instant::now();
    let mut position = problem.mesh.coords.clone();
    let amplitude = CONTACT_GAP_FRACTION * pair.normal_tolerance;
    let mut offsets = Vec::with_capacity(pair.slave_nodes.len());
    for &n in &pair.slave_nodes {
        let d = amplitude * (2.0 * unit_hash(n as u64) - 1.0);
        position[n as usize][1] += d;
        offsets.push(d);
    }
    let slave_x: Vec<Vec3> = pair
        .slave_nodes
        .iter()
        .map(|&n| position[n as usize])
        .collect();
    let perturb_s = t.elapsed().as_secs_f64();

    // Which slave nodes must find a face: those over the master surface's extent in x and
    // z (all of them here) with an offset within the normal tolerance.
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for f in &pair.face_nodes {
        for &n in f {
            let x = position[n as usize];
            for (k, i) in [0usize, 2].into_iter().enumerate() {
                lo[k] = lo[k].min(x[i]);
                hi[k] = hi[k].max(x[i]);
            }
        }
    }
    let inside: Vec<bool> = slave_x
        .iter()
        .zip(&offsets)
        .map(|(x, d)| {
            (lo[0]..=hi[0]).contains(&x[0])
                && (lo[1]..=hi[1]).contains(&x[2])
                && d.abs() <= pair.normal_tolerance
        })
        .collect();

    let mut build = Vec::new();
    let mut search = Vec::new();
    let mut total = Vec::new();
    let mut shares = Vec::new();
    let mut result: Vec<Option<Interaction>> = Vec::new();
    let mut counts = Vec::new();
    // One untimed warm-up round, then the timed repeats.
    for r in 0..=repeats.max(1) {
        let c0 = thread_cpu_time();
        let t0 = Instant::now();
        let surface = MasterSurface::new(pair, |n| position[n as usize]);
        let t1 = Instant::now();
        let found: Vec<Option<Interaction>> = slave_x
            .iter()
            .map(|x| surface.search(black_box(x)))
            .collect();
        let t2 = Instant::now();
        let cpu = thread_cpu_time() - c0;
        counts.push(found.iter().flatten().count());
        if r == 0 {
            result = found;
            continue;
        }
        build.push((t1 - t0).as_secs_f64());
        search.push((t2 - t1).as_secs_f64());
        total.push((t2 - t0).as_secs_f64());
        shares.push(cpu / (t2 - t0).as_secs_f64());
        drop(black_box(found));
    }

    // Check the warm-up round's answers: the contact point is the slave node's foot on the
    // plane y = CONTACT_H and the gap is its offset.
    let surface = MasterSurface::new(pair, |n| position[n as usize]);
    let mut max_gap_error = 0.0f64;
    let mut max_point_error = 0.0f64;
    for ((it, x), d) in result.iter().zip(&slave_x).zip(&offsets) {
        if let Some(it) = it {
            max_gap_error = max_gap_error.max((it.gap - d).abs());
            let p = surface
                .point(it.face, &it.s)
                .expect("the surface holds every face");
            let foot = [x[0], CONTACT_H, x[2]];
            max_point_error =
                max_point_error.max(solver::math::norm(&solver::math::sub(&p, &foot)));
        }
    }
    let expected = inside.iter().filter(|&&b| b).count();
    let expected_found = result
        .iter()
        .zip(&inside)
        .filter(|(it, &b)| b && it.is_some())
        .count();
    Ok(ContactResult {
        m,
        master_faces: pair.face_nodes.len(),
        slave_nodes: pair.slave_nodes.len(),
        face_size: pair.face_size,
        normal_tolerance: pair.normal_tolerance,
        tangential_tolerance: pair.tangential_tolerance,
        max_offset: offsets.iter().fold(0.0f64, |a, d| a.max(d.abs())),
        parse_s,
        perturb_s,
        build: Stat::of(&build),
        search: Stat::of(&search),
        total: Stat::of(&total),
        cpu_share: Stat::of(&shares).median,
        found: counts[0],
        expected,
        expected_found,
        consistent: counts.iter().all(|&c| c == counts[0]),
        max_gap_error,
        max_point_error,
    })
}

// ---------------------------------------------------------------------------------------
// Subprocesses
// ---------------------------------------------------------------------------------------

/// The repository the bench was built from: the scene and `run/mpirun` are found there.
fn repo_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The `solver` binary built beside this one (`run/bench` builds both).
fn solver_exe() -> Result<PathBuf, String> {
    let exe =
        std::env::current_exe().map_err(|e| format!("cannot locate the bench binary: {e}"))?;
    let solver = exe.with_file_name("solver");
    if solver.is_file() {
        Ok(solver)
    } else {
        Err(format!(
            "{} not found: build it first (`cargo build --release --bin solver`; run/bench does)",
            solver.display()
        ))
    }
}

/// How a subprocess ended.
struct Finished {
    /// Exit code; `None` when a signal ended it.
    code: Option<i32>,
    /// Why the bench stopped it (time or memory limit), if it did.
    stopped: Option<String>,
    /// Wall-clock seconds from spawn to exit.
    wall: f64,
    /// Largest VmHWM of the process itself (not its children) seen while it ran, bytes.
    peak_rss: Option<f64>,
}

/// (VmHWM, VmRSS) of a process in bytes, from /proc/<pid>/status.
fn process_memory(pid: u32) -> Option<(f64, f64)> {
    let s = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let field = |name: &str| -> Option<f64> {
        let l = s.lines().find(|l| l.starts_with(name))?;
        let kb: f64 = l.split_whitespace().nth(1)?.parse().ok()?;
        Some(kb * 1024.0)
    };
    Some((field("VmHWM:")?, field("VmRSS:")?))
}

/// MemAvailable of /proc/meminfo in bytes.
fn memory_available() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/meminfo").ok()?;
    let l = s.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: f64 = l.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0)
}

/// When the bench stops a subprocess.
#[derive(Clone, Copy, Debug)]
struct Limits {
    /// Wall-clock seconds.
    timeout_s: f64,
    /// Resident memory of the process itself (not its children), bytes.
    rss_limit: Option<f64>,
    /// The machine's MemAvailable falling below this many bytes (the process tree under
    /// mpirun is not followed: this guards the machine, whoever holds the memory).
    min_available: Option<f64>,
}

impl Limits {
    fn timeout(timeout_s: f64) -> Self {
        Limits {
            timeout_s,
            rss_limit: None,
            min_available: None,
        }
    }
}

/// Runs `cmd` with its standard output and error in the given files, stopping it at
/// `limits`.
fn run_limited(
    cmd: &mut Command,
    stdout: &Path,
    stderr: &Path,
    limits: &Limits,
) -> Result<Finished, String> {
    let open = |p: &Path| {
        std::fs::File::create(p).map_err(|e| format!("cannot create {}: {e}", p.display()))
    };
    cmd.stdin(Stdio::null())
        .stdout(open(stdout)?)
        .stderr(open(stderr)?);
    let start = Instant::now();
    let mut child = cmd
        .spawn()
        .map_err(|e| format!("cannot start {:?}: {e}", cmd.get_program()))?;
    let pid = child.id();
    let mut peak: Option<f64> = None;
    let mut stopped = None;
    let status = loop {
        if let Some(s) = child
            .try_wait()
            .map_err(|e| format!("waiting for {pid}: {e}"))?
        {
            break s;
        }
        if let Some((hwm, rss)) = process_memory(pid) {
            peak = Some(peak.map_or(hwm, |p| p.max(hwm)));
            if let Some(limit) = limits.rss_limit.filter(|&l| rss > l) {
                stopped = Some(format!(
                    "stopped at {:.0} MiB resident (limit {:.0} MiB)",
                    rss / MIB,
                    limit / MIB
                ));
            }
        }
        if let Some(floor) = limits.min_available {
            if let Some(avail) = memory_available().filter(|&a| a < floor) {
                stopped.get_or_insert(format!(
                    "stopped when the machine had {:.0} MiB available (floor {:.0} MiB)",
                    avail / MIB,
                    floor / MIB
                ));
            }
        }
        let elapsed = start.elapsed().as_secs_f64();
        if stopped.is_none() && elapsed > limits.timeout_s {
            stopped = Some(format!("stopped after {:.0} s", limits.timeout_s));
        }
        if stopped.is_some() {
            break stop(&mut child)?;
        }
        // Sleep about 1 % of the time so far: the wall time is exact to about that.
        std::thread::sleep(Duration::from_secs_f64((0.01 * elapsed).clamp(0.002, 0.1)));
    };
    Ok(Finished {
        code: status.code(),
        stopped,
        wall: start.elapsed().as_secs_f64(),
        peak_rss: peak,
    })
}

/// SIGTERM (mpirun passes it on to its ranks), then SIGKILL if it has not ended in 10 s.
fn stop(child: &mut Child) -> Result<std::process::ExitStatus, String> {
    let pid = child.id();
    let _ = Command::new("kill")
        .args(["-TERM", &pid.to_string()])
        .stderr(Stdio::null())
        .status();
    let t = Instant::now();
    while t.elapsed() < Duration::from_secs(10) {
        if let Some(s) = child
            .try_wait()
            .map_err(|e| format!("waiting for {pid}: {e}"))?
        {
            return Ok(s);
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let _ = child.kill();
    child.wait().map_err(|e| format!("waiting for {pid}: {e}"))
}

const MIB: f64 = 1024.0 * 1024.0;

/// The number written right after `key` in `line` (trailing `,` or `;` dropped).
fn number_after<T: std::str::FromStr>(line: &str, key: &str) -> Option<T> {
    let i = line.find(key)?;
    line[i + key.len()..]
        .split_whitespace()
        .next()?
        .trim_end_matches([',', ';'])
        .parse()
        .ok()
}

/// The number written right before `key` in `line` (a leading `(` dropped).
fn number_before<T: std::str::FromStr>(line: &str, key: &str) -> Option<T> {
    let i = line.find(key)?;
    line[..i]
        .split_whitespace()
        .next_back()?
        .trim_start_matches('(')
        .trim_end_matches([',', ';'])
        .parse()
        .ok()
}

fn last_line(text: &str) -> &str {
    text.lines()
        .rev()
        .find(|l| !l.trim().is_empty())
        .unwrap_or("")
}

// ---------------------------------------------------------------------------------------
// 4. Block on block: the solver on 1 and 2 ranks with each preconditioner
// ---------------------------------------------------------------------------------------

/// The benchmark scene; the solver refines it itself (`solver run --refine F`).
const BLOCK_SCENE: &str = "run/scenes/bench/block_on_block.toml";
/// Elements per edge of each block in BLOCK_SCENE.
const BLOCK_BASE_N: usize = 10;
/// Rank counts of the solver runs; the speed-up is the first over the second.
const BLOCK_RANKS: [usize; 2] = [1, 2];
/// Rank counts whose decomposition `solver check --ranks` reports.
const PARTITION_RANKS: [usize; 2] = [2, 3];
/// Node sets of BLOCK_SCENE held in y: the upper block's top (pressed down), the lower
/// block's bottom.
const BLOCK_TOP_SET: &str = "upper_top";
const BLOCK_BOTTOM_SET: &str = "lower_bottom";
/// A solver run still going after this long is stopped (a hang under MPI, not a result).
const SOLVER_TIMEOUT_S: f64 = 7200.0;
/// What the two-level preconditioner should reach on n = GOAL_N (the project's issue 9):
/// at most these fractions of Jacobi's CG iterations and wall time.
const GOAL_N: usize = 40;
const GOAL_ITERATION_RATIO: f64 = 1.0 / 5.0;
const GOAL_TIME_RATIO: f64 = 1.0 / 3.0;

/// A CG preconditioner (`solver run --preconditioner`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Precond {
    Jacobi,
    TwoLevel,
}

/// Every block-on-block size runs with each; ratios are the second over the first.
const PRECONDITIONERS: [Precond; 2] = [Precond::Jacobi, Precond::TwoLevel];

impl Precond {
    /// The value of `--preconditioner`.
    fn arg(self) -> &'static str {
        match self {
            Precond::Jacobi => "jacobi",
            Precond::TwoLevel => "two_level",
        }
    }

    fn label(self) -> &'static str {
        match self {
            Precond::Jacobi => "Jacobi",
            Precond::TwoLevel => "two-level",
        }
    }

    /// Whether the solver's `preconditioner:` line (without the prefix) says it used this
    /// one: a two-level run whose coarse space cannot be built falls back to Jacobi.
    fn used(self, line: &str) -> bool {
        match self {
            Precond::Jacobi => line == "nodal block Jacobi",
            Precond::TwoLevel => line.starts_with("two-level"),
        }
    }
}

/// What one solver run printed on standard error (rank 0, with -vv).
#[derive(Clone, Debug, PartialEq)]
struct SolverLog {
    elements: usize,
    nodes: usize,
    steps: usize,
    /// From the final `done:` line.
    cg_iterations: u64,
    /// Sum of the per-step `CG <n>`; equals `cg_iterations`.
    cg_step_sum: u64,
    /// Sum of the per-step `contact updates <n>`.
    contact_updates: u64,
    /// The run's wall time as the solver reports it (decomposition to result file).
    wall: f64,
    /// Peak memory, MiB per rank (the largest VmHWM over the ranks).
    peak_mib: f64,
    /// The `preconditioner: ..` line without its prefix (printed from -v on).
    preconditioner: Option<String>,
}

fn parse_solver_log(text: &str) -> Result<SolverLog, String> {
    let head = text
        .lines()
        .find(|l| l.contains(" elements, ") && l.contains(" rank(s)"))
        .ok_or("no '<name>: .. elements, .. nodes, .. rank(s)' line")?;
    let done = text
        .lines()
        .find(|l| l.starts_with("done: "))
        .ok_or("no 'done: ..' line")?;
    let bad = |what: &str, line: &str| format!("cannot read {what} from '{line}'");
    let mut cg_step_sum = 0u64;
    let mut contact_updates = 0u64;
    for l in text.lines().filter(|l| l.starts_with("step ")) {
        cg_step_sum += number_after::<u64>(l, " CG ").ok_or_else(|| bad("CG", l))?;
        contact_updates +=
            number_after::<u64>(l, "contact updates ").ok_or_else(|| bad("contact updates", l))?;
    }
    Ok(SolverLog {
        elements: number_before(head, " elements").ok_or_else(|| bad("elements", head))?,
        nodes: number_before(head, " nodes").ok_or_else(|| bad("nodes", head))?,
        steps: number_after(done, "done: ").ok_or_else(|| bad("steps", done))?,
        cg_iterations: number_before(done, " CG iterations").ok_or_else(|| bad("CG", done))?,
        cg_step_sum,
        contact_updates,
        wall: number_before(done, " s, peak memory").ok_or_else(|| bad("seconds", done))?,
        peak_mib: number_after(done, "peak memory ").ok_or_else(|| bad("memory", done))?,
        preconditioner: text
            .lines()
            .find_map(|l| l.strip_prefix("preconditioner: "))
            .map(|l| l.trim().to_string()),
    })
}

/// The coarse space a two-level `preconditioner:` line describes.
#[derive(Clone, Copy, Debug, PartialEq)]
struct CoarseInfo {
    aggregates: usize,
    unknowns: usize,
    cell_size: f64,
    colours: usize,
}

fn coarse_info(line: &str) -> Option<CoarseInfo> {
    let s = &line[line.find("coarse space: ")?..];
    Some(CoarseInfo {
        aggregates: number_before(s, " aggregates")?,
        unknowns: number_before(s, " unknowns")?,
        cell_size: number_after(s, "cell size ")?,
        colours: number_before(s, " colours")?,
    })
}

/// One solver run through `run/mpirun`; its standard error goes to `<stem>.log`.
fn solver_run(
    exe: &Path,
    refine: usize,
    ranks: usize,
    precond: Precond,
    result: &Path,
    limits: &Limits,
) -> Result<(SolverLog, f64), String> {
    let root = repo_root();
    let log = result.with_extension("log");
    let mut cmd = Command::new(root.join("run/mpirun"));
    cmd.args(["-np", &ranks.to_string()])
        .arg(exe)
        .args(["-vv", "run"])
        .arg(root.join(BLOCK_SCENE))
        .args(["--refine", &refine.to_string()])
        .args(["--preconditioner", precond.arg(), "-o"])
        .arg(result);
    let f = run_limited(&mut cmd, &result.with_extension("out"), &log, limits)?;
    let text =
        std::fs::read_to_string(&log).map_err(|e| format!("cannot read {}: {e}", log.display()))?;
    if let Some(why) = f.stopped {
        return Err(format!("{why} (log {})", log.display()));
    }
    if f.code != Some(0) {
        return Err(format!(
            "exit code {}: {} (log {})",
            f.code.map_or("none (signal)".into(), |c| c.to_string()),
            last_line(&text),
            log.display()
        ));
    }
    let parsed = parse_solver_log(&text).map_err(|e| format!("{}: {e}", log.display()))?;
    match parsed.preconditioner.as_deref() {
        Some(line) if precond.used(line) => Ok((parsed, f.wall)),
        Some(line) => Err(format!(
            "asked for --preconditioner {}, the solver used: {line} (log {})",
            precond.arg(),
            log.display()
        )),
        None => Err(format!("no 'preconditioner:' line in {}", log.display())),
    }
}

/// Sum over all nodes of the contact force at the last step of a result file.
fn total_contact_force(path: &Path) -> Result<Vec3, String> {
    let file = ResultFile::open(path).map_err(|e| e.to_string())?;
    let last = file
        .num_steps()
        .checked_sub(1)
        .ok_or_else(|| format!("{}: no steps", path.display()))?;
    let force = file.contact_force(last).map_err(|e| e.to_string())?;
    Ok(force.iter().fold([0.0; 3], |a, f| solver::math::add(&a, f)))
}

/// The block-on-block scene at one size on one rank count with one preconditioner,
/// repeated.
struct BlockCase {
    /// Elements per edge of each block.
    n: usize,
    ranks: usize,
    /// The first repeat's log (the counts are the same in every repeat unless
    /// `consistent` is false).
    log: SolverLog,
    consistent: bool,
    /// Solver-reported wall time.
    wall: Stat,
    /// Wall time of the `run/mpirun` process (MPI start-up and scene loading included).
    process_wall: Stat,
    peak_mib: Stat,
    /// Total contact force at the last step (from the last repeat's result file).
    contact_force: Result<Vec3, String>,
    result: PathBuf,
}

impl BlockCase {
    fn bytes_per_element(&self) -> f64 {
        self.peak_mib.median * MIB / (self.log.elements as f64 / self.ranks as f64)
    }

    fn preconditioner_line(&self) -> &str {
        self.log.preconditioner.as_deref().unwrap_or("")
    }

    fn coarse(&self) -> Option<CoarseInfo> {
        coarse_info(self.preconditioner_line())
    }

    /// The JSON record of the run (without the rank count, preconditioner and size).
    fn json(&self, marginal_bytes: Option<f64>) -> Rec {
        let l = &self.log;
        let (force, force_error) = match &self.contact_force {
            Ok(f) => (J::Arr(f.iter().map(|&x| J::Num(x)).collect()), None),
            Err(e) => (J::Null, Some(e.clone())),
        };
        let coarse = self.coarse();
        Rec::default()
            .put("elements", l.elements)
            .put("nodes", l.nodes)
            .put("steps", l.steps)
            .put("cg_iterations", l.cg_iterations)
            .put("contact_updates", l.contact_updates)
            .put("counts_same_every_repeat", self.consistent)
            .put("repeats", self.wall.repeats)
            .stat("wall_s", &self.wall)
            .stat("process_wall_s", &self.process_wall)
            .stat("peak_mib_per_rank", &self.peak_mib)
            .put("elements_per_rank", l.elements as f64 / self.ranks as f64)
            .put("bytes_per_element", self.bytes_per_element())
            .put("marginal_bytes_per_element", marginal_bytes)
            .put("contact_force", force)
            .put("contact_force_error", force_error)
            .put("preconditioner_line", self.preconditioner_line())
            .put("coarse_aggregates", coarse.map(|c| c.aggregates))
            .put("coarse_unknowns", coarse.map(|c| c.unknowns))
            .put("coarse_cell_size", coarse.map(|c| c.cell_size))
            .put("coarse_colours", coarse.map(|c| c.colours))
            .put("result_file", self.result.display().to_string())
    }
}

fn block_case(
    exe: &Path,
    dir: &Path,
    refine: usize,
    ranks: usize,
    precond: Precond,
    repeats: usize,
    limits: &Limits,
) -> Result<BlockCase, String> {
    let n = BLOCK_BASE_N * refine;
    let result = dir.join(format!("n{n}_np{ranks}_{}.h5", precond.arg()));
    let mut logs = Vec::new();
    let mut process = Vec::new();
    for r in 0..repeats.max(1) {
        let (log, wall) = solver_run(exe, refine, ranks, precond, &result, limits)?;
        eprintln!(
            "bench:   n = {n}, {}, {ranks} rank(s), run {}/{}: {} CG iterations, {} contact updates, {:.2} s, {:.1} MiB per rank",
            precond.label(),
            r + 1,
            repeats.max(1),
            log.cg_iterations,
            log.contact_updates,
            log.wall,
            log.peak_mib
        );
        logs.push(log);
        process.push(wall);
    }
    let first = logs[0].clone();
    let consistent = logs.iter().all(|l| {
        (
            l.steps,
            l.cg_iterations,
            l.cg_step_sum,
            l.contact_updates,
            &l.preconditioner,
        ) == (
            first.steps,
            first.cg_iterations,
            first.cg_step_sum,
            first.contact_updates,
            &first.preconditioner,
        )
    }) && first.cg_iterations == first.cg_step_sum;
    let walls: Vec<f64> = logs.iter().map(|l| l.wall).collect();
    let mibs: Vec<f64> = logs.iter().map(|l| l.peak_mib).collect();
    Ok(BlockCase {
        n,
        ranks,
        log: first,
        consistent,
        wall: Stat::of(&walls),
        process_wall: Stat::of(&process),
        peak_mib: Stat::of(&mibs),
        contact_force: total_contact_force(&result),
        result,
    })
}

/// `solver post compare A B`: exit code 0 when bitwise identical.
struct Compare {
    code: Option<i32>,
    /// Its last line ("result: ...").
    summary: String,
}

impl Compare {
    fn identical(&self) -> bool {
        self.code == Some(0)
    }
}

fn compare_results(exe: &Path, a: &Path, b: &Path) -> Result<Compare, String> {
    let out = Command::new(exe)
        .args(["post", "compare"])
        .arg(a)
        .arg(b)
        .output()
        .map_err(|e| format!("cannot run {} post compare: {e}", exe.display()))?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    Ok(Compare {
        code: out.status.code(),
        summary: last_line(if stdout.trim().is_empty() {
            &stderr
        } else {
            &stdout
        })
        .to_string(),
    })
}

/// "yes", or why not, of a 1-against-2-rank comparison.
fn identity_text(compare: &Option<Result<Compare, String>>) -> String {
    match compare {
        Some(Ok(c)) if c.identical() => "yes".to_string(),
        Some(Ok(c)) => format!(
            "**no** (exit {}: {})",
            c.code.map_or("none".into(), |x| x.to_string()),
            c.summary
        ),
        Some(Err(e)) => format!("not compared: {e}"),
        None => "not compared (a run failed)".to_string(),
    }
}

/// The speed-up of the first rank count over the second: (median, min, max) of the
/// first's wall time over the second's.
fn speedup(a: &BlockCase, b: &BlockCase) -> Stat {
    ratio(&a.wall, &b.wall)
}

/// `a / b` of two time statistics: the minimum from the fastest `a` over the slowest `b`.
fn ratio(a: &Stat, b: &Stat) -> Stat {
    Stat {
        median: a.median / b.median,
        min: a.min / b.max,
        max: a.max / b.min,
        repeats: a.repeats.min(b.repeats),
    }
}

/// One size with one preconditioner on every rank count of BLOCK_RANKS.
struct PrecondRuns {
    precond: Precond,
    cases: Vec<Result<BlockCase, String>>,
    /// The first rank count's result file against the second's.
    compare: Option<Result<Compare, String>>,
}

impl PrecondRuns {
    fn case(&self, ranks: usize) -> Option<&BlockCase> {
        self.cases.iter().flatten().find(|c| c.ranks == ranks)
    }

    fn speedup(&self) -> Option<Stat> {
        Some(speedup(
            self.case(BLOCK_RANKS[0])?,
            self.case(BLOCK_RANKS[1])?,
        ))
    }
}

/// One size of the block-on-block scene with every preconditioner on every rank count.
struct BlockSize {
    n: usize,
    refine: usize,
    /// In the order of PRECONDITIONERS.
    runs: Vec<PrecondRuns>,
}

impl BlockSize {
    fn runs(&self, p: Precond) -> Option<&PrecondRuns> {
        self.runs.iter().find(|r| r.precond == p)
    }

    fn case(&self, p: Precond, ranks: usize) -> Option<&BlockCase> {
        self.runs(p)?.case(ranks)
    }

    fn elements(&self) -> Option<usize> {
        self.runs
            .iter()
            .flat_map(|r| r.cases.iter().flatten())
            .map(|c| c.log.elements)
            .next()
    }

    /// The two runs compared on a rank count: (Jacobi, two-level).
    fn pair(&self, ranks: usize) -> Option<(&BlockCase, &BlockCase)> {
        Some((
            self.case(PRECONDITIONERS[0], ranks)?,
            self.case(PRECONDITIONERS[1], ranks)?,
        ))
    }

    /// Two-level CG iterations over Jacobi's.
    fn iteration_ratio(&self, ranks: usize) -> Option<f64> {
        let (j, t) = self.pair(ranks)?;
        Some(t.log.cg_iterations as f64 / j.log.cg_iterations as f64)
    }

    /// Two-level wall time over Jacobi's.
    fn time_ratio(&self, ranks: usize) -> Option<Stat> {
        let (j, t) = self.pair(ranks)?;
        Some(ratio(&t.wall, &j.wall))
    }

    /// |F_two-level - F_Jacobi| / |F_Jacobi| of the total contact force vectors.
    fn force_difference(&self, ranks: usize) -> Option<f64> {
        let (j, t) = self.pair(ranks)?;
        let (fj, ft) = (
            j.contact_force.as_ref().ok()?,
            t.contact_force.as_ref().ok()?,
        );
        Some(solver::math::norm(&solver::math::sub(ft, fj)) / solver::math::norm(fj))
    }

    /// The preconditioner lines of the two-level runs, one per distinct line, with the
    /// rank counts that printed it.
    fn coarse_lines(&self) -> Vec<(Vec<usize>, String)> {
        let mut lines: Vec<(Vec<usize>, String)> = Vec::new();
        let Some(runs) = self.runs(Precond::TwoLevel) else {
            return lines;
        };
        for c in runs.cases.iter().flatten() {
            let line = c.preconditioner_line().to_string();
            match lines.iter_mut().find(|(_, l)| *l == line) {
                Some((ranks, _)) => ranks.push(c.ranks),
                None => lines.push((vec![c.ranks], line)),
            }
        }
        lines
    }
}

fn block_size(exe: &Path, dir: &Path, refine: usize, repeats: usize) -> BlockSize {
    let n = BLOCK_BASE_N * refine;
    let limits = Limits::timeout(SOLVER_TIMEOUT_S);
    let runs = PRECONDITIONERS
        .iter()
        .map(|&precond| {
            let cases: Vec<Result<BlockCase, String>> = BLOCK_RANKS
                .iter()
                .map(|&ranks| {
                    let c = block_case(exe, dir, refine, ranks, precond, repeats, &limits);
                    if let Err(e) = &c {
                        eprintln!(
                            "bench:   n = {n}, {}, {ranks} rank(s) failed: {e}",
                            precond.label()
                        );
                    }
                    c
                })
                .collect();
            let compare = match (&cases[0], &cases[1]) {
                (Ok(a), Ok(b)) => Some(compare_results(exe, &a.result, &b.result)),
                _ => None,
            };
            PrecondRuns {
                precond,
                cases,
                compare,
            }
        })
        .collect();
    BlockSize { n, refine, runs }
}

/// The solve tolerance of BLOCK_SCENE (`solver.tolerance`).
fn block_tolerance() -> Option<f64> {
    load_scene_refined(&repo_root().join(BLOCK_SCENE), 1)
        .ok()
        .map(|p| p.solver.tolerance)
}

/// `solver check SCENE --refine F --ranks R`: the decomposition part of its output.
struct PartitionReport {
    n: usize,
    ranks: usize,
    imbalance: Option<f64>,
    edge_cut: Option<u64>,
    /// From the `decomposition:` line to the end.
    text: String,
}

fn partition_report(exe: &Path, refine: usize, ranks: usize) -> Result<PartitionReport, String> {
    let out = Command::new(exe)
        .arg("check")
        .arg(repo_root().join(BLOCK_SCENE))
        .args([
            "--refine",
            &refine.to_string(),
            "--ranks",
            &ranks.to_string(),
        ])
        .output()
        .map_err(|e| format!("cannot run {} check: {e}", exe.display()))?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    if !out.status.success() {
        return Err(format!(
            "solver check --refine {refine} --ranks {ranks}: {}",
            last_line(&String::from_utf8_lossy(&out.stderr))
        ));
    }
    let start = stdout
        .find("decomposition:")
        .ok_or("solver check printed no 'decomposition:' line")?;
    let text = stdout[start..].trim_end().to_string();
    Ok(PartitionReport {
        n: BLOCK_BASE_N * refine,
        ranks,
        imbalance: number_after(&text, "element imbalance "),
        edge_cut: number_after(&text, "edge cut "),
        text,
    })
}

// ---------------------------------------------------------------------------------------
// 5. CalculiX beside us
// ---------------------------------------------------------------------------------------

/// CalculiX gets this long per size; larger sizes are skipped after one that does not
/// finish in time.
const CCX_TIMEOUT_S: f64 = 300.0;
const CCX_THREADS: usize = 2;
/// Slope of the linear pressure-overclosure law (pressure per unit overclosure) of the
/// node-to-surface penalty contact: with contact pressures of order 10 the overclosure is
/// about 1e-6, 1e-4 of the 0.009 the top is pressed down.
const CCX_PENALTY: f64 = 1e7;
/// ccx's face label of each of our local faces 0 (-y), 1 (+x), 2 (+y), 3 (-x), 4 (-z),
/// 5 (+z): with our corner order a C3D8's face S1 is 1-2-3-4 (-z), S2 5-8-7-6 (+z), S3
/// 1-5-6-2 (-y), S4 2-6-7-3 (+x), S5 3-7-8-4 (+y), S6 4-8-5-1 (-x).
const CCX_FACE: [u8; 6] = [3, 4, 5, 6, 1, 2];

/// A name as ccx stores it (upper case; letters, digits and '_').
fn ccx_name(prefix: &str, name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_uppercase()
            } else {
                '_'
            }
        })
        .collect();
    format!("{prefix}{s}")
}

/// A CalculiX input deck of a scene: the same nodes and elements (ids = our 1-based ids),
/// a linear elastic material per body, the prescribed displacements at the last step's
/// time applied over one static step (ramped), the first contact pair as frictionless
/// node-to-surface penalty contact, and the total reaction force of every prescribed node
/// set printed to the .dat file. Only what the block-on-block scene uses is supported.
fn calculix_deck(problem: &Problem) -> Result<String, String> {
    use solver::fem::Formulation;
    use solver::material::Material;
    use solver::scene::Kinematics;
    let unsupported = |what: &str| Err(format!("the CalculiX deck does not support {what}"));
    if !matches!(problem.kinematics, Kinematics::Small) {
        return unsupported("large kinematics");
    }
    if !problem.pressures.is_empty()
        || !problem.tractions.is_empty()
        || !problem.body_forces.is_empty()
    {
        return unsupported("pressures, tractions or body forces");
    }
    let [pair] = problem.contacts.as_slice() else {
        return unsupported("other than one contact pair");
    };
    if pair.mu != 0.0 {
        return unsupported("friction");
    }
    let mesh = &problem.mesh;
    let mut d = String::new();
    let w = &mut d;
    let _ = writeln!(
        w,
        "** {} written by the solver's bench: C3D8 (2x2x2 Gauss) as the scene's \"full\",\n\
         ** frictionless node-to-surface penalty contact, linear static (no NLGEOM).\n*HEADING\n{}",
        problem.name, problem.name
    );
    let _ = writeln!(w, "*NODE, NSET=NALL");
    for (i, x) in mesh.coords.iter().enumerate() {
        let _ = writeln!(w, "{}, {:?}, {:?}, {:?}", i + 1, x[0], x[1], x[2]);
    }
    for (b, body) in mesh.bodies.iter().enumerate() {
        let model = &problem.body_models[b];
        let Material::LinearElastic(m) = &model.material else {
            return unsupported("materials other than linear elastic");
        };
        if !matches!(model.formulation, Formulation::Full) {
            return unsupported("formulations other than \"full\"");
        }
        let (lambda, mu) = (m.lambda, m.mu);
        let e = mu * (3.0 * lambda + 2.0 * mu) / (lambda + mu);
        let nu = lambda / (2.0 * (lambda + mu));
        let elset = ccx_name("E_", &body.name);
        let _ = writeln!(w, "*ELEMENT, TYPE=C3D8, ELSET={elset}");
        for k in body.first_element..body.first_element + body.num_elements {
            let c = mesh.elements[k];
            let _ = write!(w, "{}", k + 1);
            for n in c {
                let _ = write!(w, ", {}", n + 1);
            }
            let _ = writeln!(w);
        }
        let material = ccx_name("M_", &body.name);
        let _ = writeln!(
            w,
            "*MATERIAL, NAME={material}\n*ELASTIC\n{e:?}, {nu:?}\n\
             *SOLID SECTION, ELSET={elset}, MATERIAL={material}"
        );
    }

    // Prescribed displacements: one axis each, at the final time.
    let t_end = problem
        .step_times
        .last()
        .copied()
        .ok_or("the scene has no load steps")?;
    let mut boundary = Vec::new();
    let mut sets: Vec<usize> = Vec::new();
    for dc in &problem.dirichlet {
        let axis = (0..3).find(|&i| {
            (dc.direction[i].abs() - 1.0).abs() < 1e-12
                && (0..3).all(|j| j == i || dc.direction[j].abs() < 1e-12)
        });
        let Some(i) = axis else {
            return unsupported("prescribed directions other than x, y or z");
        };
        let value = dc.function.eval(t_end) / dc.direction[i];
        let set = &problem.node_sets[dc.node_set];
        boundary.push(format!(
            "{}, {}, {}, {value:?}",
            ccx_name("N_", &set.name),
            i + 1,
            i + 1
        ));
        if !sets.contains(&dc.node_set) {
            sets.push(dc.node_set);
        }
    }
    for &s in &sets {
        let set = &problem.node_sets[s];
        let _ = writeln!(w, "*NSET, NSET={}", ccx_name("N_", &set.name));
        write_ids(w, set.nodes.iter().map(|&n| n as usize + 1));
    }

    // Contact: master faces of the pair, slave faces from the side set whose nodes are
    // the pair's slave nodes.
    let face_nodes = |e: u32, f: u8| -> [u32; 4] {
        let c = mesh.elements[e as usize];
        solver::fem::hex8::FACES[f as usize].map(|a| c[a])
    };
    let slave_set = problem
        .side_sets
        .iter()
        .find(|s| {
            let mut nodes: Vec<u32> = s
                .faces
                .iter()
                .flat_map(|&(e, f)| face_nodes(e, f))
                .collect();
            nodes.sort_unstable();
            nodes.dedup();
            nodes == pair.slave_nodes
        })
        .ok_or("no side set has exactly the contact pair's slave nodes")?;
    for (name, faces) in [
        ("S_MASTER", &pair.master_faces),
        ("S_SLAVE", &slave_set.faces),
    ] {
        let _ = writeln!(w, "*SURFACE, NAME={name}, TYPE=ELEMENT");
        for &(e, f) in faces.iter() {
            let _ = writeln!(w, "{}, S{}", e + 1, CCX_FACE[f as usize]);
        }
    }
    let _ = writeln!(
        w,
        "*SURFACE INTERACTION, NAME=FRICTIONLESS\n\
         *SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n{CCX_PENALTY:?}\n\
         *CONTACT PAIR, INTERACTION=FRICTIONLESS, TYPE=NODE TO SURFACE\nS_SLAVE, S_MASTER"
    );

    let _ = writeln!(w, "*STEP\n*STATIC\n1.0, 1.0, 1.0e-5, 1.0\n*BOUNDARY");
    for b in &boundary {
        let _ = writeln!(w, "{b}");
    }
    for &s in &sets {
        let _ = writeln!(
            w,
            "*NODE PRINT, NSET={}, TOTALS=ONLY\nRF",
            ccx_name("N_", &problem.node_sets[s].name)
        );
    }
    let _ = writeln!(w, "*END STEP");
    Ok(d)
}

/// Ids sixteen to a line (ccx reads at most 16 entries per data line).
fn write_ids(w: &mut String, ids: impl Iterator<Item = usize>) {
    let ids: Vec<usize> = ids.collect();
    for chunk in ids.chunks(16) {
        let line: Vec<String> = chunk.iter().map(usize::to_string).collect();
        let _ = writeln!(w, "{}", line.join(", "));
    }
}

/// The last "total force (fx,fy,fz) for set NAME" of a ccx .dat file.
fn ccx_total_force(dat: &str, set: &str) -> Option<Vec3> {
    let key = format!("total force (fx,fy,fz) for set {set} ");
    let lines: Vec<&str> = dat.lines().collect();
    let i = lines.iter().rposition(|l| l.contains(&key))?;
    let v: Vec<f64> = lines[i + 1..]
        .iter()
        .find(|l| !l.trim().is_empty())?
        .split_whitespace()
        .filter_map(|x| x.parse().ok())
        .collect();
    (v.len() == 3).then(|| [v[0], v[1], v[2]])
}

enum CcxOutcome {
    Finished {
        /// Process wall time.
        wall: Stat,
        /// ccx's own "Total CalculiX Time" (median).
        own_time: Option<f64>,
        peak_mib: Option<f64>,
        /// Newton iterations of the step (contact iterations), first repeat.
        iterations: usize,
        /// Total reaction force of the upper block's top and of the lower block's bottom.
        top: Vec3,
        bottom: Vec3,
    },
    Stopped(String),
    Failed(String),
    Skipped(String),
}

struct CcxSize {
    n: usize,
    elements: usize,
    nodes: usize,
    deck: PathBuf,
    outcome: CcxOutcome,
}

struct Calculix {
    /// `None`: ccx is not installed (or does not run).
    version: Option<String>,
    sizes: Vec<CcxSize>,
}

fn ccx_version() -> Option<String> {
    // `ccx -v` prints "This is Version 2.20" and exits with a non-zero code.
    let out = Command::new("ccx").arg("-v").output().ok()?;
    let text = String::from_utf8_lossy(&out.stdout);
    let v = text
        .lines()
        .find_map(|l| l.trim().strip_prefix("This is Version "))
        .map(str::to_string);
    Some(v.unwrap_or_else(|| "unknown version".into()))
}

fn calculix(cfg: &Config) -> Calculix {
    let Some(version) = ccx_version() else {
        eprintln!(
            "bench: CalculiX not available (no ccx on PATH; `run/setup --calculix` installs it)"
        );
        return Calculix {
            version: None,
            sizes: Vec::new(),
        };
    };
    eprintln!("bench: CalculiX {version}");
    let mut sizes = Vec::new();
    let mut skip: Option<String> = None;
    for &refine in &cfg.calculix {
        let n = BLOCK_BASE_N * refine;
        let repeats = cfg.block.iter().find(|b| b.0 == refine).map_or(1, |b| b.1);
        let size = match &skip {
            Some(why) => Ok(CcxSize {
                n,
                elements: 0,
                nodes: 0,
                deck: PathBuf::new(),
                outcome: CcxOutcome::Skipped(why.clone()),
            }),
            None => ccx_size(&cfg.out, refine, repeats),
        };
        let size = size.unwrap_or_else(|e| CcxSize {
            n,
            elements: 0,
            nodes: 0,
            deck: PathBuf::new(),
            outcome: CcxOutcome::Failed(e),
        });
        match &size.outcome {
            CcxOutcome::Finished { wall, top, .. } => eprintln!(
                "bench:   ccx n = {n}: {:.2} s, total force {:.6}",
                wall.median, -top[1]
            ),
            CcxOutcome::Stopped(why) => {
                eprintln!("bench:   ccx n = {n}: {why}");
                skip = Some(format!("n = {n} did not finish ({why})"));
            }
            CcxOutcome::Failed(e) => eprintln!("bench:   ccx n = {n} failed: {e}"),
            CcxOutcome::Skipped(_) => {}
        }
        sizes.push(size);
    }
    Calculix {
        version: Some(version),
        sizes,
    }
}

fn ccx_size(out: &Path, refine: usize, repeats: usize) -> Result<CcxSize, String> {
    let n = BLOCK_BASE_N * refine;
    let problem = load_scene_refined(&repo_root().join(BLOCK_SCENE), refine as u32)
        .map_err(|e| e.to_string())?;
    let dir = out.join("calculix").join(format!("n{n}"));
    std::fs::create_dir_all(&dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let job = format!("block_on_block_n{n}");
    let deck = dir.join(format!("{job}.inp"));
    std::fs::write(&deck, calculix_deck(&problem)?)
        .map_err(|e| format!("cannot write {}: {e}", deck.display()))?;
    let mut size = CcxSize {
        n,
        elements: problem.mesh.num_elements(),
        nodes: problem.mesh.num_nodes(),
        deck: deck.clone(),
        outcome: CcxOutcome::Skipped(String::new()),
    };
    drop(problem);
    let (top_set, bottom_set) = (
        ccx_name("N_", BLOCK_TOP_SET),
        ccx_name("N_", BLOCK_BOTTOM_SET),
    );
    let mut walls = Vec::new();
    let mut own = Vec::new();
    let mut peak: Option<f64> = None;
    let mut first: Option<(usize, Vec3, Vec3)> = None;
    for _ in 0..repeats.max(1) {
        let dat = dir.join(format!("{job}.dat"));
        let _ = std::fs::remove_file(&dat);
        let log = dir.join("ccx.log");
        let mut cmd = Command::new("ccx");
        cmd.args(["-i", &job])
            .current_dir(&dir)
            .env("OMP_NUM_THREADS", CCX_THREADS.to_string());
        let f = run_limited(
            &mut cmd,
            &log,
            &dir.join("ccx.err"),
            &Limits {
                timeout_s: CCX_TIMEOUT_S,
                // Leave the machine a quarter of what it had (others may be working on it).
                rss_limit: memory_available().map(|m| 0.75 * m),
                min_available: None,
            },
        )?;
        if let Some(why) = f.stopped {
            size.outcome = CcxOutcome::Stopped(why);
            return Ok(size);
        }
        let text = std::fs::read_to_string(&log).unwrap_or_default();
        let dat_text = std::fs::read_to_string(&dat).unwrap_or_default();
        // ccx exits with 0 after an input error too: judge by its output.
        let error = text.lines().find(|l| l.contains("*ERROR")).map(str::trim);
        let forces = (
            ccx_total_force(&dat_text, &top_set),
            ccx_total_force(&dat_text, &bottom_set),
        );
        let (Some(top), Some(bottom), None) = (forces.0, forces.1, error) else {
            size.outcome = CcxOutcome::Failed(format!(
                "exit code {:?}; {} (log {})",
                f.code,
                error.unwrap_or("no total force in the .dat file"),
                log.display()
            ));
            return Ok(size);
        };
        walls.push(f.wall);
        own.extend(number_after::<f64>(&text, "Total CalculiX Time: "));
        if let Some(p) = f.peak_rss {
            peak = Some(peak.map_or(p, |q| q.max(p)));
        }
        let iterations = text
            .lines()
            .filter(|l| l.trim_start().starts_with("iteration "))
            .count();
        first.get_or_insert((iterations, top, bottom));
    }
    let (iterations, top, bottom) = first.expect("at least one repeat");
    size.outcome = CcxOutcome::Finished {
        wall: Stat::of(&walls),
        own_time: (!own.is_empty()).then(|| Stat::of(&own).median),
        peak_mib: peak.map(|p| p / MIB),
        iterations,
        top,
        bottom,
    };
    Ok(size)
}

// ---------------------------------------------------------------------------------------
// 6. --large: the block on block at about 10^6 elements
// ---------------------------------------------------------------------------------------

/// Refinement factor of the large run: n = 80, 2 x 512000 elements.
const LARGE_REFINE: usize = 8;
/// Refinement factors of the pilot runs whose peak memory predicts the large run's.
const LARGE_PILOT: [usize; 2] = [2, 4];
/// The large run starts only when ranks x its predicted peak per rank x this fits in the
/// machine's MemAvailable.
const LARGE_MEMORY_MARGIN: f64 = 1.25;
/// It is stopped when the machine's MemAvailable falls below this (bytes) ...
const LARGE_MIN_AVAILABLE: f64 = 1024.0 * MIB;
/// ... or after this long.
const LARGE_TIMEOUT_S: f64 = 6.0 * 3600.0;
/// Rank counts of `--large` without `--ranks`.
const LARGE_DEFAULT_RANKS: [usize; 1] = [2];
/// Heading of the large section of report.md: from it to the end of the file is that
/// section (a normal run writes it last, as it found it).
const LARGE_HEADING: &str = "## Large block on block";

/// The memory check before a large run.
struct MemoryEstimate {
    /// (n, elements, peak MiB per rank) of the pilot runs.
    pilot: Vec<(usize, usize, f64)>,
    /// Growth of the peak per element added per rank between the pilots, bytes.
    marginal_bytes: f64,
    /// Elements of the large run.
    elements: usize,
    predicted_mib_per_rank: f64,
    available_mib: Option<f64>,
    fits: bool,
}

impl MemoryEstimate {
    fn new(pilot: &[&BlockCase], ranks: usize) -> Result<MemoryEstimate, String> {
        let [a, b] = pilot else {
            return Err("the memory estimate needs two pilot runs".into());
        };
        let per_rank = |c: &BlockCase| c.log.elements as f64 / ranks as f64;
        let de = per_rank(b) - per_rank(a);
        let marginal_bytes = (b.peak_mib.median - a.peak_mib.median) * MIB / de;
        let last_refine = LARGE_PILOT[LARGE_PILOT.len() - 1];
        let elements = (b.log.elements as f64 * (LARGE_REFINE as f64 / last_refine as f64).powi(3))
            .round() as usize;
        // Linear in elements per rank through the larger pilot; if the peak did not grow
        // (a measurement gone wrong), in proportion to it.
        let predicted_mib_per_rank = if marginal_bytes > 0.0 {
            b.peak_mib.median
                + marginal_bytes * (elements as f64 / ranks as f64 - per_rank(b)) / MIB
        } else {
            b.peak_mib.median * elements as f64 / b.log.elements as f64
        };
        let available_mib = memory_available().map(|m| m / MIB);
        let fits = available_mib.is_some_and(|avail| {
            ranks as f64 * predicted_mib_per_rank * LARGE_MEMORY_MARGIN <= avail
        });
        Ok(MemoryEstimate {
            pilot: pilot
                .iter()
                .map(|c| (c.n, c.log.elements, c.peak_mib.median))
                .collect(),
            marginal_bytes,
            elements,
            predicted_mib_per_rank,
            available_mib,
            fits,
        })
    }

    fn json(&self, ranks: usize) -> J {
        Rec::default()
            .put(
                "pilot",
                J::Arr(
                    self.pilot
                        .iter()
                        .map(|&(n, e, p)| {
                            Rec::default()
                                .put("n", n)
                                .put("elements", e)
                                .put("peak_mib_per_rank", p)
                                .json()
                        })
                        .collect(),
                ),
            )
            .put("marginal_bytes_per_element", self.marginal_bytes)
            .put("elements", self.elements)
            .put("predicted_peak_mib_per_rank", self.predicted_mib_per_rank)
            .put(
                "predicted_total_mib",
                ranks as f64 * self.predicted_mib_per_rank,
            )
            .put("memory_margin", LARGE_MEMORY_MARGIN)
            .put("available_mib", self.available_mib)
            .put("fits", self.fits)
            .json()
    }

    fn text(&self, ranks: usize) -> String {
        let pilot: Vec<String> = self
            .pilot
            .iter()
            .map(|(n, e, p)| format!("n = {n} ({e} elements) {p:.1} MiB"))
            .collect();
        format!(
            "pilot peaks per rank {}; {:.0} B per element added per rank; predicted {:.0} MiB \
             per rank, {:.0} MiB on {ranks} rank(s), x {LARGE_MEMORY_MARGIN} against {} \
             available: {}",
            pilot.join(", "),
            self.marginal_bytes,
            self.predicted_mib_per_rank,
            ranks as f64 * self.predicted_mib_per_rank,
            self.available_mib
                .map_or("unknown".to_string(), |m| format!("{m:.0} MiB")),
            if self.fits { "fits" } else { "does not fit" }
        )
    }
}

/// How the large run on one rank count went.
enum LargeOutcome {
    Finished(Box<BlockCase>),
    Failed(String),
    /// Not started (the pilots failed or the memory does not suffice).
    NotRun(String),
}

struct LargeRun {
    ranks: usize,
    estimate: Result<MemoryEstimate, String>,
    outcome: LargeOutcome,
}

impl LargeRun {
    /// Growth of the peak per rank from the larger pilot to the large run, per element
    /// added per rank (bytes).
    fn marginal_bytes(&self) -> Option<f64> {
        let LargeOutcome::Finished(c) = &self.outcome else {
            return None;
        };
        let &(_, e, peak) = self.estimate.as_ref().ok()?.pilot.last()?;
        let de = (c.log.elements as f64 - e as f64) / self.ranks as f64;
        (de > 0.0).then(|| (c.peak_mib.median - peak) * MIB / de)
    }
}

/// The pilots, the memory check and the large run on `ranks` ranks.
fn large_run(exe: &Path, dir: &Path, ranks: usize) -> LargeRun {
    let limits = Limits::timeout(SOLVER_TIMEOUT_S);
    eprintln!(
        "bench: large, {ranks} rank(s): pilot runs n = {:?} (two-level) for the memory estimate",
        LARGE_PILOT.map(|f| BLOCK_BASE_N * f)
    );
    let pilot: Result<Vec<BlockCase>, String> = LARGE_PILOT
        .iter()
        .map(|&f| block_case(exe, dir, f, ranks, Precond::TwoLevel, 1, &limits))
        .collect();
    let estimate = pilot.and_then(|p| MemoryEstimate::new(&p.iter().collect::<Vec<_>>(), ranks));
    let outcome = match &estimate {
        Err(e) => LargeOutcome::NotRun(format!("memory estimate failed: {e}")),
        Ok(m) if !m.fits => LargeOutcome::NotRun(format!("not enough memory: {}", m.text(ranks))),
        Ok(m) => {
            eprintln!("bench: large, {ranks} rank(s): {}", m.text(ranks));
            eprintln!(
                "bench: large, {ranks} rank(s): n = {} ({} elements), two-level; this takes a while",
                BLOCK_BASE_N * LARGE_REFINE,
                m.elements
            );
            let limits = Limits {
                timeout_s: LARGE_TIMEOUT_S,
                rss_limit: None,
                min_available: Some(LARGE_MIN_AVAILABLE),
            };
            match block_case(exe, dir, LARGE_REFINE, ranks, Precond::TwoLevel, 1, &limits) {
                Ok(c) => LargeOutcome::Finished(Box::new(c)),
                Err(e) => LargeOutcome::Failed(e),
            }
        }
    };
    match &outcome {
        LargeOutcome::Finished(_) => {}
        LargeOutcome::Failed(why) => eprintln!("bench: large, {ranks} rank(s) failed: {why}"),
        LargeOutcome::NotRun(why) => eprintln!("bench: large, {ranks} rank(s) not run: {why}"),
    }
    LargeRun {
        ranks,
        estimate,
        outcome,
    }
}

/// Everything `--large` measured.
struct Large {
    machine: Machine,
    runs: Vec<LargeRun>,
    /// The first finished run's result file against the second's.
    compare: Option<Result<Compare, String>>,
    total_wall: f64,
    load_end: Option<String>,
    steal: Option<f64>,
}

impl Large {
    fn finished(&self) -> Vec<&BlockCase> {
        self.runs
            .iter()
            .filter_map(|r| match &r.outcome {
                LargeOutcome::Finished(c) => Some(c.as_ref()),
                _ => None,
            })
            .collect()
    }

    /// Speed-up of the fewest ranks over the most, when both finished.
    fn speedup(&self) -> Option<Stat> {
        let f = self.finished();
        let a = f.iter().min_by_key(|c| c.ranks)?;
        let b = f.iter().max_by_key(|c| c.ranks)?;
        (a.ranks < b.ranks).then(|| speedup(a, b))
    }

    fn json(&self) -> J {
        let m = &self.machine;
        let runs = self
            .runs
            .iter()
            .map(|r| {
                let head = Rec::default().put("ranks", r.ranks);
                let head = match &r.estimate {
                    Ok(e) => head.put("memory_check", e.json(r.ranks)),
                    Err(e) => head.put(
                        "memory_check",
                        Rec::default().put("error", e.as_str()).json(),
                    ),
                };
                match &r.outcome {
                    LargeOutcome::Finished(c) => head
                        .put("status", "finished")
                        .extend(c.json(r.marginal_bytes()))
                        .json(),
                    LargeOutcome::Failed(e) => head
                        .put("status", "failed")
                        .put("reason", e.as_str())
                        .json(),
                    LargeOutcome::NotRun(e) => head
                        .put("status", "not_run")
                        .put("reason", e.as_str())
                        .json(),
                }
            })
            .collect();
        let rec = Rec::default()
            .put(
                "meta",
                Rec::default()
                    .put("date", m.date.as_str())
                    .put("git_commit", m.git_commit.clone())
                    .put("git_dirty", m.git_dirty)
                    .put("cpu_model", m.cpu_model.as_str())
                    .put("logical_cpus", m.logical_cpus)
                    .put("total_wall_s", self.total_wall)
                    .put("load_average_start", m.load_start.clone())
                    .put("load_average_end", self.load_end.clone())
                    .put("cpu_steal_fraction", self.steal)
                    .json(),
            )
            .put("scene", BLOCK_SCENE)
            .put("n", BLOCK_BASE_N * LARGE_REFINE)
            .put("refine", LARGE_REFINE)
            .put("preconditioner", Precond::TwoLevel.arg())
            .put("timeout_s", LARGE_TIMEOUT_S)
            .put("min_available_mib", LARGE_MIN_AVAILABLE / MIB)
            .put("runs", J::Arr(runs));
        let rec = match self.speedup() {
            Some(s) => rec.stat("speedup", &s),
            None => rec.put("speedup_median", J::Null),
        };
        match &self.compare {
            Some(Ok(c)) => rec
                .put("bitwise_identical", c.identical())
                .put("compare_summary", c.summary.as_str()),
            Some(Err(e)) => rec
                .put("bitwise_identical", J::Null)
                .put("compare_error", e.as_str()),
            None => rec.put("bitwise_identical", J::Null),
        }
        .json()
    }

    fn markdown(&self, dir: &Path) -> String {
        let m = &self.machine;
        let mut s = String::new();
        let w = &mut s;
        let _ = writeln!(
            w,
            "{LARGE_HEADING} (n = {}, `run/bench --large`)\n",
            BLOCK_BASE_N * LARGE_REFINE
        );
        let _ = writeln!(
            w,
            "{} on {}, commit {}{}; load average {} at the start, {} at the end; hypervisor \
             steal {}; {:.0} s in all. `{BLOCK_SCENE}` refined by {LARGE_REFINE} (n = {} \
             elements per edge per block), `--preconditioner two_level`, one run per rank \
             count. Before each, two-level runs at n = {} on the same rank count measure the \
             peak memory per rank; extrapolated linearly in elements per rank it must fit \
             {LARGE_MEMORY_MARGIN} times over in the memory available, and the run is stopped \
             if the machine's available memory falls below {:.0} MiB or after {:.0} h. \
             Columns as in the block-on-block table; \"marginal\" is the growth of the peak \
             per element added per rank from the larger pilot run. Result files and logs in \
             `{}`.\n",
            m.date,
            m.cpu_model,
            m.git_commit.as_deref().unwrap_or("unknown"),
            if m.git_dirty == Some(true) {
                " (with uncommitted changes)"
            } else {
                ""
            },
            m.load_start.as_deref().unwrap_or("unknown"),
            self.load_end.as_deref().unwrap_or("unknown"),
            self.steal
                .map_or("unknown".to_string(), |x| format!("{:.1} %", 100.0 * x)),
            self.total_wall,
            BLOCK_BASE_N * LARGE_REFINE,
            LARGE_PILOT
                .map(|f| (BLOCK_BASE_N * f).to_string())
                .join(" and "),
            LARGE_MIN_AVAILABLE / MIB,
            LARGE_TIMEOUT_S / 3600.0,
            dir.display(),
        );
        let _ = writeln!(
            w,
            "| ranks | elements | CG iterations | contact updates | time s | process s | peak MiB/rank | B/element | marginal B/element | contact force y | coarse space |"
        );
        let _ = writeln!(w, "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|");
        for r in &self.runs {
            let _ = match &r.outcome {
                LargeOutcome::Finished(c) => writeln!(
                    w,
                    "| {} | {} | {} | {} | {:.1} | {:.1} | {:.1} | {:.0} | {} | {} | {} |",
                    r.ranks,
                    c.log.elements,
                    c.log.cg_iterations,
                    c.log.contact_updates,
                    c.wall.median,
                    c.process_wall.median,
                    c.peak_mib.median,
                    c.bytes_per_element(),
                    r.marginal_bytes().map_or("-".into(), |m| format!("{m:.0}")),
                    match &c.contact_force {
                        Ok(f) => format!("{:.6}", f[1]),
                        Err(e) => format!("unreadable: {}", e.replace('|', "/")),
                    },
                    c.preconditioner_line().replace('|', "/")
                ),
                LargeOutcome::Failed(e) => {
                    writeln!(
                        w,
                        "| {} | failed: {} |||||||||",
                        r.ranks,
                        e.replace('|', "/")
                    )
                }
                LargeOutcome::NotRun(e) => {
                    writeln!(
                        w,
                        "| {} | not run: {} |||||||||",
                        r.ranks,
                        e.replace('|', "/")
                    )
                }
            };
        }
        let _ = writeln!(w);
        for r in &self.runs {
            let _ = match &r.estimate {
                Ok(e) => writeln!(
                    w,
                    "- memory check, {} rank(s): {}",
                    r.ranks,
                    e.text(r.ranks)
                ),
                Err(e) => writeln!(w, "- memory check, {} rank(s): failed: {e}", r.ranks),
            };
        }
        if let Some(s) = self.speedup() {
            let _ = writeln!(
                w,
                "- speed-up {:.2}; bitwise identical: {}",
                s.median,
                identity_text(&self.compare)
            );
        }
        s
    }
}

/// `bench --large`: the large runs, merged into `<out>/results.json` and `<out>/report.md`.
fn large(out: &Path, ranks: &[usize]) -> Result<(), String> {
    let start = Instant::now();
    let dir = out.join("large");
    std::fs::create_dir_all(&dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let machine = machine();
    let exe = solver_exe()?;
    eprintln!(
        "bench: large block on block (n = {}, two-level) on {ranks:?} rank(s)",
        BLOCK_BASE_N * LARGE_REFINE
    );
    let runs: Vec<LargeRun> = ranks.iter().map(|&r| large_run(&exe, &dir, r)).collect();
    let finished: Vec<&BlockCase> = runs
        .iter()
        .filter_map(|r| match &r.outcome {
            LargeOutcome::Finished(c) => Some(c.as_ref()),
            _ => None,
        })
        .collect();
    let compare = match finished.as_slice() {
        [a, b, ..] => Some(compare_results(&exe, &a.result, &b.result)),
        _ => None,
    };
    let steal = steal_since(&machine);
    let large = Large {
        machine,
        runs,
        compare,
        total_wall: start.elapsed().as_secs_f64(),
        load_end: load_average(),
        steal,
    };

    let section = large.markdown(&dir);
    let (jpath, rpath) = merge_large(out, large.json(), &section)?;
    println!("{section}");
    eprintln!("bench: wrote {} and {}", jpath.display(), rpath.display());
    let failed = large
        .runs
        .iter()
        .filter(|r| !matches!(r.outcome, LargeOutcome::Finished(_)))
        .count();
    if failed > 0 {
        return Err(format!(
            "{failed} large run(s) did not finish; see the report"
        ));
    }
    Ok(())
}

/// Writes the large section into `<out>/results.json` and `<out>/report.md`, replacing an
/// earlier one and keeping the rest (files that do not exist yet get only this section).
fn merge_large(out: &Path, json: J, section: &str) -> Result<(PathBuf, PathBuf), String> {
    let jpath = out.join("results.json");
    let rpath = out.join("report.md");
    let mut root = std::fs::read_to_string(&jpath)
        .ok()
        .and_then(|t| serde_json::from_str::<J>(&t).ok())
        .filter(|j| matches!(j, J::Obj(_)))
        .unwrap_or_else(|| {
            let doc = DOC
                .iter()
                .filter(|(k, _)| ["schema", "statistics", "large", "units"].contains(k))
                .map(|(k, v)| (k.to_string(), J::Str(v.to_string())))
                .collect();
            Rec::default()
                .put("schema", SCHEMA)
                .put("doc", J::Obj(doc))
                .json()
        });
    root.set("large", json);
    let mut report = std::fs::read_to_string(&rpath)
        .unwrap_or_else(|_| "# Solver performance benchmark\n\n".to_string());
    if let Some(i) = report.find(LARGE_HEADING) {
        report.truncate(i);
    } else if !report.ends_with("\n\n") {
        report.push('\n');
    }
    report.push_str(section);
    let text = serde_json::to_string_pretty(&root)
        .map_err(|e| format!("cannot serialise the results: {e}"))?;
    std::fs::write(&jpath, text + "\n")
        .map_err(|e| format!("cannot write {}: {e}", jpath.display()))?;
    std::fs::write(&rpath, &report)
        .map_err(|e| format!("cannot write {}: {e}", rpath.display()))?;
    Ok((jpath, rpath))
}

/// The large section of earlier files in `out`, for a normal run to keep: its JSON and
/// its part of report.md (from LARGE_HEADING to the end).
fn earlier_large(out: &Path) -> Option<(J, String)> {
    let json = std::fs::read_to_string(out.join("results.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<J>(&t).ok())
        .and_then(|j| j.get("large").cloned())
        .filter(|j| !matches!(j, J::Null));
    let text = std::fs::read_to_string(out.join("report.md"))
        .ok()
        .and_then(|r| r.find(LARGE_HEADING).map(|i| r[i..].to_string()));
    if json.is_none() && text.is_none() {
        return None;
    }
    Some((json.unwrap_or(J::Null), text.unwrap_or_default()))
}

/// Fraction of the machine's CPU time the hypervisor gave to other guests since `m` was
/// taken.
fn steal_since(m: &Machine) -> Option<f64> {
    match (m.jiffies_start, cpu_jiffies()) {
        (Some((a0, s0)), Some((a1, s1))) if a1 > a0 => {
            Some(s1.saturating_sub(s0) as f64 / (a1 - a0) as f64)
        }
        _ => None,
    }
}

// ---------------------------------------------------------------------------------------
// Output
// ---------------------------------------------------------------------------------------

/// Identifier and version of results.json's layout.
const SCHEMA: &str = "solver-bench/3";

const DOC: [(&str, &str); 17] = [
    ("schema", "identifier and version of this file's layout"),
    ("meta", "when and where it ran: date (RFC 3339, UTC), git commit (short) and whether tracked files had uncommitted changes, CPU model and cache size from /proc/cpuinfo (under a hypervisor the cache size may be a nominal figure), logical CPUs and physical cores, quick mode, total wall time in s, /proc/loadavg (1, 5, 15 min) at the start and the end (other processes on the machine inflate wall times), cpu_steal_fraction = share of all CPUs' time the hypervisor gave to other guests during the run (from /proc/stat)"),
    ("statistics", "every measured figure is given as <name>_median, <name>_min and <name>_max over `repeats` timed runs (after one untimed warm-up for the kernels and the bandwidth); rates are derived from the times, so rate_min comes from the slowest run"),
    ("cpu_share", "median over the repeats of (CPU time of the benchmark thread) / (wall time): about 1 when the core was ours, lower when other processes took it and the wall time is inflated accordingly"),
    ("memory_bandwidth", "STREAM-like loops over f64 arrays much larger than the caches: copy b = a (2 arrays counted), triad a = b + 3 c (3 arrays counted); bytes counted as in STREAM (write-allocate traffic not counted); gb_s in 1e9 B/s"),
    ("element_kernels", "one record per (case, operation): Assembly::internal_force or Assembly::diagonal over the whole mesh on one core (one rank, one thread) with a smooth displacement field of strain ~1e-3; seconds is per call over all elements; elements_per_s and ns_per_element derived from it"),
    ("element_kernels.model_bytes_per_element", "memory-traffic model with no reuse of shared nodes: 8 nodes x 3 coords x 8 B + 8 x 3 displacement x 8 B read + 8 x k result x 8 B read and written (k = 3 force, 9 diagonal block) + 8 x 4 B connectivity = 800 B (force), 1568 B (diagonal)"),
    ("element_kernels.model_gb_s", "model_bytes_per_element x elements_per_s_median / 1e9"),
    ("element_kernels.fraction_of_triad_1core", "model_gb_s / the one-core triad bandwidth median"),
    ("element_kernels.checksum", "sum of |entries| of the result, to show it is not trivial"),
    ("cg_cube", "unit cube, linear elastic E = 1e6, nu = 0.3, u_y = 0 at y = 0, u_x = 0 at x = 0, u_z = 0 at z = 0, u_y = -0.01 at y = 1, one load step, tolerance 1e-8, nodal block-Jacobi preconditioner (solver.preconditioner = \"jacobi\"; the block-on-block section compares it with the two-level one), solved by solver::run::run on SerialComm; run_wall includes decomposition and set-up, solve_wall is the load step; unknowns = free degrees of freedom; iterations_per_cbrt_unknowns = cg_iterations / unknowns^(1/3); force_call is one internal_force call on the same mesh and kernel_share = cg_iterations x force_call_min / solve_wall_min (true-residual recomputations not counted; minima are the least disturbed by other load); max_error_rel = max |u - u_exact| / 0.01 against the exact uniaxial-stress field"),
    ("contact_search", "two blocks stacked at y = 0.1 (lower [0,1]x[0,0.1]x[0,1] divided m x 1 x m, upper [0,1]x[0.1,0.2]x[0,1] divided (m-1) x 1 x (m-1), so the meshes do not match), generated as a scene and read by parse_scene (parse_s, not part of the timings); master = the lower block's top (m^2 faces), slave = the upper block's bottom nodes (m^2), each offset along y by a pseudo-random gap uniform in [-0.5, 0.5] x normal_tolerance (perturb_s, not timed either); default tolerances (normal 0.5 x face_size, tangential 0.1 x face_size). Per repeat, on one thread: build_s = MasterSurface::new (face corners and the BVH of their inflated boxes), search_s = MasterSurface::search of every slave node (collecting the results), total_s = both; after one untimed warm-up round; slave_nodes_per_s and us_per_query derived from search_s, total_slave_nodes_per_s from total_s. interactions_found = slave nodes with an interaction; expected = slave nodes over the master surface's x-z extent with |offset| <= normal_tolerance, expected_found = how many of those found a face; max_gap_error = max |gap - offset| and max_point_error = max distance of the contact point from the node's foot on y = 0.1, over the interactions"),
    ("block_on_block", "run/scenes/bench/block_on_block.toml (two linear elastic blocks, E = 1000, nu = 0.3, the upper one [0.05,0.95]x[1,1.9]x[0.05,0.95] pressed by u_y = -0.009 at its top onto the lower [0,1]^3 held at its bottom; frictionless, non-matching meshes, 2 load steps, solve tolerance `tolerance`) refined by `solver run --refine F` to n = 10 F elements per edge per block, run as `run/mpirun -np R target/release/solver -vv run SCENE --refine F --preconditioner P -o out/bench/block/nN_npR_P.h5` (standard error in nN_npR_P.log) for P = jacobi (nodal block Jacobi) and two_level (plus the coarse space of aggregate rigid-body modes); a run whose `preconditioner:` line is not the one asked for (a two-level run falling back to Jacobi) counts as failed. Per size, preconditioner and rank count (`runs`): steps, cg_iterations and contact_updates summed over the steps (the same every repeat unless counts_same_every_repeat is false), wall_s = the run time the solver prints (decomposition to result file; without MPI start-up and scene loading), process_wall_s = wall time of the mpirun process, peak_mib_per_rank = the largest VmHWM over the ranks as the solver prints it, bytes_per_element = peak / (elements / ranks), marginal_bytes_per_element = the growth of the peak over the next smaller size (same preconditioner and ranks) per element added per rank (the fixed cost of the runtime cancels), contact_force = sum over all nodes of /results/contact/force at the last step read with solver::output::ResultFile, preconditioner_line = the solver's `preconditioner:` line and coarse_* the coarse space it describes (aggregates, unknowns = 6 per aggregate, grid cell size, colours). two_level_over_jacobi, per rank count: iteration_ratio = two-level / Jacobi CG iterations, time_ratio = two-level / Jacobi wall_s (min from the fastest two-level over the slowest Jacobi repeat), *_goal_met against `goal` (judged on n = goal.n), contact_force_relative_difference = |F_two_level - F_jacobi| / |F_jacobi| of the total force vectors, contact_force_within_tolerance = that <= tolerance. one_against_two_ranks, per preconditioner: speedup = 1-rank wall_s / 2-rank wall_s (min from the slowest 1-rank over the fastest 2-rank run); bitwise_identical = `solver post compare` of the 1- and 2-rank result files exited with 0. coarse_space: the distinct two-level preconditioner lines with the rank counts that printed them"),
    ("partition", "`solver check SCENE --refine F --ranks R` for R = 2, 3: element imbalance (max/mean), edge cut, owned and ghost elements and nodes per rank, master faces each rank owns / holds for its slave nodes; text is its output from the `decomposition:` line on"),
    ("calculix", "CalculiX ccx (Debian calculix-ccx; `run/setup --calculix`) on the same problem: the input deck is written from the scene as the solver loads it (same nodes, elements and ids; C3D8 elements, 2x2x2 Gauss like the scene's full integration; E and nu per body; the prescribed displacements at the final time over one *STATIC step; frictionless NODE TO SURFACE penalty contact of the scene's slave faces on its master faces with PRESSURE-OVERCLOSURE=LINEAR of slope penalty_slope; *NODE PRINT TOTALS=ONLY of RF for the prescribed node sets), run as `ccx -i JOB` with OMP_NUM_THREADS = 2 in out/bench/calculix/nN/, stopped after 5 minutes (larger sizes are then skipped) or at 3/4 of the memory available. wall_s = process wall time, ccx_time_s = its own \"Total CalculiX Time\", peak_mib = its VmHWM, iterations = its Newton (contact) iterations; total_force = -RF_y summed over the upper block's top, bottom_force = RF_y summed over the lower block's bottom; relative_difference = (ccx total_force - our contact force y) / ours; ours = the two-level 2-rank run (our_preconditioner, our_ranks): our_contact_force_y, our_process_wall_s = its process wall time, our_wall_s = its solver-reported time"),
    ("large", "written by `run/bench --large` only (never by the normal or quick run, which keep an earlier large section as it is): the block on block refined by 8 (n = 80, 2 x 512000 elements) with --preconditioner two_level on the rank counts of `--ranks` (default 2), each after a memory check: two_level pilot runs at n = 20 and 40 on the same rank count, their peak per rank extrapolated linearly in elements per rank to n = 80 (predicted_peak_mib_per_rank), and the run started only when ranks x that x memory_margin fits in MemAvailable (available_mib); stopped when MemAvailable falls below min_available_mib or after timeout_s. Fields of a finished run as in block_on_block.runs; meta as in `meta`, of the large run itself"),
    ("units", "seconds (s), elements per second, nanoseconds per element, 1e9 bytes per second (GB/s), slave nodes per second, microseconds per query (us)"),
];

struct Results {
    cfg_quick: bool,
    machine: Machine,
    cfg_kernel_n: usize,
    stream: Vec<Stream>,
    kernels: Vec<KernelResult>,
    cubes: Vec<CubeResult>,
    contact: ContactResult,
    blocks: Vec<BlockSize>,
    /// The solve tolerance of BLOCK_SCENE.
    block_tolerance: Option<f64>,
    partitions: Vec<Result<PartitionReport, String>>,
    calculix: Calculix,
    total_wall: f64,
    load_end: Option<String>,
    /// Fraction of the machine's CPU time stolen by the hypervisor during the run.
    steal: Option<f64>,
    /// The large section of an earlier `--large` run, carried over as it was: its JSON
    /// and its part of report.md.
    large: Option<(J, String)>,
}

impl Results {
    fn triad_1core(&self) -> Option<f64> {
        self.stream
            .iter()
            .find(|s| s.kernel == "triad" && s.threads == 1)
            .map(|s| s.gbs.median)
    }

    fn json(&self) -> J {
        let m = &self.machine;
        let meta = Rec::default()
            .put("date", m.date.as_str())
            .put("git_commit", m.git_commit.clone())
            .put("git_dirty", m.git_dirty)
            .put("cpu_model", m.cpu_model.as_str())
            .put("cpu_cache", m.cache.as_str())
            .put("logical_cpus", m.logical_cpus)
            .put("physical_cores", m.physical_cores)
            .put("quick", self.cfg_quick)
            .put("total_wall_s", self.total_wall)
            .put("load_average_start", m.load_start.clone())
            .put("load_average_end", self.load_end.clone())
            .put("cpu_steal_fraction", self.steal)
            .json();
        let stream = self
            .stream
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
            .collect();
        let triad = self.triad_1core();
        let kernels = self
            .kernels
            .iter()
            .map(|k| {
                let ne = k.elements as f64;
                let rate = k.seconds.rate(ne);
                let model_gbs = k.model_bytes * rate.median / 1e9;
                Rec::default()
                    .put("case", k.case.label)
                    .put("operation", k.operation)
                    .put("integration", k.case.integration)
                    .put("volumetric", k.case.volumetric)
                    .put(
                        "material",
                        if k.case.large {
                            "neo_hookean"
                        } else {
                            "linear_elastic"
                        },
                    )
                    .put("kinematics", if k.case.large { "large" } else { "small" })
                    .put("mesh", format!("{n}x{n}x{n}", n = self.cfg_kernel_n))
                    .put("elements", k.elements)
                    .put("nodes", k.nodes)
                    .put("repeats", k.seconds.repeats)
                    .stat("seconds", &k.seconds)
                    .stat("elements_per_s", &rate)
                    .stat("ns_per_element", &k.seconds.scaled(1e9 / ne))
                    .put("cpu_share", k.cpu_share)
                    .put("model_bytes_per_element", k.model_bytes)
                    .put("model_gb_s", model_gbs)
                    .put("fraction_of_triad_1core", triad.map(|t| model_gbs / t))
                    .put("checksum", k.checksum)
                    .json()
            })
            .collect();
        let cubes = self
            .cubes
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
                        c.cg_iterations as f64 / (c.unknowns as f64).cbrt(),
                    )
                    .put("repeats", c.solve_wall.repeats)
                    .stat("run_wall_s", &c.run_wall)
                    .stat("solve_wall_s", &c.solve_wall)
                    .put("cpu_share", c.cpu_share)
                    .put(
                        "ms_per_iteration",
                        1e3 * c.solve_wall.median / c.cg_iterations.max(1) as f64,
                    )
                    .stat("force_call_s", &c.force_call)
                    .put("kernel_share", kernel_share(c))
                    .put("max_error_rel", c.max_error)
                    .json()
            })
            .collect();
        let c = &self.contact;
        let ns = c.slave_nodes as f64;
        let contact = Rec::default()
            .put("master_divisions", format!("{m}x1x{m}", m = c.m))
            .put("slave_divisions", format!("{k}x1x{k}", k = c.m - 1))
            .put("master_faces", c.master_faces)
            .put("slave_nodes", c.slave_nodes)
            .put("face_size", c.face_size)
            .put("normal_tolerance", c.normal_tolerance)
            .put("tangential_tolerance", c.tangential_tolerance)
            .put("max_abs_offset", c.max_offset)
            .put("threads", 1usize)
            .put("parse_s", c.parse_s)
            .put("perturb_s", c.perturb_s)
            .put("repeats", c.total.repeats)
            .stat("build_s", &c.build)
            .stat("search_s", &c.search)
            .stat("total_s", &c.total)
            .put("cpu_share", c.cpu_share)
            .stat("slave_nodes_per_s", &c.search.rate(ns))
            .stat("us_per_query", &c.search.scaled(1e6 / ns))
            .stat("total_slave_nodes_per_s", &c.total.rate(ns))
            .put("interactions_found", c.found)
            .put("interactions_same_every_repeat", c.consistent)
            .put("expected", c.expected)
            .put("expected_found", c.expected_found)
            .put("all_expected_found", c.expected_found == c.expected)
            .put("max_gap_error", c.max_gap_error)
            .put("max_point_error", c.max_point_error)
            .json();
        let doc = J::Obj(
            DOC.iter()
                .map(|(k, v)| (k.to_string(), J::Str(v.to_string())))
                .collect(),
        );
        Rec::default()
            .put("schema", SCHEMA)
            .put("doc", doc)
            .put("meta", meta)
            .put("memory_bandwidth", J::Arr(stream))
            .put("element_kernels", J::Arr(kernels))
            .put("cg_cube", J::Arr(cubes))
            .put("contact_search", contact)
            .put("block_on_block", self.block_json())
            .put("partition", self.partition_json())
            .put("calculix", self.calculix_json())
            .put("large", self.large.as_ref().map(|l| l.0.clone()))
            .json()
    }

    fn markdown(&self) -> String {
        let m = &self.machine;
        let mut s = String::new();
        let w = &mut s;
        let _ = writeln!(w, "# Solver performance benchmark\n");
        let _ = writeln!(
            w,
            "{} on {} ({} logical CPUs{}, cache {}), commit {}{}{}.\n",
            m.date,
            m.cpu_model,
            m.logical_cpus,
            m.physical_cores
                .map(|c| format!(", {c} physical cores"))
                .unwrap_or_default(),
            m.cache,
            m.git_commit.as_deref().unwrap_or("unknown"),
            if m.git_dirty == Some(true) {
                " (with uncommitted changes)"
            } else {
                ""
            },
            if self.cfg_quick {
                "; **quick mode** (smaller sizes, fewer repeats)"
            } else {
                ""
            }
        );
        let _ =
            writeln!(
            w,
            "What is measured and how: every figure is the median of repeated timed runs, with \
             [min, max] and the number of repeats (n). The element kernels run on one core \
             (one rank, one thread) over a {k}x{k}x{k} structured hex mesh of the unit cube, with \
             a smooth displacement field (strains ~1e-3), after one untimed warm-up call; \
             the problem comes from a generated scene through `parse_scene`, a 1-part \
             decomposition, `LocalMesh::new` and `Assembly::new`. Memory bandwidth is a \
             STREAM-like copy and triad over {mb:.0} MB f64 arrays in the same run (bytes counted \
             as STREAM does, without write-allocate). The CG figures come from \
             `solver::run::run` on one rank (no output file). Times are wall-clock; the \
             \"CPU/wall\" columns give the median ratio of the benchmark thread's CPU time to \
             wall time, about 1 when the core was ours and lower when other processes took \
             it (load average {ls} at the start, {le} at the end; hypervisor steal {st}, which \
             that ratio cannot see). Total benchmark wall time: {tw:.1} s.\n",
            k = self.cfg_kernel_n,
            mb = self.stream.first().map_or(0.0, |x| x.array_bytes as f64 / 1e6),
            tw = self.total_wall,
            ls = m.load_start.as_deref().unwrap_or("unknown"),
            le = self.load_end.as_deref().unwrap_or("unknown"),
            st = self
                .steal
                .map_or("unknown".to_string(), |x| format!("{:.1} %", 100.0 * x)),
        );

        let _ = writeln!(w, "## Memory bandwidth\n");
        let _ = writeln!(w, "| loop | threads | arrays x size | GB/s |");
        let _ = writeln!(w, "|---|---:|---|---|");
        for x in &self.stream {
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

        let triad = self.triad_1core();
        let _ = writeln!(w, "\n## Element kernels (one core)\n");
        let _ = writeln!(
            w,
            "Traffic model, no reuse of nodes shared between elements: coordinates 8 x 3 x 8 B \
             + displacements 8 x 3 x 8 B read + result 8 x k x 8 B read and written (k = 3 \
             force, 9 diagonal 3x3 block) + connectivity 8 x 4 B = {} B/element for \
             `internal_force`, {} B/element for `diagonal`. \"% of triad\" is the model's \
             bandwidth at the median rate over the one-core triad bandwidth{}. With perfect \
             cache reuse on this structured mesh each element brings only about one new node \
             (about 130 B), so the real DRAM traffic is lower still.\n",
            model_bytes(3),
            model_bytes(9),
            triad.map_or(String::new(), |t| format!(" ({t:.2} GB/s)"))
        );
        let _ = writeln!(
            w,
            "| case | operation | n | elements/s | ns/element | CPU/wall | model GB/s | % of triad |"
        );
        let _ = writeln!(w, "|---|---|---:|---|---|---:|---:|---:|");
        for k in &self.kernels {
            let ne = k.elements as f64;
            let rate = k.seconds.rate(ne);
            let ns = k.seconds.scaled(1e9 / ne);
            let gbs = k.model_bytes * rate.median / 1e9;
            let _ = writeln!(
                w,
                "| {} | `{}` | {} | {} | {} | {:.2} | {:.2} | {} |",
                k.case.label,
                k.operation,
                k.seconds.repeats,
                fmt_rate(&rate),
                fmt_stat(&ns, 0),
                k.cpu_share,
                gbs,
                triad.map_or("-".into(), |t| format!("{:.1} %", 100.0 * gbs / t))
            );
        }

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
        for c in &self.cubes {
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
                c.cg_iterations as f64 / (c.unknowns as f64).cbrt(),
                c.solve_wall.repeats,
                fmt_stat(&c.solve_wall, 3),
                fmt_stat(&c.run_wall, 3),
                c.cpu_share,
                1e3 * c.solve_wall.median / c.cg_iterations.max(1) as f64,
                100.0 * kernel_share(c),
                c.max_error,
                n = c.n,
            );
        }
        if self.cubes.len() >= 2 {
            let a = &self.cubes[0];
            let b = &self.cubes[self.cubes.len() - 1];
            let slope = (b.cg_iterations as f64 / a.cg_iterations as f64).ln()
                / (b.unknowns as f64 / a.unknowns as f64).ln();
            let _ = writeln!(
                w,
                "\nTrend: iterations grow like unknowns^{slope:.2} from {}^3 to {}^3 \
                 (unknowns^(1/3), i.e. 1/h, is what Jacobi-preconditioned CG is expected to show).",
                a.n, b.n
            );
        }

        let c = &self.contact;
        let ns = c.slave_nodes as f64;
        let _ = writeln!(w, "\n## Contact search\n");
        let _ = writeln!(
            w,
            "Two blocks stacked at y = 0.1 with non-matching meshes: the master surface is the \
             top of the lower block ({m}x1x{m} elements, {mf} faces of size {fs:.3e}), the \
             slave nodes the bottom of the upper block ({k}x1x{k} elements, {sn} nodes), each \
             offset along y by a pseudo-random gap uniform in ±{a:.3e} ({fr} x the normal \
             tolerance {nt:.3e}; largest |offset| {mo:.3e}; tangential tolerance {tt:.3e}). One thread. \"build\" is \
             `MasterSurface::new` (face corners and the BVH of the inflated face boxes), \
             \"search\" is `MasterSurface::search` of every slave node, \"total\" both; \
             after one untimed warm-up round. Not timed: scene generation and `parse_scene` \
             {ps:.2} s, slave offsets {pt:.2} ms. \"found / expected\": slave nodes with an \
             interaction / slave nodes over the master surface within the normal tolerance \
             ({ef} of the {ex} expected found{cons}); over the interactions, max |gap - offset| \
             = {ge:.1e} and max distance of the contact point from the node's foot on the \
             plane = {pe:.1e}.\n",
            m = c.m,
            k = c.m - 1,
            mf = c.master_faces,
            fs = c.face_size,
            sn = c.slave_nodes,
            a = CONTACT_GAP_FRACTION * c.normal_tolerance,
            fr = CONTACT_GAP_FRACTION,
            mo = c.max_offset,
            nt = c.normal_tolerance,
            tt = c.tangential_tolerance,
            ps = c.parse_s,
            pt = 1e3 * c.perturb_s,
            ef = c.expected_found,
            ex = c.expected,
            cons = if c.consistent {
                ", the same count every repeat"
            } else {
                "; **the count varied between repeats**"
            },
            ge = c.max_gap_error,
            pe = c.max_point_error,
        );
        let _ = writeln!(
            w,
            "| master faces | slave nodes | n | build ms | search ms | total ms | slave nodes/s (search) | µs / query | CPU/wall | found / expected |"
        );
        let _ = writeln!(w, "|---:|---:|---:|---|---|---|---|---|---:|---:|");
        let _ = writeln!(
            w,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {:.2} | {} / {} |",
            c.master_faces,
            c.slave_nodes,
            c.total.repeats,
            fmt_stat(&c.build.scaled(1e3), 2),
            fmt_stat(&c.search.scaled(1e3), 2),
            fmt_stat(&c.total.scaled(1e3), 2),
            fmt_rate(&c.search.rate(ns)),
            fmt_stat(&c.search.scaled(1e6 / ns), 3),
            c.cpu_share,
            c.found,
            c.expected,
        );

        self.block_markdown(w);
        self.calculix_markdown(w);
        if let Some((_, text)) = &self.large {
            let _ = write!(w, "\n{text}");
        }
        s
    }
}

impl Results {
    /// Growth of the peak memory per rank over the next smaller size, per element added
    /// per rank (bytes).
    fn marginal_bytes(&self, i: usize, p: Precond, ranks: usize) -> Option<f64> {
        let b = self.blocks.get(i)?.case(p, ranks)?;
        let a = self.blocks.get(i.checked_sub(1)?)?.case(p, ranks)?;
        let de = (b.log.elements as f64 - a.log.elements as f64) / ranks as f64;
        (de > 0.0).then(|| (b.peak_mib.median - a.peak_mib.median) * MIB / de)
    }

    /// The run CalculiX is set beside on a size: two-level on 2 ranks.
    fn our_case(&self, n: usize) -> Option<&BlockCase> {
        self.blocks
            .iter()
            .find(|b| b.n == n)?
            .case(Precond::TwoLevel, BLOCK_RANKS[1])
    }

    /// Our total contact force (y) on a size: the two-level 2-rank run's, else the
    /// two-level 1-rank run's.
    fn our_force(&self, n: usize) -> Option<(f64, &BlockCase)> {
        let size = self.blocks.iter().find(|b| b.n == n)?;
        BLOCK_RANKS.iter().rev().find_map(|&r| {
            let c = size.case(Precond::TwoLevel, r)?;
            c.contact_force.as_ref().ok().map(|f| (f[1], c))
        })
    }

    fn block_json(&self) -> J {
        let tol = self.block_tolerance;
        let sizes = self
            .blocks
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let runs = b
                    .runs
                    .iter()
                    .flat_map(|pr| {
                        pr.cases
                            .iter()
                            .zip(BLOCK_RANKS)
                            .map(|(c, r)| (pr.precond, r, c))
                    })
                    .map(|(p, ranks, c)| {
                        let head = Rec::default()
                            .put("preconditioner", p.arg())
                            .put("ranks", ranks);
                        match c {
                            Err(e) => head.put("error", e.as_str()).json(),
                            Ok(c) => head.extend(c.json(self.marginal_bytes(i, p, ranks))).json(),
                        }
                    })
                    .collect();
                let ranks_compared = b
                    .runs
                    .iter()
                    .map(|pr| {
                        let rec = Rec::default().put("preconditioner", pr.precond.arg());
                        let rec = match pr.speedup() {
                            Some(s) => rec.stat("speedup", &s),
                            None => rec.put("speedup_median", J::Null),
                        };
                        match &pr.compare {
                            Some(Ok(c)) => rec
                                .put("bitwise_identical", c.identical())
                                .put("compare_exit_code", c.code.map(|x| x as i64).map(J::Int))
                                .put("compare_summary", c.summary.as_str()),
                            Some(Err(e)) => rec
                                .put("bitwise_identical", J::Null)
                                .put("compare_error", e.as_str()),
                            None => rec.put("bitwise_identical", J::Null),
                        }
                        .json()
                    })
                    .collect();
                let precond_compared = BLOCK_RANKS
                    .iter()
                    .map(|&r| {
                        let pair = b.pair(r);
                        let it = b.iteration_ratio(r);
                        let time = b.time_ratio(r);
                        let df = b.force_difference(r);
                        let rec = Rec::default()
                            .put("ranks", r)
                            .put("cg_iterations_jacobi", pair.map(|p| p.0.log.cg_iterations))
                            .put(
                                "cg_iterations_two_level",
                                pair.map(|p| p.1.log.cg_iterations),
                            )
                            .put("wall_s_jacobi", pair.map(|p| p.0.wall.median))
                            .put("wall_s_two_level", pair.map(|p| p.1.wall.median))
                            .put("iteration_ratio", it);
                        let rec = match &time {
                            Some(t) => rec.stat("time_ratio", t),
                            None => rec.put("time_ratio_median", J::Null),
                        };
                        rec.put("iteration_goal_met", it.map(|x| x <= GOAL_ITERATION_RATIO))
                            .put("time_goal_met", time.map(|t| t.median <= GOAL_TIME_RATIO))
                            .put("contact_force_relative_difference", df)
                            .put(
                                "contact_force_within_tolerance",
                                df.zip(tol).map(|(d, t)| d <= t),
                            )
                            .json()
                    })
                    .collect();
                let coarse = b
                    .coarse_lines()
                    .into_iter()
                    .map(|(ranks, line)| {
                        Rec::default()
                            .put("ranks", J::Arr(ranks.into_iter().map(J::from).collect()))
                            .put("line", line)
                            .json()
                    })
                    .collect();
                Rec::default()
                    .put("n", b.n)
                    .put("refine", b.refine)
                    .put("elements", b.elements())
                    .put("runs", J::Arr(runs))
                    .put("two_level_over_jacobi", J::Arr(precond_compared))
                    .put("one_against_two_ranks", J::Arr(ranks_compared))
                    .put("coarse_space", J::Arr(coarse))
                    .json()
            })
            .collect();
        Rec::default()
            .put("scene", BLOCK_SCENE)
            .put(
                "ranks",
                J::Arr(BLOCK_RANKS.iter().map(|&r| r.into()).collect()),
            )
            .put(
                "preconditioners",
                J::Arr(PRECONDITIONERS.iter().map(|p| p.arg().into()).collect()),
            )
            .put("tolerance", tol)
            .put(
                "goal",
                Rec::default()
                    .put("n", GOAL_N)
                    .put("iteration_ratio_at_most", GOAL_ITERATION_RATIO)
                    .put("time_ratio_at_most", GOAL_TIME_RATIO)
                    .json(),
            )
            .put("sizes", J::Arr(sizes))
            .json()
    }

    fn partition_json(&self) -> J {
        J::Arr(
            self.partitions
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

    fn calculix_json(&self) -> J {
        let c = &self.calculix;
        let sizes = c
            .sizes
            .iter()
            .map(|s| {
                let ours = self.our_force(s.n);
                let ours_2 = self.our_case(s.n);
                let rec = Rec::default()
                    .put("n", s.n)
                    .put("elements", s.elements)
                    .put("nodes", s.nodes)
                    .put("deck", s.deck.display().to_string())
                    .put("threads", CCX_THREADS)
                    .put("our_preconditioner", Precond::TwoLevel.arg())
                    .put("our_ranks", BLOCK_RANKS[1])
                    .put("our_contact_force_y", ours.map(|o| o.0))
                    .put("our_process_wall_s", ours_2.map(|b| b.process_wall.median))
                    .put("our_wall_s", ours_2.map(|b| b.wall.median));
                match &s.outcome {
                    CcxOutcome::Finished {
                        wall,
                        own_time,
                        peak_mib,
                        iterations,
                        top,
                        bottom,
                    } => rec
                        .put("status", "finished")
                        .put("repeats", wall.repeats)
                        .stat("wall_s", wall)
                        .put("ccx_time_s", *own_time)
                        .put("peak_mib", *peak_mib)
                        .put("iterations", *iterations)
                        .put("total_force", -top[1])
                        .put("bottom_force", bottom[1])
                        .put("relative_difference", ours.map(|o| (-top[1] - o.0) / o.0)),
                    CcxOutcome::Stopped(why) => {
                        rec.put("status", "stopped").put("reason", why.as_str())
                    }
                    CcxOutcome::Failed(e) => rec.put("status", "failed").put("reason", e.as_str()),
                    CcxOutcome::Skipped(why) => {
                        rec.put("status", "skipped").put("reason", why.as_str())
                    }
                }
                .json()
            })
            .collect();
        Rec::default()
            .put("available", c.version.is_some())
            .put("version", c.version.clone())
            .put("threads", CCX_THREADS)
            .put("timeout_s", CCX_TIMEOUT_S)
            .put("penalty_slope", CCX_PENALTY)
            .put("sizes", J::Arr(sizes))
            .json()
    }

    fn block_markdown(&self, w: &mut String) {
        let _ = writeln!(
            w,
            "\n## Block on block: the solver on 1 and 2 ranks, Jacobi and two-level\n"
        );
        let repeats: Vec<String> = self
            .blocks
            .iter()
            .map(|b| {
                let r = b
                    .runs
                    .iter()
                    .flat_map(|pr| pr.cases.iter().flatten())
                    .map(|c| c.wall.repeats)
                    .max()
                    .unwrap_or(0);
                format!("n = {}: {r}", b.n)
            })
            .collect();
        let tol = self
            .block_tolerance
            .map_or("unknown".to_string(), |t| format!("{t:e}"));
        let _ = writeln!(
            w,
            "`{BLOCK_SCENE}`: the upper block [0.05,0.95]x[1,1.9]x[0.05,0.95] pressed by u_y = \
             -0.009 at its top (x, z held) onto the lower block [0,1]^3 held at its bottom, both \
             linear elastic (E = 1000, nu = 0.3), n^3 hexahedra each with non-matching meshes, \
             frictionless contact, 2 load steps, tolerance {tol}. The solver refines it \
             (`solver run --refine F`) and runs as a subprocess under `run/mpirun -np R`, once \
             with `--preconditioner jacobi` (nodal block Jacobi) and once with `two_level` \
             (the same plus a coarse space of aggregate rigid-body modes). \
             Repeats per run: {}{}. \"time\" is the run time the solver prints (decomposition to result \
             file, without MPI start-up and scene loading), \"process\" the wall time of the \
             mpirun process. \"peak\" is the largest VmHWM over the ranks as the solver prints \
             it; \"B/element\" = peak / (elements / ranks), \"marginal\" = growth of the peak \
             over the next smaller size per element added per rank, same preconditioner (the \
             runtime's fixed cost cancels). \"contact force\" = sum of the y components of \
             `/results/contact/force` over all nodes at the last step.\n",
            repeats.join(", "),
            if self.blocks.iter().any(|b| b.n == GOAL_N) {
                " (one repeat on the largest size: its Jacobi run alone takes about 10 minutes \
                 on one rank)"
            } else {
                ""
            }
        );
        let _ = writeln!(
            w,
            "| n | elements | preconditioner | ranks | CG iterations | contact updates | n runs | time s | process s | peak MiB/rank | B/element | marginal B/element | contact force y |"
        );
        let _ = writeln!(
            w,
            "|---:|---:|---|---:|---:|---:|---:|---|---|---|---:|---:|---:|"
        );
        for (i, b) in self.blocks.iter().enumerate() {
            for pr in &b.runs {
                let p = pr.precond;
                for (c, ranks) in pr.cases.iter().zip(BLOCK_RANKS) {
                    match c {
                        Err(e) => {
                            let _ = writeln!(
                                w,
                                "| {} | {} | {} | {ranks} | failed: {} |||||||||",
                                b.n,
                                b.elements().map_or("-".into(), |e| e.to_string()),
                                p.label(),
                                e.replace('|', "/")
                            );
                        }
                        Ok(c) => {
                            let _ = writeln!(
                                w,
                                "| {} | {} | {} | {ranks} | {}{} | {} | {} | {} | {} | {} | {:.0} | {} | {} |",
                                b.n,
                                c.log.elements,
                                p.label(),
                                c.log.cg_iterations,
                                if c.consistent { "" } else { " (varied)" },
                                c.log.contact_updates,
                                c.wall.repeats,
                                fmt_stat(&c.wall, 2),
                                fmt_stat(&c.process_wall, 2),
                                fmt_stat(&c.peak_mib, 1),
                                c.bytes_per_element(),
                                self.marginal_bytes(i, p, ranks)
                                    .map_or("-".into(), |m| format!("{m:.0}")),
                                match &c.contact_force {
                                    Ok(f) => format!("{:.6}", f[1]),
                                    Err(e) => format!("unreadable: {}", e.replace('|', "/")),
                                }
                            );
                        }
                    }
                }
            }
        }

        let _ = writeln!(w, "\n### Two-level against Jacobi\n");
        let _ = writeln!(
            w,
            "Ratios are two-level over Jacobi on the same rank count: CG iterations, and the \
             solver's run time (median [min, max], the extremes from the fastest over the \
             slowest repeat). The goal on n = {GOAL_N} is a CG ratio of at most {:.2} and a \
             time ratio of at most {:.2}. \"force difference\" = |F_two-level - F_Jacobi| / \
             |F_Jacobi| of the total contact force vectors; both solves stop at the relative \
             residual {tol}, and the forces should agree to about that.\n",
            GOAL_ITERATION_RATIO, GOAL_TIME_RATIO
        );
        let _ = writeln!(
            w,
            "| n | ranks | CG Jacobi | CG two-level | CG ratio | time Jacobi s | time two-level s | time ratio | force difference |"
        );
        let _ = writeln!(w, "|---:|---:|---:|---:|---:|---:|---:|---|---:|");
        for b in &self.blocks {
            for r in BLOCK_RANKS {
                let Some((j, t)) = b.pair(r) else {
                    let _ = writeln!(w, "| {} | {r} | not compared (a run failed) ||||||||", b.n);
                    continue;
                };
                let _ = writeln!(
                    w,
                    "| {} | {r} | {} | {} | {} | {:.2} | {:.2} | {} | {} |",
                    b.n,
                    j.log.cg_iterations,
                    t.log.cg_iterations,
                    b.iteration_ratio(r)
                        .map_or("-".into(), |x| format!("{x:.3}")),
                    j.wall.median,
                    t.wall.median,
                    b.time_ratio(r).map_or("-".into(), |s| fmt_stat(&s, 3)),
                    b.force_difference(r)
                        .map_or("-".into(), |d| format!("{d:.1e}")),
                );
            }
        }
        let goal = self.blocks.iter().find(|b| b.n == GOAL_N);
        let _ = match goal {
            None => writeln!(w, "\nGoal: n = {GOAL_N} was not run."),
            Some(b) => {
                let met = |ok: bool| if ok { "met" } else { "**not met**" };
                let parts: Vec<String> = BLOCK_RANKS
                    .iter()
                    .filter_map(|&r| {
                        let it = b.iteration_ratio(r)?;
                        let t = b.time_ratio(r)?.median;
                        Some(format!(
                            "{r} rank(s): CG ratio {it:.3} ({}), time ratio {t:.3} ({})",
                            met(it <= GOAL_ITERATION_RATIO),
                            met(t <= GOAL_TIME_RATIO)
                        ))
                    })
                    .collect();
                if parts.is_empty() {
                    writeln!(w, "\nGoal on n = {GOAL_N}: not judged (a run failed).")
                } else {
                    writeln!(w, "\nGoal on n = {GOAL_N}: {}.", parts.join("; "))
                }
            }
        };

        let _ = writeln!(w, "\n### 2 ranks against 1\n");
        let _ = writeln!(
            w,
            "| n | preconditioner | 1-rank time s | 2-rank time s | speed-up | 1 and 2 ranks bitwise identical |"
        );
        let _ = writeln!(w, "|---:|---|---:|---:|---|---|");
        for b in &self.blocks {
            for pr in &b.runs {
                let t = |r: usize| {
                    pr.case(r)
                        .map_or("-".into(), |c| format!("{:.2}", c.wall.median))
                };
                let _ = writeln!(
                    w,
                    "| {} | {} | {} | {} | {} | {} |",
                    b.n,
                    pr.precond.label(),
                    t(BLOCK_RANKS[0]),
                    t(BLOCK_RANKS[1]),
                    pr.speedup().map_or("-".into(), |s| fmt_stat(&s, 2)),
                    identity_text(&pr.compare)
                );
            }
        }

        let _ = writeln!(w, "\n### Coarse space\n");
        let _ = writeln!(
            w,
            "The two-level runs' `preconditioner:` line (`solver -vv`): aggregates are the nodes \
             of one body in one cell of a uniform grid, 6 rigid-body modes each.\n"
        );
        let _ = writeln!(
            w,
            "| n | ranks | aggregates | coarse unknowns | cell size | colours | line |"
        );
        let _ = writeln!(w, "|---:|---|---:|---:|---:|---:|---|");
        for b in &self.blocks {
            for (ranks, line) in b.coarse_lines() {
                let ranks: Vec<String> = ranks.iter().map(usize::to_string).collect();
                let c = coarse_info(&line);
                let _ = writeln!(
                    w,
                    "| {} | {} | {} | {} | {} | {} | {} |",
                    b.n,
                    ranks.join(", "),
                    c.map_or("-".into(), |c| c.aggregates.to_string()),
                    c.map_or("-".into(), |c| c.unknowns.to_string()),
                    c.map_or("-".into(), |c| format!("{:.4e}", c.cell_size)),
                    c.map_or("-".into(), |c| c.colours.to_string()),
                    line.replace('|', "/")
                );
            }
        }

        let _ = writeln!(w, "\n## Partition\n");
        let _ = writeln!(
            w,
            "`solver check {BLOCK_SCENE} --refine F --ranks R`: how the mesh splits (METIS), \
             and the master faces each rank owns / holds for its slave nodes.\n"
        );
        for p in &self.partitions {
            match p {
                Ok(p) => {
                    let _ = writeln!(
                        w,
                        "n = {}, {} ranks:\n\n```\n{}\n```\n",
                        p.n, p.ranks, p.text
                    );
                }
                Err(e) => {
                    let _ = writeln!(w, "{e}\n");
                }
            }
        }
    }

    fn calculix_markdown(&self, w: &mut String) {
        let c = &self.calculix;
        let _ = writeln!(w, "## CalculiX beside us\n");
        let Some(version) = &c.version else {
            let _ = writeln!(
                w,
                "CalculiX not available (no `ccx` on PATH; `run/setup --calculix` installs \
                 Debian's calculix-ccx)."
            );
            return;
        };
        let _ = writeln!(
            w,
            "CalculiX {version} (`ccx`) on the same problem, from an input deck the bench writes \
             from the scene as the solver loads it: the same nodes and elements (C3D8, 2x2x2 \
             Gauss like the scene's full integration), E and nu, the prescribed displacements \
             at the final time over one static step (no NLGEOM), and frictionless \
             node-to-surface penalty contact of the slave faces on the master faces with a \
             linear pressure-overclosure law of slope {CCX_PENALTY:e} (overclosure about 1e-6 \
             at these pressures). `OMP_NUM_THREADS={CCX_THREADS}`, direct solver (SPOOLES as \
             Debian builds it), at most {CCX_TIMEOUT_S:.0} s per size (larger sizes are \
             skipped after one that does not finish). \"ccx force\" = -(sum of RF_y over the \
             upper block's top), \"bottom\" = sum of RF_y over the lower block's bottom; \
             \"ours\" = our total contact force (two-level preconditioner, 2 ranks). Times are \
             process wall times on both sides (ours: `run/mpirun -np 2 ... --preconditioner \
             two_level`, medians; the repeats are those of the table above). \
             Decks and logs in `out/bench/calculix/`.\n"
        );
        let _ = writeln!(
            w,
            "| n | elements | our two-level 2-rank process s | ccx s (2 threads) | ccx / ours | ccx peak MiB | ccx iterations | our force | ccx force | bottom | relative difference |"
        );
        let _ = writeln!(w, "|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|");
        for s in &c.sizes {
            let ours = self.our_force(s.n);
            let ours_2 = self.our_case(s.n);
            let our_t = ours_2.map(|b| b.process_wall.median);
            let head = format!(
                "| {} | {} | {} |",
                s.n,
                if s.elements > 0 {
                    s.elements.to_string()
                } else {
                    "-".into()
                },
                our_t.map_or("-".into(), |t| format!("{t:.2}"))
            );
            let our_f = ours.map_or("-".into(), |o| format!("{:.6}", o.0));
            let _ = match &s.outcome {
                CcxOutcome::Finished {
                    wall,
                    peak_mib,
                    iterations,
                    top,
                    bottom,
                    ..
                } => writeln!(
                    w,
                    "{head} {} | {} | {} | {} | {our_f} | {:.6} | {:.6} | {} |",
                    fmt_stat(wall, 2),
                    our_t.map_or("-".into(), |t| format!("{:.2}", wall.median / t)),
                    peak_mib.map_or("-".into(), |m| format!("{m:.0}")),
                    iterations,
                    -top[1],
                    bottom[1],
                    ours.map_or("-".into(), |o| format!("{:+.2e}", (-top[1] - o.0) / o.0)),
                ),
                CcxOutcome::Stopped(why) => {
                    writeln!(w, "{head} {why} |||| {our_f} ||||")
                }
                CcxOutcome::Failed(e) => {
                    writeln!(
                        w,
                        "{head} failed: {} |||| {our_f} ||||",
                        e.replace('|', "/")
                    )
                }
                CcxOutcome::Skipped(why) => writeln!(w, "{head} not run: {why} |||| {our_f} ||||"),
            };
        }
    }
}

fn kernel_share(c: &CubeResult) -> f64 {
    c.cg_iterations as f64 * c.force_call.min / c.solve_wall.min
}

fn fmt_stat(s: &Stat, digits: usize) -> String {
    format!(
        "{:.d$} [{:.d$}, {:.d$}]",
        s.median,
        s.min,
        s.max,
        d = digits
    )
}

/// Rates in millions with three significant-ish digits.
fn fmt_rate(s: &Stat) -> String {
    format!(
        "{:.3}e6 [{:.3}e6, {:.3}e6]",
        s.median / 1e6,
        s.min / 1e6,
        s.max / 1e6
    )
}

// ---------------------------------------------------------------------------------------
// Main
// ---------------------------------------------------------------------------------------

const USAGE: &str = concat!(
    "usage: bench [--quick] [--out DIR]\n",
    "       bench --large [--ranks R[,R]] [--out DIR]\n",
    "  --quick      smaller sizes and fewer repeats (a smoke test, about a minute)\n",
    "  --large      only the block on block at n = 80 (about 10^6 elements), two-level, after\n",
    "               a memory check; merged into results.json and report.md as a section of\n",
    "               its own\n",
    "  --ranks R,.. rank counts of --large, in order (default 2; 1,2 or 2,1 for both)\n",
    "  --out DIR    where results.json and report.md go (default out/bench)",
);

fn main() -> ExitCode {
    let mut quick = false;
    let mut large_mode = false;
    let mut ranks: Option<Vec<usize>> = None;
    let mut out = PathBuf::from("out/bench");
    let mut args = std::env::args().skip(1);
    let usage_error = |msg: &str| {
        eprintln!("bench: {msg}\n{USAGE}");
        ExitCode::from(2)
    };
    while let Some(a) = args.next() {
        match a.as_str() {
            "--quick" => quick = true,
            "--large" => large_mode = true,
            "--ranks" => {
                let list: Option<Vec<usize>> = args.next().and_then(|v| {
                    v.split(',')
                        .map(|r| r.trim().parse().ok().filter(|&r: &usize| r >= 1))
                        .collect()
                });
                match list {
                    Some(l) if !l.is_empty() => ranks = Some(l),
                    _ => return usage_error("--ranks needs rank counts such as 2 or 1,2"),
                }
            }
            "--out" => match args.next() {
                Some(d) => out = PathBuf::from(d),
                None => return usage_error("--out needs a directory"),
            },
            "-h" | "--help" => {
                println!("{USAGE}");
                return ExitCode::SUCCESS;
            }
            other => return usage_error(&format!("unknown argument '{other}'")),
        }
    }
    if large_mode && quick {
        return usage_error("--large and --quick do not go together");
    }
    if ranks.is_some() && !large_mode {
        return usage_error("--ranks goes with --large only");
    }
    let done = if large_mode {
        large(&out, &ranks.unwrap_or(LARGE_DEFAULT_RANKS.to_vec()))
    } else {
        bench(Config::new(quick, out))
    };
    match done {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("bench: {e}");
            ExitCode::FAILURE
        }
    }
}

fn bench(cfg: Config) -> Result<(), String> {
    let start = Instant::now();
    std::fs::create_dir_all(&cfg.out)
        .map_err(|e| format!("cannot create {}: {e}", cfg.out.display()))?;
    let machine = machine();
    eprintln!(
        "bench: {} mode on {} ({} logical CPUs)",
        if cfg.quick { "quick" } else { "full" },
        machine.cpu_model,
        machine.logical_cpus
    );

    eprintln!(
        "bench: memory bandwidth ({:.0} MB arrays, {} repeats)",
        cfg.stream_len as f64 * 8.0 / 1e6,
        cfg.stream_repeats
    );
    let stream = memory_bandwidth(&cfg, machine.logical_cpus);
    for s in &stream {
        eprintln!(
            "bench:   {} x{}: {:.2} GB/s",
            s.kernel, s.threads, s.gbs.median
        );
    }

    eprintln!(
        "bench: element kernels on {n}x{n}x{n} ({} / {} repeats)",
        cfg.force_repeats,
        cfg.diagonal_repeats,
        n = cfg.kernel_n
    );
    let kernels = kernels(&cfg)?;

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

    let (m, repeats) = cfg.contact;
    let t = Instant::now();
    let contact = contact_search(m, repeats)?;
    eprintln!(
        "bench: contact search {} slave nodes vs {} master faces: build {:.2} ms, search {:.2} ms \
         ({:.3} us/query), {} / {} found, {:.1} s in all",
        contact.slave_nodes,
        contact.master_faces,
        1e3 * contact.build.median,
        1e3 * contact.search.median,
        1e6 * contact.search.median / contact.slave_nodes as f64,
        contact.found,
        contact.expected,
        t.elapsed().as_secs_f64()
    );

    let exe = solver_exe()?;
    let block_dir = cfg.out.join("block");
    std::fs::create_dir_all(&block_dir)
        .map_err(|e| format!("cannot create {}: {e}", block_dir.display()))?;
    let mut blocks = Vec::new();
    for &(refine, repeats) in &cfg.block {
        let t = Instant::now();
        let n = BLOCK_BASE_N * refine;
        eprintln!(
            "bench: block on block n = {n} on {BLOCK_RANKS:?} ranks, {} ({repeats} repeat(s))",
            PRECONDITIONERS.map(Precond::label).join(" and ")
        );
        let b = block_size(&exe, &block_dir, refine, repeats);
        for pr in &b.runs {
            eprintln!(
                "bench:   n = {n}, {}: speed-up {}, 1 and 2 ranks {}",
                pr.precond.label(),
                pr.speedup()
                    .map_or("-".into(), |s| format!("{:.2}", s.median)),
                match &pr.compare {
                    Some(Ok(c)) if c.identical() => "bitwise identical".to_string(),
                    Some(Ok(c)) => format!("differ ({})", c.summary),
                    Some(Err(e)) => format!("not compared: {e}"),
                    None => "not compared".to_string(),
                }
            );
        }
        for r in BLOCK_RANKS {
            if let (Some(it), Some(tr), Some(df)) =
                (b.iteration_ratio(r), b.time_ratio(r), b.force_difference(r))
            {
                eprintln!(
                    "bench:   n = {n}, {r} rank(s): two-level / Jacobi: CG {it:.3}, time {:.3}; contact forces differ by {df:.1e}",
                    tr.median
                );
            }
        }
        eprintln!(
            "bench:   n = {n}: {:.1} s in all",
            t.elapsed().as_secs_f64()
        );
        blocks.push(b);
    }
    let partitions: Vec<Result<PartitionReport, String>> = PARTITION_RANKS
        .iter()
        .map(|&r| partition_report(&exe, cfg.partition_refine, r))
        .collect();
    let calculix = calculix(&cfg);

    let steal = steal_since(&machine);
    let results = Results {
        cfg_quick: cfg.quick,
        machine,
        cfg_kernel_n: cfg.kernel_n,
        stream,
        kernels,
        cubes,
        contact,
        blocks,
        block_tolerance: block_tolerance(),
        partitions,
        calculix,
        total_wall: start.elapsed().as_secs_f64(),
        load_end: load_average(),
        steal,
        large: earlier_large(&cfg.out),
    };
    let json = serde_json::to_string_pretty(&results.json())
        .map_err(|e| format!("cannot serialise the results: {e}"))?;
    let report = results.markdown();
    let jpath = cfg.out.join("results.json");
    let rpath = cfg.out.join("report.md");
    std::fs::write(&jpath, json + "\n")
        .map_err(|e| format!("cannot write {}: {e}", jpath.display()))?;
    std::fs::write(&rpath, &report)
        .map_err(|e| format!("cannot write {}: {e}", rpath.display()))?;
    println!("{report}");
    eprintln!("bench: wrote {} and {}", jpath.display(), rpath.display());
    let failed = results
        .blocks
        .iter()
        .flat_map(|b| &b.runs)
        .flat_map(|pr| &pr.cases)
        .filter(|c| c.is_err())
        .count();
    if failed > 0 {
        return Err(format!(
            "{failed} block-on-block run(s) failed; see the report"
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solver_log_is_parsed() {
        let log = "\
block_on_block_r2: 2 bodies, 16000 elements, 18522 nodes, 2 steps, 2 rank(s)
decomposition: 2 part(s), element imbalance 1.000 (max/mean), edge cut 1234
  rank    own elems  ghost elems    own nodes  ghost nodes
     0         8000          400         9261          441
     1         8000          400         9261          441
preconditioner: two-level; coarse space: 128 aggregates (768 unknowns), cell size 2.8087e-1, 54 colours
step 1/2  t = 0.500000    CG   1027  residual 1.891e-9 (reference 2.025e-1)  cut-backs 0  7.883 s  contact updates 5, in contact 441 (stick 0, slip 441), released 0, max penetration 1.91e-10
step 2/2  t = 1.000000    CG    835  residual 3.237e-9 (reference 4.050e-1)  cut-backs 0  5.981 s  contact updates 6, in contact 441 (stick 0, slip 441), released 0, max penetration 1.48e-9
done: 2 steps, 1862 CG iterations, 13.953 s, peak memory 59.5 MiB per rank; results in out/x.h5
";
        let l = parse_solver_log(log).unwrap();
        assert_eq!(
            l,
            SolverLog {
                elements: 16000,
                nodes: 18522,
                steps: 2,
                cg_iterations: 1862,
                cg_step_sum: 1862,
                contact_updates: 11,
                wall: 13.953,
                peak_mib: 59.5,
                preconditioner: Some(
                    "two-level; coarse space: 128 aggregates (768 unknowns), cell size \
                     2.8087e-1, 54 colours"
                        .into()
                ),
            }
        );
        assert!(parse_solver_log("error: no such file").is_err());
        let line = l.preconditioner.as_deref().unwrap();
        assert!(Precond::TwoLevel.used(line) && !Precond::Jacobi.used(line));
        assert_eq!(
            coarse_info(line),
            Some(CoarseInfo {
                aggregates: 128,
                unknowns: 768,
                cell_size: 0.28087,
                colours: 54
            })
        );
        assert!(Precond::Jacobi.used("nodal block Jacobi"));
        assert!(!Precond::TwoLevel.used("nodal block Jacobi (no coarse space: why)"));
        assert_eq!(coarse_info("nodal block Jacobi"), None);
    }

    /// results.json read back keeps its key order, and a large section set into it goes
    /// last (or replaces the earlier one in place).
    #[test]
    fn json_round_trip_keeps_order() {
        let text = r#"{"schema":"x","z":[1,2.5,null,true],"a":{"k":"v","b":-3}}"#;
        let mut j: J = serde_json::from_str(text).unwrap();
        assert_eq!(serde_json::to_string(&j).unwrap(), text);
        j.set("large", J::Int(1));
        j.set("z", J::Null);
        assert_eq!(
            serde_json::to_string(&j).unwrap(),
            r#"{"schema":"x","z":null,"a":{"k":"v","b":-3},"large":1}"#
        );
        assert!(matches!(j.get("large"), Some(J::Int(1))));
    }

    /// `--large` puts its section into the normal run's files in place of an earlier one,
    /// and a normal run finds it there to keep.
    #[test]
    fn large_section_is_merged_and_found() {
        let out = std::env::temp_dir().join(format!("bench-large-{}", std::process::id()));
        std::fs::create_dir_all(&out).unwrap();
        let report = |out: &Path| std::fs::read_to_string(out.join("report.md")).unwrap();
        let keys = |out: &Path| -> Vec<String> {
            let t = std::fs::read_to_string(out.join("results.json")).unwrap();
            match serde_json::from_str::<J>(&t).unwrap() {
                J::Obj(kv) => kv.into_iter().map(|(k, _)| k).collect(),
                _ => panic!("not an object"),
            }
        };
        // No earlier files: only the large section.
        merge_large(&out, J::Int(1), &format!("{LARGE_HEADING} (a)\n")).unwrap();
        assert_eq!(keys(&out), ["schema", "doc", "large"]);
        assert!(report(&out).ends_with(&format!("\n\n{LARGE_HEADING} (a)\n")));
        // A normal run's files: the section goes last, then replaces itself.
        std::fs::write(
            out.join("results.json"),
            r#"{"schema":"s","meta":{},"block_on_block":[],"large":null,"calculix":{}}"#,
        )
        .unwrap();
        std::fs::write(out.join("report.md"), "# Bench\n\n## CalculiX\n\ntable\n").unwrap();
        assert!(earlier_large(&out).is_none());
        merge_large(&out, J::Int(2), &format!("{LARGE_HEADING} (b)\n")).unwrap();
        merge_large(&out, J::Int(3), &format!("{LARGE_HEADING} (c)\n")).unwrap();
        assert_eq!(
            keys(&out),
            ["schema", "meta", "block_on_block", "large", "calculix"]
        );
        assert_eq!(
            report(&out),
            format!("# Bench\n\n## CalculiX\n\ntable\n\n{LARGE_HEADING} (c)\n")
        );
        let (j, text) = earlier_large(&out).unwrap();
        assert!(matches!(j, J::Int(3)));
        assert_eq!(text, format!("{LARGE_HEADING} (c)\n"));
        let _ = std::fs::remove_dir_all(&out);
    }

    #[test]
    fn ccx_totals_are_read() {
        let dat = "
 total force (fx,fy,fz) for set N_UPPER_TOP and time  0.1000000E+01

        3.006675E-06 -4.346548E+00 -3.006675E-06
";
        let f = ccx_total_force(dat, "N_UPPER_TOP").unwrap();
        assert_eq!(f, [3.006675e-6, -4.346548, -3.006675e-6]);
        assert!(ccx_total_force(dat, "N_UPPER").is_none());
    }

    #[test]
    fn a_process_past_its_time_limit_is_stopped() {
        let dir = std::env::temp_dir();
        let out = dir.join(format!("bench-test-{}.out", std::process::id()));
        let f = run_limited(
            Command::new("sleep").arg("30"),
            &out,
            &out,
            &Limits::timeout(0.3),
        )
        .unwrap();
        let _ = std::fs::remove_file(&out);
        assert!(f.stopped.is_some() && f.code.is_none(), "{:?}", f.stopped);
        assert!(f.wall < 5.0, "stopped after {} s", f.wall);
    }

    /// The deck of the bench scene: every node and element, the master faces on the lower
    /// block's top (+y: S5), the slave faces on the upper block's bottom (-y: S3).
    #[test]
    fn calculix_deck_of_the_bench_scene() {
        let problem = load_scene_refined(&repo_root().join(BLOCK_SCENE), 1).unwrap();
        let deck = calculix_deck(&problem).unwrap();
        let block = |start: &str| -> Vec<&str> {
            deck.lines()
                .skip_while(|l| !l.starts_with(start))
                .skip(1)
                .take_while(|l| !l.starts_with('*'))
                .collect()
        };
        assert_eq!(block("*NODE").len(), 2 * 11 * 11 * 11);
        assert_eq!(block("*ELEMENT, TYPE=C3D8, ELSET=E_LOWER").len(), 1000);
        let master = block("*SURFACE, NAME=S_MASTER");
        let slave = block("*SURFACE, NAME=S_SLAVE");
        assert_eq!(master.len(), 100);
        assert_eq!(slave.len(), 100);
        assert!(master.iter().all(|l| l.ends_with(", S5")));
        assert!(slave.iter().all(|l| l.ends_with(", S3")));
        let elastic: Vec<f64> = block("*ELASTIC")[0]
            .split(", ")
            .map(|x| x.parse().unwrap())
            .collect();
        assert!((elastic[0] - 1000.0).abs() < 1e-9 && (elastic[1] - 0.3).abs() < 1e-12);
        assert!(deck.contains("N_UPPER_TOP, 2, 2, -0.009\n"));
    }
}
