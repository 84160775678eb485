//! Exodus II meshes in scenes (`[exodus] file = ...`, `exodus_block`, `exodus_node_set`,
//! `exodus_side_set`): a mesh written as Exodus by our own writer from a Gmsh mesh's run
//! (cylinder_on_block) and a generated one's (stick_slip: three blocks, side sets, friction)
//! and read back gives results bitwise identical to the original run's (`solver post
//! compare`, tolerance 0); bad files are refused with one line naming the file and the item,
//! exit code 2 and nothing written.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common;
use common::{repo, solver, stderr_text};

fn dir(name: &str) -> PathBuf {
    common::fresh_dir(&format!("exodus-mesh-tests/{name}"))
}

fn run(scene: &Path, out: &Path) -> std::process::Output {
    solver()
        .arg("run")
        .arg(scene)
        .arg("-o")
        .arg(out)
        .arg("-q")
        .output()
        .expect("the solver starts")
}

/// `text` with its mesh taken from the Exodus file `mesh` instead: every body its element
/// block, every set the Exodus set of its name (a `body` restriction kept, which the written
/// set already obeys).
fn exodus_scene(text: &str, mesh: &str) -> String {
    let mut v: toml::Table = text.parse().unwrap();
    v.remove("gmsh");
    let mut e = toml::Table::new();
    e.insert("file".into(), mesh.into());
    v.insert("exodus".into(), e.into());
    let swap = |v: &mut toml::Table, table: &str, drop: &[&str], key: &str| {
        for item in v
            .get_mut(table)
            .and_then(|b| b.as_array_mut())
            .into_iter()
            .flatten()
        {
            let t = item.as_table_mut().unwrap();
            for k in drop {
                t.remove(*k);
            }
            let name = t["name"].clone();
            t.insert(key.into(), name);
        }
    };
    swap(
        &mut v,
        "body",
        &["box", "corners", "divisions", "gmsh_volume"],
        "exodus_block",
    );
    let sets = [
        "plane",
        "box",
        "ids",
        "faces",
        "tolerance",
        "gmsh_group",
        "gmsh_surface",
    ];
    swap(&mut v, "node_set", &sets, "exodus_node_set");
    swap(&mut v, "side_set", &sets, "exodus_side_set");
    toml::to_string(&v).unwrap()
}

/// Runs `scene`, writes its mesh as Exodus (`-o NAME.e`), runs the scene rewritten onto that
/// mesh and compares the two HDF5 results bitwise.
fn round_trip(scene: &Path, d: &Path) {
    let stem = scene.file_stem().unwrap().to_string_lossy().to_string();
    let e = d.join(format!("{stem}.e"));
    let o = run(scene, &e);
    assert!(o.status.success(), "{}", stderr_text(&o));
    let text = std::fs::read_to_string(scene).unwrap();
    let again = d.join(format!("{stem}_exodus.toml"));
    std::fs::write(&again, exodus_scene(&text, &format!("{stem}.e"))).unwrap();
    let h5 = d.join(format!("{stem}_exodus.h5"));
    let o = run(&again, &h5);
    assert!(o.status.success(), "{}", stderr_text(&o));
    let (o, out) = compare(&e.with_extension("h5"), &h5);
    assert!(o.status.success(), "{out}{}", stderr_text(&o));
    assert!(out.contains("result: bitwise identical"), "{out}");
}

#[test]
fn a_gmsh_mesh_written_as_exodus_and_read_back_gives_the_same_bits() {
    round_trip(&repo("run/examples/cylinder_on_block.toml"), &dir("gmsh"));
}

#[test]
fn a_generated_mesh_written_as_exodus_and_read_back_gives_the_same_bits() {
    round_trip(&repo("run/scenes/paper/stick_slip.toml"), &dir("generated"));
}

/// Changes a copy of the bar's Exodus mesh with Python's netCDF4 (an independent writer).
fn damaged(d: &Path, name: &str, python: &str) -> PathBuf {
    let e = d.join("bar.e");
    if !e.exists() {
        let o = run(&repo("run/examples/bar.toml"), &e);
        assert!(o.status.success(), "{}", stderr_text(&o));
    }
    let out = d.join(name);
    std::fs::copy(&e, &out).unwrap();
    if !python.is_empty() {
        let script = format!(
            "import netCDF4, sys\nd = netCDF4.Dataset(sys.argv[1], 'a')\n{python}\nd.close()\n"
        );
        let o = Command::new("/usr/bin/python3")
            .args(["-c", &script])
            .arg(&out)
            .output()
            .expect("/usr/bin/python3 with python3-netcdf4 (run/setup)");
        assert!(o.status.success(), "{}", stderr_text(&o));
    }
    out
}

