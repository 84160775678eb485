//! Allocations large enough to fail when the estimate was wrong: reserved fallibly, so the
//! failure is an error the run reports (and every rank learns), not an abort.

/// An allocation the system refused.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AllocError {
    /// What it was for ("the mesh's element connectivity", ...).
    pub what: String,
    pub bytes: u128,
}

impl std::fmt::Display for AllocError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "out of memory: the system refused {} for {} (the memory estimate was too low; run \
             on more ranks or machines)",
            super::bytes::format_bytes(self.bytes as f64),
            self.what
        )
    }
}

impl std::error::Error for AllocError {}

impl From<AllocError> for String {
    fn from(e: AllocError) -> String {
        e.to_string()
    }
}

/// An empty vector with room for `n` values, or the error naming `what`.
pub fn try_with_capacity<T>(n: usize, what: &str) -> Result<Vec<T>, AllocError> {
    let mut v = Vec::new();
    super::guard::fallible(|| v.try_reserve_exact(n)).map_err(|_| AllocError {
        what: what.to_string(),
        bytes: n as u128 * std::mem::size_of::<T>() as u128,
    })?;
    Ok(v)
}

/// `n` copies of `value` (like `vec![value; n]`), or the error naming `what`.
pub fn try_filled<T: Clone>(value: T, n: usize, what: &str) -> Result<Vec<T>, AllocError> {
    let mut v = try_with_capacity(n, what)?;
    v.resize(n, value);
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_impossible_reservation_is_an_error_naming_it() {
        // 2^60 values of 8 bytes exceed any address space: refused, never allocated.
        let e = try_filled(0.0f64, 1 << 60, "the test's vector").unwrap_err();
        assert_eq!(e.bytes, 8u128 << 60);
        assert!(e
            .to_string()
            .contains("refused 8192.0 PiB for the test's vector"));
        let v = try_filled(1u8, 3, "small").unwrap();
        assert_eq!(v, vec![1, 1, 1]);
    }
}
