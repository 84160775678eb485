//! What the multilevel hierarchy of linear bodies was built from (`BuildRows`): the
//! constraint rows and slip springs of the model problem it was measured on. The hierarchy
//! is kept from one load increment to the next while the constraint set stays close to
//! these rows (`Cg::setup_multilevel`); a restart file carries them so that a continued
//! run builds the very hierarchy the uninterrupted run was using (the same bits).
//!
//! The words (f64, every integer exact): `[VERSION, nodes, per node: global id, rows, per
//! row: kind, value, direction (3), masters, per master: global id, weight; springs, per
//! spring: global id, stiffness (9, row-major)]`, nodes and springs in global id order.
//! A rank's own words (`local_words`) have the same form over its owned nodes; rank 0
//! merges them (`merge`).

use super::model::ModelProblem;
use crate::comm::Comm;
use crate::constraints::{Row, RowKind, RowSpec};
use crate::math::Mat3;
use crate::mesh::local::LocalMesh;
use crate::springs::Spring;

/// The words' layout; raised with any change of it.
const VERSION: f64 = 1.0;

/// The rows and springs of this rank's owned nodes a hierarchy was built from, by global
/// node id (ascending).
pub(super) struct BuildRows {
    nodes: Vec<(u32, Vec<Row>)>,
    springs: Vec<(u32, Mat3)>,
}

/// One node's rows or one spring, as the words give them.
enum Record {
    Node(u32, Vec<Row>),
    Spring(u32, Mat3),
}

fn kind_word(k: RowKind) -> f64 {
    match k {
        RowKind::Dirichlet(i) => -(i as f64) - 1.0,
        RowKind::Contact {
            constraint,
            component,
        } => (4 * constraint + component as usize) as f64,
    }
}

fn word_kind(w: f64) -> Option<RowKind> {
    if w.fract() != 0.0 || w.abs() > u32::MAX as f64 * 4.0 {
        return None;
    }
    Some(if w < 0.0 {
        RowKind::Dirichlet((-w - 1.0) as usize)
    } else {
        let k = w as usize;
        RowKind::Contact {
            constraint: k / 4,
            component: (k % 4) as u8,
        }
    })
}

/// A node id or count word: a whole number in 0..limit.
fn index(w: f64, limit: usize) -> Option<usize> {
    (w >= 0.0 && w.fract() == 0.0 && w < limit as f64).then_some(w as usize)
}

fn push_node(out: &mut Vec<f64>, g: u32, rows: &[Row]) {
    out.extend([f64::from(g), rows.len() as f64]);
    for r in rows {
        out.extend([kind_word(r.kind), r.value]);
        out.extend(r.dir);
        out.push(r.masters.len() as f64);
        for &(m, w) in &r.masters {
            out.extend([f64::from(m), w]);
        }
    }
}

/// A reader of words, one at a time.
struct Cursor<'a> {
    words: &'a [f64],
    at: usize,
}

impl Cursor<'_> {
    fn next(&mut self) -> Option<f64> {
        let w = self.words.get(self.at).copied();
        self.at += 1;
        w
    }

    /// A node record: its global id and rows.
    fn node(&mut self, nodes: usize) -> Option<(u32, Vec<Row>)> {
        let len = self.words.len();
        let g = index(self.next()?, nodes)? as u32;
        let nr = index(self.next()?, 4)?;
        let mut rows = Vec::with_capacity(nr);
        for _ in 0..nr {
            let kind = word_kind(self.next()?)?;
            let value = self.next()?;
            let dir = [self.next()?, self.next()?, self.next()?];
            let nm = index(self.next()?, len)?;
            let mut masters = Vec::with_capacity(nm);
            for _ in 0..nm {
                masters.push((index(self.next()?, nodes)? as u32, self.next()?));
            }
            rows.push(Row {
                dir,
                value,
                masters,
                kind,
            });
        }
        Some((g, rows))
    }

    /// A spring record: its node's global id and stiffness.
    fn spring(&mut self, nodes: usize) -> Option<(u32, Mat3)> {
        let g = index(self.next()?, nodes)? as u32;
        let k: [f64; 9] = std::array::from_fn(|_| self.next().unwrap_or(f64::NAN));
        if k.iter().any(|v| !v.is_finite()) {
            return None;
        }
        Some((
            g,
            [[k[0], k[1], k[2]], [k[3], k[4], k[5]], [k[6], k[7], k[8]]],
        ))
    }
}

