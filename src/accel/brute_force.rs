//! The lecture's ray casting loop: every ray against every primitive, nearest wins.

use crate::accel::Accel;
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
}

impl Accel for BruteForce<'_> {
    fn intersect(&self, ray: &Ray) -> Hit {
        let mut hit = Hit::none(ray);
        for (i, p) in self.prims.iter().enumerate() {
            p.intersect(ray, i as u32, &mut hit);
        }
        hit
    }

    fn intersect_packet<F: SimdFloat>(&self, rays: &RayPacket<F>) -> HitPacket<F> {
        let mut hits = HitPacket::none(rays);
        for (i, p) in self.prims.iter().enumerate() {
            p.intersect_packet(rays, i as u32, &mut hits);
        }
        hits
    }

    fn occluded(&self, ray: &Ray) -> bool {
        let mut hit = Hit::none(ray);
        self.prims
            .iter()
            .enumerate()
            .any(|(i, p)| p.intersect(ray, i as u32, &mut hit))
    }

    fn occluded_packet<F: SimdFloat>(&self, rays: &RayPacket<F>) -> F {
        // Occluded lanes drop out of the packet; stop once none is left.
        let mut pending = *rays;
        let mut hits = HitPacket::none(rays);
        for (i, p) in self.prims.iter().enumerate() {
            p.intersect_packet(&pending, i as u32, &mut hits);
            pending.active = pending.active.and_not(hits.hit_mask());
            if pending.active.none() {
                break;
            }
        }
        rays.active & hits.hit_mask()
    }
}
