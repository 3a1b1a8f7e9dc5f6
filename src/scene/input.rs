//! Reading scene files: the whole file into memory at once (the parsers then walk
//! one byte slice, without per-token allocation), gunzipped when it starts with
//! the gzip magic bytes, whatever its name says; and the byte-level text helpers
//! the text parsers share (lines, tokens, numbers, quoting bad input in messages).

use std::borrow::Cow;
use std::io::Read;
use std::path::Path;

use flate2::read::MultiGzDecoder;

use crate::scene::error::SceneError;

/// The gzip magic number, RFC 1952 §2.3.1.
const GZIP_MAGIC: [u8; 2] = [0x1f, 0x8b];

/// Longest piece of bad input quoted in an error message, in characters.
const QUOTE_MAX: usize = 24;

/// The bytes of the file at `path`.
pub fn read_file(path: &Path) -> Result<Vec<u8>, SceneError> {
    std::fs::read(path).map_err(|e| SceneError::file(path, format!("cannot read the file: {e}")))
}

/// How much larger than its gzip data a scene may decompress: text meshes
/// compress about 4:1, and deflate at most about 1032:1.
pub const MAX_INFLATION: u64 = 64;

/// Decompressed size allowed whatever the ratio: 256 MiB.
pub const MIN_INFLATED_LIMIT: u64 = 256 << 20;

/// `bytes` decompressed if they are gzip data (by magic number), else as they are.
/// Concatenated gzip members are read as one stream, as `gzip -d` does. The
/// output may be at most [`MAX_INFLATION`] times the input or
/// [`MIN_INFLATED_LIMIT`], whichever is larger, so a small gzip bomb cannot
/// take gigabytes; a file beyond that is refused with the limit named.
pub fn gunzip_if_needed<'a>(path: &Path, bytes: &'a [u8]) -> Result<Cow<'a, [u8]>, SceneError> {
    if !bytes.starts_with(&GZIP_MAGIC) {
        return Ok(Cow::Borrowed(bytes));
    }
    let limit = (bytes.len() as u64)
        .saturating_mul(MAX_INFLATION)
        .max(MIN_INFLATED_LIMIT);
    // Text meshes compress about 4:1; reserve that much to avoid regrowing.
    let mut out = Vec::with_capacity(bytes.len().saturating_mul(4));
    MultiGzDecoder::new(bytes)
        .take(limit + 1)
        .read_to_end(&mut out)
        .map_err(|e| SceneError::file(path, format!("corrupt or truncated gzip data: {e}")))?;
    if out.len() as u64 > limit {
        return Err(SceneError::file(
            path,
            format!(
                "the gzip data decompresses to more than {limit} bytes ({MAX_INFLATION} times its size, \
                 at least {MIN_INFLATED_LIMIT}): decompress it yourself (gunzip) if it really is a scene"
            ),
        ));
    }
    Ok(Cow::Owned(out))
}

/// The lines of `text` with their 1-based numbers; a trailing `\r` is dropped.
/// A file ending in a newline yields one last empty line, which callers skip as
/// blank; its number is the line after the last, where "unexpected end" belongs.
pub fn lines(text: &[u8]) -> impl Iterator<Item = (usize, &[u8])> {
    text.split(|&b| b == b'\n')
        .enumerate()
        .map(|(i, line)| (i + 1, line.strip_suffix(b"\r").unwrap_or(line)))
}

/// The whitespace-separated tokens of a line.
#[inline]
pub fn tokens(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(u8::is_ascii_whitespace).filter(|t| !t.is_empty())
}

/// `line` up to its first `#` (comments run to the end of the line).
#[inline]
pub fn strip_comment(line: &[u8]) -> &[u8] {
    match line.iter().position(|&b| b == b'#') {
        Some(i) => &line[..i],
        None => line,
    }
}

/// A token as a finite `f32`, or a message saying what is wrong with it.
/// Parsed straight from the decimal text (no `f64` detour), so an ASCII file
/// gives the same bits as the binary `float` it was printed from.
#[inline]
pub fn finite_f32(token: &[u8]) -> Result<f32, String> {
    let value = parse_f32(token)?;
    if value.is_finite() {
        Ok(value)
    } else {
        Err(format!("{} is not a finite number", quote(token)))
    }
}

