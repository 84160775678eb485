//! No two files of one crate import each other, directly or around a circle: the files of
//! the solver crate (`src/`), of `partition/` and of the tools (`tools/`: bench and suite)
//! form a graph with an arrow from a file to every file whose module or item it names
//! (`use crate::a::b`, `super::x`, `self::x`, a child module or an imported module's path
//! in code; a re-export followed to the file that defines the item), and no strongly
//! connected component of it holds more than one file. A module declaring its children
//! (`mod x;`) is no arrow; test modules (`#[cfg(test)]`) are left out. docs/layout.md.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// One module backed by a file.
struct Module {
    file: PathBuf,
    parent: Option<usize>,
    root: usize,
    children: BTreeMap<String, usize>,
    /// Names a `use` brings into scope: the path it names, from this module.
    aliases: BTreeMap<String, Vec<String>>,
    /// Paths named in code (`use` paths and paths in expressions and types).
    paths: Vec<Vec<String>>,
}

/// A file's code: without `//` comments and without its inline `#[cfg(test)]` module.
fn code_of(text: &str) -> String {
    let mut out = String::new();
    let mut lines = text.lines().peekable();
    while let Some(line) = lines.next() {
        let code = line.split("//").next().unwrap();
        if code.trim() == "#[cfg(test)]" {
            let next = lines.peek().map_or("", |l| l.trim());
            if next.starts_with("mod ") && next.ends_with('{') {
                lines.next();
                let mut depth = 1i32;
                for l in lines.by_ref() {
                    let c = l.split("//").next().unwrap();
                    depth += c.matches('{').count() as i32 - c.matches('}').count() as i32;
                    if depth <= 0 {
                        break;
                    }
                }
                continue;
            }
        }
        out.push_str(code);
        out.push('\n');
    }
    out
}

/// The child modules a file declares (`mod x;`), outside `#[cfg(test)]`.
fn declared_children(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut test_next = false;
    for line in code.lines().map(str::trim) {
        if line.starts_with("#[cfg(test)]") {
            test_next = true;
            continue;
        }
        let rest = line
            .trim_start_matches("pub(crate) ")
            .trim_start_matches("pub(super) ")
            .trim_start_matches("pub ");
        if let Some(name) = rest.strip_prefix("mod ").and_then(|r| r.strip_suffix(';')) {
            if !test_next {
                out.push(name.trim().to_string());
            }
        }
        if !line.starts_with("#[") {
            test_next = false;
        }
    }
    out
}

/// The file of child module `name` of the module in `file`.
fn child_file(file: &Path, name: &str) -> PathBuf {
    let stem = file.file_stem().unwrap().to_string_lossy();
    let dir = file.parent().unwrap();
    let dir = if matches!(stem.as_ref(), "mod" | "lib" | "main") {
        dir.to_path_buf()
    } else {
        dir.join(stem.as_ref())
    };
    let flat = dir.join(format!("{name}.rs"));
    if flat.is_file() {
        flat
    } else {
        dir.join(name).join("mod.rs")
    }
}

fn is_ident(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// The paths (two segments or more) written in `code`, each as its segments.
fn code_paths(code: &str) -> Vec<Vec<String>> {
    let chars: Vec<char> = code.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let starts =
            is_ident(chars[i]) && (i == 0 || !(is_ident(chars[i - 1]) || chars[i - 1] == ':'));
        if !starts {
            i += 1;
            continue;
        }
        let mut segs = Vec::new();
        loop {
            let s = i;
            while i < chars.len() && is_ident(chars[i]) {
                i += 1;
            }
            segs.push(chars[s..i].iter().collect::<String>());
            let more = chars.get(i) == Some(&':')
                && chars.get(i + 1) == Some(&':')
                && chars.get(i + 2).is_some_and(|c| is_ident(*c));
            if !more {
                break;
            }
            i += 2;
        }
        if segs.len() > 1 {
            out.push(segs);
        }
    }
    out
}

/// The `use` declarations of `code` expanded: (the path, the name it brings in; `*` for a glob).
fn use_items(code: &str) -> Vec<(Vec<String>, String)> {
    let mut out = Vec::new();
    let mut rest = code;
    while let Some(k) = rest.find("use ") {
        let before = rest[..k].chars().last();
        let after = &rest[k + 4..];
        rest = after;
        if before.is_some_and(|c| is_ident(c) || c == ':') {
            continue;
        }
        let Some(end) = after.find(';') else { break };
        let tree = after[..end].replace('\n', " ");
        let well_formed = tree
            .chars()
            .all(|c| is_ident(c) || c.is_whitespace() || ":{},*".contains(c));
        if well_formed && tree.matches('{').count() == tree.matches('}').count() {
            expand(tree.trim(), &[], &mut out);
        }
    }
    out
}

