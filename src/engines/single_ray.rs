//! The structure of an engine that traces one ray at a time (the peers), as
//! an [`Accel`]. The commands offer such an engine single rays only (its
//! [`Capabilities`](super::Capabilities) say no packets); a packet that
//! reaches it anyway is traced lane by lane, so every answer is still right.

use crate::accel::Accel;
use crate::accel::stats::Counter;
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::SimdFloat;

/// One-ray queries of an engine's structure.
pub trait SingleRayQueries: Sync {
    /// The nearest hit of `ray` in `[t_min, t_max]`, primitive numbered as the scene's.
    fn nearest(&self, ray: &Ray) -> Hit;
    /// Whether anything lies on `ray` in `[t_min, t_max]`.
    fn blocked(&self, ray: &Ray) -> bool;
}

/// A single-ray engine's structure `T` as an [`Accel`] (which counts no work).
pub struct SingleRays<T>(pub T);

impl<T: SingleRayQueries> Accel for SingleRays<T> {
    const COUNTS_WORK: bool = false;

    #[inline]
    fn intersect_counted<S: Counter>(&self, ray: &Ray, _: &mut S) -> Hit {
        self.0.nearest(ray)
    }

    fn intersect_packet_counted<F: SimdFloat, S: Counter>(
        &self,
        rays: &RayPacket<F>,
        _: &mut S,
    ) -> HitPacket<F> {
        let mut hits = HitPacket::none(rays);
        for i in (0..F::LANES).filter(|&i| rays.is_active(i)) {
            hits.set_hit(i, &self.0.nearest(&rays.ray(i)));
        }
        hits
    }

    #[inline]
    fn occluded_counted<S: Counter>(&self, ray: &Ray, _: &mut S) -> bool {
        self.0.blocked(ray)
    }

    fn occluded_packet_counted<F: SimdFloat, S: Counter>(&self, rays: &RayPacket<F>, _: &mut S) -> F {
        let blocked = (0..F::LANES)
            .filter(|&i| rays.is_active(i) && self.0.blocked(&rays.ray(i)))
            .fold(0u32, |bits, i| bits | 1 << i);
        F::mask_from_bits(blocked)
    }
}
