//! What a render counts of its traversal work, chosen at compile time so that
//! an uncounted render (and `bench scene`) pays nothing for it.
//!
//! A tile traces with one [`TileCounter`]: [`NoStats`] counts nothing,
//! [`TraversalStats`] the totals of the caption and the sidecar, and
//! [`LaneCosts`] the totals and each pixel's cost for `--heatmap cost`. The
//! kernels tell the counter which batch lanes a query traces; the tile hands
//! each lane's cost to its pixel once the lane's whole ray tree (primary,
//! secondary and shadow rays) is traced.

use crate::accel::TraversalStats;
use crate::accel::stats::{Counter, NoStats};
use crate::render::batch::BATCH;
use crate::render::lane_costs::LaneCosts;
use crate::render::stats::RayCounts;

/// Whether and how a render counts its traversal work.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Counting {
    /// Not at all: the plain render.
    Off,
    /// Node visits, primitive tests and SIMD lanes, in total and per tile.
    Totals,
    /// The totals, and each pixel's cost (node visits plus primitive tests).
    PerPixel,
}

/// A tile's traversal counter, told which batch lanes the queries trace.
pub trait TileCounter: Counter + Default + Send {
    /// Whether [`end_batch`](Self::end_batch) hands out per-pixel costs.
    const PER_PIXEL: bool = false;

    /// The queries that follow trace the batch lanes from `first` on: a
    /// packet's lane `j` is batch lane `first + j`, a single ray is lane `first`.
    /// Only per-pixel counters care.
    #[inline(always)]
    fn batch_lanes(&mut self, _first: usize) {}

    /// Add the cost of each lane of `active` since the last call to
    /// `cost[index[lane]]`, and start every lane again from zero; does nothing
    /// unless [`PER_PIXEL`](Self::PER_PIXEL).
    #[inline(always)]
    fn end_batch(&mut self, _active: u32, _index: &[usize; BATCH], _cost: &mut [u64]) {}

    /// The totals counted so far; None when nothing is counted.
    fn totals(&self) -> Option<TraversalStats>;
}

impl TileCounter for NoStats {
    fn totals(&self) -> Option<TraversalStats> {
        None
    }
}

impl TileCounter for TraversalStats {
    fn totals(&self) -> Option<TraversalStats> {
        Some(*self)
    }
}

impl TileCounter for LaneCosts {
    const PER_PIXEL: bool = true;

    #[inline(always)]
    fn batch_lanes(&mut self, first: usize) {
        self.route(first);
    }

    #[inline]
    fn end_batch(&mut self, active: u32, index: &[usize; BATCH], cost: &mut [u64]) {
        let lanes = self.take();
        for (lane, &pixel) in index
            .iter()
            .enumerate()
            .filter(|&(lane, _)| active >> lane & 1 == 1)
        {
            cost[pixel] += lanes[lane];
        }
    }

    fn totals(&self) -> Option<TraversalStats> {
        Some(*self.total())
    }
}

/// What a tile counts as it traces: rays by kind, and traversal work in `C`.
/// 48 bytes plus `C`.
#[derive(Clone, Copy, Debug, Default)]
pub struct Tally<C> {
    /// Rays traced, by kind.
    pub rays: RayCounts,
    /// Traversal work.
    pub traversal: C,
}

/// The traversal statistics of a counted render. 112 bytes plus the vectors.
#[derive(Clone, Debug, PartialEq)]
pub struct Traversal {
    /// Every query of the render.
    pub total: TraversalStats,
    /// Each tile's queries, in tile order.
    pub tiles: Vec<TraversalStats>,
    /// Each pixel's cost, row-major: node visits plus primitive tests of all
    /// the rays traced for it (primary, secondary, shadow). Only when counted
    /// [`Counting::PerPixel`].
    pub pixel_cost: Option<Vec<u64>>,
}
