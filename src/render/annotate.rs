//! Timing-annotated images: the render, optionally a heat map of where the time
//! went beside it with a colour legend, and a caption band underneath with the
//! numbers of the run.
//!
//! ```text
//! +---------+   +---------+ +-+ max
//! | render  |   | heat    | | |
//! |         |   | map     | | | 0 us/px
//! +---------+   +---------+ +-+
//! | caption: scene, resolution, kernel, threads, times, rays by kind |
//! +-------------------------------------------------------------------+
//! ```
//!
//! The heat map colours each tile by its cost per pixel (its time divided by
//! its pixel count, so the smaller tiles at the right and bottom edges compare
//! fairly), on a scale from 0 to the most expensive tile.

use image::{Rgb, RgbImage};

use crate::render::colormap::heat;
use crate::render::report::RenderReport;
use crate::render::text;
use crate::render::{Render, Tile};

/// Space between panels, in pixels.
const GAP: u32 = 8;
/// Width of the legend's colour bar.
const BAR: u32 = 16;
/// Caption band background.
const BAND: Rgb<u8> = Rgb([24, 24, 28]);
/// Caption text.
const INK: Rgb<u8> = Rgb([230, 230, 230]);
/// Legend labels ticks: fractions of the scale that get a label.
const TICKS: [f64; 3] = [1.0, 0.5, 0.0];

/// Per-tile times to show as a heat map. 32 bytes (two borrowed slices).
#[derive(Clone, Copy, Debug)]
pub struct HeatMap<'a> {
    /// The tiles (in image pixels).
    pub tiles: &'a [Tile],
    /// CPU seconds spent in each tile.
    pub seconds: &'a [f64],
}

impl HeatMap<'_> {
    /// Microseconds per pixel of each tile.
    pub fn cost_per_pixel_us(&self) -> Vec<f64> {
        self.tiles
            .iter()
            .zip(self.seconds)
            .map(|(t, s)| 1e6 * s / t.pixels().max(1) as f64)
            .collect()
    }
}

/// Text scale for an image `width` pixels wide: 8-pixel glyphs up to 800
/// pixels, larger beyond so the caption stays readable at a glance.
fn text_scale(width: u32) -> u32 {
    (width / 800).clamp(1, 3)
}

/// The annotated image: `render`, the heat map and legend when `heat` is given,
/// and `caption` (one entry per paragraph, wrapped to the width) in a band below.
pub fn annotate(render: &RgbImage, caption: &[String], heat_map: Option<&HeatMap>) -> RgbImage {
    let (w, h) = render.dimensions();
    let scale = text_scale(w * if heat_map.is_some() { 2 } else { 1 });
    let label_columns = 10;
    let legend_width = BAR + GAP / 2 + label_columns * text::GLYPH * scale;
    let panel_width = match heat_map {
        Some(_) => w + GAP + w + GAP + legend_width + GAP,
        None => w,
    };
    let line_height = text::GLYPH * scale + 4;
    let columns = ((panel_width.saturating_sub(2 * GAP)) / (text::GLYPH * scale)).max(1) as usize;
    let lines: Vec<String> = caption.iter().flat_map(|p| text::wrap(p, columns)).collect();
    let band_height = lines.len() as u32 * line_height + 2 * GAP - 4;
    let mut out = RgbImage::from_pixel(panel_width, h + band_height, BAND);

    image::imageops::replace(&mut out, render, 0, 0);
    if let Some(hm) = heat_map {
        draw_heat_map(&mut out, hm, w + GAP, scale);
    }
    for (k, line) in lines.iter().enumerate() {
        let y = h + GAP + k as u32 * line_height;
        text::draw(&mut out, i64::from(GAP), i64::from(y), line, scale, INK);
    }
    out
}

/// The picture of `render` with the caption of `report` under it, and with
/// `heat_map` the per-tile heat map and its legend beside it.
pub fn annotate_render(render: &Render, report: &RenderReport, heat_map: bool) -> RgbImage {
    let mut caption = report.caption();
    let heat = heat_map.then(|| {
        caption.push(report.heat_caption());
        HeatMap {
            tiles: &render.tiles,
            seconds: &render.tile_seconds,
        }
    });
    annotate(&render.frame.to_rgb8(), &caption, heat.as_ref())
}

