//! Gmsh node tags are honoured as the file gives them: a node block in another order, or
//! other tags for the same nodes, is the same mesh (bitwise the same result); a file whose
//! tags or counts are wrong is refused with the line (ASCII) or byte (binary) named.

use std::path::{Path, PathBuf};

use crate::common;
use common::{fresh_dir, repo, restart, solver, stderr_text};

fn dir(name: &str) -> PathBuf {
    fresh_dir(&format!("gmsh-tags-{name}"))
}

/// The ASCII example mesh with every `$Nodes` block rewritten by `edit`, which gets the
/// block's (tag line, coordinate line) pairs; `tags` maps every node tag of the file (in
/// `$Nodes` and `$Elements`) to a new one.
fn rewrite_nodes(
    text: &str,
    mut edit: impl FnMut(&mut Vec<(String, String)>),
    tags: impl Fn(u64) -> u64,
) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let mut out: Vec<String> = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i];
        out.push(line.to_string());
        i += 1;
        if line == "$Nodes" {
            let h: Vec<u64> = lines[i]
                .split_whitespace()
                .map(|w| w.parse().unwrap())
                .collect();
            out.push(format!("{} {} {} {}", h[0], h[1], tags(h[2]), tags(h[3])));
            i += 1;
            for _ in 0..h[0] {
                let b: Vec<usize> = lines[i]
                    .split_whitespace()
                    .map(|w| w.parse().unwrap())
                    .collect();
                assert_eq!(b[2], 0, "the example has no parametric nodes");
                out.push(lines[i].to_string());
                i += 1;
                let n = b[3];
                let mut pairs: Vec<(String, String)> = (0..n)
                    .map(|k| {
                        let t: u64 = lines[i + k].trim().parse().unwrap();
                        (tags(t).to_string(), lines[i + n + k].to_string())
                    })
                    .collect();
                edit(&mut pairs);
                out.extend(pairs.iter().map(|p| p.0.clone()));
                out.extend(pairs.iter().map(|p| p.1.clone()));
                i += 2 * n;
            }
        }
        if line == "$Elements" {
            out.push(lines[i].to_string());
            let blocks: usize = lines[i].split_whitespace().next().unwrap().parse().unwrap();
            i += 1;
            for _ in 0..blocks {
                let n: usize = lines[i].split_whitespace().nth(3).unwrap().parse().unwrap();
                out.push(lines[i].to_string());
                i += 1;
                for _ in 0..n {
                    let w: Vec<u64> = lines[i]
                        .split_whitespace()
                        .map(|w| w.parse().unwrap())
                        .collect();
                    let mut l = w[0].to_string();
                    for &t in &w[1..] {
                        l += &format!(" {}", tags(t));
                    }
                    out.push(l);
                    i += 1;
                }
            }
        }
    }
    out.join("\n") + "\n"
}

