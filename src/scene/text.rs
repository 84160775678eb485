//! The scene file's bytes as text: UTF-8, or an error saying where it is not.

/// The bytes as a string, or where the first byte that is not UTF-8 is: line and column
/// (1-based, the column counted in characters) and byte offset.
pub fn utf8_text(bytes: Vec<u8>) -> Result<String, String> {
    String::from_utf8(bytes).map_err(|e| {
        let bytes = e.as_bytes();
        let at = e.utf8_error().valid_up_to();
        // The bytes before `at` are valid UTF-8.
        let before = std::str::from_utf8(&bytes[..at]).unwrap_or_default();
        let line = before.matches('\n').count() + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        format!(
            "not UTF-8 text: line {line}, column {column} (byte {at}, 0x{:02x}); save the file as UTF-8",
            bytes[at]
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_bad_byte_is_located() {
        assert_eq!(utf8_text(b"a = 1\n".to_vec()).unwrap(), "a = 1\n");
        // Latin-1 "é" (0xe9) after "é" in UTF-8: column 8 counts the UTF-8 one as one.
        let e = utf8_text(b"x = 1\nname = \"\xc3\xa9\xe9\"\n".to_vec()).unwrap_err();
        assert_eq!(
            e,
            "not UTF-8 text: line 2, column 10 (byte 16, 0xe9); save the file as UTF-8"
        );
    }
}