/// One use tree (`a::b::{c, d::e as f, self, *}`) under `prefix`.
fn expand(tree: &str, prefix: &[String], out: &mut Vec<(Vec<String>, String)>) {
    let tree = tree.trim();
    if let (Some(open), Some(close)) = (tree.find('{'), tree.rfind('}')) {
        let mut base = prefix.to_vec();
        base.extend(segments(tree[..open].trim().trim_end_matches("::")));
        let inner = &tree[open + 1..close];
        let (mut depth, mut start) = (0, 0);
        for (i, c) in inner.char_indices() {
            match c {
                '{' => depth += 1,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    expand(&inner[start..i], &base, out);
                    start = i + 1;
                }
                _ => {}
            }
        }
        expand(&inner[start..], &base, out);
        return;
    }
    let words: Vec<&str> = tree.split_whitespace().collect();
    let (path, alias) = match words[..] {
        [p] => (p, None),
        [p, "as", a] => (p, Some(a)),
        _ => return,
    };
    let mut full = prefix.to_vec();
    full.extend(segments(path));
    if full.last().is_some_and(|s| s == "self") {
        full.pop();
    }
    let name = alias.map_or_else(|| full.last().cloned().unwrap_or_default(), str::to_string);
    if !full.is_empty() {
        out.push((full, name));
    }
}

fn segments(path: &str) -> Vec<String> {
    path.split("::")
        .filter(|s| !s.is_empty())
        .map(str::to_string)
        .collect()
}
/// The module tree of the crate rooted at `root_file`, appended to `modules`.
fn load_crate(root_file: &Path, modules: &mut Vec<Module>) {
    let root = modules.len();
    let mut todo: Vec<(PathBuf, Option<(usize, String)>)> = vec![(root_file.to_path_buf(), None)];
    while let Some((file, parent)) = todo.pop() {
        let text =
            std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        let code = code_of(&text);
        let me = modules.len();
        if let Some((p, name)) = &parent {
            modules[*p].children.insert(name.clone(), me);
        }
        let mut aliases = BTreeMap::new();
        for (path, name) in use_items(&code) {
            if name != "*" {
                aliases.insert(name, path);
            }
        }
        let mut paths: Vec<Vec<String>> = use_items(&code).into_iter().map(|u| u.0).collect();
        paths.extend(code_paths(&code));
        for child in declared_children(&code) {
            todo.push((child_file(&file, &child), Some((me, child))));
        }
        modules.push(Module {
            file,
            parent: parent.map(|p| p.0),
            root,
            children: BTreeMap::new(),
            aliases,
            paths,
        });
    }
}

/// The module `path` names from module `m`, and the item name after it if any, following
/// `use` aliases (re-exports) to where the item is defined. `None`: outside the crate.
fn resolve(modules: &[Module], m: usize, path: &[String], depth: usize) -> Option<usize> {
    if depth > 16 || path.is_empty() {
        return None;
    }
    let first = path[0].as_str();
    let mut cur = match first {
        "crate" => modules[m].root,
        "super" => modules[m].parent?,
        "self" => m,
        _ if modules[m].children.contains_key(first) => modules[m].children[first],
        _ => {
            let target = modules[m].aliases.get(first)?;
            if target.len() == 1 && target[0] == first {
                return None;
            }
            let mut full = target.clone();
            full.extend_from_slice(&path[1..]);
            return resolve(modules, m, &full, depth + 1);
        }
    };
    for (k, seg) in path.iter().enumerate().skip(1) {
        match seg.as_str() {
            "super" => cur = modules[cur].parent?,
            "self" | "*" => {}
            s if modules[cur].children.contains_key(s) => cur = modules[cur].children[s],
            s => {
                // An item of `cur`: where it is defined, if `cur` only imports it.
                if let Some(target) = modules[cur].aliases.get(s) {
                    let mut full = target.clone();
                    full.extend_from_slice(&path[k + 1..]);
                    return resolve(modules, cur, &full, depth + 1).or(Some(cur));
                }
                return Some(cur);
            }
        }
    }
    Some(cur)
}

/// The arrows between files: (from, to) as indices of `modules`.
fn arrows(modules: &[Module]) -> BTreeSet<(usize, usize)> {
    let mut out = BTreeSet::new();
    for (m, module) in modules.iter().enumerate() {
        for p in &module.paths {
            if let Some(t) = resolve(modules, m, p, 0) {
                if t != m {
                    out.insert((m, t));
                }
            }
        }
    }
    out
}

