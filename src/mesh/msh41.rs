//! A reader of Gmsh's MSH 4.1 format, ASCII and binary: the sections the solver uses
//! (`$PhysicalNames`, `$Entities`, `$Nodes`, `$Elements`); the others are skipped.
//!
//! Node and element tags are kept as the file gives them (never assumed contiguous or in file
//! order), and the file is checked as it is read: a tag that is zero, repeated or outside the
//! range its section header gives, an element referring to a node `$Nodes` does not define, a
//! count that disagrees with the blocks or exceeds what the rest of the file can hold (checked
//! before anything of that size is allocated), a number that does not parse: each an error
//! naming the line (ASCII) or the byte offset (binary).

use std::collections::{HashMap, HashSet};

use crate::math::Vec3;

/// One block of elements of one entity and one type.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ElementBlock {
    pub entity_dim: i32,
    pub entity_tag: i32,
    pub element_type: i32,
    /// Nodes per element.
    pub nodes_per_element: usize,
    pub tags: Vec<u64>,
    /// `nodes_per_element` node tags per element, flat.
    pub nodes: Vec<u64>,
}

/// What the solver uses of an MSH 4.1 file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Msh {
    /// (dimension, physical tag, name).
    pub physical_names: Vec<(i32, i32, String)>,
    /// Physical tags of each entity, by (dimension, entity tag).
    pub entity_groups: HashMap<(i32, i32), Vec<i32>>,
    /// Node tag -> coordinates.
    pub nodes: HashMap<u64, Vec3>,
    pub element_blocks: Vec<ElementBlock>,
}

/// Nodes of each Gmsh element type (GmshDefines.h), `None` for types this table lacks.
pub fn nodes_per_element(element_type: i32) -> Option<usize> {
    const TABLE: [usize; 31] = [
        2, 3, 4, 4, 8, 6, 5, 3, 6, 9, 10, 27, 18, 14, 1, 8, 20, 15, 13, 9, 10, 12, 15, 15, 21, 4,
        5, 6, 20, 35, 56,
    ];
    match element_type {
        1..=31 => Some(TABLE[element_type as usize - 1]),
        92 => Some(64),
        93 => Some(125),
        _ => None,
    }
}

/// The bytes of the file and where the reader is.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    binary: bool,
    /// `sizeof(size_t)` of a binary file.
    size_t: usize,
}

/// Smallest number of bytes one ASCII number takes (a digit and a separator).
const MIN_ASCII: usize = 2;

impl<'a> Cursor<'a> {
    /// "line L" (ASCII) or "byte B" (binary) of offset `at`.
    fn place(&self, at: usize) -> String {
        if self.binary {
            format!("byte {at}")
        } else {
            let line = self.bytes[..at.min(self.bytes.len())]
                .iter()
                .filter(|&&b| b == b'\n')
                .count()
                + 1;
            format!("line {line}")
        }
    }

    fn err(&self, at: usize, msg: impl std::fmt::Display) -> String {
        format!("{}: {msg}", self.place(at))
    }

    /// Where the next value starts (after blanks, in ASCII).
    fn here(&mut self) -> usize {
        if !self.binary {
            self.skip_space();
        }
        self.pos
    }

    fn skip_space(&mut self) {
        while self.pos < self.bytes.len() && self.bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
    }

    /// The next whitespace-separated word, and where it starts.
    fn word(&mut self, what: &str) -> Result<(&'a str, usize), String> {
        self.skip_space();
        let start = self.pos;
        while self.pos < self.bytes.len() && !self.bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        if start == self.pos {
            return Err(self.err(start, format!("the file ends where {what} was expected")));
        }
        let w = std::str::from_utf8(&self.bytes[start..self.pos]).map_err(|_| {
            self.err(
                start,
                format!("expected {what}, found bytes that are not text"),
            )
        })?;
        Ok((w, start))
    }

