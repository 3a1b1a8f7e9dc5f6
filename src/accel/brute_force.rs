//! The lecture's ray casting loop: every ray against every primitive, nearest wins.

use crate::accel::Accel;
use crate::accel::stats::Counter;
use crate::geometry::{Intersect, Primitive};
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::SimdFloat;

/// Brute-force ray queries over a slice of primitives (no acceleration).
#[derive(Clone, Copy, Debug)]
pub struct BruteForce<'a> {
    prims: &'a [Primitive],
}

impl<'a> BruteForce<'a> {
    /// Queries over `prims`; a hit's primitive index is the position in `prims`.
    pub fn new(prims: &'a [Primitive]) -> Self {
        Self { prims }
    }

    /// Nearest hit, every primitive tested.
    #[inline]
    fn nearest<S: Counter>(&self, ray: &Ray, stats: &mut S) -> Hit {
        stats.rays(1);
        let mut hit = Hit::none(ray);
        for (i, p) in self.prims.iter().enumerate() {
            stats.prim();
            p.intersect(ray, i as u32, &mut hit);
        }
        hit
    }

    /// Nearest hits of a packet, every primitive tested.
    #[inline]
    fn nearest_packet<F: SimdFloat, S: Counter>(&self, rays: &RayPacket<F>, stats: &mut S) -> HitPacket<F> {
        stats.rays(u64::from(rays.active.bitmask().count_ones()));
        stats.packet();
        let mut hits = HitPacket::none(rays);
        for (i, p) in self.prims.iter().enumerate() {
            stats.packet_prim(rays.active);
            p.intersect_packet(rays, i as u32, &mut hits);
        }
        hits
    }

    /// Any hit: stops at the first primitive hit.
    #[inline]
    fn any<S: Counter>(&self, ray: &Ray, stats: &mut S) -> bool {
        stats.rays(1);
        let mut hit = Hit::none(ray);
        self.prims.iter().enumerate().any(|(i, p)| {
            stats.prim();
            p.intersect(ray, i as u32, &mut hit)
        })
    }

    /// Any hit per lane: occluded lanes drop out of the packet; stops once none is left.
    #[inline]
    fn any_packet<F: SimdFloat, S: Counter>(&self, rays: &RayPacket<F>, stats: &mut S) -> F {
        stats.rays(u64::from(rays.active.bitmask().count_ones()));
        stats.packet();
        let mut pending = *rays;
        let mut hits = HitPacket::none(rays);
        for (i, p) in self.prims.iter().enumerate() {
            if pending.active.none() {
                break;
            }
            stats.packet_prim(pending.active);
            p.intersect_packet(&pending, i as u32, &mut hits);
            pending.active = pending.active.and_not(hits.hit_mask());
        }
        rays.active & hits.hit_mask()
    }
}

impl Accel for BruteForce<'_> {
    fn intersect_counted<S: Counter>(&self, ray: &Ray, stats: &mut S) -> Hit {
        self.nearest(ray, stats)
    }

    fn intersect_packet_counted<F: SimdFloat, S: Counter>(
        &self,
        rays: &RayPacket<F>,
        stats: &mut S,
    ) -> HitPacket<F> {
        self.nearest_packet(rays, stats)
    }

    fn occluded_counted<S: Counter>(&self, ray: &Ray, stats: &mut S) -> bool {
        self.any(ray, stats)
    }

    fn occluded_packet_counted<F: SimdFloat, S: Counter>(&self, rays: &RayPacket<F>, stats: &mut S) -> F {
        self.any_packet(rays, stats)
    }
}
