//! Traversal statistics: what a ray query cost, counted without slowing the
//! plain path.
//!
//! Traversal code is generic over a [`Counter`]. The `*_counted` queries of
//! [`Accel`] run with a counter the caller owns: a [`TraversalCounter`]
//! counts the totals, a [`TraversalStats`] (and, when asked, each lane's
//! cost), so a renderer keeps one per tile and adds the totals up with
//! [`TraversalStats::merge`]; the plain queries run the same code with
//! [`NoStats`], a zero-sized counter whose methods are empty and vanish after
//! inlining. No atomics, no globals. (Every query is compiled once per counter
//! type and instruction set, which is why there are only these two.)
//!
//! [`Accel`]: crate::accel::Accel
//! [`TraversalCounter`]: crate::accel::traversal_counter::TraversalCounter

use std::ops::AddAssign;

use crate::simd::SimdFloat;

/// Receives the events of a traversal. Packet events take the mask of lanes
/// taking part, so the popcount is only paid for when something counts.
pub trait Counter {
    /// `n` rays started (a packet counts its active lanes).
    fn rays(&mut self, n: u64);
    /// A packet was started.
    fn packet(&mut self);
    /// One ray visited one node.
    fn node(&mut self);
    /// One ray ran one primitive kernel.
    fn prim(&mut self);
    /// A packet visited one node with the lanes of `mask` taking part.
    fn packet_node<F: SimdFloat>(&mut self, mask: F);
    /// A packet ran one primitive kernel with the lanes of `mask` taking part.
    fn packet_prim<F: SimdFloat>(&mut self, mask: F);
    /// `n` lanes of a packet left it to finish as single rays.
    fn fallback(&mut self, n: u64);
    /// The single-ray events that follow are the work of lane `lane` of the
    /// packet being traced, finishing a subtree on its own: lets a counter
    /// charge each lane its own work (the totals do not need it).
    fn lane(&mut self, lane: usize);
    /// The events until [`leave_instance`](Self::leave_instance) are a mesh's
    /// walk inside instances ([`TwoLevel`](crate::accel::TwoLevel)): its rays
    /// and packets were counted when they entered the top level, and starting
    /// again in each instance they meet does not count them twice.
    fn enter_instance(&mut self);
    /// Back at the top level: rays and packets count again.
    fn leave_instance(&mut self);
}

/// The counter that counts nothing (0 bytes): the plain queries use it.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoStats;

impl Counter for NoStats {
    #[inline(always)]
    fn rays(&mut self, _: u64) {}
    #[inline(always)]
    fn packet(&mut self) {}
    #[inline(always)]
    fn node(&mut self) {}
    #[inline(always)]
    fn prim(&mut self) {}
    #[inline(always)]
    fn packet_node<F: SimdFloat>(&mut self, _: F) {}
    #[inline(always)]
    fn packet_prim<F: SimdFloat>(&mut self, _: F) {}
    #[inline(always)]
    fn fallback(&mut self, _: u64) {}
    #[inline(always)]
    fn lane(&mut self, _: usize) {}
    #[inline(always)]
    fn enter_instance(&mut self) {}
    #[inline(always)]
    fn leave_instance(&mut self) {}
}

/// What the ray queries of a tile, an image or one ray cost. 64 bytes.
///
/// Per-ray figures count a packet's work once per lane taking part, so that
/// single-ray and packet traversal report comparable "nodes visited per ray";
/// the SIMD counters say how full the packets' lanes were.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct TraversalStats {
    /// Rays traced (a packet adds its active lanes).
    pub rays: u64,
    /// Packets traced.
    pub packets: u64,
    /// Node visits summed over rays (a packet's visit adds its lanes taking part).
    pub nodes_visited: u64,
    /// Ray-primitive tests summed over rays (a packet kernel call adds its lanes taking part).
    pub prim_tests: u64,
    /// SIMD steps made by packets: node visits plus packet kernel calls.
    pub simd_steps: u64,
    /// Lanes taking part, summed over SIMD steps.
    pub simd_active_lanes: u64,
    /// Lane slots, summed over SIMD steps (steps × packet width).
    pub simd_lane_slots: u64,
    /// Packet lanes traced by single-ray traversal (those of incoherent packets).
    pub fallback_rays: u64,
}