/// The heat map with its top-left corner at column `x0`, then the legend.
fn draw_heat_map(out: &mut RgbImage, hm: &HeatMap, x0: u32, scale: u32) {
    let cost = hm.cost_per_pixel_us();
    let max = cost.iter().copied().fold(0.0f64, f64::max);
    let level = |c: f64| if max > 0.0 { (c / max) as f32 } else { 0.0 };
    for (tile, &c) in hm.tiles.iter().zip(&cost) {
        let color = heat(level(c));
        for y in tile.y..tile.y + tile.height {
            for x in tile.x..tile.x + tile.width {
                if x0 + x < out.width() && y < out.height() {
                    out.put_pixel(x0 + x, y, color);
                }
            }
        }
    }
    // Legend: a vertical bar from the maximum (top) to 0 (bottom), with labels.
    let panel_height = hm.tiles.iter().map(|t| t.y + t.height).max().unwrap_or(0);
    let panel_width = hm.tiles.iter().map(|t| t.x + t.width).max().unwrap_or(0);
    let bar_x = x0 + panel_width + GAP;
    for y in 0..panel_height {
        let color = heat(1.0 - y as f32 / (panel_height.max(2) - 1) as f32);
        for x in bar_x..bar_x + BAR {
            if x < out.width() {
                out.put_pixel(x, y, color);
            }
        }
    }
    let label_x = i64::from(bar_x + BAR + GAP / 2);
    let glyph = i64::from(text::GLYPH * scale);
    let bottom = i64::from(panel_height) - glyph;
    for f in TICKS {
        let y = ((1.0 - f) * bottom as f64) as i64;
        text::draw(out, label_x, y, &format!("{:.3}", f * max), scale, INK);
    }
    text::draw(out, label_x, bottom / 2 + glyph + 2, "us/px", scale, INK);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::tiles::tiles;

    #[test]
    fn layout_holds_render_heat_map_legend_and_caption() {
        let render = RgbImage::from_pixel(64, 48, Rgb([10, 200, 30]));
        let grid = tiles(64, 48, 16);
        // The last tile is the most expensive: it gets the brightest colour.
        let seconds: Vec<f64> = (0..grid.len()).map(|i| (i + 1) as f64 * 1e-3).collect();
        let hm = HeatMap {
            tiles: &grid,
            seconds: &seconds,
        };
        let caption = vec!["scene: test  64x48".to_string(), "rays: eye 3072".to_string()];
        let img = annotate(&render, &caption, Some(&hm));
        assert!(img.width() > 2 * 64 + GAP);
        assert!(img.height() > 48);
        // The render is copied unchanged into the top-left corner.
        assert_eq!(img.get_pixel(5, 5).0, [10, 200, 30]);
        // Heat map: brightest at the last tile, darkest at the first.
        let x0 = 64 + GAP;
        assert_eq!(*img.get_pixel(x0 + 60, 44), heat(1.0));
        assert_eq!(*img.get_pixel(x0 + 1, 1), heat(1.0 / 12.0));
        // Legend bar: top is the maximum colour.
        assert_eq!(*img.get_pixel(x0 + 64 + GAP + 1, 0), heat(1.0));
        // Caption band: some ink below the images.
        let ink = (48..img.height())
            .flat_map(|y| (0..img.width()).map(move |x| (x, y)))
            .filter(|&(x, y)| *img.get_pixel(x, y) == INK)
            .count();
        assert!(ink > 50);
    }

    #[test]
    fn tiny_images_and_empty_captions_do_not_panic() {
        let render = RgbImage::new(1, 1);
        let grid = tiles(1, 1, 16);
        let img = annotate(
            &render,
            &[],
            Some(&HeatMap {
                tiles: &grid,
                seconds: &[0.0],
            }),
        );
        assert!(img.width() >= 1 && img.height() >= 1);
        let plain = annotate(&render, &["a long caption that will wrap".to_string()], None);
        assert_eq!(plain.width(), 1);
    }
}
