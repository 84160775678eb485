//! The library's modules form layers that only import downward: a module may name (through
//! `crate::...`) only modules of its own layer or below. The order is docs/layout.md's; this
//! test reads every `crate::` path in `src/` (comments excluded) and fails
//! on an arrow that runs up, and on a top-level module the order does not place.
//! Above them all sit the tools (`tools/`: bench and suite), a crate of their own that sees
//! the solver crate's public API only: no binary in `src/`, no tools source reaching into
//! `src/` by path, and nothing below naming the tools.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Bottom to top. Modules of one layer may import each other.
const LAYERS: &[&[&str]] = &[
    &["math", "memory"],
    &["comm"],
    &["output"],
    &["material"],
    &["fem"],
    &["mesh"],
    &["problem"],
    &["scene"],
    &["constraints", "springs"],
    &["precond"],
    &["contact"],
    &["solver"],
    &["run", "preflight"],
    &["post"],
];

fn layer(module: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&module))
}

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

/// The top-level module a file of `src/` belongs to (`None` for the crate root and the
/// binary, which sit above every layer).
fn owner(src: &Path, file: &Path) -> Option<String> {
    let rel = file.strip_prefix(src).unwrap();
    let first = rel
        .components()
        .next()?
        .as_os_str()
        .to_string_lossy()
        .into_owned();
    let name = first.strip_suffix(".rs").unwrap_or(&first).to_string();
    (!matches!(name.as_str(), "lib" | "main")).then_some(name)
}

/// The modules a file names as `crate::NAME`, with the line, outside `//` comments.
fn imports(text: &str) -> Vec<(usize, String)> {
    let mut found = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let code = line.split("//").next().unwrap();
        let mut rest = code;
        while let Some(k) = rest.find("crate::") {
            let after = &rest[k + 7..];
            let name: String = after
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            if !name.is_empty() {
                found.push((i + 1, name));
            }
            rest = after;
        }
    }
    found
}

#[test]
fn no_module_imports_a_higher_layer() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let lib = std::fs::read_to_string(src.join("lib.rs")).unwrap();
    let declared: BTreeSet<String> = lib
        .lines()
        .filter_map(|l| l.trim().strip_prefix("pub mod "))
        .map(|m| m.trim_end_matches(';').to_string())
        .collect();
    for m in &declared {
        assert!(
            layer(m).is_some(),
            "src/lib.rs declares `{m}`, which LAYERS does not place"
        );
    }
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    let mut upward = Vec::new();
    let mut arrows = BTreeSet::new();
    for f in &files {
        let Some(from) = owner(&src, f) else { continue };
        let from_layer =
            layer(&from).unwrap_or_else(|| panic!("{}: module not placed", f.display()));
        for (line, to) in imports(&std::fs::read_to_string(f).unwrap()) {
            let Some(to_layer) = layer(&to) else { continue };
            if to != from {
                arrows.insert(format!("{from} -> {to}"));
            }
            if to_layer > from_layer {
                upward.push(format!("{}:{line}: {from} imports {to}", f.display()));
            }
        }
    }
    println!("{} arrows between modules: {arrows:?}", arrows.len());
    assert!(
        upward.is_empty(),
        "imports up the layers:\n{}",
        upward.join("\n")
    );
}

#[test]
fn the_check_sees_an_upward_import() {
    // The reader finds `crate::` paths in code, not in comments.
    let text = "use crate::solver::cg; // crate::post\nlet x = crate::math::dot(a, b);";
    assert_eq!(
        imports(text),
        vec![(1, "solver".to_string()), (2, "math".to_string())]
    );
    assert!(layer("solver") > layer("contact"));
    assert!(layer("solver") > layer("precond") && layer("precond") > layer("constraints"));
}

#[test]
fn the_tools_sit_above_the_solver_crate() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    assert!(
        !root.join("src/bin").exists(),
        "src/bin: the bench and the suites live in tools/"
    );
    let mut tools = Vec::new();
    rust_files(&root.join("tools"), &mut tools);
    assert!(
        tools.len() > 50,
        "found only {} files in tools/",
        tools.len()
    );
    for f in &tools {
        let text = std::fs::read_to_string(f).unwrap();
        for (i, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap();
            assert!(
                !code.contains("#[path") && !code.contains("include!("),
                "{}:{}: tools reach source files by path",
                f.display(),
                i + 1
            );
        }
    }
    let mut below = Vec::new();
    rust_files(&root.join("src"), &mut below);
    rust_files(&root.join("partition"), &mut below);
    for f in &below {
        let text = std::fs::read_to_string(f).unwrap();
        assert!(
            !text.contains("solver_tools"),
            "{} names the tools crate",
            f.display()
        );
    }
}
