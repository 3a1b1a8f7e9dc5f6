//! Where a TOML scene's errors point and how they read: the line of a byte
//! offset, serde's messages reworded "expected …, found …", and the error for
//! a file that is not UTF-8 text.

use std::path::Path;

use crate::scene::error::SceneError;

/// `bytes` as text, or an error at the line of the first byte that is not UTF-8.
pub fn utf8_text<'a>(path: &Path, bytes: &'a [u8]) -> Result<&'a str, SceneError> {
    std::str::from_utf8(bytes).map_err(|e| {
        let line = line_of(bytes, e.valid_up_to());
        SceneError::at(path, line, "expected UTF-8 text (TOML), found binary data")
    })
}

/// 1-based line of byte `offset`.
pub(super) fn line_of(text: &[u8], offset: usize) -> usize {
    1 + text[..offset.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
}

/// serde's "invalid type: X, expected Y" reworded as "expected Y, found X".
pub(super) fn reword(message: &str) -> String {
    for prefix in ["invalid type: ", "invalid value: ", "invalid length "] {
        if let Some(rest) = message.strip_prefix(prefix)
            && let Some((found, expected)) = rest.split_once(", expected ")
        {
            let found = if prefix == "invalid length " {
                format!("length {found}")
            } else {
                found.to_string()
            };
            return format!("expected {expected}, found {found}");
        }
    }
    message.to_string()
}
