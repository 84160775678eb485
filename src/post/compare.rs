//! `solver post compare`: two result files, dataset by dataset.

use std::collections::BTreeSet;
use std::fmt::Write;
use std::path::{Path, PathBuf};

use crate::output::{layout, NumericData, OutputError, ResultFile};

/// Datasets reported but never failing a comparison: they legitimately differ between runs.
const NOT_COUNTED: [&str; 2] = [layout::STATS_WALL_TIME, layout::ELEMENT_RANK];

/// Values read at once per dataset.
const BLOCK_VALUES: usize = 1 << 20;

/// The comparison of one dataset present in both files.
#[derive(Clone, Debug, PartialEq)]
pub struct DatasetComparison {
    pub name: String,
    pub shape: Vec<usize>,
    /// Largest |a - b|.
    pub max_abs_diff: f64,
    /// `max_abs_diff` over the largest |a| of the dataset (0 when both are all zero,
    /// infinite when only a is all zero).
    pub max_rel_diff: f64,
    /// Number of values that are not bitwise equal.
    pub differing: u64,
    pub bitwise_identical: bool,
    /// Whether the dataset can fail the comparison (not `/stats/wall_time` nor
    /// `/partition/element_rank`).
    pub counted: bool,
    /// Whether the difference is within the tolerance (bitwise equality for tolerance 0).
    pub within_tol: bool,
}

/// The outcome of comparing two result files.
#[derive(Clone, Debug, PartialEq)]
pub struct CompareReport {
    pub a: PathBuf,
    pub b: PathBuf,
    pub tol: f64,
    pub datasets: Vec<DatasetComparison>,
    pub only_in_a: Vec<String>,
    pub only_in_b: Vec<String>,
    /// The `scene_name` attributes of a and b.
    pub scene_names: (String, String),
}

impl CompareReport {
    fn failing(&self) -> Vec<&DatasetComparison> {
        self.datasets
            .iter()
            .filter(|d| d.counted && !d.within_tol)
            .collect()
    }

    /// True when the scene names agree and every counted dataset is within the tolerance.
    pub fn passed(&self) -> bool {
        self.scene_names.0 == self.scene_names.1 && self.failing().is_empty()
    }

    /// True when the scene names agree and every counted dataset is bitwise identical.
    pub fn bitwise_identical(&self) -> bool {
        self.scene_names.0 == self.scene_names.1
            && self
                .datasets
                .iter()
                .all(|d| !d.counted || d.bitwise_identical)
    }

    /// 0 when passed, 1 otherwise.
    pub fn exit_code(&self) -> i32 {
        if self.passed() {
            0
        } else {
            1
        }
    }

