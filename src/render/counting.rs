//! What a render counts of its traversal work, chosen at compile time so that
//! an uncounted render (and `bench scene`) pays nothing for it.
//!
//! A tile traces with one [`TileCounter`]: [`NoStats`] counts nothing; a
//! [`TraversalCounter`] counts the totals of the caption and the sidecar, and,
//! made [`per_lane`](TraversalCounter::per_lane), each pixel's cost for
//! `--heatmap cost` too (one counting type, so that the trace loop and the
//! traversal are compiled once for both). The kernels tell the counter which
//! batch lanes a query traces; the tile hands each lane's cost to its pixel
//! once the lane's whole ray tree (primary, secondary and shadow rays) is
//! traced.

use crate::accel::stats::{Counter, NoStats};
use crate::accel::traversal_counter::COUNTED_LANES;
use crate::accel::{TraversalCounter, TraversalStats};
use crate::render::batch::BATCH;
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

// A batch's lanes are all counted one by one.
const _: () = assert!(BATCH <= COUNTED_LANES);

/// A tile's traversal counter, told which batch lanes the queries trace. Each
/// tile starts from a clone of the render's (fresh) counter.
pub trait TileCounter: Counter + Clone + Send + Sync {
    /// Whether [`end_batch`](Self::end_batch) hands out per-pixel costs.
    fn counts_per_pixel(&self) -> bool {
        false
    }

    /// The queries that follow trace the batch lanes from `first` on: a
    /// packet's lane `j` is batch lane `first + j`, a single ray is lane `first`.
    /// Only per-pixel counters care.
    #[inline(always)]
    fn batch_lanes(&mut self, _first: usize) {}

    /// Add the cost of each lane of `active` since the last call to
    /// `cost[index[lane]]`, and start every lane again from zero; does nothing
    /// unless [`counts_per_pixel`](Self::counts_per_pixel).
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

impl TileCounter for TraversalCounter {
    fn counts_per_pixel(&self) -> bool {
        self.counts_lanes()
    }

    #[inline(always)]
    fn batch_lanes(&mut self, first: usize) {
        self.route(first);
    }

    #[inline]
    fn end_batch(&mut self, active: u32, index: &[usize; BATCH], cost: &mut [u64]) {
        if !self.counts_lanes() {
            return;
        }
        for (lane, (&pixel, lane_cost)) in index.iter().zip(batch_costs(self)).enumerate() {
            if active >> lane & 1 == 1 {
                cost[pixel] += lane_cost;
            }
        }
    }

