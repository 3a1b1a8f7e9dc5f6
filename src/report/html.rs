//! HTML text: escaping, a table of names and values, and images inlined as
//! data URIs (the page must load nothing from the network or the disk).

use std::fmt::Write as _;

use base64::Engine as _;
use base64::engine::general_purpose::STANDARD;

/// `text` safe inside an element or a double-quoted attribute.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(c),
        }
    }
    out
}

/// A table of one name and value per row (an environment), escaped.
pub fn pairs_table(rows: &[(&str, String)]) -> String {
    let mut out = String::from("<table><tbody>");
    for (name, value) in rows {
        // Writing to a String cannot fail.
        let _ = write!(
            out,
            "<tr><th>{}</th><td>{}</td></tr>",
            escape(name),
            escape(value)
        );
    }
    out.push_str("</tbody></table>\n");
    out
}

/// An `<img>` of the SVG document `svg`, inlined as a base64 data URI.
pub fn svg_image(svg: &str, alt: &str) -> String {
    format!(
        "<img src=\"data:image/svg+xml;base64,{}\" alt=\"{}\">",
        STANDARD.encode(svg),
        escape(alt)
    )
}

/// An `<img>` of the PNG file `png`, inlined as a base64 data URI.
pub fn png_image(png: &[u8], alt: &str) -> String {
    format!(
        "<img src=\"data:image/png;base64,{}\" alt=\"{}\">",
        STANDARD.encode(png),
        escape(alt)
    )
}

/// True when `bytes` start with the PNG signature.
pub fn is_png(bytes: &[u8]) -> bool {
    bytes.starts_with(b"\x89PNG\r\n\x1a\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_markup_and_quotes() {
        assert_eq!(
            escape("a<b & \"c\" 'd'>"),
            "a&lt;b &amp; &quot;c&quot; &#39;d&#39;&gt;"
        );
        assert_eq!(escape("±5% Mrays/s"), "±5% Mrays/s");
    }

    #[test]
    fn inlines_png_as_base64_and_knows_its_signature() {
        let png = b"\x89PNG\r\n\x1a\nrest";
        assert!(is_png(png) && !is_png(b"GIF89a"));
        assert_eq!(
            png_image(png, "<r>"),
            "<img src=\"data:image/png;base64,iVBORw0KGgpyZXN0\" alt=\"&lt;r&gt;\">"
        );
    }

    #[test]
    fn pairs_make_rows_of_a_table() {
        assert_eq!(
            pairs_table(&[("cpu", "a<b".into()), ("isa", "avx2".into())]),
            "<table><tbody><tr><th>cpu</th><td>a&lt;b</td></tr>\
             <tr><th>isa</th><td>avx2</td></tr></tbody></table>\n"
        );
    }

    #[test]
    fn inlines_svg_as_base64() {
        let img = svg_image("<svg/>", "a \"chart\"");
        assert_eq!(
            img,
            "<img src=\"data:image/svg+xml;base64,PHN2Zy8+\" alt=\"a &quot;chart&quot;\">"
        );
    }
}
