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

/// Break `text` into lines of at most `columns` characters at spaces (a word
/// longer than a line is cut). Runs of two spaces separate fields in captions,
/// and a line never starts with the space it was broken at.
pub fn wrap(text: &str, columns: usize) -> Vec<String> {
    let columns = columns.max(1);
    let mut lines = Vec::new();
    let mut line = String::new();
    for word in text.split(' ') {
        let needed = if line.is_empty() {
            word.len()
        } else {
            line.len() + 1 + word.len()
        };
        if needed > columns && !line.is_empty() {
            lines.push(std::mem::take(&mut line).trim_end().to_string());
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
    if !line.trim().is_empty() {
        lines.push(line.trim_end().to_string());
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
}