    fn totals(&self) -> Option<TraversalStats> {
        Some(*self.total())
    }
}

/// The batch lanes' costs since the last call, zeroing them.
#[inline]
fn batch_costs(counter: &mut TraversalCounter) -> [u64; BATCH] {
    let lanes = counter.take();
    std::array::from_fn(|lane| lanes[lane])
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

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use wide::{f32x4, f32x8, f32x16};

    use super::*;
    use crate::accel::{Accel, Bvh};
    use crate::packet::RayPacket;
    use crate::ray::Ray;
    use crate::render::batch::{ALL_LANES, Rays};
    use crate::render::kernel::{PacketKernel, ScalarKernel, TraceKernel};
    use crate::rng::Rng;
    use crate::scene::generate::random::random_spheres;

    /// Random rays from inside a sphere cloud split packets and send lanes down
    /// the single-ray fallback: the lane costs still add up to the totals, and
    /// the totals are what the plain counted queries report.
    #[test]
    fn lane_costs_sum_to_the_totals_of_the_same_queries() {
        let bvh = Bvh::new(&random_spheres(400, 3));
        let mut rng = Rng::new(11);
        for _ in 0..300 {
            let rays: Rays = std::array::from_fn(|_| {
                Ray::unbounded(
                    rng.point_in(Vec3::splat(-1.0), Vec3::splat(1.0)),
                    rng.unit_vector(),
                )
            });
            let active = 1 + rng.below((1 << BATCH) - 1);
            let mut direct = TraversalCounter::totals();
            let packet = RayPacket::<f32x16>::from_rays_masked(&rays, active);
            bvh.intersect_packet_counted(&packet, &mut direct);
            bvh.occluded_packet_counted(&packet, &mut direct);
            let mut lanes = TraversalCounter::per_lane();
            PacketKernel::<f32x16>::intersect(&bvh, &rays, active, &mut lanes);
            PacketKernel::<f32x16>::occluded(&bvh, &rays, active, &mut lanes);
            assert_eq!(lanes.total(), direct.total());
            let cost = batch_costs(&mut lanes);
            assert_eq!(
                cost.iter().sum::<u64>(),
                direct.total().nodes_visited + direct.total().prim_tests
            );
            assert!((0..BATCH).all(|i| active >> i & 1 == 1 || cost[i] == 0));

            // Two 8-wide or four 4-wide packets per batch, and the scalar
            // kernel: lane sums match too.
            for costs in [
                lane_sum::<PacketKernel<f32x8>>(&bvh, &rays, active),
                lane_sum::<PacketKernel<f32x4>>(&bvh, &rays, active),
                lane_sum::<ScalarKernel>(&bvh, &rays, active),
            ] {
                assert_eq!(costs.0, costs.1);
                assert!((0..BATCH).all(|i| active >> i & 1 == 1 || costs.2[i] == 0));
            }
        }
        // The scalar kernel's lane cost is exactly its ray's own count.
        let rays: Rays = std::array::from_fn(|i| {
            Ray::unbounded(
                Vec3::new(0.0, 0.0, -9.0),
                Vec3::new(0.01 * i as f32, 0.0, 1.0).normalize(),
            )
        });
        let mut lanes = TraversalCounter::per_lane();
        ScalarKernel::intersect(&bvh, &rays, ALL_LANES, &mut lanes);
        let cost = batch_costs(&mut lanes);
        for (i, ray) in rays.iter().enumerate() {
            let mut one = TraversalCounter::totals();
            bvh.intersect_counted(ray, &mut one);
            assert_eq!(
                cost[i],
                one.total().nodes_visited + one.total().prim_tests,
                "lane {i}"
            );
        }
    }

    /// Incoherent packets of two lanes finish as single rays from the root:
    /// each lane's own traversal is charged to that lane, whatever its packet.
    #[test]
    fn single_ray_fallbacks_are_charged_to_their_own_lanes() {
        let bvh = Bvh::new(&random_spheres(300, 5));
        let mut rng = Rng::new(12);
        // From the eight corners of a cube towards its middle: any two lanes
        // are at least 70° apart, so no pair counts as a coherent packet.
        let rays: Rays = std::array::from_fn(|i| {
            let corner = Vec3::new(
                if i & 1 == 0 { -1.0 } else { 1.0 },
                if i & 2 == 0 { -1.0 } else { 1.0 },
                if i & 4 == 0 { -1.0 } else { 1.0 },
            );
            let o = 4.0 * corner.normalize();
            Ray::unbounded(
                o,
                (rng.point_in(Vec3::splat(-0.5), Vec3::splat(0.5)) - o).normalize(),
            )
        });
        // Each ray traced on its own (the scalar kernel) costs what its lane
        // is charged in a one-lane packet's total.
        let alone: [u64; BATCH] = std::array::from_fn(|i| {
            let (sum, total, cost) = lane_sum::<PacketKernel<f32x8>>(&bvh, &rays, 1 << i);
            assert_eq!((sum, cost[i]), (total, total), "lane {i}");
            lane_sum::<ScalarKernel>(&bvh, &rays, 1 << i).2[i]
        });
        assert!(alone.iter().all(|&c| c > 0));
        for (a, b) in [(0, 7), (2, 5), (6, 3)] {
            let (_, _, cost) = lane_sum::<PacketKernel<f32x8>>(&bvh, &rays, 1 << a | 1 << b);
            assert_eq!((cost[a], cost[b]), (alone[a], alone[b]), "lanes {a} and {b}");
        }
    }

    /// (lane costs summed, totals' nodes + prims, lane costs) of one nearest-hit batch.
    fn lane_sum<K: TraceKernel>(bvh: &Bvh, rays: &Rays, active: u32) -> (u64, u64, [u64; BATCH]) {
        let mut lanes = TraversalCounter::per_lane();
        K::intersect(bvh, rays, active, &mut lanes);
        let total = lanes.total().nodes_visited + lanes.total().prim_tests;
        let cost = batch_costs(&mut lanes);
        (cost.iter().sum(), total, cost)
    }
}