impl TraversalStats {
    /// Add another tile's (or ray's) counts to these.
    pub fn merge(&mut self, other: &TraversalStats) {
        self.rays += other.rays;
        self.packets += other.packets;
        self.nodes_visited += other.nodes_visited;
        self.prim_tests += other.prim_tests;
        self.simd_steps += other.simd_steps;
        self.simd_active_lanes += other.simd_active_lanes;
        self.simd_lane_slots += other.simd_lane_slots;
        self.fallback_rays += other.fallback_rays;
    }

    /// Mean node visits per ray (0 without rays).
    pub fn nodes_per_ray(&self) -> f64 {
        ratio(self.nodes_visited, self.rays)
    }

    /// Mean ray-primitive tests per ray (0 without rays).
    pub fn prims_per_ray(&self) -> f64 {
        ratio(self.prim_tests, self.rays)
    }

    /// The traversal cost of one ray for a heat map: node visits plus primitive
    /// tests per ray (with fresh stats per ray or packet, the cost of that query).
    pub fn cost_per_ray(&self) -> f64 {
        ratio(self.nodes_visited + self.prim_tests, self.rays)
    }

    /// SIMD lane utilisation of packets: active lanes / lane slots, in `[0, 1]`
    /// (0 when no packet was traced).
    pub fn lane_utilisation(&self) -> f64 {
        ratio(self.simd_active_lanes, self.simd_lane_slots)
    }

    /// Single-ray fallbacks per ray: lanes of incoherent packets traced as
    /// single rays, per ray traced (0 without rays; at most 1).
    pub fn fallbacks_per_ray(&self) -> f64 {
        ratio(self.fallback_rays, self.rays)
    }

    /// A one-line summary for image captions and logs, e.g.
    /// `31.2 nodes/ray, 4.1 prims/ray, lanes 83% (packets), 0.12 single-ray fallbacks/ray`
    /// (the packet figures only when packets were traced).
    pub fn caption(&self) -> String {
        let mut s = format!(
            "{:.1} nodes/ray, {:.1} prims/ray",
            self.nodes_per_ray(),
            self.prims_per_ray()
        );
        if self.simd_lane_slots > 0 {
            s += &format!(
                ", lanes {:.0}% (packets), {:.2} single-ray fallbacks/ray",
                100.0 * self.lane_utilisation(),
                self.fallbacks_per_ray()
            );
        }
        s
    }
}

impl AddAssign<&TraversalStats> for TraversalStats {
    fn add_assign(&mut self, other: &TraversalStats) {
        self.merge(other);
    }
}

fn ratio(a: u64, b: u64) -> f64 {
    if b == 0 { 0.0 } else { a as f64 / b as f64 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn caption_names_the_packet_figures_when_packets_were_traced() {
        let s = TraversalStats {
            rays: 16,
            nodes_visited: 8,
            prim_tests: 4,
            simd_steps: 4,
            simd_active_lanes: 12,
            simd_lane_slots: 32,
            fallback_rays: 4,
            ..TraversalStats::default()
        };
        assert!(
            s.caption()
                .contains("lanes 38% (packets), 0.25 single-ray fallbacks/ray"),
            "{}",
            s.caption()
        );
        let mut total = s;
        total += &s;
        assert_eq!((total.rays, total.simd_active_lanes), (32, 24));
    }

    #[test]
    fn empty_stats_have_zero_ratios() {
        let s = TraversalStats::default();
        assert_eq!(s.nodes_per_ray(), 0.0);
        assert_eq!(s.lane_utilisation(), 0.0);
        assert!(!s.caption().contains("lanes"));
    }
}
