//! Heat maps: a value per pixel, the CPU time of each tile or the traversal
//! cost of each pixel, with the top of its colour scale. The time heat map
//! colours each tile by its CPU time per pixel (its time divided by its pixel
//! count, so the smaller tiles at the right and bottom edges compare fairly);
//! the cost heat map colours each pixel by the node visits plus primitive tests
//! of all its rays. Both scales run from 0 to the 99th percentile of the pixels,
//! since a few tiles (one preempted, or holding a deep mirror path) or pixels
//! (grazing rays) cost many times the rest and would leave everything else
//! black. [`annotate`](crate::picture::annotate) draws them.

use crate::render::Tile;

/// Percentile of the pixel values at the top of both scales.
const TOP_PERCENTILE: f64 = 0.99;

/// The top of a heat map's scale: the 99th percentile of `values`, or their
/// maximum if that percentile is 0 (a map of mostly nothing).
fn robust_top(values: &[f64]) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_unstable_by(f64::total_cmp);
    let rank = (TOP_PERCENTILE * sorted.len() as f64).ceil() as usize;
    let percentile = sorted.get(rank.max(1) - 1).copied().unwrap_or(0.0);
    if percentile > 0.0 {
        percentile
    } else {
        sorted.last().copied().unwrap_or(0.0)
    }
}

/// What a heat map beside the render shows (`--heatmap time|cost`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum HeatMapKind {
    /// CPU time per pixel of each tile.
    Time,
    /// Traversal cost of each pixel: node visits plus primitive tests of all its rays.
    Cost,
}

/// A cost heat map was asked of a render without per-pixel traversal costs.
#[derive(Clone, Copy, Debug, thiserror::Error)]
#[error(
    "cost heat map needs raypack's traversal statistics: render with --engine raypack and without \
     --no-traversal-stats (or use --heatmap time)"
)]
pub struct NoPixelCosts;

/// A value per pixel to show as a heat map, with the legend's unit.
/// 64 bytes plus 8 per pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct HeatMap {
    width: u32,
    height: u32,
    /// Row-major, `width × height`.
    values: Vec<f64>,
    /// The value of the brightest colour; larger values get it too.
    top: f64,
    unit: &'static str,
    /// Decimals of the legend's labels.
    decimals: usize,
}

impl HeatMap {
    /// Each tile's CPU time per pixel in microseconds, over the tile's pixels.
    pub fn tile_times(tiles: &[Tile], seconds: &[f64]) -> Self {
        let width = tiles.iter().map(|t| t.x + t.width).max().unwrap_or(0);
        let height = tiles.iter().map(|t| t.y + t.height).max().unwrap_or(0);
        let mut values = vec![0.0; width as usize * height as usize];
        for (tile, s) in tiles.iter().zip(seconds) {
            let us = 1e6 * s / tile.pixels().max(1) as f64;
            for y in tile.y..tile.y + tile.height {
                let row = (y * width) as usize;
                values[row + tile.x as usize..row + (tile.x + tile.width) as usize].fill(us);
            }
        }
        Self {
            width,
            height,
            top: robust_top(&values),
            values,
            unit: "us/px",
            decimals: 3,
        }
    }

    /// Each pixel's traversal cost (node visits plus primitive tests), `cost`
    /// being row-major with `width × height` entries.
    pub fn pixel_costs(width: u32, height: u32, cost: &[u64]) -> Self {
        debug_assert_eq!(cost.len(), width as usize * height as usize);
        let values: Vec<f64> = cost.iter().map(|&c| c as f64).collect();
        Self {
            width,
            height,
            top: robust_top(&values),
            values,
            unit: "nodes+prims/px",
            decimals: 0,
        }
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The legend's unit (`us/px`, `nodes+prims/px`).
    pub fn unit(&self) -> &'static str {
        self.unit
    }

    /// Decimals of the legend's labels.
    pub fn decimals(&self) -> usize {
        self.decimals
    }

    /// The value of pixel `(x, y)`.
    pub fn value(&self, x: u32, y: u32) -> f64 {
        self.values[(y * self.width + x) as usize]
    }

    /// The largest value (0 for an empty map).
    pub fn max(&self) -> f64 {
        self.values.iter().copied().fold(0.0, f64::max)
    }

    /// The value of the brightest colour: the 99th percentile of the pixels
    /// (larger values are as bright), or the maximum if that is 0.
    pub fn top(&self) -> f64 {
        self.top
    }
}
