//! Tracing through an [`EmbreeScene`]: raypack's [`Accel`] queries answered by
//! Embree, so every command can use Embree like any other acceleration
//! structure.
//!
//! | [`Accel`] | Embree |
//! | --- | --- |
//! | `intersect` | `rtcIntersect1` |
//! | `intersect_packet` (4 / 8 / 16 lanes) | `rtcIntersect4/8/16`, valid lanes = the packet's active lanes |
//! | `occluded` | `rtcOccluded1` |
//! | `occluded_packet` | `rtcOccluded4/8/16` |
//!
//! Hit records carry raypack's primitive index (file order); `u, v` are
//! Embree's (barycentric for triangles, the same convention as raypack's). Rays
//! with a non-finite origin or direction are not sent to Embree and miss, as
//! they do in raypack. Queries set FTZ/DAZ on the calling thread
//! ([`flush_denormals`]).

use glam::Vec3;

use embree4_sys as sys;

use crate::accel::Accel;
use crate::accel::stats::Counter;
use crate::embree::denormals::flush_denormals;
use crate::embree::ray_hit::{
    INVALID_ID, RayHit1, RayHit4, RayHit8, RayHit16, RayHitPacket, intersect_arguments, occluded_arguments,
    traceable,
};
use crate::embree::scene::EmbreeScene;
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, NO_HIT, Ray};
use crate::simd::{SimdFloat, SimdU32};

impl EmbreeScene {
    /// Packet query through the `P`-lane record type (`P::LANES == F::LANES`).
    #[inline]
    fn packet<F: SimdFloat, P: RayHitPacket>(&self, rays: &RayPacket<F>) -> HitPacket<F> {
        let mut record = P::new(rays);
        let mut hits = HitPacket::none(rays);
        if record.valid_bits() == 0 {
            return hits;
        }
        flush_denormals();
        let mut args = intersect_arguments();
        args.flags = packet_flags(rays);
        // SAFETY: a committed scene.
        unsafe { record.intersect(self.raw_scene(), &mut args) };
        let mut prim = <F::U32 as SimdU32>::Array::default();
        let (geom, prim_id, inst) = (record.geom_id(), record.prim_id(), record.inst_id());
        for (i, p) in prim.as_mut().iter_mut().enumerate() {
            *p = if geom[i] == INVALID_ID {
                NO_HIT
            } else {
                self.prim_of(geom[i], prim_id[i], inst[i])
            };
        }
        let lanes = |x: &[f32]| {
            let mut a = F::Array::default();
            a.as_mut().copy_from_slice(x);
            F::from_array(a)
        };
        hits.t = lanes(record.tfar());
        hits.prim = F::U32::from_array(prim);
        hits.u = lanes(record.u());
        hits.v = lanes(record.v());
        hits
    }

    /// Packet occlusion through the `P`-lane record type.
    #[inline]
    fn packet_occluded<F: SimdFloat, P: RayHitPacket>(&self, rays: &RayPacket<F>) -> F {
        let mut record = P::new(rays);
        if record.valid_bits() == 0 {
            return F::splat(0.0);
        }
        flush_denormals();
        let mut args = occluded_arguments();
        args.flags = packet_flags(rays);
        // SAFETY: a committed scene.
        unsafe { record.occluded(self.raw_scene(), &mut args) };
        let bits = record
            .tfar()
            .iter()
            .enumerate()
            .fold(0, |bits, (i, &t)| bits | (((t == f32::NEG_INFINITY) as u32) << i));
        F::mask_from_bits(bits & record.valid_bits())
    }
}

/// The query flags for a packet: `RTC_RAY_QUERY_FLAG_COHERENT` where every
/// lane points the way of the others ([`RayPacket::is_coherent`], the test raypack's own
/// packet traversal makes), as Embree's documentation asks of coherent rays
/// (primary rays, shadow rays to one light), so that Embree uses its packet
/// traversal for them; incoherent otherwise. Embree's coherent packets run
/// faster with the flag and its incoherent ones slower (figures:
/// `docs/measurements.md`, "Constants").
#[inline]
fn packet_flags<F: SimdFloat>(rays: &RayPacket<F>) -> sys::RTCRayQueryFlags {
    if rays.is_coherent() {
        sys::RTCRayQueryFlags::COHERENT
    } else {
        sys::RTCRayQueryFlags::INCOHERENT
    }
}

// Embree's traversal is a black box: the counters see nothing.
impl Accel for EmbreeScene {
    const COUNTS_WORK: bool = false;

    fn intersect_counted<S: Counter>(&self, ray: &Ray, _: &mut S) -> Hit {
        if !traceable(ray) {
            return Hit::none(ray);
        }
        flush_denormals();
        let mut record = RayHit1::new(ray);
        let mut args = intersect_arguments();
        // SAFETY: a committed scene and a record padded for Embree ≥ 4.3.
        unsafe { sys::rtcIntersect1(self.raw_scene(), &mut record.inner, &mut args) };
        let h = &record.inner.hit;
        if h.geomID == INVALID_ID {
            return Hit::none(ray);
        }
        Hit {
            t: record.inner.ray.tfar,
            prim: self.prim_of(h.geomID, h.primID, h.instID[0]),
            u: h.u,
            v: h.v,
            ng: Vec3::ZERO,
        }
    }

    fn intersect_packet_counted<F: SimdFloat, S: Counter>(
        &self,
        rays: &RayPacket<F>,
        _: &mut S,
    ) -> HitPacket<F> {
        match F::LANES {
            4 => self.packet::<F, RayHit4>(rays),
            8 => self.packet::<F, RayHit8>(rays),
            16 => self.packet::<F, RayHit16>(rays),
            n => unreachable!("SimdFloat has 4, 8 or 16 lanes, not {n}"),
        }
    }

    fn occluded_counted<S: Counter>(&self, ray: &Ray, _: &mut S) -> bool {
        if !traceable(ray) {
            return false;
        }
        flush_denormals();
        let mut record = RayHit1::new(ray);
        let mut args = occluded_arguments();
        // SAFETY: a committed scene; occlusion writes only tfar.
        unsafe { sys::rtcOccluded1(self.raw_scene(), &mut record.inner.ray, &mut args) };
        record.inner.ray.tfar == f32::NEG_INFINITY
    }

    fn occluded_packet_counted<F: SimdFloat, S: Counter>(&self, rays: &RayPacket<F>, _: &mut S) -> F {
        match F::LANES {
            4 => self.packet_occluded::<F, RayHit4>(rays),
            8 => self.packet_occluded::<F, RayHit8>(rays),
            16 => self.packet_occluded::<F, RayHit16>(rays),
            n => unreachable!("SimdFloat has 4, 8 or 16 lanes, not {n}"),
        }
    }
}
