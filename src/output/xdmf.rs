//! The XDMF 3 companion file: a temporal collection of uniform grids (hexahedra, 10-node
//! tetrahedra, or both as XDMF's "Mixed" topology) whose data items point into the HDF5
//! result file (hyperslabs of the per-step datasets).
//!
//! Checked with ParaView 5.11 (Debian 12): the Xdmf3 readers (Xdmf3ReaderS/T) read every
//! grid, attribute and value, and keep `stress` as a 6-component tensor in the stored order
//! xx yy zz xy yz zx, which is VTK's symmetric-tensor order (XX YY ZZ XY YZ XZ). The legacy
//! "XDMF Reader" (Xdmf2) cannot read XDMF 3's hyperslab notation.

use super::layout;

/// The form of `/mesh/all_connectivity` (`super::cells`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Topology {
    /// Every element has `nodes_per_element` nodes: `[elements, nodes_per_element]`.
    Uniform { nodes_per_element: usize },
    /// Elements of several node counts: XDMF's "Mixed" array of `length` entries.
    Mixed { length: usize },
}

/// What the XDMF text needs to know about the result file.
pub struct XdmfDescription<'a> {
    /// The HDF5 file's name relative to the `.xmf` file (they sit side by side).
    pub h5_name: &'a str,
    pub nodes: usize,
    pub elements: usize,
    pub topology: Topology,
    pub times: &'a [f64],
    /// The file has `/results/plastic_strain`.
    pub plastic: bool,
    /// The file has `/results/contact/pressure`.
    pub pressure: bool,
}

fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

/// NumberType and Precision attributes of a data item.
#[derive(Clone, Copy)]
enum Number {
    F64,
    U64,
    U8,
}

impl Number {
    fn attrs(self) -> &'static str {
        match self {
            Number::F64 => r#"NumberType="Float" Precision="8""#,
            Number::U64 => r#"NumberType="UInt" Precision="8""#,
            Number::U8 => r#"NumberType="UChar" Precision="1""#,
        }
    }
}

/// One per-step attribute of every grid.
struct AttributeSpec {
    name: &'static str,
    /// XDMF AttributeType.
    kind: &'static str,
    on_cells: bool,
    /// Components per node/cell, `None` for a scalar.
    components: Option<usize>,
    number: Number,
    dataset: &'static str,
}

const ATTRIBUTES: [AttributeSpec; 6] = [
    AttributeSpec {
        name: "displacement",
        kind: "Vector",
        on_cells: false,
        components: Some(3),
        number: Number::F64,
        dataset: layout::DISPLACEMENT,
    },
    AttributeSpec {
        name: "reaction",
        kind: "Vector",
        on_cells: false,
        components: Some(3),
        number: Number::F64,
        dataset: layout::REACTION,
    },
    AttributeSpec {
        name: "contact_force",
        kind: "Vector",
        on_cells: false,
        components: Some(3),
        number: Number::F64,
        dataset: layout::CONTACT_FORCE,
    },
    AttributeSpec {
        name: "contact_status",
        kind: "Scalar",
        on_cells: false,
        components: None,
        number: Number::U8,
        dataset: layout::CONTACT_STATUS,
    },
    AttributeSpec {
        name: "contact_gap",
        kind: "Scalar",
        on_cells: false,
        components: None,
        number: Number::F64,
        dataset: layout::CONTACT_GAP,
    },
    // Stored order xx yy zz xy yz zx equals ParaView's Tensor6 order xx yy zz xy yz xz.
    AttributeSpec {
        name: "stress",
        kind: "Tensor6",
        on_cells: true,
        components: Some(6),
        number: Number::F64,
        dataset: layout::STRESS,
    },
];

/// Written when the file has the contact pressure (every file a run writes, unless it
/// continues one written before the pressure was recorded).
const CONTACT_PRESSURE: AttributeSpec = AttributeSpec {
    name: "contact_pressure",
    kind: "Scalar",
    on_cells: false,
    components: None,
    number: Number::F64,
    dataset: layout::CONTACT_PRESSURE,
};

/// Written when the scene has a plastic body.
const PLASTIC_STRAIN: AttributeSpec = AttributeSpec {
    name: "plastic_strain",
    kind: "Scalar",
    on_cells: true,
    components: None,
    number: Number::F64,
    dataset: layout::PLASTIC_STRAIN,
};