    fn ascii<T: std::str::FromStr>(&mut self, what: &str) -> Result<(T, usize), String> {
        let (w, at) = self.word(what)?;
        w.parse()
            .map(|v| (v, at))
            .map_err(|_| self.err(at, format!("expected {what}, found `{w}`")))
    }

    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], String> {
        if self.bytes.len() - self.pos < n {
            return Err(self.err(self.pos, format!("the file ends inside {what}")));
        }
        let s = &self.bytes[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    /// An `int`.
    fn int(&mut self, what: &str) -> Result<(i32, usize), String> {
        if !self.binary {
            return self.ascii(what);
        }
        let at = self.pos;
        let b = self.take(4, what)?;
        Ok((i32::from_le_bytes(b.try_into().expect("4 bytes")), at))
    }

    /// A `size_t`.
    fn size(&mut self, what: &str) -> Result<(u64, usize), String> {
        if !self.binary {
            return self.ascii(what);
        }
        let at = self.pos;
        let b = self.take(self.size_t, what)?;
        let v = if self.size_t == 8 {
            u64::from_le_bytes(b.try_into().expect("8 bytes"))
        } else {
            u64::from(u32::from_le_bytes(b.try_into().expect("4 bytes")))
        };
        Ok((v, at))
    }

    /// A `double`, finite.
    fn real(&mut self, what: &str) -> Result<f64, String> {
        let (v, at) = if self.binary {
            let at = self.pos;
            let b = self.take(8, what)?;
            (f64::from_le_bytes(b.try_into().expect("8 bytes")), at)
        } else {
            self.ascii::<f64>(what)?
        };
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.err(at, format!("{what} is {v}")))
        }
    }

    /// A count of items of at least `item_bytes` bytes each (binary; ASCII items take at least
    /// `item_words` numbers): refused when the rest of the file cannot hold that many.
    fn count(&mut self, what: &str, item_bytes: usize, item_words: usize) -> Result<usize, String> {
        let (n, at) = self.size(what)?;
        let per = if self.binary {
            item_bytes
        } else {
            item_words * MIN_ASCII
        }
        .max(1) as u64;
        let room = (self.bytes.len() - self.pos) as u64 / per;
        if n > room {
            return Err(self.err(
                at,
                format!("{what} is {n}, more than the rest of the file can hold ({room} at most)"),
            ));
        }
        Ok(n as usize)
    }

    /// Expects the line `$End<name>`.
    fn end(&mut self, name: &str) -> Result<(), String> {
        let (w, at) = self.word(&format!("$End{name}"))?;
        if w == format!("$End{name}") {
            Ok(())
        } else {
            Err(self.err(at, format!("expected $End{name}, found `{w}`")))
        }
    }
}

/// The `$MeshFormat` section: version 4.1, ASCII or little-endian binary with an 8-byte
/// `size_t`.
fn mesh_format(c: &mut Cursor) -> Result<(), String> {
    let (w, at) = c.word("$MeshFormat")?;
    if w != "$MeshFormat" {
        return Err(c.err(at, "not a Gmsh mesh file (no $MeshFormat header)"));
    }
    let (version, at) = c.word("the format version")?;
    if version != "4.1" {
        return Err(c.err(
            at,
            format!(
                "MSH format {version}; only format 4.1 (ASCII or binary) is read: save it with \
                 `gmsh -save -format msh41` or Mesh.MshFileVersion = 4.1"
            ),
        ));
    }
    let (file_type, at) = c.ascii::<i32>("the file type (0 ASCII, 1 binary)")?;
    let (size_t, st) = c.ascii::<usize>("the data size")?;
    match file_type {
        0 => {}
        1 => {
            if size_t != 8 && size_t != 4 {
                return Err(c.err(st, format!("data size {size_t}; expected 8 (or 4)")));
            }
            c.binary = true;
            c.size_t = size_t;
            // The line ends, then the integer 1 in the writer's byte order.
            if c.bytes.get(c.pos) == Some(&b'\n') {
                c.pos += 1;
            }
            let (one, at) = c.int("the byte-order mark (the integer 1)")?;
            if one != 1 {
                return Err(c.err(
                    at,
                    "the binary data are not little-endian (or the header is damaged)",
                ));
            }
        }
        _ => return Err(c.err(at, format!("file type {file_type}; expected 0 or 1"))),
    }
    c.end("MeshFormat")
}

