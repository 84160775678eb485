//! No Rust file of the solver crate (`src/`), of `partition/`, of the tools (`tools/`: bench
//! and suite, their tests) or of the tests (`tests/`) is over 800 lines: a file that grows past that holds more than one concept and wants
//! splitting (docs/layout.md). The function limit, 100 lines, is clippy's `too_many_lines`
//! (clippy.toml), which `run/tests` runs with `-D warnings`.

use std::path::{Path, PathBuf};

/// The most lines a file may have.
const MAX_LINES: usize = 800;

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

#[test]
fn no_rust_file_is_over_800_lines() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    for dir in ["src", "partition", "tools", "tests"] {
        rust_files(&root.join(dir), &mut files);
    }
    assert!(files.len() > 200, "found only {} files", files.len());
    let mut over: Vec<String> = files
        .iter()
        .filter_map(|f| {
            let lines = std::fs::read_to_string(f).unwrap().lines().count();
            (lines > MAX_LINES).then(|| {
                let name = f.strip_prefix(root).unwrap().display();
                format!("{name}: {lines} lines")
            })
        })
        .collect();
    over.sort();
    assert!(
        over.is_empty(),
        "files over {MAX_LINES} lines (split them by concept):\n{}",
        over.join("\n")
    );
}
