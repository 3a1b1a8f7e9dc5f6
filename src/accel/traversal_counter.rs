//! The counter that counts: a traversal's totals and, when asked, each lane's
//! share of them.
//!
//! It is the one counting [`Counter`]: every query is compiled once per
//! counter type and instruction set, so one type that counts totals or costs
//! per lane (chosen when it is made) keeps the counted copies of the traversal
//! at one per level. Counting per lane adds a branch per event when it is off.

use crate::accel::stats::{Counter, TraversalStats};
use crate::simd::SimdFloat;

/// The most lanes a [`TraversalCounter`] charges one by one: a render batch,
/// two 8-wide packets or one 16-wide.
pub const COUNTED_LANES: usize = 16;

/// Traversal totals plus, when made with [`per_lane`](Self::per_lane), each
/// lane's cost (node visits plus primitive tests). 72 bytes, plus 144 on the
/// heap when counting per lane: the lanes live apart from the totals so that
/// counting totals alone costs a test of a pointer that does not change.
#[derive(Clone, Debug, Default)]
pub struct TraversalCounter {
    total: TraversalStats,
    lanes: Option<Box<LaneCosts>>,
    /// Inside instances: rays and packets starting there are not counted again.
    inside_instances: bool,
}

/// Each lane's cost, and where events are charged. 144 bytes.
#[derive(Clone, Debug, Default)]
struct LaneCosts {
    cost: [u64; COUNTED_LANES],
    /// Lane of a packet's lane 0.
    first: usize,
    /// Lane that single-ray events are charged to.
    single: usize,
}

impl TraversalCounter {
    /// A counter of the totals only (the same as `default()`).
    pub fn totals() -> Self {
        Self::default()
    }

    /// A counter of the totals and each lane's cost.
    pub fn per_lane() -> Self {
        Self {
            lanes: Some(Box::default()),
            ..Self::default()
        }
    }

    /// Whether it charges events to lanes.
    pub fn counts_lanes(&self) -> bool {
        self.lanes.is_some()
    }

    /// The totals counted so far.
    pub fn total(&self) -> &TraversalStats {
        &self.total
    }

    /// Charge the events that follow from lane `first` on: a packet's lane
    /// `j` is lane `first + j`, a single ray is lane `first`.
    #[inline(always)]
    pub fn route(&mut self, first: usize) {
        if let Some(lanes) = self.lanes.as_deref_mut() {
            lanes.first = first;
            lanes.single = first;
        }
    }

    /// Each lane's cost since the last call, zeroing them (all zero unless
    /// counting per lane).
    #[inline]
    pub fn take(&mut self) -> [u64; COUNTED_LANES] {
        self.lanes
            .as_deref_mut()
            .map_or([0; COUNTED_LANES], |lanes| std::mem::take(&mut lanes.cost))
    }

    /// One more for the lane single-ray events are charged to.
    #[inline(always)]
    fn charge_single(&mut self) {
        if let Some(lanes) = self.lanes.as_deref_mut() {
            lanes.cost[lanes.single] += 1;
        }
    }

    /// One more for each lane of the packet mask `mask`: a branch-free add
    /// over all lanes (each adds its bit), cheaper than a loop over the set
    /// bits, whose count the branch predictor cannot guess. The bits come
    /// from a movemask, not a store of the mask: in the test profile's giant
    /// entry points, the store intrinsic (with its debug checks) was left out
    /// of line.
    #[inline(always)]
    fn charge_lanes<F: SimdFloat>(&mut self, mask: F) {
        if let Some(lanes) = self.lanes.as_deref_mut() {
            let bits = mask.bitmask();
            for (j, cost) in lanes.cost[lanes.first..].iter_mut().take(F::LANES).enumerate() {
                *cost += u64::from(bits >> j & 1);
            }
        }
    }
}