/// The bar on the Exodus mesh `mesh`: exit 2, one line naming the mesh file and `needles`,
/// no result written.
fn refused(d: &Path, mesh: &Path, block: &str, needles: &[&str]) {
    let mesh_name = mesh.file_name().unwrap().to_string_lossy().to_string();
    let scene = d.join(format!("{mesh_name}.toml"));
    let text = std::fs::read_to_string(repo("run/examples/bar.toml")).unwrap();
    let text = exodus_scene(&text, &mesh_name).replace(
        "exodus_block = \"bar\"",
        &format!("exodus_block = \"{block}\""),
    );
    std::fs::write(&scene, text).unwrap();
    let out = d.join(format!("{mesh_name}.h5"));
    let o = run(&scene, &out);
    let err = stderr_text(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    for n in needles.iter().chain([&mesh_name.as_str()]) {
        assert!(err.contains(n), "expected '{n}' in: {err}");
    }
    assert!(!out.exists() && !out.with_extension("xmf").exists());
}

#[test]
fn bad_exodus_meshes_are_refused_naming_the_file_and_the_item() {
    let d = dir("bad");
    let truncated = damaged(&d, "truncated.e", "");
    let bytes = std::fs::read(&truncated).unwrap();
    std::fs::write(&truncated, &bytes[..bytes.len() / 3]).unwrap();
    refused(&d, &truncated, "bar", &["exodus.file", "is truncated"]);
    let garbage = damaged(&d, "garbage.e", "");
    std::fs::write(&garbage, "not a mesh\n").unwrap();
    refused(
        &d,
        &garbage,
        "bar",
        &["exodus.file", "not a readable Exodus II"],
    );
    let tet = damaged(&d, "tet.e", "d['connect1'].elem_type = 'TETRA4'");
    refused(
        &d,
        &tet,
        "bar",
        &["element block 'bar'", "TETRA4", "only HEX8"],
    );
    let node = damaged(&d, "node.e", "d['node_ns1'][0] = 9999");
    refused(&d, &node, "bar", &["node set 'left'", "node 9999"]);
    let unknown = damaged(&d, "unknown.e", "");
    refused(&d, &unknown, "beam", &["body[0].gmsh_volume", "'beam'"]);
}

/// Python's netCDF4 (an independent writer) copies bar's Exodus mesh into a netCDF-4 file
/// (HDF5, zlib-compressed, as Cubit may write it); the bar run from it is bitwise the
/// generated bar's (tolerance 0).
const TO_NETCDF4_PY: &str = r#"
import netCDF4, sys
src = netCDF4.Dataset(sys.argv[1]); src.set_auto_mask(False)
dst = netCDF4.Dataset(sys.argv[2], "w", format="NETCDF4")
for k in src.ncattrs(): dst.setncattr(k, src.getncattr(k))
for n, d in src.dimensions.items(): dst.createDimension(n, None if d.isunlimited() else len(d))
for n, v in src.variables.items():
    w = dst.createVariable(n, v.datatype, v.dimensions, zlib=True)
    for k in v.ncattrs(): w.setncattr(k, v.getncattr(k))
    w.set_auto_mask(False)
    w[...] = v[...]
dst.close()
"#;

#[test]
fn a_netcdf4_exodus_mesh_from_python_gives_the_same_bits() {
    let d = dir("netcdf4");
    let e = d.join("bar.e");
    let o = run(&repo("run/examples/bar.toml"), &e);
    assert!(o.status.success(), "{}", stderr_text(&o));
    let o = Command::new("/usr/bin/python3")
        .args(["-c", TO_NETCDF4_PY])
        .arg(&e)
        .arg(d.join("bar4.e"))
        .output()
        .expect("/usr/bin/python3 with python3-netcdf4 (run/setup)");
    assert!(o.status.success(), "{}", stderr_text(&o));
    let text = std::fs::read_to_string(repo("run/examples/bar.toml")).unwrap();
    let scene = d.join("bar4.toml");
    std::fs::write(&scene, exodus_scene(&text, "bar4.e")).unwrap();
    let h5 = d.join("bar4.h5");
    let o = run(&scene, &h5);
    assert!(o.status.success(), "{}", stderr_text(&o));
    let (_, out) = compare(&e.with_extension("h5"), &h5);
    assert!(out.contains("result: bitwise identical"), "{out}");
}

/// `solver post compare a b` (tolerance 0) and its standard output.
fn compare(a: &Path, b: &Path) -> (std::process::Output, String) {
    let o = solver()
        .args(["post", "compare"])
        .arg(a)
        .arg(b)
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout).to_string();
    (o, out)
}