/// The example scene with its mesh file replaced.
fn example_scene(d: &Path, name: &str, mesh: &str) -> PathBuf {
    let text = std::fs::read_to_string(repo("run/examples/cylinder_on_block.toml"))
        .unwrap()
        .replace("../gmsh/cylinder_on_block.msh", mesh)
        .replace("name = \"cylinder_on_block\"", "name = \"cylinder\"");
    let path = d.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_reordered_node_block_gives_a_bitwise_identical_result() {
    let d = dir("reordered");
    let text = std::fs::read_to_string(repo("run/gmsh/cylinder_on_block.msh")).unwrap();
    // Every node block shuffled, tags and coordinates together: the same mesh.
    let mut rng = common::Rng::new(20);
    let shuffled = rewrite_nodes(
        &text,
        |pairs| {
            for k in (1..pairs.len()).rev() {
                let j = ((rng.next() + 1.0) * 0.5 * (k + 1) as f64) as usize;
                pairs.swap(k, j.min(k));
            }
        },
        |t| t,
    );
    assert_ne!(shuffled, text);
    // Other tags for the same nodes, in the same order (gaps, no longer from 1).
    let renumbered = rewrite_nodes(&text, |_| {}, |t| 3 * t + 7);
    std::fs::write(d.join("original.msh"), &text).unwrap();
    std::fs::write(d.join("shuffled.msh"), &shuffled).unwrap();
    std::fs::write(d.join("renumbered.msh"), &renumbered).unwrap();
    let original = example_scene(&d, "original", "original.msh");
    let reordered = example_scene(&d, "shuffled", "shuffled.msh");
    let other_tags = example_scene(&d, "renumbered", "renumbered.msh");

    // The problems are equal (mesh, sets, loads), which the result then follows.
    let p0 = solver::scene::load_scene(&original).unwrap();
    for path in [&reordered, &other_tags] {
        let p = solver::scene::load_scene(path).unwrap();
        assert_eq!(p.mesh.coords, p0.mesh.coords, "{}", path.display());
        assert_eq!(p.mesh.elements, p0.mesh.elements, "{}", path.display());
        let sets = |p: &solver::problem::Problem| {
            let n: Vec<_> = p.node_sets.iter().map(|s| s.nodes.clone()).collect();
            let f: Vec<_> = p.side_sets.iter().map(|s| s.faces.clone()).collect();
            (n, f)
        };
        assert_eq!(sets(&p), sets(&p0), "{}", path.display());
    }

    // And the results of the original and the shuffled mesh, run side by side.
    let runs: Vec<_> = [(&original, "a.h5"), (&reordered, "b.h5")]
        .into_iter()
        .map(|(scene, out)| {
            solver()
                .args(["-q", "run"])
                .arg(scene)
                .arg("-o")
                .arg(d.join(out))
                .spawn()
                .unwrap()
        })
        .collect();
    for mut r in runs {
        assert!(r.wait().unwrap().success());
    }
    let (same, report) = restart::post_compare(&d.join("a.h5"), &d.join("b.h5"));
    println!("{}", report.lines().last().unwrap_or_default());
    assert!(same, "{report}");
    assert!(report.contains("result: bitwise identical"), "{report}");
}

/// `tests/fixtures/gmsh/cube.msh` with line `line` (1-based) replaced.
fn cube_with(line: usize, new: &str) -> String {
    let text = std::fs::read_to_string(repo("tests/fixtures/gmsh/cube.msh")).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    lines[line - 1] = new.to_string();
    lines.join("\n") + "\n"
}

fn check(d: &Path, name: &str, mesh: &[u8]) -> (Option<i32>, String) {
    std::fs::write(d.join(format!("{name}.msh")), mesh).unwrap();
    let scene = format!(
        "[gmsh]\nfile = \"{name}.msh\"\n\n[[body]]\nname = \"b\"\ngmsh_volume = \"cube\"\n\
         material = {{ model = \"linear_elastic\", E = 1000.0, nu = 0.3 }}\n\n\
         [time]\nsegments = [{{ end = 1.0, steps = 1 }}]\n"
    );
    let path = d.join(format!("{name}.toml"));
    std::fs::write(&path, scene).unwrap();
    let out = solver().arg("check").arg(&path).output().unwrap();
    (out.status.code(), stderr_text(&out))
}

/// (name, line of `cube.msh` replaced, its new text, the message expected).
fn malformed_cases() -> Vec<(&'static str, usize, String, &'static str)> {
    const HUGE: &str = "100000000000000000";
    vec![
        ("duplicate_tag", 20, "1".into(), "line 20: node tag 1 appears twice"),
        ("zero_tag", 19, "0".into(), "line 19: node tag 0; node tags start at 1"),
        ("moved_tag", 26, "9".into(), "line 26: node tag 9 is outside the range 1..8"),
        (
            "header_range",
            17,
            "1 8 1 9".into(),
            "line 17: the $Nodes header gives the tag range 1..9, the nodes have 1..8",
        ),
        (
            "missing_node",
            43,
            "3 1 2 3 4 5 6 7 80".into(),
            "line 43: element 3 refers to node 80, which $Nodes does not define",
        ),
        (
            "duplicate_element",
            41,
            "1 1 4 3 2".into(),
            "line 41: element tag 1 appears twice",
        ),
        (
            "node_count_mismatch",
            17,
            "1 9 1 8".into(),
            "line 17: the $Nodes header gives 9 nodes, its blocks hold 8",
        ),
        (
            "physical_names_1e17",
            5,
            "1e17".into(),
            "line 5: expected the number of physical names, found `1e17`",
        ),
        (
            "physical_names_huge",
            5,
            HUGE.into(),
            "line 5: the number of physical names is 100000000000000000, more than the rest of the file can hold",
        ),
        (
            "entity_count_huge",
            11,
            format!("1 0 1 {HUGE}"),
            "line 11: the number of volumes is 100000000000000000, more than the rest",
        ),
        (
            "physical_tags_huge",
            14,
            format!("1 0 0 0 1 1 1 {HUGE} 1 0"),
            "line 14: the number of physical tags is 100000000000000000, more than the rest",
        ),
        (
            "node_blocks_huge",
            17,
            format!("{HUGE} 8 1 8"),
            "line 17: the number of node blocks is 100000000000000000, more than the rest",
        ),
        (
            "nodes_huge",
            17,
            format!("1 {HUGE} 1 8"),
            "line 17: the number of nodes is 100000000000000000, more than the rest",
        ),
        (
            "block_nodes_huge",
            18,
            format!("3 1 0 {HUGE}"),
            "line 18: the number of nodes in the block is 100000000000000000, more than the rest",
        ),
        (
            "elements_huge",
            37,
            format!("3 {HUGE} 1 3"),
            "line 37: the number of elements is 100000000000000000, more than the rest",
        ),
        (
            "block_elements_huge",
            42,
            format!("3 1 5 {HUGE}"),
            "line 42: the number of elements in the block is 100000000000000000, more than the rest",
        ),
        (
            "negative_count",
            18,
            "3 1 0 -8".into(),
            "line 18: expected the number of nodes in the block, found `-8`",
        ),
    ]
}

#[test]
fn malformed_tags_and_counts_are_refused_naming_the_line() {
    let d = dir("malformed");
    let (code, err) = check(&d, "good", cube_with(1, "$MeshFormat").as_bytes());
    assert_eq!(code, Some(0), "the unmodified cube is read: {err}");
    let cases = malformed_cases();
    for (name, line, new, expected) in &cases {
        let (code, err) = check(&d, name, cube_with(*line, new).as_bytes());
        println!("{name}: {err}");
        assert_eq!(code, Some(2), "{name}: {err}");
        assert!(
            err.contains(&format!(
                "{name}.msh is not a readable MSH 4.1 file: {expected}"
            )),
            "{name}: {err}"
        );
    }
    println!("{} malformed variants refused", cases.len());
}

/// The binary example mesh: the offset of the tags of its first node block of two nodes or
/// more, and their number.
fn binary_block(bytes: &[u8]) -> (usize, usize) {
    let u64_at = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap()) as usize;
    let i32_at = |at: usize| i32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
    let start = bytes.windows(7).position(|w| w == b"$Nodes\n").unwrap() + 7;
    let mut at = start + 4 * 8; // numEntityBlocks, numNodes, min and max tag
    for _ in 0..u64_at(start) {
        assert_eq!(i32_at(at + 8), 0, "the example has no parametric nodes");
        let n = u64_at(at + 12);
        at += 12 + 8;
        if n >= 2 {
            return (at, n);
        }
        at += 8 * n + 24 * n;
    }
    panic!("no node block with two nodes");
}

