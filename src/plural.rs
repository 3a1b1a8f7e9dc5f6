//! Counts in messages: "1 vertex", "3 vertices", "0 hits".

/// `n` followed by `singular` when `n` is 1 and by `plural` otherwise.
pub fn count(n: impl Into<u64>, singular: &str, plural: &str) -> String {
    let n = n.into();
    format!("{n} {}", if n == 1 { singular } else { plural })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_is_singular_and_everything_else_plural() {
        assert_eq!(count(1u32, "vertex", "vertices"), "1 vertex");
        assert_eq!(count(0u32, "hit", "hits"), "0 hits");
        assert_eq!(count(3u64, "vertex", "vertices"), "3 vertices");
    }
}
