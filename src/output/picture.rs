//! Where a picture of `solver post` (plot, figure, hertz) may be written.
//!
//! The same rules as for a result file, for a bitmap: the path's extension names a format the
//! drawing library writes (`.png`, `.bmp`, `.jpg`/`.jpeg`); an existing file under that name
//! must be a regular file holding a picture of such a format (checked by its first bytes),
//! never an input of the command (compared by device and inode) and never a symbolic link,
//! a directory or a device. The picture is drawn into a new temporary file beside the target
//! and renamed onto it only when complete, so a failed drawing leaves the old file as it was.

use std::path::{Path, PathBuf};

use super::error::{io_error, OutputError};
use super::paths::{check_parent, head, kind, same_file};

/// The formats the drawing library writes, by extension, with the first bytes of such a file.
const FORMATS: [(&str, &[&[u8]]); 4] = [
    ("png", &[b"\x89PNG\r\n\x1a\n"]),
    ("bmp", &[b"BM"]),
    ("jpg", &[b"\xff\xd8\xff"]),
    ("jpeg", &[b"\xff\xd8\xff"]),
];

fn bad(file: &Path, message: impl Into<String>) -> OutputError {
    OutputError::BadPicture {
        file: file.to_path_buf(),
        message: message.into(),
    }
}

/// The known format of `path` by its extension (lower case), or an error listing them.
fn format_of(path: &Path) -> Result<&'static [&'static [u8]], OutputError> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    FORMATS
        .iter()
        .find(|(e, _)| *e == ext)
        .map(|(_, magic)| *magic)
        .ok_or_else(|| {
            bad(
                path,
                format!(
                    "the extension {} names no picture format written here; expected .png, .bmp, .jpg or .jpeg",
                    if ext.is_empty() { "(none)".to_string() } else { format!("'.{ext}'") }
                ),
            )
        })
}

/// Checks that `output` can take a picture: see the module documentation. `inputs` are the
/// files the command reads (path and what it is).
pub fn check_picture_output(output: &Path, inputs: &[(&Path, &str)]) -> Result<(), OutputError> {
    let magic = format_of(output)?;
    check_parent(output).map_err(|e| match e {
        OutputError::BadOutput { file, message } => OutputError::BadPicture { file, message },
        other => other,
    })?;
    let m = match std::fs::symlink_metadata(output) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(bad(output, e.to_string())),
    };
    if !m.file_type().is_file() {
        return Err(bad(
            output,
            format!(
                "it is {}; a picture must be a regular file or a new path",
                kind(&m)
            ),
        ));
    }
    for (path, what) in inputs {
        if std::fs::metadata(path).is_ok_and(|im| same_file(&m, &im)) {
            return Err(bad(
                output,
                format!(
                    "it is {what} of this command ({}); choose another output path",
                    path.display()
                ),
            ));
        }
    }
    let first = head(output).map_err(|e| bad(output, e.to_string()))?;
    if !magic.iter().any(|mg| first.starts_with(mg)) {
        return Err(bad(
            output,
            "it exists and is not a picture of the format its extension names; remove it or choose another output path",
        ));
    }
    Ok(())
}

/// The temporary name a picture for `output` is drawn into: hidden, beside it, unique to
/// this process, with the same extension (the drawing library picks the format by it).
fn temp_picture_name(output: &Path) -> PathBuf {
    let name = output
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let ext = output
        .extension()
        .map(|e| e.to_string_lossy().into_owned())
        .unwrap_or_default();
    output.with_file_name(format!(".{name}.{}.tmp.{ext}", std::process::id()))
}

/// Checks `output` ([`check_picture_output`]), creates its directory, lets `draw` write the
/// picture into a temporary file and renames that onto `output` when `draw` succeeded.
pub fn write_picture(
    output: &Path,
    inputs: &[(&Path, &str)],
    draw: impl FnOnce(&Path) -> Result<(), OutputError>,
) -> Result<(), OutputError> {
    check_picture_output(output, inputs)?;
    if let Some(dir) = output.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| io_error(dir, "creating the directory", e))?;
    }
    let tmp = temp_picture_name(output);
    let drawn = draw(&tmp).and_then(|()| {
        std::fs::rename(&tmp, output).map_err(|e| io_error(output, "renaming the picture", e))
    });
    if drawn.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    drawn
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir() -> PathBuf {
        let d = std::env::temp_dir().join(format!("picture-test-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn msg(r: Result<(), OutputError>) -> String {
        let e = r.unwrap_err();
        assert_eq!(e.exit_code(), 2, "{e}");
        e.to_string()
    }

    #[test]
    fn refuses_what_is_not_a_picture() {
        let d = dir().join("refuse");
        std::fs::create_dir_all(&d).unwrap();
        let text = d.join("notes.png");
        std::fs::write(&text, "my notes").unwrap();
        assert!(msg(check_picture_output(&text, &[])).contains("is not a picture"));
        assert!(msg(check_picture_output(&d.join("a.txt"), &[])).contains("'.txt'"));
        assert!(msg(check_picture_output(&d.join("a"), &[])).contains("(none)"));
        let sub = d.join("sub.png");
        std::fs::create_dir_all(&sub).unwrap();
        assert!(msg(check_picture_output(&sub, &[])).contains("a directory"));
        let link = d.join("link.png");
        let _ = std::fs::remove_file(&link);
        std::os::unix::fs::symlink(&text, &link).unwrap();
        assert!(msg(check_picture_output(&link, &[])).contains("a symbolic link"));
        let under = text.join("x.png");
        assert!(msg(check_picture_output(&under, &[])).contains("not a directory"));
        // An input of the command, even under another name (a hard link).
        let png = d.join("in.png");
        std::fs::write(&png, b"\x89PNG\r\n\x1a\nrest").unwrap();
        let other = d.join("other.png");
        let _ = std::fs::remove_file(&other);
        std::fs::hard_link(&png, &other).unwrap();
        assert!(
            msg(check_picture_output(&other, &[(&png, "the result file")]))
                .contains("the result file of this command")
        );
        assert_eq!(std::fs::read(&text).unwrap(), b"my notes");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn replaces_a_picture_only_when_the_drawing_succeeds() {
        let d = dir().join("replace");
        std::fs::create_dir_all(&d).unwrap();
        let png = d.join("p.png");
        std::fs::write(&png, b"\x89PNG\r\n\x1a\nold").unwrap();
        let failed = write_picture(&png, &[], |tmp| {
            std::fs::write(tmp, b"half").unwrap();
            Err(OutputError::Plot {
                file: tmp.to_path_buf(),
                message: "drawing failed".into(),
            })
        });
        assert!(failed.is_err());
        assert_eq!(std::fs::read(&png).unwrap(), b"\x89PNG\r\n\x1a\nold");
        write_picture(&png, &[], |tmp| {
            std::fs::write(tmp, b"\x89PNG\r\n\x1a\nnew").map_err(|e| io_error(tmp, "w", e))
        })
        .unwrap();
        assert_eq!(std::fs::read(&png).unwrap(), b"\x89PNG\r\n\x1a\nnew");
        let left: Vec<_> = std::fs::read_dir(&d).unwrap().collect();
        assert_eq!(left.len(), 1, "no temporary file is left");
        std::fs::remove_dir_all(&d).unwrap();
    }
}