/// Walks the records of `words` (a rank's or the merged ones), checked: whole ids below
/// `nodes`, every count within the words; gives each record with the range of words it
/// takes. None when they do not parse.
fn walk(
    words: &[f64],
    nodes: usize,
    mut record: impl FnMut(Record, std::ops::Range<usize>),
) -> Option<()> {
    let mut c = Cursor { words, at: 0 };
    if c.next()? != VERSION {
        return None;
    }
    let count = index(c.next()?, words.len())?;
    for _ in 0..count {
        let at = c.at;
        let (g, rows) = c.node(nodes)?;
        record(Record::Node(g, rows), at..c.at);
    }
    let count = index(c.next()?, words.len())?;
    for _ in 0..count {
        let at = c.at;
        let (g, k) = c.spring(nodes)?;
        record(Record::Spring(g, k), at..c.at);
    }
    (c.at == words.len()).then_some(())
}

/// The records of `words`, checked as `walk` checks them.
fn records(words: &[f64], nodes: usize) -> Option<Vec<Record>> {
    let mut out = Vec::new();
    walk(words, nodes, |r, _| out.push(r))?;
    Some(out)
}

fn words_of(nodes: &[(u32, Vec<Row>)], springs: &[(u32, Mat3)]) -> Vec<f64> {
    let mut out = vec![VERSION, nodes.len() as f64];
    for (g, rows) in nodes {
        push_node(&mut out, *g, rows);
    }
    out.push(springs.len() as f64);
    for (g, k) in springs {
        out.push(f64::from(*g));
        out.extend(k.iter().flatten());
    }
    out
}

impl BuildRows {
    /// The owned rows and springs of the model problem (not collective).
    pub(super) fn record<C: Comm + ?Sized>(pb: &ModelProblem<C>) -> Self {
        let ids = &pb.asm.mesh.node_global;
        let mut nodes: Vec<(u32, Vec<Row>)> = (0..pb.owned())
            .filter_map(|l| {
                let rows: Vec<Row> = pb.cons.rows(l).map(|(_, r)| r.clone()).collect();
                (!rows.is_empty()).then(|| (ids[l], rows))
            })
            .collect();
        nodes.sort_by_key(|n| n.0);
        let mut springs: Vec<(u32, Mat3)> = pb.springs.iter().map(|s| (ids[s.node], s.k)).collect();
        springs.sort_by_key(|s| s.0);
        BuildRows { nodes, springs }
    }

    /// This rank's words (`merge` puts every rank's together).
    pub(super) fn local_words(&self) -> Vec<f64> {
        words_of(&self.nodes, &self.springs)
    }

    /// The owned nodes' part of the merged words (checked against the mesh when the
    /// restart file was read, `words_fit`); None when they do not parse (not collective).
    pub(super) fn of_words(words: &[f64], mesh: &LocalMesh) -> Option<Self> {
        let nodes = u32::MAX as usize;
        let mut out = BuildRows {
            nodes: Vec::new(),
            springs: Vec::new(),
        };
        for r in records(words, nodes)? {
            match r {
                Record::Node(g, rows) if mesh.owned_node(g).is_some() => {
                    out.nodes.push((g, rows));
                }
                Record::Spring(g, k) if mesh.owned_node(g).is_some() => out.springs.push((g, k)),
                _ => {}
            }
        }
        Some(out)
    }

    /// The rows as the constraint set takes them (owned local nodes).
    pub(super) fn specs(&self, mesh: &LocalMesh) -> Vec<RowSpec> {
        let mut out = Vec::new();
        for (g, rows) in &self.nodes {
            let node = mesh.owned_node(*g).expect("an owned node");
            out.extend(rows.iter().map(|row| RowSpec {
                node,
                row: row.clone(),
            }));
        }
        out
    }

    /// The springs as the operator takes them (their anchors play no part in it).
    pub(super) fn springs(&self, mesh: &LocalMesh) -> Vec<Spring> {
        self.springs
            .iter()
            .map(|&(g, k)| Spring {
                node: mesh.owned_node(g).expect("an owned node"),
                k,
                anchor: [0.0; 3],
            })
            .collect()
    }

    /// [rows, contact rows] on this rank.
    pub(super) fn counts(&self) -> [i64; 2] {
        let mut c = [0i64; 2];
        for (_, rows) in &self.nodes {
            c[0] += rows.len() as i64;
            c[1] += rows
                .iter()
                .filter(|r| matches!(r.kind, RowKind::Contact { .. }))
                .count() as i64;
        }
        c
    }

