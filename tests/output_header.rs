//! The result file's mesh written a round of rows at a time (`output::header`), and the
//! closing check reading a step a range of nodes at a time (`ResultFile::verify`).

use std::path::Path;

use solver::output::{
    layout, ElementNodes, NumericData, OutputBody, OutputError, OutputMesh, ResultFile,
    ResultWriter, CHUNK_ROWS,
};

use crate::common;
use common::synthetic::{synthetic_info, synthetic_step, test_dir};

/// A mesh of more nodes and elements than a round of the header's writing (`CHUNK_ROWS`
/// rows, one chunk), whose bodies end inside a round: read back, `/mesh` is the mesh given,
/// and `/mesh/all_connectivity` is its bodies' rows concatenated; with a body of 10-node
/// elements after a hexahedral one, XDMF's "Mixed" array. Exact: ids are written as given.
#[test]
fn a_mesh_larger_than_a_round_is_written_as_given() {
    let dir = test_dir("header_rounds");
    let (mut coordinates, lower) = common::synthetic::block([0.0; 3], [12, 12, 20], 0);
    let first_upper = coordinates.len() as u64;
    let (upper_coords, upper) =
        common::synthetic::block([0.0, 0.0, 30.0], [20, 20, 20], first_upper);
    coordinates.extend(upper_coords);
    let nodes = coordinates.len();
    assert!(nodes > CHUNK_ROWS && lower.len() < CHUNK_ROWS);
    assert!(lower.len() + upper.len() > CHUNK_ROWS);
    // A step of a per-node field is more than `verify` reads at once (6 CHUNK_ROWS values).
    assert!(3 * nodes > 6 * CHUNK_ROWS);
    // The upper body's elements as 10-node rows (their first 8 nodes and 2 more of theirs:
    // the writer reads indices, not geometry).
    let tets: Vec<[u64; 10]> = upper
        .iter()
        .map(|h| {
            [
                h[0],
                h[1],
                h[2],
                h[3],
                h[4],
                h[5],
                h[6],
                h[7],
                h[0] + 1,
                h[6] - 1,
            ]
        })
        .collect();
    let body = |name: &str, connectivity: ElementNodes, first: u64| OutputBody {
        name: name.into(),
        element_ids: (first + 1..=first + connectivity.len() as u64).collect(),
        connectivity,
    };
    for (case, second) in [
        ("uniform", ElementNodes::from_rows(&upper)),
        ("mixed", ElementNodes::from_rows(&tets)),
    ] {
        let mesh = OutputMesh {
            node_ids: (0..nodes as u64).map(|i| 3 * i + 2).collect(),
            coordinates: coordinates.clone(),
            bodies: vec![
                body("lower", ElementNodes::from_rows(&lower), 0),
                body("upper", second, lower.len() as u64),
            ],
            node_sets: vec![("first".into(), vec![2, 5])],
            side_sets: vec![("bottom".into(), vec![(1, 4), (2, 4)])],
        };
        let mut info = synthetic_info();
        info.element_rank = vec![0; mesh.num_elements()];
        let path = dir.join(format!("{case}.h5"));
        let w = ResultWriter::create(&path, &info, &mesh).unwrap();
        let tmp = w.tmp_path().to_path_buf();
        let f = ResultFile::open(&tmp).unwrap();
        assert_eq!(f.mesh().unwrap(), mesh, "{case}");
        let all = match f
            .read_numeric_rows(
                layout::ALL_CONNECTIVITY,
                0..f.shape(layout::ALL_CONNECTIVITY).unwrap()[0],
            )
            .unwrap()
        {
            NumericData::Unsigned(v) => v,
            other => panic!("{case}: {other:?}"),
        };
        match mesh.all_connectivity() {
            Ok(rows) => {
                assert_eq!(case, "uniform");
                assert_eq!(all, rows.flat);
            }
            Err(mixed) => {
                assert_eq!(case, "mixed");
                assert_eq!(all, mixed);
            }
        }
        drop(f);
        if case == "mixed" {
            drop(w);
            continue;
        }
        let mut w = w;
        w.append_step(&synthetic_step(0, &mesh)).unwrap();
        let done = w.finish(1.0).unwrap();
        assert!(ResultFile::open(&done).unwrap().verify().unwrap() > 20);
        flipped_in_the_last_round_is_found(&dir, &done);
    }
}

/// A bit flipped in the displacement's last chunk of `done` (the step's last round of
/// nodes): `verify`, reading the step a range of nodes at a time, names the dataset and step.
fn flipped_in_the_last_round_is_found(dir: &Path, done: &Path) {
    let (addr, size) = {
        let h = hdf5::File::open(done).unwrap();
        let ds = h.dataset(layout::DISPLACEMENT).unwrap();
        let last = ds.num_chunks().unwrap() - 1;
        let info = ds.chunk_info(last).unwrap();
        assert!(
            info.offset[1] as usize >= 2 * CHUNK_ROWS,
            "{:?}",
            info.offset
        );
        (info.addr as usize, info.size as usize)
    };
    let mut bytes = std::fs::read(done).unwrap();
    bytes[addr + size / 2] ^= 4;
    let flipped = dir.join("flipped.h5");
    std::fs::write(&flipped, &bytes).unwrap();
    let err = ResultFile::open(&flipped).unwrap().verify().unwrap_err();
    assert!(
        matches!(
            &err,
            OutputError::Damaged { dataset, step: Some(0), .. } if dataset == layout::DISPLACEMENT
        ),
        "{err}"
    );
}