/// `$PhysicalNames`: text in ASCII and binary files alike.
fn physical_names(c: &mut Cursor, out: &mut Msh) -> Result<(), String> {
    let (n, at) = c.ascii::<u64>("the number of physical names")?;
    // `d t "n"` and a newline take at least 7 bytes.
    let room = (c.bytes.len() - c.pos) as u64 / 7;
    if n > room {
        return Err(c.err(
            at,
            format!("the number of physical names is {n}, more than the rest of the file can hold ({room} at most)"),
        ));
    }
    for _ in 0..n {
        let (dim, at) = c.ascii::<i32>("a physical group's dimension")?;
        if !(0..=3).contains(&dim) {
            return Err(c.err(at, format!("dimension {dim}; expected 0 to 3")));
        }
        let (tag, _) = c.ascii::<i32>("a physical group's tag")?;
        c.skip_space();
        let start = c.pos;
        let line_end = c.bytes[start..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(c.bytes.len(), |k| start + k);
        let text = String::from_utf8_lossy(&c.bytes[start..line_end]);
        let name = text.trim();
        if name.len() < 2 || !name.starts_with('"') || !name.ends_with('"') {
            return Err(c.err(start, format!("expected a quoted name, found `{name}`")));
        }
        out.physical_names
            .push((dim, tag, name[1..name.len() - 1].to_string()));
        c.pos = line_end;
    }
    c.end("PhysicalNames")
}

/// `$Entities`: the physical tags of each point, curve, surface and volume.
fn entities(c: &mut Cursor, out: &mut Msh) -> Result<(), String> {
    let mut counts = [0usize; 4];
    for (dim, n) in counts.iter_mut().enumerate() {
        let what = ["points", "curves", "surfaces", "volumes"][dim];
        // A point is an int, 3 doubles and a count; the others have 6 doubles and 2 counts.
        let bytes = if dim == 0 { 36 } else { 68 };
        *n = c.count(&format!("the number of {what}"), bytes, 5)?;
    }
    for (dim, &n) in counts.iter().enumerate() {
        for _ in 0..n {
            let (tag, at) = c.int("an entity tag")?;
            for _ in 0..if dim == 0 { 3 } else { 6 } {
                c.real("an entity's coordinate")?;
            }
            let k = c.count("the number of physical tags", 4, 1)?;
            let mut tags = Vec::with_capacity(k);
            for _ in 0..k {
                tags.push(c.int("a physical tag")?.0);
            }
            if dim > 0 {
                let b = c.count("the number of bounding entities", 4, 1)?;
                for _ in 0..b {
                    c.int("a bounding entity's tag")?;
                }
            }
            if out.entity_groups.insert((dim as i32, tag), tags).is_some() {
                return Err(c.err(
                    at,
                    format!("entity {tag} of dimension {dim} is defined twice"),
                ));
            }
        }
    }
    c.end("Entities")
}

/// `$Nodes`, every tag checked.
fn nodes(c: &mut Cursor, out: &mut Msh) -> Result<(), String> {
    let blocks = c.count("the number of node blocks", 20, 4)?;
    let total_at = c.here();
    let total = c.count("the number of nodes", 32, 4)?;
    let (min, min_at) = c.size("the smallest node tag")?;
    let (max, _) = c.size("the largest node tag")?;
    out.nodes.reserve(total);
    let mut read = 0usize;
    let mut found = (u64::MAX, 0u64);
    for _ in 0..blocks {
        let (dim, at) = c.int("a node block's entity dimension")?;
        if !(0..=3).contains(&dim) {
            return Err(c.err(at, format!("entity dimension {dim}; expected 0 to 3")));
        }
        c.int("a node block's entity tag")?;
        let (parametric, at) = c.int("a node block's parametric flag")?;
        if parametric != 0 && parametric != 1 {
            return Err(c.err(at, format!("parametric flag {parametric}; expected 0 or 1")));
        }
        let extra = if parametric == 1 { dim as usize } else { 0 };
        let (n_at, n) = (
            c.here(),
            c.count("the number of nodes in the block", 32, 4)?,
        );
        if read + n > total {
            return Err(c.err(
                n_at,
                format!("the node blocks hold more than the {total} nodes the $Nodes header gives"),
            ));
        }
        let mut tags = Vec::with_capacity(n);
        for _ in 0..n {
            let (tag, at) = c.size("a node tag")?;
            if tag == 0 {
                return Err(c.err(at, "node tag 0; node tags start at 1"));
            }
            if tag < min || tag > max {
                return Err(c.err(
                    at,
                    format!(
                        "node tag {tag} is outside the range {min}..{max} the $Nodes header gives"
                    ),
                ));
            }
            found = (found.0.min(tag), found.1.max(tag));
            tags.push((tag, at));
        }
        for (tag, at) in tags {
            let x = [
                c.real("a coordinate")?,
                c.real("a coordinate")?,
                c.real("a coordinate")?,
            ];
            for _ in 0..extra {
                c.real("a parametric coordinate")?;
            }
            if out.nodes.insert(tag, x).is_some() {
                return Err(c.err(at, format!("node tag {tag} appears twice")));
            }
        }
        read += n;
    }
    if read != total {
        return Err(c.err(
            total_at,
            format!("the $Nodes header gives {total} nodes, its blocks hold {read}"),
        ));
    }
    if total > 0 && found != (min, max) {
        return Err(c.err(
            min_at,
            format!(
                "the $Nodes header gives the tag range {min}..{max}, the nodes have {}..{}",
                found.0, found.1
            ),
        ));
    }
    c.end("Nodes")
}

/// One element of a block: its tag (in the header's range, not seen before) and its nodes
/// (each defined in `$Nodes`).
fn element(
    c: &mut Cursor,
    out: &Msh,
    seen: &mut HashSet<u64>,
    (min, max): (u64, u64),
    block: &mut ElementBlock,
) -> Result<(), String> {
    let (tag, at) = c.size("an element tag")?;
    if tag == 0 || tag < min || tag > max {
        return Err(c.err(
            at,
            format!("element tag {tag} is outside the range {min}..{max} the $Elements header gives (tags start at 1)"),
        ));
    }
    if !seen.insert(tag) {
        return Err(c.err(at, format!("element tag {tag} appears twice")));
    }
    for _ in 0..block.nodes_per_element {
        let (node, at) = c.size("a node tag")?;
        if !out.nodes.contains_key(&node) {
            return Err(c.err(
                at,
                format!("element {tag} refers to node {node}, which $Nodes does not define"),
            ));
        }
        block.nodes.push(node);
    }
    block.tags.push(tag);
    Ok(())
}

/// `$Elements`, every tag and node reference checked.
fn elements(c: &mut Cursor, out: &mut Msh) -> Result<(), String> {
    let blocks = c.count("the number of element blocks", 20, 4)?;
    let total_at = c.here();
    let total = c.count("the number of elements", 16, 2)?;
    let (min, _) = c.size("the smallest element tag")?;
    let (max, _) = c.size("the largest element tag")?;
    let mut seen = HashSet::with_capacity(total);
    let mut read = 0usize;
    for _ in 0..blocks {
        let (dim, at) = c.int("an element block's entity dimension")?;
        if !(0..=3).contains(&dim) {
            return Err(c.err(at, format!("entity dimension {dim}; expected 0 to 3")));
        }
        let (entity, _) = c.int("an element block's entity tag")?;
        let (kind, kind_at) = c.int("an element type")?;
        let per = match nodes_per_element(kind) {
            Some(k) => k,
            None => {
                return Err(c.err(
                    kind_at,
                    format!("element type {kind} is not one this reader knows"),
                ))
            }
        };
        let (n_at, n) = (
            c.here(),
            c.count(
                "the number of elements in the block",
                8 * (per + 1),
                per + 1,
            )?,
        );
        if read + n > total {
            return Err(c.err(
                n_at,
                format!("the element blocks hold more than the {total} elements the $Elements header gives"),
            ));
        }
        let mut block = ElementBlock {
            entity_dim: dim,
            entity_tag: entity,
            element_type: kind,
            nodes_per_element: per,
            tags: Vec::with_capacity(n),
            nodes: Vec::with_capacity(n * per),
        };
        for _ in 0..n {
            element(c, out, &mut seen, (min, max), &mut block)?;
        }
        read += n;
        out.element_blocks.push(block);
    }
    if read != total {
        return Err(c.err(
            total_at,
            format!("the $Elements header gives {total} elements, its blocks hold {read}"),
        ));
    }
    c.end("Elements")
}

/// Skips a section this reader does not use, up to its `$End<name>` line.
fn skip(c: &mut Cursor, name: &str, at: usize) -> Result<(), String> {
    let end = format!("$End{name}");
    let rest = &c.bytes[c.pos..];
    match rest.windows(end.len()).position(|w| w == end.as_bytes()) {
        Some(k) => {
            c.pos += k + end.len();
            Ok(())
        }
        None => Err(c.err(at, format!("section ${name} has no {end}"))),
    }
}

/// Reads an MSH 4.1 file. Errors name the line (ASCII) or byte (binary) and what is wrong.
pub fn parse(bytes: &[u8]) -> Result<Msh, String> {
    let mut c = Cursor {
        bytes,
        pos: 0,
        binary: false,
        size_t: 8,
    };
    mesh_format(&mut c)?;
    let mut out = Msh::default();
    let mut have_nodes = false;
    loop {
        c.skip_space();
        if c.pos >= bytes.len() {
            return Ok(out);
        }
        let (w, at) = c.word("a section")?;
        let Some(name) = w.strip_prefix('$') else {
            return Err(c.err(at, format!("expected a section ($Name), found `{w}`")));
        };
        // Binary data start right after the header line's newline.
        if c.binary {
            if c.bytes.get(c.pos) == Some(&b'\r') {
                c.pos += 1;
            }
            if c.bytes.get(c.pos) == Some(&b'\n') {
                c.pos += 1;
            }
        }
        match name {
            "PhysicalNames" => physical_names(&mut c, &mut out)?,
            "Entities" => entities(&mut c, &mut out)?,
            "PartitionedEntities" => {
                return Err(c.err(
                    at,
                    "a partitioned mesh; save the mesh unpartitioned (Mesh.PartitionOldStyleMsh2 is not read either)",
                ))
            }
            "Nodes" => {
                nodes(&mut c, &mut out)?;
                have_nodes = true;
            }
            "Elements" if !have_nodes => {
                return Err(c.err(at, "$Elements comes before $Nodes"));
            }
            "Elements" => elements(&mut c, &mut out)?,
            _ => skip(&mut c, name, at)?,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn element_types_have_gmsh_node_counts() {
        assert_eq!(nodes_per_element(5), Some(8));
        assert_eq!(nodes_per_element(3), Some(4));
        assert_eq!(nodes_per_element(13), Some(18));
        assert_eq!(nodes_per_element(15), Some(1));
        assert_eq!(nodes_per_element(93), Some(125));
        assert_eq!(nodes_per_element(0), None);
    }

    #[test]
    fn binary_blocks_are_read_with_their_tags() {
        // One node block with tags 7, 3 (out of order), a point element on node 3.
        let mut b = b"$MeshFormat\n4.1 1 8\n".to_vec();
        b.extend(1i32.to_le_bytes());
        b.extend(b"\n$EndMeshFormat\n$Nodes\n");
        for v in [1u64, 2, 3, 7] {
            b.extend(v.to_le_bytes());
        }
        for v in [0i32, 1, 0] {
            b.extend(v.to_le_bytes());
        }
        b.extend(2u64.to_le_bytes());
        b.extend(7u64.to_le_bytes());
        let second = b.len();
        b.extend(3u64.to_le_bytes());
        for v in [7.0f64, 0.0, 0.0, 3.0, 0.0, 0.0] {
            b.extend(v.to_le_bytes());
        }
        b.extend(b"\n$EndNodes\n$Elements\n");
        for v in [1u64, 1, 5, 5] {
            b.extend(v.to_le_bytes());
        }
        for v in [0i32, 1, 15] {
            b.extend(v.to_le_bytes());
        }
        for v in [1u64, 5, 3] {
            b.extend(v.to_le_bytes());
        }
        b.extend(b"\n$EndElements\n");
        let m = parse(&b).unwrap();
        assert_eq!(m.nodes[&7], [7.0, 0.0, 0.0]);
        assert_eq!(m.nodes[&3], [3.0, 0.0, 0.0]);
        assert_eq!(m.element_blocks[0].tags, vec![5]);
        assert_eq!(m.element_blocks[0].nodes, vec![3]);
        // The same node tag twice, named by its byte offset.
        let mut dup = b.clone();
        dup[second..second + 8].copy_from_slice(&7u64.to_le_bytes());
        let e = parse(&dup).unwrap_err();
        assert_eq!(e, format!("byte {second}: node tag 7 appears twice"));
    }
}
