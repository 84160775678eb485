//! When and where the run happened: `meta` of results.json, the head of report.md.

use super::json::{Rec, J};
use super::markdown::{dirty, fmt_steal};
use crate::results::Results;
use std::fmt::Write as _;

pub fn json(r: &Results) -> J {
    let i = &r.info;
    let m = &i.machine;
    Rec::default()
        .put("date", m.date.as_str())
        .put("git_commit", m.git_commit.clone())
        .put("git_dirty", m.git_dirty)
        .put("cpu_model", m.cpu_model.as_str())
        .put("cpu_cache", m.cache.as_str())
        .put("logical_cpus", m.logical_cpus)
        .put("physical_cores", m.physical_cores)
        .put("quick", r.quick)
        .put("total_wall_s", i.total_wall)
        .put("load_average_start", m.load_start.clone())
        .put("load_average_end", i.load_end.clone())
        .put("cpu_steal_fraction", i.steal)
        .json()
}

pub fn markdown(r: &Results, w: &mut String) {
    let i = &r.info;
    let m = &i.machine;
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
        dirty(m.git_dirty),
        if r.quick {
            "; **quick mode** (smaller sizes, fewer repeats)"
        } else {
            ""
        }
    );
    let _ = writeln!(
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
        k = r.kernel_n,
        mb = r.stream.first().map_or(0.0, |x| x.array_bytes as f64 / 1e6),
        tw = i.total_wall,
        ls = m.load_start.as_deref().unwrap_or("unknown"),
        le = i.load_end.as_deref().unwrap_or("unknown"),
        st = fmt_steal(i.steal),
    );
}