#[test]
fn a_malformed_binary_file_is_refused_naming_the_byte() {
    let d = dir("binary");
    let bytes = std::fs::read(repo("run/gmsh/cylinder_on_block_binary.msh")).unwrap();
    let (tags, _) = binary_block(&bytes);
    let put = |b: &mut Vec<u8>, at: usize, v: u64| b[at..at + 8].copy_from_slice(&v.to_le_bytes());
    let first = u64::from_le_bytes(bytes[tags..tags + 8].try_into().unwrap());

    let mut dup = bytes.clone();
    put(&mut dup, tags + 8, first);
    let mut zero = bytes.clone();
    put(&mut zero, tags + 8, 0);
    let mut huge = bytes.clone();
    put(&mut huge, tags - 8, 1 << 60);
    for (name, mesh, expected) in [
        (
            "dup",
            dup,
            format!("byte {}: node tag {first} appears twice", tags + 8),
        ),
        ("zero", zero, format!("byte {}: node tag 0", tags + 8)),
        (
            "huge",
            huge,
            format!(
                "byte {}: the number of nodes in the block is {}",
                tags - 8,
                1u64 << 60
            ),
        ),
    ] {
        std::fs::write(d.join(format!("{name}.msh")), &mesh).unwrap();
        let err = solver::mesh::gmsh::GmshMesh::read(&d.join(format!("{name}.msh"))).unwrap_err();
        println!("{name}: {err}");
        assert!(err.contains(&expected), "{name}: {err}");
    }
}
