//! Traversal cost per batch lane, the data of the per-pixel cost heat map.
//!
//! A packet event (a node visit or a primitive kernel call) costs 1 for each
//! lane taking part; a single-ray event costs 1 for the lane being traced: the
//! scalar kernel's ray, or the packet lane that [`Counter::lane`] names while it
//! finishes a subtree on its own. Summed over the lanes, the costs are the
//! totals' node visits plus primitive tests.

use crate::accel::TraversalStats;
use crate::accel::stats::Counter;
use crate::render::batch::BATCH;
use crate::simd::SimdFloat;

/// Traversal totals plus each batch lane's cost (node visits plus primitive
/// tests). 208 bytes.
#[derive(Clone, Copy, Debug, Default)]
pub struct LaneCosts {
    total: TraversalStats,
    lanes: [u64; BATCH],
    /// Batch lane of a packet's lane 0.
    first: usize,
    /// Batch lane that single-ray events are charged to.
    single: usize,
}

impl LaneCosts {
    /// The totals counted so far.
    pub fn total(&self) -> &TraversalStats {
        &self.total
    }

    /// Charge the events that follow from batch lane `first` on: a packet's lane
    /// `j` is batch lane `first + j`, a single ray is batch lane `first`.
    #[inline(always)]
    pub fn route(&mut self, first: usize) {
        self.first = first;
        self.single = first;
    }

    /// Each batch lane's cost since the last call, zeroing them.
    #[inline]
    pub fn take(&mut self) -> [u64; BATCH] {
        std::mem::take(&mut self.lanes)
    }

    /// One more for each lane of the packet mask `mask`: a branch-free add
    /// over all lanes (each adds its bit), cheaper than a loop over the set
    /// bits, whose count the branch predictor cannot guess. The bits come
    /// from a movemask, not a store of the mask: in the test profile's giant
    /// entry points, the store intrinsic (with its debug checks) was left out
    /// of line.
    #[inline(always)]
    fn charge_lanes<F: SimdFloat>(&mut self, mask: F) {
        let bits = mask.bitmask();
        for (j, cost) in self.lanes[self.first..].iter_mut().take(F::LANES).enumerate() {
            *cost += u64::from(bits >> j & 1);
        }
    }
}

impl Counter for LaneCosts {
    #[inline(always)]
    fn rays(&mut self, n: u64) {
        self.total.rays(n);
    }
    #[inline(always)]
    fn packet(&mut self) {
        self.total.packet();
    }
    #[inline(always)]
    fn node(&mut self) {
        self.total.node();
        self.lanes[self.single] += 1;
    }
    #[inline(always)]
    fn prim(&mut self) {
        self.total.prim();
        self.lanes[self.single] += 1;
    }
    #[inline(always)]
    fn packet_node<F: SimdFloat>(&mut self, mask: F) {
        self.total.packet_node(mask);
        self.charge_lanes(mask);
    }
    #[inline(always)]
    fn packet_prim<F: SimdFloat>(&mut self, mask: F) {
        self.total.packet_prim(mask);
        self.charge_lanes(mask);
    }
    #[inline(always)]
    fn fallback(&mut self, n: u64) {
        self.total.fallback(n);
    }
    #[inline(always)]
    fn lane(&mut self, lane: usize) {
        self.single = self.first + lane;
    }
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

    #[test]
    fn events_are_charged_to_the_lanes_that_did_them() {
        let mut c = LaneCosts::default();
        c.route(4);
        c.packet_node(f32x4::mask_from_bits(0b1010));
        c.node(); // a single ray: batch lane 4
        c.lane(2); // packet lane 2 finishes alone: batch lane 6
        c.node();
        c.prim();
        let mut expected = [0; BATCH];
        expected[4..8].copy_from_slice(&[1, 1, 2, 1]);
        assert_eq!(c.take(), expected);
        assert_eq!(c.take(), [0; BATCH]);
        assert_eq!(c.total().nodes_visited, 4);
        assert_eq!(c.total().prim_tests, 1);
    }

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
            let mut direct = TraversalStats::default();
            let packet = RayPacket::<f32x16>::from_rays_masked(&rays, active);
            bvh.intersect_packet_counted(&packet, &mut direct);
            bvh.occluded_packet_counted(&packet, &mut direct);
            let mut lanes = LaneCosts::default();
            PacketKernel::<f32x16>::intersect(&bvh, &rays, active, &mut lanes);
            PacketKernel::<f32x16>::occluded(&bvh, &rays, active, &mut lanes);
            assert_eq!(*lanes.total(), direct);
            let cost = lanes.take();
            assert_eq!(cost.iter().sum::<u64>(), direct.nodes_visited + direct.prim_tests);
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
        let mut lanes = LaneCosts::default();
        ScalarKernel::intersect(&bvh, &rays, ALL_LANES, &mut lanes);
        let cost = lanes.take();
        for (i, ray) in rays.iter().enumerate() {
            let mut one = TraversalStats::default();
            bvh.intersect_counted(ray, &mut one);
            assert_eq!(cost[i], one.nodes_visited + one.prim_tests, "lane {i}");
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
        let mut lanes = LaneCosts::default();
        K::intersect(bvh, rays, active, &mut lanes);
        let total = lanes.total().nodes_visited + lanes.total().prim_tests;
        let cost = lanes.take();
        (cost.iter().sum(), total, cost)
    }
}
