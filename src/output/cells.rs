//! Element connectivity as a result file holds it: each body's elements of one node count
//! (8: hexahedra, 10: 10-node tetrahedra), and `/mesh/all_connectivity`, every body's
//! elements concatenated: `[elements, nodes]` while all have the same node count, else
//! XDMF's "Mixed" form, one flat array in which each element is its XDMF cell type code
//! followed by its nodes (README, "Result files").

/// The cell types a result file writes: nodes per element, XDMF topology name, XDMF
/// "Mixed" type code, Exodus element type.
const CELL_TYPES: [(usize, &str, u64, &str); 2] = [
    (8, "Hexahedron", 9, "HEX8"),
    (10, "Tetrahedron_10", 38, "TETRA10"),
];

/// The XDMF topology name of elements of `nodes` nodes.
pub fn xdmf_topology(nodes: usize) -> Option<&'static str> {
    CELL_TYPES.iter().find(|c| c.0 == nodes).map(|c| c.1)
}

/// The XDMF "Mixed" type code of elements of `nodes` nodes.
pub fn xdmf_code(nodes: usize) -> Option<u64> {
    CELL_TYPES.iter().find(|c| c.0 == nodes).map(|c| c.2)
}

/// The Exodus element type of elements of `nodes` nodes.
pub fn exodus_type(nodes: usize) -> Option<&'static str> {
    CELL_TYPES.iter().find(|c| c.0 == nodes).map(|c| c.3)
}

/// Nodes per element of an XDMF "Mixed" type code.
fn code_nodes(code: u64) -> Option<usize> {
    CELL_TYPES.iter().find(|c| c.2 == code).map(|c| c.0)
}

/// Elements of one node count: their 0-based node indices, row after row.
#[derive(Clone, Debug, PartialEq)]
pub struct ElementNodes {
    pub nodes_per_element: usize,
    pub flat: Vec<u64>,
}

impl Default for ElementNodes {
    fn default() -> Self {
        ElementNodes {
            nodes_per_element: 8,
            flat: Vec::new(),
        }
    }
}

impl ElementNodes {
    /// Elements given as rows of `N` nodes.
    pub fn from_rows<const N: usize>(rows: &[[u64; N]]) -> Self {
        ElementNodes {
            nodes_per_element: N,
            flat: rows.iter().flatten().copied().collect(),
        }
    }

    /// Number of elements.
    pub fn len(&self) -> usize {
        self.flat.len() / self.nodes_per_element.max(1)
    }

    pub fn is_empty(&self) -> bool {
        self.flat.is_empty()
    }

    /// Every element's nodes, in order.
    pub fn iter(&self) -> std::slice::ChunksExact<'_, u64> {
        self.flat.chunks_exact(self.nodes_per_element.max(1))
    }
}

impl std::ops::Index<usize> for ElementNodes {
    type Output = [u64];

    fn index(&self, e: usize) -> &[u64] {
        let n = self.nodes_per_element;
        &self.flat[e * n..(e + 1) * n]
    }
}

impl std::ops::IndexMut<usize> for ElementNodes {
    fn index_mut(&mut self, e: usize) -> &mut [u64] {
        let n = self.nodes_per_element;
        &mut self.flat[e * n..(e + 1) * n]
    }
}

impl<'a> IntoIterator for &'a ElementNodes {
    type Item = &'a [u64];
    type IntoIter = std::slice::ChunksExact<'a, u64>;

    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

/// The bodies' elements concatenated: `Ok` rows of one node count when they all have it,
/// `Err` the XDMF "Mixed" array otherwise.
pub fn concatenate<'a>(
    bodies: impl Iterator<Item = &'a ElementNodes> + Clone,
) -> Result<ElementNodes, Vec<u64>> {
    let mut widths = bodies
        .clone()
        .filter(|b| !b.is_empty())
        .map(|b| b.nodes_per_element);
    let first = widths.next().unwrap_or(8);
    if widths.all(|w| w == first) {
        return Ok(ElementNodes {
            nodes_per_element: first,
            flat: bodies.flat_map(|b| b.flat.iter().copied()).collect(),
        });
    }
    let mut mixed = Vec::new();
    for b in bodies {
        let code = xdmf_code(b.nodes_per_element).expect("a known cell type");
        for el in b {
            mixed.push(code);
            mixed.extend_from_slice(el);
        }
    }
    Err(mixed)
}

/// The number of elements of an XDMF "Mixed" array, or what is wrong with it.
pub fn count_mixed(mixed: &[u64]) -> Result<usize, String> {
    let (mut at, mut count) = (0, 0);
    while at < mixed.len() {
        let n = code_nodes(mixed[at]).ok_or_else(|| {
            format!(
                "entry {at} is {}, not a cell type code (9 hexahedron, 38 10-node tetrahedron)",
                mixed[at]
            )
        })?;
        if at + 1 + n > mixed.len() {
            return Err(format!("the element at entry {at} is cut short"));
        }
        at += 1 + n;
        count += 1;
    }
    Ok(count)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_node_count_stays_a_table_and_two_make_a_mixed_array() {
        let hex = ElementNodes::from_rows(&[[0, 1, 2, 3, 4, 5, 6, 7]]);
        let tet = ElementNodes::from_rows(&[[8, 9, 10, 11, 12, 13, 14, 15, 16, 17]; 2]);
        let same = concatenate([&hex, &hex].into_iter()).unwrap();
        assert_eq!((same.nodes_per_element, same.len()), (8, 2));
        let mixed = concatenate([&hex, &tet].into_iter()).unwrap_err();
        assert_eq!(mixed.len(), 9 + 2 * 11);
        assert_eq!((mixed[0], mixed[9], mixed[20]), (9, 38, 38));
        assert_eq!(count_mixed(&mixed), Ok(3));
        assert!(count_mixed(&mixed[..30]).unwrap_err().contains("cut short"));
        assert!(count_mixed(&[7, 1])
            .unwrap_err()
            .contains("not a cell type"));
    }
}
