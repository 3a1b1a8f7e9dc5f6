//! Timing-annotated images: the render, optionally a heat map of where the time
//! or the traversal work went beside it with a colour legend, and a caption
//! band underneath with the numbers of the run.
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
//! The heat maps are [`HeatMap`]s; their legend runs from 0 to the top of the
//! scale, the 99th percentile of the pixels (labelled `N+` when something lies
//! above it, and `top: p99`).

use image::{Rgb, RgbImage};

use crate::picture::colormap::heat;
use crate::picture::heat_map::{HeatMap, HeatMapKind, NoPixelCosts};
use crate::picture::render_report::RenderReport;
use crate::picture::text;
use crate::render::Render;

/// Space between panels, in pixels: the heat map starts `GAP` pixels right of the render.
pub const GAP: u32 = 8;
/// Width of the legend's colour bar.
const BAR: u32 = 16;
/// Caption band background.
const BAND: Rgb<u8> = Rgb([24, 24, 28]);
/// Caption text.
const INK: Rgb<u8> = Rgb([230, 230, 230]);
/// Legend labels ticks: fractions of the scale that get a label.
const TICKS: [f64; 3] = [1.0, 0.5, 0.0];
/// Legend label width in characters, at least.
const LABEL_COLUMNS: usize = 10;
/// Width in pixels of `hm`'s legend at text scale `scale`.
fn legend_width(hm: &HeatMap, scale: u32) -> u32 {
    BAR + GAP / 2 + hm.unit().len().max(LABEL_COLUMNS) as u32 * text::GLYPH * scale
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
    let panel_width = match heat_map {
        Some(hm) => w + GAP + w + GAP + legend_width(hm, scale) + GAP,
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
/// `heat_map` that heat map and its legend beside it. A cost heat map needs
/// the render's per-pixel traversal costs.
pub fn annotate_render(
    render: &Render,
    report: &RenderReport,
    heat_map: Option<HeatMapKind>,
) -> Result<RgbImage, NoPixelCosts> {
    let mut caption = report.caption();
    let heat = match heat_map {
        None => None,
        Some(kind) => {
            caption.push(report.heat_caption(kind));
            Some(match kind {
                HeatMapKind::Time => HeatMap::tile_times(&render.tiles, &render.tile_seconds),
                HeatMapKind::Cost => {
                    let cost = render
                        .traversal
                        .as_ref()
                        .and_then(|t| t.pixel_cost.as_deref())
                        .ok_or(NoPixelCosts)?;
                    HeatMap::pixel_costs(render.frame.width, render.frame.height, cost)
                }
            })
        }
    };
    Ok(annotate(&render.frame.to_rgb8(), &caption, heat.as_ref()))
}

/// The heat map with its top-left corner at column `x0`, then the legend.
fn draw_heat_map(out: &mut RgbImage, hm: &HeatMap, x0: u32, scale: u32) {
    let top = hm.top();
    let level = |v: f64| if top > 0.0 { (v / top) as f32 } else { 0.0 };
    for y in 0..hm.height().min(out.height()) {
        for x in 0..hm.width() {
            if x0 + x < out.width() {
                out.put_pixel(x0 + x, y, heat(level(hm.value(x, y))));
            }
        }
    }
    // Legend: a vertical bar from the maximum (top) to 0 (bottom), with labels.
    let bar_x = x0 + hm.width() + GAP;
    for y in 0..hm.height() {
        let color = heat(1.0 - y as f32 / (hm.height().max(2) - 1) as f32);
        for x in bar_x..bar_x + BAR {
            if x < out.width() {
                out.put_pixel(x, y, color);
            }
        }
    }
    let label_x = i64::from(bar_x + BAR + GAP / 2);
    let glyph = i64::from(text::GLYPH * scale);
    let bottom = i64::from(hm.height()) - glyph;
    let clipped = hm.max() > top;
    for f in TICKS {
        let y = ((1.0 - f) * bottom as f64) as i64;
        let plus = if f == 1.0 && clipped { "+" } else { "" };
        text::draw(
            out,
            label_x,
            y,
            &format!("{:.*}{plus}", hm.decimals(), f * top),
            scale,
            INK,
        );
    }
    text::draw(out, label_x, bottom / 2 + glyph + 2, hm.unit(), scale, INK);
    // Say what the top of the scale is.
    text::draw(out, label_x, bottom / 2 + 2 * glyph + 4, "top: p99", scale, INK);
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
        let hm = HeatMap::tile_times(&grid, &seconds);
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
    fn cost_heat_map_colours_each_pixel_by_its_cost() {
        let render = RgbImage::new(6, 4);
        // Cost grows to the right; pixel (5, 3) is the costliest.
        let cost: Vec<u64> = (0..24).map(|k| (k % 6) * 10 + u64::from(k == 23)).collect();
        let hm = HeatMap::pixel_costs(6, 4, &cost);
        assert_eq!(hm.max(), 51.0);
        // The scale tops out at the 99th percentile: the 24th of 24 values.
        assert_eq!(hm.top(), 51.0);
        assert_eq!(hm.value(2, 1), 20.0);
        let img = annotate(&render, &[], Some(&hm));
        let x0 = 6 + GAP;
        assert_eq!(*img.get_pixel(x0 + 5, 3), heat(1.0));
        assert_eq!(*img.get_pixel(x0, 0), heat(0.0));
        assert_eq!(*img.get_pixel(x0 + 2, 1), heat((20.0 / 51.0) as f32));
        // One outlier among 200 pixels does not set the scale; it is as bright as the top.
        let mut spiky = vec![10u64; 200];
        spiky[7] = 1000;
        let hm = HeatMap::pixel_costs(20, 10, &spiky);
        assert_eq!((hm.top(), hm.max()), (10.0, 1000.0));
        let img = annotate(&RgbImage::new(20, 10), &[], Some(&hm));
        assert_eq!(*img.get_pixel(20 + GAP + 7, 0), heat(1.0));
        assert_eq!(*img.get_pixel(20 + GAP + 8, 0), heat(1.0));
        // Mostly zero: the maximum is the top.
        let mut sparse = vec![0u64; 200];
        sparse[3] = 5;
        assert_eq!(HeatMap::pixel_costs(20, 10, &sparse).top(), 5.0);
        assert_eq!(HeatMap::pixel_costs(0, 0, &[]).top(), 0.0);
        // The legend's unit fits beside the bar.
        assert!(img.width() >= x0 + 6 + GAP + BAR + GAP / 2 + "nodes+prims/px".len() as u32 * text::GLYPH);
        // The time map of the same tiles is per tile: every pixel of a tile alike.
        let grid = tiles(6, 4, 2);
        let seconds: Vec<f64> = (0..grid.len()).map(|i| i as f64).collect();
        let times = HeatMap::tile_times(&grid, &seconds);
        assert_eq!(times.value(0, 0), times.value(1, 1));
        assert_eq!(times.value(5, 3), 1e6 * 5.0 / 4.0);
    }

    #[test]
    fn time_heat_map_scale_ignores_one_outlier_tile() {
        // 100 tiles of 1 ms and one preempted tile of 1 s: the scale tops out
        // at the ordinary tiles, which are not black, and the outlier is as
        // bright as the top.
        let grid = tiles(160, 160, 16);
        let mut seconds = vec![1e-3; grid.len()];
        seconds[42] = 1.0;
        let hm = HeatMap::tile_times(&grid, &seconds);
        let ordinary = 1e6 * 1e-3 / 256.0;
        assert!((hm.top() - ordinary).abs() < 1e-9, "{}", hm.top());
        assert!(hm.max() > 100.0 * hm.top());
        let img = annotate(&RgbImage::new(160, 160), &[], Some(&hm));
        assert_eq!(*img.get_pixel(160 + GAP + 1, 1), heat(1.0));
    }

    #[test]
    fn tiny_images_and_empty_captions_do_not_panic() {
        let render = RgbImage::new(1, 1);
        let grid = tiles(1, 1, 16);
        let img = annotate(&render, &[], Some(&HeatMap::tile_times(&grid, &[0.0])));
        assert!(img.width() >= 1 && img.height() >= 1);
        let plain = annotate(&render, &["a long caption that will wrap".to_string()], None);
        assert_eq!(plain.width(), 1);
    }
}
