//! The restart state's contact words carry a layout version: a file of another layout is
//! refused by `--restart` with a message naming both layouts, not misread.

use solver::output::layout;
use std::path::Path;
use std::process::Command;

fn solver() -> Command {
    Command::new(env!("CARGO_BIN_EXE_solver"))
}

/// Sets (or with None removes) the layout attribute of both slots' contact datasets.
fn set_layout(h5: &Path, value: Option<u64>) {
    let f = hdf5::File::open_rw(h5).unwrap();
    for k in 0..2 {
        let ds = f
            .dataset(&format!(
                "{}/{}",
                layout::restart_slot(k),
                layout::SLOT_CONTACT
            ))
            .unwrap();
        if ds.attr(layout::ATTR_CONTACT_LAYOUT).is_ok() {
            ds.delete_attr(layout::ATTR_CONTACT_LAYOUT).unwrap();
        }
        if let Some(v) = value {
            ds.new_attr::<u64>()
                .shape(())
                .create(layout::ATTR_CONTACT_LAYOUT)
                .unwrap()
                .write_scalar(&v)
                .unwrap();
        }
    }
}

#[test]
fn a_restart_of_another_contact_layout_is_refused() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene = root.join("run/examples/bar.toml");
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("restart-layout-tests");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let first = dir.join("bar.h5");
    let o = solver()
        .args([
            "-q",
            "run",
            scene.to_str().unwrap(),
            "-o",
            first.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let f = hdf5::File::open(&first).unwrap();
    let written: u64 = f
        .dataset(&format!(
            "{}/{}",
            layout::restart_slot(0),
            layout::SLOT_CONTACT
        ))
        .unwrap()
        .attr(layout::ATTR_CONTACT_LAYOUT)
        .unwrap()
        .read_scalar()
        .unwrap();
    drop(f);
    assert_eq!(written, layout::CONTACT_LAYOUT);

    let restart = |name: &str| {
        solver()
            .args(["-q", "run", scene.to_str().unwrap(), "--restart"])
            .arg(&first)
            .arg("-o")
            .arg(dir.join(name))
            .output()
            .unwrap()
    };
    set_layout(&first, Some(layout::CONTACT_LAYOUT + 1));
    let o = restart("again.h5");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    let want = format!(
        "contact constraints are in layout {}, this solver reads layout {}",
        layout::CONTACT_LAYOUT + 1,
        layout::CONTACT_LAYOUT
    );
    assert!(err.contains(&want), "{err}");
    assert!(err.contains("/contact"), "names the dataset: {err}");

    // A file without the attribute (written before it existed) is layout 1.
    set_layout(&first, None);
    let o = restart("old.h5");
    assert_eq!(
        o.status.code(),
        Some(if layout::CONTACT_LAYOUT == 1 { 0 } else { 2 }),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}