/// A token as an `f32` (NaN and infinities allowed), or a message.
#[inline]
pub fn parse_f32(token: &[u8]) -> Result<f32, String> {
    std::str::from_utf8(token)
        .ok()
        .and_then(|s| s.parse::<f32>().ok())
        .ok_or_else(|| format!("{} is not a number", quote(token)))
}

/// A token as an `f64` (NaN and infinities allowed), or a message.
#[inline]
pub fn parse_f64(token: &[u8]) -> Result<f64, String> {
    std::str::from_utf8(token)
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
        .ok_or_else(|| format!("{} is not a number", quote(token)))
}

/// A token as an integer, or a message.
#[inline]
pub fn parse_int(token: &[u8]) -> Result<i64, String> {
    std::str::from_utf8(token)
        .ok()
        .and_then(|s| s.parse::<i64>().ok())
        .ok_or_else(|| format!("{} is not an integer", quote(token)))
}

/// A piece of input quoted for an error message: back-ticked, shortened, with
/// control characters and invalid UTF-8 escaped so binary garbage stays readable.
pub fn quote(token: &[u8]) -> String {
    let text = String::from_utf8_lossy(token);
    let mut shown: String = text
        .chars()
        .take(QUOTE_MAX)
        .flat_map(char::escape_debug)
        .collect();
    if text.chars().count() > QUOTE_MAX {
        shown.push('…');
    }
    format!("`{shown}`")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_gzip_bomb_is_refused_with_its_limit() {
        use std::io::Write;
        // 300 MiB of zeros compress to about 300 KiB: over the 256 MiB floor.
        let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
        let zeros = vec![0u8; 1 << 20];
        for _ in 0..300 {
            gz.write_all(&zeros).unwrap();
        }
        let bomb = gz.finish().unwrap();
        assert!(bomb.len() < 1 << 20, "{}", bomb.len());
        let e = gunzip_if_needed(Path::new("bomb.ply.gz"), &bomb).unwrap_err();
        assert!(
            e.to_string()
                .contains("decompresses to more than 268435456 bytes"),
            "{e}"
        );
        // A small file decompresses as before.
        let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        gz.write_all(b"ply\n").unwrap();
        let small = gz.finish().unwrap();
        assert_eq!(&*gunzip_if_needed(Path::new("s.gz"), &small).unwrap(), b"ply\n");
    }

    #[test]
    fn quote_escapes_and_shortens() {
        assert_eq!(quote(b"abc"), "`abc`");
        assert_eq!(quote(b"a\x01\xff"), "`a\\u{1}\u{fffd}`");
        assert_eq!(quote(&[b'x'; 30]), format!("`{}…`", "x".repeat(QUOTE_MAX)));
    }

    #[test]
    fn lines_are_numbered_from_one_without_carriage_returns() {
        let got: Vec<_> = lines(b"a\r\nb\n\nc").collect();
        assert_eq!(got, vec![(1, &b"a"[..]), (2, b"b"), (3, b""), (4, b"c")]);
    }

    #[test]
    fn numbers_reject_garbage_and_non_finite() {
        assert_eq!(finite_f32(b"-1.5e2"), Ok(-150.0));
        assert!(finite_f32(b"nan").unwrap_err().contains("not a finite number"));
        assert!(finite_f32(b"1e39").unwrap_err().contains("not a finite number"));
        assert!(finite_f32(b"1,5").unwrap_err().contains("not a number"));
        assert_eq!(parse_int(b"+7"), Ok(7));
        assert!(parse_int(b"7.0").unwrap_err().contains("not an integer"));
    }

    #[test]
    fn plain_bytes_pass_through_and_gzip_is_detected_by_magic() {
        use std::io::Write;
        let path = Path::new("mem.bin");
        assert!(matches!(gunzip_if_needed(path, b"ply\n"), Ok(Cow::Borrowed(_))));
        let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        enc.write_all(b"hello mesh").unwrap();
        let gz = enc.finish().unwrap();
        assert_eq!(&*gunzip_if_needed(path, &gz).unwrap(), b"hello mesh");
        let err = gunzip_if_needed(path, &gz[..gz.len() - 6]).unwrap_err();
        assert!(
            err.to_string()
                .starts_with("mem.bin: corrupt or truncated gzip data"),
            "{err}"
        );
    }
}