impl Counter for TraversalCounter {
    #[inline(always)]
    fn rays(&mut self, n: u64) {
        if !self.inside_instances {
            self.total.rays += n;
        }
    }
    #[inline(always)]
    fn packet(&mut self) {
        if !self.inside_instances {
            self.total.packets += 1;
        }
    }
    #[inline(always)]
    fn node(&mut self) {
        self.total.nodes_visited += 1;
        self.charge_single();
    }
    #[inline(always)]
    fn prim(&mut self) {
        self.total.prim_tests += 1;
        self.charge_single();
    }
    #[inline(always)]
    fn packet_node<F: SimdFloat>(&mut self, mask: F) {
        self.total.nodes_visited += self.simd_step(mask);
        self.charge_lanes(mask);
    }
    #[inline(always)]
    fn packet_prim<F: SimdFloat>(&mut self, mask: F) {
        self.total.prim_tests += self.simd_step(mask);
        self.charge_lanes(mask);
    }
    #[inline(always)]
    fn fallback(&mut self, n: u64) {
        self.total.fallback_rays += n;
    }
    #[inline(always)]
    fn lane(&mut self, lane: usize) {
        if let Some(lanes) = self.lanes.as_deref_mut() {
            lanes.single = lanes.first + lane;
        }
    }
    #[inline(always)]
    fn enter_instance(&mut self) {
        self.inside_instances = true;
    }
    #[inline(always)]
    fn leave_instance(&mut self) {
        self.inside_instances = false;
    }
}

impl TraversalCounter {
    /// Count one SIMD step of the lanes of `mask`; returns how many took part.
    #[inline(always)]
    fn simd_step<F: SimdFloat>(&mut self, mask: F) -> u64 {
        let lanes = u64::from(mask.bitmask().count_ones());
        self.total.simd_steps += 1;
        self.total.simd_active_lanes += lanes;
        self.total.simd_lane_slots += F::LANES as u64;
        lanes
    }
}

#[cfg(test)]
mod tests {
    use wide::{f32x4, f32x8};

    use super::*;

    #[test]
    fn packet_events_count_lanes_and_slots() {
        let mut c = TraversalCounter::totals();
        c.rays(8);
        c.packet_node(f32x8::mask_from_bits(0b1111_0000));
        c.packet_prim(f32x8::mask_from_bits(0b0000_0011));
        let s = *c.total();
        assert_eq!(s.nodes_visited, 4);
        assert_eq!(s.prim_tests, 2);
        assert_eq!(s.simd_steps, 2);
        assert_eq!(s.simd_lane_slots, 16);
        assert!((s.lane_utilisation() - 6.0 / 16.0).abs() < 1e-12);
        assert!((s.cost_per_ray() - 6.0 / 8.0).abs() < 1e-12);
        let mut total = TraversalStats::default();
        total += &s;
        total += &s;
        assert_eq!(total.simd_active_lanes, 12);
        assert_eq!(total.rays, 16);
        c.fallback(4);
        assert_eq!(c.total().fallback_rays, 4);
        assert_eq!(c.take(), [0; COUNTED_LANES], "a totals counter charges no lane");
    }

    #[test]
    fn events_are_charged_to_the_lanes_that_did_them() {
        let mut c = TraversalCounter::per_lane();
        c.route(4);
        c.packet_node(f32x4::mask_from_bits(0b1010));
        c.node(); // a single ray: lane 4
        c.lane(2); // packet lane 2 finishes alone: lane 6
        c.node();
        c.prim();
        let mut expected = [0; COUNTED_LANES];
        expected[4..8].copy_from_slice(&[1, 1, 2, 1]);
        assert_eq!(c.take(), expected);
        assert_eq!(c.take(), [0; COUNTED_LANES]);
        assert_eq!(c.total().nodes_visited, 4);
        assert_eq!(c.total().prim_tests, 1);
    }

    /// Counting per lane changes nothing in the totals.
    #[test]
    fn per_lane_and_totals_counters_count_the_same_totals() {
        let (mut a, mut b) = (TraversalCounter::totals(), TraversalCounter::per_lane());
        for c in [&mut a, &mut b] {
            c.rays(3);
            c.packet();
            c.packet_node(f32x8::mask_from_bits(0b0110_0001));
            c.lane(1);
            c.node();
            c.prim();
            c.fallback(1);
        }
        assert_eq!(a.total(), b.total());
        assert_eq!(b.take().iter().sum::<u64>(), 5);
    }
}