    /// The report `solver post compare` prints; its last line is the verdict.
    pub fn render(&self) -> String {
        let mut s = String::new();
        let tol = if self.tol == 0.0 {
            "bitwise".to_string()
        } else {
            format!("relative {:e}", self.tol)
        };
        let _ = writeln!(s, "a: {}", self.a.display());
        let _ = writeln!(s, "b: {}", self.b.display());
        let _ = writeln!(s, "tolerance: {tol}");
        let width = self
            .datasets
            .iter()
            .map(|d| d.name.len())
            .max()
            .unwrap_or(7)
            .max(7);
        let _ = writeln!(
            s,
            "{:width$}  {:>16}  {:>12}  {:>12}  status",
            "dataset", "shape", "max abs diff", "max rel diff"
        );
        for d in &self.datasets {
            let shape = format!("{:?}", d.shape);
            let status = match (d.bitwise_identical, d.counted, d.within_tol) {
                (true, true, _) => "identical".to_string(),
                (true, false, _) => "identical (not counted)".to_string(),
                (false, false, _) => format!("{} values differ (not counted)", d.differing),
                (false, true, true) => format!("within tolerance, {} values differ", d.differing),
                (false, true, false) => format!("EXCEEDS tolerance, {} values differ", d.differing),
            };
            let _ = writeln!(
                s,
                "{:width$}  {:>16}  {:>12.4e}  {:>12.4e}  {status}",
                d.name, shape, d.max_abs_diff, d.max_rel_diff
            );
        }
        if !self.only_in_a.is_empty() {
            let _ = writeln!(s, "only in a: {}", self.only_in_a.join(", "));
        }
        if !self.only_in_b.is_empty() {
            let _ = writeln!(s, "only in b: {}", self.only_in_b.join(", "));
        }
        let scenes_agree = self.scene_names.0 == self.scene_names.1;
        if !scenes_agree {
            let _ = writeln!(
                s,
                "attribute scene_name differs: '{}' vs '{}'",
                self.scene_names.0, self.scene_names.1
            );
        }
        let counted = self.datasets.iter().filter(|d| d.counted).count();
        let failing = self.failing();
        if self.bitwise_identical() {
            let _ = writeln!(s, "result: bitwise identical ({counted} counted datasets)");
        } else if self.passed() {
            let differ = self
                .datasets
                .iter()
                .filter(|d| d.counted && !d.bitwise_identical)
                .count();
            let _ = writeln!(
                s,
                "result: within tolerance {tol} ({differ} of {counted} counted datasets differ bitwise)"
            );
        } else {
            let mut what: Vec<String> = failing.iter().map(|d| d.name.clone()).collect();
            if !scenes_agree {
                what.push("attribute scene_name".into());
            }
            let _ = writeln!(
                s,
                "result: DIFFERENT: {} exceed{} the tolerance: {}",
                what.len(),
                if what.len() == 1 { "s" } else { "" },
                what.join(", ")
            );
        }
        s
    }
}

/// Running extremes of a comparison.
#[derive(Default)]
struct Accumulator {
    max_abs_diff: f64,
    max_abs_a: f64,
    differing: u64,
}

impl Accumulator {
    fn add(&mut self, a: &NumericData, b: &NumericData) -> bool {
        match (a, b) {
            (NumericData::Float(a), NumericData::Float(b)) => {
                for (x, y) in a.iter().zip(b) {
                    self.max_abs_a = self.max_abs_a.max(x.abs());
                    if x.to_bits() != y.to_bits() {
                        self.differing += 1;
                        self.max_abs_diff = self.max_abs_diff.max((x - y).abs());
                    }
                }
            }
            (NumericData::Unsigned(a), NumericData::Unsigned(b)) => {
                for (x, y) in a.iter().zip(b) {
                    self.max_abs_a = self.max_abs_a.max(*x as f64);
                    if x != y {
                        self.differing += 1;
                        self.max_abs_diff = self.max_abs_diff.max(x.abs_diff(*y) as f64);
                    }
                }
            }
            (NumericData::Signed(a), NumericData::Signed(b)) => {
                for (x, y) in a.iter().zip(b) {
                    self.max_abs_a = self.max_abs_a.max(x.unsigned_abs() as f64);
                    if x != y {
                        self.differing += 1;
                        self.max_abs_diff = self.max_abs_diff.max(x.abs_diff(*y) as f64);
                    }
                }
            }
            _ => return false,
        }
        true
    }
}

/// Integer datasets under `/mesh` describe the mesh itself: any difference is a mismatch.
fn is_topology(name: &str, data: &NumericData) -> bool {
    name.starts_with("/mesh/") && !matches!(data, NumericData::Float(_))
}

/// Compares every numeric dataset present in both files.
///
/// Returns `Err(OutputError::Mismatch)` when the files cannot be compared: a dataset has
/// different shapes or number kinds in the two files, or the meshes' ids, connectivity or
/// sets differ.
pub fn compare_files(a: &Path, b: &Path, tol: f64) -> Result<CompareReport, OutputError> {
    compare_files_only(a, b, tol, &[])
}

