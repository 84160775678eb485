//! NumPy `.npy` files (format version 1.0, little-endian, C order): arrays other programs
//! read with `numpy.load`, for the assembled model problem (`run::export`).

use std::io::Write;
use std::path::Path;

/// An element type of an `.npy` array.
pub trait NpyScalar: Copy {
    /// The NumPy type string (`<f8`, `<i8`, ...).
    const DESCR: &'static str;
    fn write_le(self, out: &mut Vec<u8>);
}

impl NpyScalar for f64 {
    const DESCR: &'static str = "<f8";
    fn write_le(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
}

impl NpyScalar for i64 {
    const DESCR: &'static str = "<i8";
    fn write_le(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
}

impl NpyScalar for i32 {
    const DESCR: &'static str = "<i4";
    fn write_le(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
}

/// The bytes of an `.npy` file holding `data` with `shape` (row-major).
pub fn npy_bytes<T: NpyScalar>(data: &[T], shape: &[usize]) -> Vec<u8> {
    let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    let shape_text = match dims.len() {
        1 => format!("({},)", dims[0]),
        _ => format!("({})", dims.join(", ")),
    };
    let mut header = format!(
        "{{'descr': '{}', 'fortran_order': False, 'shape': {shape_text}, }}",
        T::DESCR
    );
    // Magic (6) + version (2) + length (2) + header + newline: a multiple of 64 bytes.
    let unpadded = 10 + header.len() + 1;
    header.push_str(&" ".repeat((64 - unpadded % 64) % 64));
    header.push('\n');
    let mut out = Vec::with_capacity(10 + header.len() + 8 * data.len());
    out.extend_from_slice(b"\x93NUMPY\x01\x00");
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    for &v in data {
        v.write_le(&mut out);
    }
    out
}

/// Writes `data` with `shape` to `path`; the error names the file.
pub fn write_npy<T: NpyScalar>(path: &Path, data: &[T], shape: &[usize]) -> Result<(), String> {
    assert_eq!(
        shape.iter().product::<usize>(),
        data.len(),
        "npy: shape and data differ"
    );
    let bytes = npy_bytes(data, shape);
    std::fs::File::create(path)
        .and_then(|mut f| f.write_all(&bytes))
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_is_padded_and_data_follows() {
        let b = npy_bytes(&[1.5f64, -2.0, 3.0, 4.0, 5.0, 6.0], &[2, 3]);
        assert_eq!(&b[..8], b"\x93NUMPY\x01\x00");
        let hlen = u16::from_le_bytes([b[8], b[9]]) as usize;
        assert_eq!((10 + hlen) % 64, 0);
        let header = std::str::from_utf8(&b[10..10 + hlen]).unwrap();
        assert!(header.starts_with("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }"));
        assert!(header.ends_with('\n'));
        assert_eq!(b.len(), 10 + hlen + 48);
        assert_eq!(&b[10 + hlen..10 + hlen + 8], &1.5f64.to_le_bytes());
        let v = npy_bytes(&[7i32], &[1]);
        let hlen = u16::from_le_bytes([v[8], v[9]]) as usize;
        assert!(std::str::from_utf8(&v[10..10 + hlen])
            .unwrap()
            .contains("'shape': (1,)"));
    }
}