/// The strongly connected components of more than one node (Tarjan).
fn circles(n: usize, arrows: &BTreeSet<(usize, usize)>) -> Vec<Vec<usize>> {
    struct T<'a> {
        next: Vec<Vec<usize>>,
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        stack: Vec<usize>,
        on: Vec<bool>,
        count: usize,
        out: &'a mut Vec<Vec<usize>>,
    }
    fn visit(t: &mut T, v: usize) {
        t.index[v] = Some(t.count);
        t.low[v] = t.count;
        t.count += 1;
        t.stack.push(v);
        t.on[v] = true;
        for w in t.next[v].clone() {
            match t.index[w] {
                None => {
                    visit(t, w);
                    t.low[v] = t.low[v].min(t.low[w]);
                }
                Some(i) if t.on[w] => t.low[v] = t.low[v].min(i),
                _ => {}
            }
        }
        if Some(t.low[v]) == t.index[v] {
            let mut c = Vec::new();
            loop {
                let w = t.stack.pop().unwrap();
                t.on[w] = false;
                c.push(w);
                if w == v {
                    break;
                }
            }
            if c.len() > 1 {
                c.sort_unstable();
                t.out.push(c);
            }
        }
    }
    let mut next = vec![Vec::new(); n];
    for &(a, b) in arrows {
        next[a].push(b);
    }
    let mut out = Vec::new();
    let mut t = T {
        next,
        index: vec![None; n],
        low: vec![0; n],
        stack: vec![],
        on: vec![false; n],
        count: 0,
        out: &mut out,
    };
    for v in 0..n {
        if t.index[v].is_none() {
            visit(&mut t, v);
        }
    }
    out
}

/// Every crate root of the repository: the solver's library and binary, partition, and
/// each binary of the tools (`tools/src/<name>/main.rs`).
fn crate_roots(repo: &Path) -> Vec<PathBuf> {
    let mut roots: Vec<PathBuf> = ["src/lib.rs", "src/main.rs", "partition/src/lib.rs"]
        .iter()
        .map(|r| repo.join(r))
        .collect();
    let mut tools: Vec<PathBuf> = std::fs::read_dir(repo.join("tools/src"))
        .unwrap()
        .map(|e| e.unwrap().path().join("main.rs"))
        .filter(|p| p.is_file())
        .collect();
    tools.sort();
    assert!(tools.len() >= 2, "tools/src: {tools:?}");
    roots.extend(tools);
    roots
}

/// The circles among the files of the crates rooted at `roots`, each as paths relative to
/// `repo`, with the number of files and arrows.
fn circles_of(repo: &Path, roots: &[PathBuf]) -> (Vec<Vec<String>>, usize, usize) {
    let mut modules = Vec::new();
    for root in roots {
        load_crate(root, &mut modules);
    }
    let arrows = arrows(&modules);
    let name = |i: usize| {
        let f = &modules[i].file;
        f.strip_prefix(repo).unwrap_or(f).display().to_string()
    };
    let mut found: Vec<Vec<String>> = circles(modules.len(), &arrows)
        .iter()
        .map(|c| {
            let mut names: Vec<String> = c.iter().map(|&i| name(i)).collect();
            names.sort();
            names
        })
        .collect();
    found.sort();
    (found, modules.len(), arrows.len())
}

#[test]
fn no_files_import_each_other_around_a_circle() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let (found, files, arrows) = circles_of(repo, &crate_roots(repo));
    println!("{files} files, {arrows} arrows, {} circles:", found.len());
    for c in &found {
        println!("  {}", c.join(" <-> "));
    }
    assert!(files > 200, "the module trees hold only {files} files");
    let bad: Vec<String> = found.iter().map(|c| c.join(" <-> ")).collect();
    assert!(
        bad.is_empty(),
        "files importing each other around a circle (docs/layout.md):\n{}",
        bad.join("\n")
    );
}

#[test]
fn the_check_sees_a_circle_through_a_re_export() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("cycles");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("report")).unwrap();
    let files = [
        ("main.rs", "mod model;\nmod report;\nmod runner;\n"),
        ("model.rs", "pub struct Data;\n"),
        (
            "runner.rs",
            "use crate::report;\nfn f() { report::write(); }\n",
        ),
        (
            "report/mod.rs",
            "mod table; // crate::model in a comment\npub use table::write;\n",
        ),
        (
            "report/table.rs",
            "use crate::{model::Data, runner::{self as r}};\npub fn write() {}\n\
             #[cfg(test)]\nmod tests {\n    use crate::runner::f;\n}\n",
        ),
    ];
    for (f, text) in files {
        std::fs::write(dir.join(f), text).unwrap();
    }
    let (found, files, arrows) = circles_of(&dir, &[dir.join("main.rs")]);
    // runner -> report/mod (`use crate::report`) and -> report/table (`report::write`,
    // re-exported), report/mod -> report/table, report/table -> model and -> runner.
    assert_eq!((files, arrows), (5, 5));
    assert_eq!(
        found,
        vec![vec!["report/mod.rs", "report/table.rs", "runner.rs"]]
    );
    std::fs::write(dir.join("report/table.rs"), "pub fn write() {}\n").unwrap();
    assert!(circles_of(&dir, &[dir.join("main.rs")]).0.is_empty());
}

#[test]
fn use_trees_are_expanded() {
    let code = "pub use crate::{a::{self, B}, c::D as E};\nuse super::*;\nlet user = 1;";
    let got: Vec<(String, String)> = use_items(code)
        .into_iter()
        .map(|(p, n)| (p.join("::"), n))
        .collect();
    let want = [
        ("crate::a", "a"),
        ("crate::a::B", "B"),
        ("crate::c::D", "E"),
        ("super::*", "*"),
    ];
    assert_eq!(got, want.map(|(p, n)| (p.to_string(), n.to_string())));
}
