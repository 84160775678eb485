//! What a solver run printed on standard error (rank 0, with -vv), read back.

/// The number written right after `key` in `line` (trailing `,` or `;` dropped).
pub fn number_after<T: std::str::FromStr>(line: &str, key: &str) -> Option<T> {
    let i = line.find(key)?;
    line[i + key.len()..]
        .split_whitespace()
        .next()?
        .trim_end_matches([',', ';'])
        .parse()
        .ok()
}

/// The number written right before `key` in `line` (a leading `(` dropped).
pub fn number_before<T: std::str::FromStr>(line: &str, key: &str) -> Option<T> {
    let i = line.find(key)?;
    line[..i]
        .split_whitespace()
        .next_back()?
        .trim_start_matches('(')
        .trim_end_matches([',', ';'])
        .parse()
        .ok()
}

/// The last line of `text` that is not blank.
pub fn last_line(text: &str) -> &str {
    text.lines()
        .rev()
        .find(|l| !l.trim().is_empty())
        .unwrap_or("")
}

/// What one solver run printed on standard error (rank 0, with -vv).
#[derive(Clone, Debug, PartialEq)]
pub struct SolverLog {
    pub elements: usize,
    pub nodes: usize,
    pub steps: usize,
    /// From the final `done:` line.
    pub cg_iterations: u64,
    /// Sum of the per-step `CG <n>`; equals `cg_iterations`.
    pub cg_step_sum: u64,
    /// Sum of the per-step `contact updates <n>`.
    pub contact_updates: u64,
    /// The run's wall time as the solver reports it (decomposition to result file).
    pub wall: f64,
    /// Peak memory, MiB per rank (the largest VmHWM over the ranks).
    pub peak_mib: f64,
    /// The `preconditioner: ..` line without its prefix (printed from -v on).
    pub preconditioner: Option<String>,
}

impl SolverLog {
    /// The counts that must not change from one repeat of a run to the next.
    fn counts(&self) -> (usize, u64, u64, u64, &Option<String>) {
        (
            self.steps,
            self.cg_iterations,
            self.cg_step_sum,
            self.contact_updates,
            &self.preconditioner,
        )
    }

    /// Whether every repeat in `logs` counted what the first did, and the first's step
    /// sum agrees with its total.
    pub fn consistent(logs: &[SolverLog]) -> bool {
        let Some(first) = logs.first() else {
            return false;
        };
        logs.iter().all(|l| l.counts() == first.counts())
            && first.cg_iterations == first.cg_step_sum
    }
}

pub fn parse_solver_log(text: &str) -> Result<SolverLog, String> {
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
pub struct CoarseInfo {
    pub aggregates: usize,
    pub unknowns: usize,
    pub cell_size: f64,
    pub colours: usize,
}

pub fn coarse_info(line: &str) -> Option<CoarseInfo> {
    let s = &line[line.find("coarse space: ")?..];
    Some(CoarseInfo {
        aggregates: number_before(s, " aggregates")?,
        unknowns: number_before(s, " unknowns")?,
        cell_size: number_after(s, "cell size ")?,
        colours: number_before(s, " colours")?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const LOG: &str = "\
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

    #[test]
    fn solver_log_is_parsed() {
        let l = parse_solver_log(LOG).unwrap();
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
        assert_eq!(
            coarse_info(line),
            Some(CoarseInfo {
                aggregates: 128,
                unknowns: 768,
                cell_size: 0.28087,
                colours: 54
            })
        );
        assert_eq!(coarse_info("nodal block Jacobi"), None);
    }

    /// A step line whose count cannot be read names the line.
    #[test]
    fn an_unreadable_step_line_is_an_error() {
        let bad = LOG.replace("CG    835", "CG    x");
        let e = parse_solver_log(&bad).unwrap_err();
        assert!(e.starts_with("cannot read CG from 'step 2/2"), "{e}");
    }

    #[test]
    fn repeats_agree_only_when_every_count_does() {
        let l = parse_solver_log(LOG).unwrap();
        assert!(SolverLog::consistent(&[l.clone(), l.clone()]));
        let mut other = l.clone();
        other.contact_updates += 1;
        assert!(!SolverLog::consistent(&[l.clone(), other]));
        let mut odd = l.clone();
        odd.cg_step_sum -= 1;
        assert!(!SolverLog::consistent(&[odd]));
        assert!(!SolverLog::consistent(&[]));
        // Wall time and memory may differ between repeats.
        let mut slower = l.clone();
        slower.wall *= 2.0;
        assert!(SolverLog::consistent(&[l, slower]));
    }

    #[test]
    fn numbers_around_keys() {
        assert_eq!(number_after::<u64>("a CG 12, b", " CG "), Some(12));
        assert_eq!(
            number_before::<u64>("(768 unknowns)", " unknowns"),
            Some(768)
        );
        assert_eq!(number_before::<u64>("x unknowns", " unknowns"), None);
        assert_eq!(last_line("a\nb\n\n  \n"), "b");
    }
}
