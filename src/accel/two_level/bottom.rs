//! What an instance leads to: a bottom-level structure whose single-ray walk
//! can be compiled into the top level's instruction-set entry point, with
//! the lane types chosen there (a ray meeting twenty instances picks its
//! instruction set once, not twenty-one times). Packets entering an instance
//! go through the structure's own entry point ([`Accel`]): a packet's work
//! there dwarfs the call, and one copy of the packet walks per level is what
//! keeps the build time down. They enter it in the portable lanes of their
//! width, the lanes every other caller passes: in the calling level's own
//! lanes, each structure's entry points would be compiled again for every
//! level's types, a level's intrinsics inside another level's entry point
//! (tests/cli/inlining.rs).

use crate::accel::bvh::dispatch::{self, at_width};
use crate::accel::bvh::query::Scope;
use crate::accel::bvh::{occlusion, traverse_single};
use crate::accel::stats::Counter;
use crate::accel::{Accel, BruteForce, Bvh};
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::isa::{Level, PortableLanes};
use crate::simd::{Simd8, SimdFloat};

/// A structure a [`TwoLevel`](super::TwoLevel) holds per mesh, its single
/// rays queried with the top level's 8-lane type `N`.
pub trait BottomLevel: Accel {
    /// The nearest hit of `ray`, written into `hit` (whatever it held).
    fn intersect_into_on<N: Simd8, S: Counter>(&self, ray: &Ray, hit: &mut Hit, stats: &mut S);
    /// Whether anything lies on `ray` within `[t_min, t_max]`.
    fn occluded_on<N: Simd8, S: Counter>(&self, ray: &Ray, stats: &mut S) -> bool;
    /// [`Accel::occluded_packet_counted`] in this structure as a tree of
    /// `scope` (the world's own primitives, or an instance's mesh).
    fn occluded_packet_in<F: SimdFloat, S: Counter>(
        &self,
        rays: &RayPacket<F>,
        scope: Scope,
        stats: &mut S,
    ) -> F;
}

/// raypack's BVH: its traversals, compiled into the caller's entry point.
impl BottomLevel for Bvh {
    #[inline(always)]
    fn intersect_into_on<N: Simd8, S: Counter>(&self, ray: &Ray, hit: &mut Hit, stats: &mut S) {
        traverse_single::intersect_into::<N, S>(self, ray, hit, stats);
    }

    #[inline(always)]
    fn occluded_on<N: Simd8, S: Counter>(&self, ray: &Ray, stats: &mut S) -> bool {
        occlusion::occluded::<N, S>(self, ray, stats)
    }

    #[inline(always)]
    fn occluded_packet_in<F: SimdFloat, S: Counter>(
        &self,
        rays: &RayPacket<F>,
        scope: Scope,
        stats: &mut S,
    ) -> F {
        dispatch::occluded_packet(self, rays, scope, stats)
    }
}

/// The reference: every primitive tested, whatever the lane types.
impl BottomLevel for BruteForce<'_> {
    fn intersect_into_on<N: Simd8, S: Counter>(&self, ray: &Ray, hit: &mut Hit, stats: &mut S) {
        *hit = self.intersect_counted(ray, stats);
    }

    fn occluded_on<N: Simd8, S: Counter>(&self, ray: &Ray, stats: &mut S) -> bool {
        self.occluded_counted(ray, stats)
    }

    fn occluded_packet_in<F: SimdFloat, S: Counter>(
        &self,
        rays: &RayPacket<F>,
        _: Scope,
        stats: &mut S,
    ) -> F {
        self.occluded_packet_counted(rays, stats)
    }
}

/// The nearest hits of `rays`' active lanes in `structure`, through its own
/// entry point in the portable lanes of their width.
#[inline(always)]
pub(super) fn nearest_packet<F: SimdFloat, S: Counter>(
    structure: &impl Accel,
    rays: &RayPacket<F>,
    stats: &mut S,
) -> HitPacket<F> {
    at_width!(F, PortableLanes, nearest_in(structure, rays, stats))
}

/// The blocked lanes of `rays` in `structure`, a tree of `scope`, as
/// [`nearest_packet`] enters it.
#[inline(always)]
pub(super) fn blocked_packet<F: SimdFloat, S: Counter>(
    structure: &impl BottomLevel,
    rays: &RayPacket<F>,
    scope: Scope,
    stats: &mut S,
) -> F {
    at_width!(F, PortableLanes, blocked_in(structure, rays, scope, stats))
}

#[inline(always)]
fn nearest_in<G: SimdFloat>(
    structure: &impl Accel,
    rays: &RayPacket<impl SimdFloat>,
    stats: &mut impl Counter,
) -> HitPacket<G> {
    structure.intersect_packet_counted(&rays.convert::<G>(), stats)
}

#[inline(always)]
fn blocked_in<G: SimdFloat>(
    structure: &impl BottomLevel,
    rays: &RayPacket<impl SimdFloat>,
    scope: Scope,
    stats: &mut impl Counter,
) -> G {
    structure.occluded_packet_in(&rays.convert::<G>(), scope, stats)
}