    /// The model problem's owned contact rows whose node had no contact row with the same
    /// component and the same master nodes (in order) when these rows were recorded: ties
    /// that moved to other master faces since (not collective).
    pub(super) fn moved_ties<C: Comm + ?Sized>(&self, pb: &ModelProblem<C>) -> i64 {
        let ids = &pb.asm.mesh.node_global;
        let mut moved = 0;
        for l in 0..pb.owned() {
            let built = self
                .nodes
                .binary_search_by_key(&ids[l], |n| n.0)
                .map_or(&[][..], |i| &self.nodes[i].1[..]);
            for (_, row) in pb.cons.rows(l) {
                let RowKind::Contact { component, .. } = row.kind else {
                    continue;
                };
                let same = built.iter().any(|b| {
                    matches!(b.kind, RowKind::Contact { component: c, .. } if c == component)
                        && b.masters.len() == row.masters.len()
                        && b.masters.iter().zip(&row.masters).all(|(x, y)| x.0 == y.0)
                });
                moved += i64::from(!same);
            }
        }
        moved
    }
}

/// Every rank's words put together on rank 0 in global id order (collective; empty on
/// the other ranks). Each record is copied as it is from the rank's words, where `walk`
/// found it: rank 0 holds the gathered words and the merged ones, not the rows parsed
/// from them as well (at n = 40 those were 1.5 MB more at the end of every step that
/// writes a restart state).
pub(super) fn merge<C: Comm + ?Sized>(comm: &C, local: &[f64]) -> Vec<f64> {
    let nodes = u32::MAX as usize;
    let parts = comm.gather_f64(local);
    if !comm.is_root() {
        return Vec::new();
    }
    // (global id, part, words) of every node record and every spring, in rank order.
    let mut all_nodes = Vec::new();
    let mut all_springs = Vec::new();
    for (p, part) in parts.iter().enumerate() {
        walk(part, nodes, |r, at| match r {
            Record::Node(g, _) => all_nodes.push((g, p, at)),
            Record::Spring(g, _) => all_springs.push((g, p, at)),
        })
        .expect("words this solver wrote");
    }
    // Stable: as `words_of` orders them (each id is one rank's).
    all_nodes.sort_by_key(|n| n.0);
    all_springs.sort_by_key(|s| s.0);
    let len = 3 + parts
        .iter()
        .map(|p| p.len().saturating_sub(3))
        .sum::<usize>();
    let mut out = Vec::with_capacity(len);
    out.extend([VERSION, all_nodes.len() as f64]);
    for (_, p, at) in &all_nodes {
        out.extend_from_slice(&parts[*p][at.clone()]);
    }
    out.push(all_springs.len() as f64);
    for (_, p, at) in &all_springs {
        out.extend_from_slice(&parts[*p][at.clone()]);
    }
    out
}

/// Whether `words` parse for a mesh of `nodes` nodes (a restart file's check).
pub fn words_fit(words: &[f64], nodes: usize) -> bool {
    records(words, nodes).is_some()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(kind: RowKind, masters: Vec<(u32, f64)>) -> Row {
        Row {
            dir: [0.6, 0.0, -0.8],
            value: 1.5e-3,
            masters,
            kind,
        }
    }

    #[test]
    fn words_give_back_the_rows_and_springs_bit_for_bit() {
        let nodes = vec![
            (3, vec![row(RowKind::Dirichlet(0), vec![])]),
            (
                7,
                vec![
                    row(RowKind::Dirichlet(2), vec![]),
                    row(
                        RowKind::Contact {
                            constraint: 11,
                            component: 2,
                        },
                        vec![(1, 0.25), (9, 0.75)],
                    ),
                ],
            ),
        ];
        let springs = vec![(7, [[1.0, 0.5, 0.0], [0.5, 2.0, 0.0], [0.0, 0.0, 1e-300]])];
        let words = words_of(&nodes, &springs);
        let back = records(&words, 10).expect("parses");
        assert_eq!(back.len(), 3);
        let Record::Node(7, rows) = &back[1] else {
            panic!("node 7 second")
        };
        assert_eq!(rows[1].kind, nodes[1].1[1].kind);
        assert_eq!(rows[1].masters, nodes[1].1[1].masters);
        assert_eq!(rows[0].kind, RowKind::Dirichlet(2));
        assert_eq!(
            rows[1].dir.map(f64::to_bits),
            nodes[1].1[1].dir.map(f64::to_bits)
        );
        let Record::Spring(7, k) = &back[2] else {
            panic!("the spring last")
        };
        assert_eq!(*k, springs[0].1);
        // A node id beyond the mesh, a cut word list or a trailing word: refused.
        assert!(records(&words, 8).is_none());
        assert!(records(&words[..words.len() - 1], 10).is_none());
        let mut longer = words.clone();
        longer.push(0.0);
        assert!(records(&longer, 10).is_none());
        assert!(records(&[], 10).is_none());
    }
}
