//! `results.csv`: one row per series, refinement, tolerance and rank count.

use super::row::Row;
use std::fmt::Write as _;
use std::path::Path;

pub fn write_csv(path: &Path, rows: &[Row]) -> Result<(), String> {
    let mut s = String::from(
        "series,scene,refinement,element_size_rel,tolerance,ranks,error,wall_time_s,cg_iterations,contact_updates,identical_to_1_rank,status\n",
    );
    for r in rows {
        let _ = writeln!(
            s,
            "{},{},{},{},{:e},{},{},{},{},{},{},\"{}\"",
            r.series,
            r.scene,
            r.factor,
            1.0 / r.factor as f64,
            r.tolerance,
            r.ranks,
            r.error.map_or(String::new(), |v| format!("{v:e}")),
            r.wall_time.map_or(String::new(), |v| format!("{v:e}")),
            r.cg_iterations.map_or(String::new(), |v| format!("{v}")),
            r.contact_updates.map_or(String::new(), |v| format!("{v}")),
            r.identical.map_or(String::new(), |b| b.to_string()),
            r.status.replace('"', "'")
        );
    }
    std::fs::write(path, s).map_err(|e| format!("{}: {e}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_row_is_written_with_empty_cells_for_what_is_missing() {
        let path = std::env::temp_dir().join(format!("suite-study-{}.csv", std::process::id()));
        let row = Row {
            series: "capture_release".into(),
            scene: "capture_release".into(),
            factor: 2,
            tolerance: 1e-9,
            ranks: 2,
            error: Some(4e-13),
            wall_time: None,
            cg_iterations: Some(13.0),
            contact_updates: Some(51.0),
            identical: Some(true),
            status: "exit Some(1): \"x\"".into(),
        };
        write_csv(&path, &[row]).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(
            text.lines().nth(1),
            Some("capture_release,capture_release,2,0.5,1e-9,2,4e-13,,13,51,true,\"exit Some(1): 'x'\"")
        );
        std::fs::remove_file(&path).unwrap();
    }
}
