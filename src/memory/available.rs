//! The memory this process may still use: the machine's MemAvailable, the headroom under
//! the cgroup's limit (v2 `memory.max`, v1 `memory.limit_in_bytes`) and under the address
//! space limit (`ulimit -v`, `prlimit --as`). Linux only; elsewhere nothing is known.

use std::path::Path;

/// One bound on the memory a run may take, in bytes, with where it comes from.
#[derive(Clone, Debug, PartialEq)]
pub struct Bound {
    pub bytes: f64,
    /// "MemAvailable", "cgroup memory.max 8.0 GiB, 1.2 GiB used", ...
    pub source: String,
    /// Shared by every process of the machine (or cgroup); the address space limit is per
    /// process.
    pub shared: bool,
}

/// The bounds that apply now, tightest first.
pub fn bounds() -> Vec<Bound> {
    let mut out: Vec<Bound> = [mem_available(), cgroup_headroom(), address_space_headroom()]
        .into_iter()
        .flatten()
        .collect();
    out.sort_by(|a, b| a.bytes.total_cmp(&b.bytes));
    out
}

/// A `/proc` file's `Name:  N kB` field in bytes.
fn kb_field(text: &str, name: &str) -> Option<f64> {
    let line = text.lines().find(|l| l.starts_with(name))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0)
}

/// MemAvailable of /proc/meminfo.
pub fn mem_available() -> Option<Bound> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    Some(Bound {
        bytes: kb_field(&text, "MemAvailable:")?,
        source: "MemAvailable".into(),
        shared: true,
    })
}

/// A limit file's value; "max" and the v1 "unlimited" (2^63 rounded to pages) are none.
fn limit_value(path: &Path) -> Option<f64> {
    let text = std::fs::read_to_string(path).ok()?;
    let v: u64 = text.trim().parse().ok()?;
    (v < 1 << 60).then_some(v as f64)
}

fn used_value(path: &Path) -> Option<f64> {
    std::fs::read_to_string(path).ok()?.trim().parse().ok()
}

/// Limit minus usage of this process's memory cgroup: v2 (`0::/path` in /proc/self/cgroup,
/// memory.max and memory.current), else v1 (the `memory` controller's
/// memory.limit_in_bytes and memory.usage_in_bytes). Inside a cgroup namespace the own
/// cgroup is mounted at the root, so that is tried too.
pub fn cgroup_headroom() -> Option<Bound> {
    let own = std::fs::read_to_string("/proc/self/cgroup").unwrap_or_default();
    let path_of = |pred: &dyn Fn(&str) -> bool| -> Option<String> {
        own.lines().find_map(|l| {
            let mut it = l.splitn(3, ':');
            let (_, controllers, path) = (it.next()?, it.next()?, it.next()?);
            pred(controllers).then(|| path.trim_start_matches('/').to_string())
        })
    };
    let root = Path::new("/sys/fs/cgroup");
    let mut candidates = Vec::new();
    if let Some(p) = path_of(&|c: &str| c.is_empty()) {
        for base in [root.to_path_buf(), root.join("unified")] {
            candidates.push((base.join(&p), "memory.max", "memory.current", 2));
            candidates.push((base.clone(), "memory.max", "memory.current", 2));
        }
    }
    let v1 = root.join("memory");
    if let Some(p) = path_of(&|c: &str| c.split(',').any(|c| c == "memory")) {
        candidates.push((
            v1.join(p),
            "memory.limit_in_bytes",
            "memory.usage_in_bytes",
            1,
        ));
    }
    candidates.push((v1, "memory.limit_in_bytes", "memory.usage_in_bytes", 1));
    candidates.into_iter().find_map(|(dir, max, cur, v)| {
        let limit = limit_value(&dir.join(max))?;
        let used = used_value(&dir.join(cur)).unwrap_or(0.0);
        Some(Bound {
            bytes: (limit - used).max(0.0),
            source: format!(
                "cgroup v{v} {max} {} with {} in use",
                super::bytes::format_bytes(limit),
                super::bytes::format_bytes(used)
            ),
            shared: true,
        })
    })
}

/// The address space limit (RLIMIT_AS) less the address space already mapped, in resident
/// terms: what is mapped but not resident (the MPI and HDF5 libraries' reservations) stays
/// so, and a run's growth is resident.
pub fn address_space_headroom() -> Option<Bound> {
    let mut lim = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: getrlimit writes the struct it is given and nothing else.
    if unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut lim) } != 0
        || lim.rlim_cur == libc::RLIM_INFINITY
    {
        return None;
    }
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let size = kb_field(&status, "VmSize:")?;
    let rss = kb_field(&status, "VmRSS:")?;
    let limit = lim.rlim_cur as f64;
    Some(Bound {
        bytes: (limit - size + rss).max(0.0),
        source: format!(
            "address space limit {} with {} mapped",
            super::bytes::format_bytes(limit),
            super::bytes::format_bytes(size)
        ),
        shared: false,
    })
}

/// This process's resident memory now, bytes.
pub fn resident() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    kb_field(&status, "VmRSS:")
}