/// `compare_files` over the datasets whose path starts with one of `only` (every dataset
/// when `only` is empty).
pub fn compare_files_only(
    a: &Path,
    b: &Path,
    tol: f64,
    only: &[String],
) -> Result<CompareReport, OutputError> {
    if !(tol.is_finite() && tol >= 0.0) {
        return Err(OutputError::Usage {
            file: a.to_path_buf(),
            message: format!("--tol must be a finite number >= 0, not {tol}"),
        });
    }
    let fa = ResultFile::open(a)?;
    let fb = ResultFile::open(b)?;
    let kept = |n: &String| only.is_empty() || only.iter().any(|p| n.starts_with(p.as_str()));
    let names_a: BTreeSet<String> = fa.dataset_names().into_iter().filter(kept).collect();
    let names_b: BTreeSet<String> = fb.dataset_names().into_iter().filter(kept).collect();
    let mismatch = |message: String| OutputError::Mismatch {
        a: a.to_path_buf(),
        b: b.to_path_buf(),
        message,
    };

    let mut problems = Vec::new();
    let mut datasets = Vec::new();
    for name in names_a.intersection(&names_b) {
        if let Some(d) = compare_dataset(&fa, &fb, name, tol, &mut problems)? {
            datasets.push(d);
        }
    }
    if !problems.is_empty() {
        let shown = problems.len().min(12);
        let mut message = problems[..shown].join("\n  ");
        if problems.len() > shown {
            message += &format!("\n  ... and {} more", problems.len() - shown);
        }
        return Err(mismatch(format!("\n  {message}")));
    }
    let scene_names = (fa.attributes()?.scene_name, fb.attributes()?.scene_name);
    Ok(CompareReport {
        a: a.to_path_buf(),
        b: b.to_path_buf(),
        tol,
        datasets,
        only_in_a: names_a.difference(&names_b).cloned().collect(),
        only_in_b: names_b.difference(&names_a).cloned().collect(),
        scene_names,
    })
}

/// Compares one dataset present in both files, block by block; None when it is not
/// numeric or cannot be compared (the reason then goes to `problems`).
fn compare_dataset(
    fa: &ResultFile,
    fb: &ResultFile,
    name: &String,
    tol: f64,
    problems: &mut Vec<String>,
) -> Result<Option<DatasetComparison>, OutputError> {
    let (ka, kb) = (fa.numeric_kind(name)?, fb.numeric_kind(name)?);
    if ka.is_none() && kb.is_none() {
        return Ok(None);
    }
    let (sa, sb) = (fa.shape(name)?, fb.shape(name)?);
    let counted = !NOT_COUNTED.contains(&name.as_str());
    if ka != kb {
        problems.push(format!("{name} holds {ka:?} numbers in a, {kb:?} in b"));
        return Ok(None);
    }
    if sa != sb {
        if counted {
            problems.push(format!("{name} has shape {sa:?} in a, {sb:?} in b"));
        }
        return Ok(None);
    }
    let rows = sa.first().copied().unwrap_or(1);
    let row_len: usize = sa.iter().skip(1).product::<usize>().max(1);
    let block = (BLOCK_VALUES / row_len).max(1);
    let mut acc = Accumulator::default();
    let mut topology = false;
    let mut start = 0;
    while start < rows {
        let end = (start + block).min(rows);
        let va = fa.read_numeric_rows(name, start..end)?;
        let vb = fb.read_numeric_rows(name, start..end)?;
        topology = is_topology(name, &va);
        if !acc.add(&va, &vb) {
            problems.push(format!("{name} cannot be compared"));
        }
        start = end;
    }
    if topology && acc.differing > 0 {
        problems.push(format!(
            "meshes differ: {name} has {} differing values",
            acc.differing
        ));
        return Ok(None);
    }
    let bitwise_identical = acc.differing == 0;
    let max_rel_diff = if acc.max_abs_diff == 0.0 {
        0.0
    } else if acc.max_abs_a > 0.0 {
        acc.max_abs_diff / acc.max_abs_a
    } else {
        f64::INFINITY
    };
    let within_tol = bitwise_identical || (tol > 0.0 && max_rel_diff <= tol);
    Ok(Some(DatasetComparison {
        name: name.clone(),
        shape: sa,
        max_abs_diff: acc.max_abs_diff,
        max_rel_diff,
        differing: acc.differing,
        bitwise_identical,
        counted,
        within_tol,
    }))
}
