//! Exodus's fixed-width names: `char` variables of `len_name` (33) bytes per name, padded
//! with NUL, as the Exodus library writes them.

use netcdf::types::{NcTypeDescriptor, NcVariableType};

/// One byte of a netCDF `char` variable (the crate reads and writes `NC_CHAR` only through
/// a type that says it is one).
#[repr(transparent)]
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct NcChar(pub u8);

// SAFETY: NcChar is one byte, as NC_CHAR is.
unsafe impl NcTypeDescriptor for NcChar {
    fn type_descriptor() -> NcVariableType {
        NcVariableType::Char
    }
}

/// `names` as rows of `width` bytes, NUL-padded; a name longer than `width - 1` bytes is
/// cut (Exodus keeps a terminating NUL).
pub(super) fn name_rows(names: &[&str], width: usize) -> Vec<NcChar> {
    let mut out = vec![NcChar(0); names.len() * width];
    for (i, name) in names.iter().enumerate() {
        for (k, b) in name.bytes().take(width - 1).enumerate() {
            out[i * width + k] = NcChar(b);
        }
    }
    out
}

/// The names in rows of `width` bytes, each up to its first NUL.
pub fn rows_to_names(bytes: &[NcChar], width: usize) -> Vec<String> {
    bytes
        .chunks(width.max(1))
        .map(|row| {
            let end = row.iter().position(|c| c.0 == 0).unwrap_or(row.len());
            String::from_utf8_lossy(&row[..end].iter().map(|c| c.0).collect::<Vec<_>>())
                .into_owned()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_through_padded_rows() {
        let rows = name_rows(&["displ_x", "abc"], 33);
        assert_eq!(rows.len(), 66);
        assert_eq!(rows_to_names(&rows, 33), vec!["displ_x", "abc"]);
    }
}
