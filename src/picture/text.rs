//! Bitmap text for captions: the public-domain 8×8 font of the `font8x8` crate
//! (its basic-Latin table), drawn at an integer scale. A crate rather than a
//! hand-made glyph table: the 95 printable ASCII glyphs are a solved, reviewed
//! job, and one table dependency is smaller than the code to maintain them.

use image::{Rgb, RgbImage};

/// Glyph cell edge in font pixels.
pub const GLYPH: u32 = 8;

/// The 8 rows of a character's glyph (bit `i` of a row is column `i`); a
/// non-ASCII character draws as `?`.
#[inline]
fn glyph(c: char) -> [u8; 8] {
    let code = if c.is_ascii() { c as usize } else { '?' as usize };
    font8x8::legacy::BASIC_LEGACY[code]
}

/// Draw `text` with its top-left corner at `(x, y)`, each font pixel a
/// `scale × scale` square; whatever falls outside the image is clipped.
pub fn draw(img: &mut RgbImage, x: i64, y: i64, text: &str, scale: u32, color: Rgb<u8>) {
    let scale = i64::from(scale.max(1));
    let (w, h) = (i64::from(img.width()), i64::from(img.height()));
    for (k, c) in text.chars().enumerate() {
        let left = x + k as i64 * i64::from(GLYPH) * scale;
        for (row, bits) in glyph(c).iter().enumerate() {
            for col in 0..8 {
                if bits >> col & 1 == 0 {
                    continue;
                }
                for dy in 0..scale {
                    for dx in 0..scale {
                        let px = left + col * scale + dx;
                        let py = y + row as i64 * scale + dy;
                        if (0..w).contains(&px) && (0..h).contains(&py) {
                            img.put_pixel(px as u32, py as u32, color);
                        }
                    }
                }
            }
        }
    }
}

/// Break `text` into lines of at most `columns` characters. Runs of two
/// spaces separate the fields of a caption (`threads: 2  setup: 0.4 ms`): a
/// line breaks between fields, so a field stays whole on one line, and only a
/// field longer than a line is broken at its own spaces (a word longer than a
/// line is cut). A line never starts or ends with the space it was broken at.
pub fn wrap(text: &str, columns: usize) -> Vec<String> {
    let columns = columns.max(1);
    let mut lines = Vec::new();
    let mut line = String::new();
    for field in text.split("  ").map(str::trim).filter(|f| !f.is_empty()) {
        let width = field.chars().count();
        let needed = if line.is_empty() {
            width
        } else {
            line.chars().count() + 2 + width
        };
        if needed <= columns {
            if !line.is_empty() {
                line.push_str("  ");
            }
            line.push_str(field);
            continue;
        }
        if !line.is_empty() {
            lines.push(std::mem::take(&mut line));
        }
        if width <= columns {
            line.push_str(field);
        } else {
            // A field too long for any line: break it at its spaces and keep
            // its last piece open for the next field.
            let mut pieces = wrap_words(field, columns);
            line = pieces.pop().unwrap_or_default();
            lines.extend(pieces);
        }
    }
    if !line.is_empty() {
        lines.push(line);
    }
    lines
}

/// Break `text` at single spaces into lines of at most `columns` characters,
/// cutting words longer than a line.
fn wrap_words(text: &str, columns: usize) -> Vec<String> {
    let mut lines = Vec::new();
    let mut line = String::new();
    for word in text.split(' ').filter(|w| !w.is_empty()) {
        let needed = if line.is_empty() {
            word.chars().count()
        } else {
            line.chars().count() + 1 + word.chars().count()
        };
        if needed > columns && !line.is_empty() {
            lines.push(std::mem::take(&mut line));
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(word);
        while line.chars().count() > columns {
            let cut: String = line.chars().take(columns).collect();
            line = line.chars().skip(columns).collect();
            lines.push(cut);
        }
    }
    if !line.is_empty() {
        lines.push(line);
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glyphs_draw_at_scale_and_clip_at_the_border() {
        let mut img = RgbImage::new(20, 10);
        draw(&mut img, 0, 0, "I", 1, Rgb([255, 0, 0]));
        let lit = img.pixels().filter(|p| p.0 == [255, 0, 0]).count();
        assert!(lit > 0);
        let mut big = RgbImage::new(20, 10);
        draw(&mut big, 0, 0, "I", 2, Rgb([255, 0, 0]));
        // Rows 0..5 of the glyph fit in 10 pixel rows at scale 2.
        assert!(big.pixels().filter(|p| p.0 == [255, 0, 0]).count() > lit);
        // Far outside: nothing drawn, nothing panics.
        let mut none = RgbImage::new(4, 4);
        draw(&mut none, -100, 50, "hello", 3, Rgb([1, 1, 1]));
        assert!(none.pixels().all(|p| p.0 == [0, 0, 0]));
    }

    #[test]
    fn wrapping_breaks_at_spaces_and_cuts_long_words() {
        assert_eq!(wrap("ab cd ef", 5), vec!["ab cd", "ef"]);
        assert_eq!(wrap("abcdefgh", 3), vec!["abc", "def", "gh"]);
        assert_eq!(wrap("a  b", 10), vec!["a  b"]);
        for line in wrap("scene: x.nff  512x512  kernel: packet8  threads: 2", 12) {
            assert!(line.len() <= 12 && !line.starts_with(' '), "{line:?}");
        }
    }

    #[test]
    fn captions_break_between_fields_not_inside_them() {
        let caption =
            "gen:gears  512x512  mode: whitted (depth 5)  threads: 2  setup: 6.0 ms  trace: 356.6 ms";
        let lines = wrap(caption, 30);
        assert_eq!(
            lines,
            vec![
                "gen:gears  512x512",
                "mode: whitted (depth 5)",
                "threads: 2  setup: 6.0 ms",
                "trace: 356.6 ms"
            ]
        );
        // Every field of the caption is whole on one line.
        for field in caption.split("  ") {
            assert!(lines.iter().any(|l| l.contains(field)), "{field} was split");
        }
        // A field wider than a line still wraps at its own spaces.
        assert_eq!(
            wrap("traversal: 11.0 nodes/ray  x", 16),
            vec!["traversal: 11.0", "nodes/ray  x"]
        );
    }
}
