//! Acceleration structures behind one small API, [`Accel`]: nearest hit and
//! any hit (occlusion), for single rays and for packets.
//!
//! [`BruteForce`] is the lecture's loop (every ray against every object) and the
//! reference every other structure is checked against; [`Bvh`] is the SAH
//! bounding volume hierarchy. [`AccelKind`] picks one (`--accel none|bvh`).
//! Every query takes a counter of its cost ([`stats::Counter`]); the plain
//! methods count nothing.

pub mod brute_force;
pub mod bvh;
pub mod kind;
pub mod queries;
pub mod stats;
pub mod traversal_counter;
pub mod two_level;

pub use brute_force::BruteForce;
pub use bvh::Bvh;
pub use kind::AccelKind;
pub use stats::TraversalStats;
pub use traversal_counter::TraversalCounter;
pub use two_level::TwoLevel;

use crate::accel::stats::{Counter, NoStats};
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::SimdFloat;

/// Ray queries over a set of primitives, indexed by their position in the
/// scene: nearest hit and any hit, for single rays and packets. Each query
/// reports its traversal work (node visits, primitive tests, SIMD lanes) to a
/// [`Counter`] the caller owns; the plain methods pass [`NoStats`], whose
/// counting compiles away, and return exactly what the counted ones return.
pub trait Accel: Sync {
    /// Whether the queries report their work to the counter. raypack's own
    /// structures do; an outside library (Embree) is a black box, and a render
    /// through it is not counted (its traversal statistics are `None`).
    const COUNTS_WORK: bool = true;

    /// The nearest hit of `ray` (the record's `ng` is not filled in).
    fn intersect_counted<S: Counter>(&self, ray: &Ray, stats: &mut S) -> Hit;

    /// The nearest hit of every active lane.
    fn intersect_packet_counted<F: SimdFloat, S: Counter>(
        &self,
        rays: &RayPacket<F>,
        stats: &mut S,
    ) -> HitPacket<F>;

    /// Whether anything lies on `ray` in `[t_min, t_max]` (shadow rays).
    fn occluded_counted<S: Counter>(&self, ray: &Ray, stats: &mut S) -> bool;

    /// The mask of active lanes on which something lies in `[t_min, t_max]`.
    fn occluded_packet_counted<F: SimdFloat, S: Counter>(&self, rays: &RayPacket<F>, stats: &mut S) -> F;

    /// The nearest hits of up to `F::LANES` rays traced as one packet, the
    /// lanes of `mask` active: [`intersect_packet_counted`](Self::intersect_packet_counted)
    /// of [`RayPacket::from_rays_masked`]. A BVH packs them in its instruction
    /// set's lanes itself (a packet stored in one lane type and read in
    /// another would stall on every vector).
    #[inline]
    fn intersect_rays_counted<F: SimdFloat, S: Counter>(
        &self,
        rays: &[Ray],
        mask: u32,
        stats: &mut S,
    ) -> HitPacket<F> {
        self.intersect_packet_counted(&RayPacket::<F>::from_rays_masked(rays, mask), stats)
    }

    /// The occluded lanes of up to `F::LANES` rays traced as one packet, as
    /// [`intersect_rays_counted`](Self::intersect_rays_counted).
    #[inline]
    fn occluded_rays_counted<F: SimdFloat, S: Counter>(&self, rays: &[Ray], mask: u32, stats: &mut S) -> F {
        self.occluded_packet_counted(&RayPacket::<F>::from_rays_masked(rays, mask), stats)
    }

    /// The nearest hits of the rays whose bit is set in `active`, one ray at
    /// a time, into `hits` (the other records are left alone); ray `i`'s work
    /// is reported after `stats.lane(i)`. The same answers as
    /// [`intersect_counted`](Self::intersect_counted) ray by ray, in one call
    /// (a BVH enters its instruction set's code once for all of them).
    #[inline]
    fn intersect_each_counted<S: Counter>(&self, rays: &[Ray], active: u32, hits: &mut [Hit], stats: &mut S) {
        for (i, (ray, hit)) in rays.iter().zip(hits).enumerate() {
            if active >> i & 1 == 1 {
                stats.lane(i);
                *hit = self.intersect_counted(ray, stats);
            }
        }
    }

    /// The mask of the rays whose bit is set in `active` that are blocked,
    /// one ray at a time, as [`intersect_each_counted`](Self::intersect_each_counted).
    #[inline]
    fn occluded_each_counted<S: Counter>(&self, rays: &[Ray], active: u32, stats: &mut S) -> u32 {
        let mut blocked = 0;
        for (i, ray) in rays.iter().enumerate() {
            if active >> i & 1 == 1 {
                stats.lane(i);
                blocked |= u32::from(self.occluded_counted(ray, stats)) << i;
            }
        }
        blocked
    }

    /// [`intersect_counted`](Self::intersect_counted), uncounted.
    #[inline]
    fn intersect(&self, ray: &Ray) -> Hit {
        self.intersect_counted(ray, &mut NoStats)
    }

    /// [`intersect_packet_counted`](Self::intersect_packet_counted), uncounted.
    #[inline]
    fn intersect_packet<F: SimdFloat>(&self, rays: &RayPacket<F>) -> HitPacket<F> {
        self.intersect_packet_counted(rays, &mut NoStats)
    }

    /// [`occluded_counted`](Self::occluded_counted), uncounted.
    #[inline]
    fn occluded(&self, ray: &Ray) -> bool {
        self.occluded_counted(ray, &mut NoStats)
    }

    /// [`occluded_packet_counted`](Self::occluded_packet_counted), uncounted.
    #[inline]
    fn occluded_packet<F: SimdFloat>(&self, rays: &RayPacket<F>) -> F {
        self.occluded_packet_counted(rays, &mut NoStats)
    }
}