fn dims(d: &[usize]) -> String {
    d.iter().map(usize::to_string).collect::<Vec<_>>().join(" ")
}

impl XdmfDescription<'_> {
    fn hdf_item(&self, indent: &str, shape: &[usize], number: Number, dataset: &str) -> String {
        format!(
            "{indent}<DataItem Dimensions=\"{}\" {} Format=\"HDF\">{}:{dataset}</DataItem>\n",
            dims(shape),
            number.attrs(),
            escape(self.h5_name)
        )
    }

    /// The slab of `step` out of a dataset of shape `[steps, inner...]`, in XDMF 3's own
    /// hyperslab notation `file:/dataset|start:stride:count:dataset_dims` (what the XDMF 3
    /// library writes itself). ParaView's Xdmf3 readers read it; they skip attributes given
    /// as `ItemType="HyperSlab"` data items (checked with ParaView 5.11).
    fn step_slab(
        &self,
        indent: &str,
        step: usize,
        inner: &[usize],
        number: Number,
        dataset: &str,
    ) -> String {
        let rank = inner.len() + 1;
        let mut start = vec![step];
        start.extend(std::iter::repeat_n(0, inner.len()));
        let stride = vec![1; rank];
        let mut count = vec![1];
        count.extend_from_slice(inner);
        let mut full = vec![self.times.len()];
        full.extend_from_slice(inner);
        format!(
            "{indent}<DataItem Dimensions=\"{}\" {} Format=\"HDF\">{}:{dataset}|{}:{}:{}:{}</DataItem>\n",
            dims(inner),
            number.attrs(),
            escape(self.h5_name),
            dims(&start),
            dims(&stride),
            dims(&count),
            dims(&full)
        )
    }

    fn attribute(&self, step: usize, a: &AttributeSpec) -> String {
        let (count, center) = if a.on_cells {
            (self.elements, "Cell")
        } else {
            (self.nodes, "Node")
        };
        let inner: Vec<usize> = match a.components {
            Some(c) => vec![count, c],
            None => vec![count],
        };
        let mut s = format!(
            "      <Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"{center}\">\n",
            a.name, a.kind
        );
        s += &self.step_slab("        ", step, &inner, a.number, a.dataset);
        s += "      </Attribute>\n";
        s
    }

    /// The grid's `Topology` element.
    fn topology(&self) -> String {
        let e = self.elements;
        let (head, dims) = match self.topology {
            Topology::Uniform {
                nodes_per_element: k,
            } => (
                format!(
                    "      <Topology TopologyType=\"{}\" NumberOfElements=\"{e}\" \
                     NodesPerElement=\"{k}\">\n",
                    super::cells::xdmf_topology(k).expect("a known cell type")
                ),
                vec![e, k],
            ),
            Topology::Mixed { length } => (
                format!("      <Topology TopologyType=\"Mixed\" NumberOfElements=\"{e}\">\n"),
                vec![length],
            ),
        };
        head + &self.hdf_item("        ", &dims, Number::U64, layout::ALL_CONNECTIVITY)
            + "      </Topology>\n"
    }

    /// The complete `.xmf` text.
    pub fn render(&self) -> String {
        let n = self.nodes;
        let mut s = String::from(
            "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n\
             <!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n\
             <Xdmf Version=\"3.0\" xmlns:xi=\"http://www.w3.org/2001/XInclude\">\n\
             <Domain>\n\
             <Grid Name=\"results\" GridType=\"Collection\" CollectionType=\"Temporal\">\n",
        );
        for (step, time) in self.times.iter().enumerate() {
            s += &format!("    <Grid Name=\"step {step}\" GridType=\"Uniform\">\n");
            s += &format!("      <Time Value=\"{time:e}\"/>\n");
            s += &self.topology();
            s += "      <Geometry GeometryType=\"XYZ\">\n";
            s += &self.hdf_item("        ", &[n, 3], Number::F64, layout::COORDINATES);
            s += "      </Geometry>\n";
            for a in &ATTRIBUTES {
                s += &self.attribute(step, a);
            }
            if self.pressure {
                s += &self.attribute(step, &CONTACT_PRESSURE);
            }
            if self.plastic {
                s += &self.attribute(step, &PLASTIC_STRAIN);
            }
            s += "    </Grid>\n";
        }
        s += "</Grid>\n</Domain>\n</Xdmf>\n";
        s
    }
}
