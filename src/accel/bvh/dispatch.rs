//! Where a BVH query picks its instruction set: each query is a
//! [`LevelTask`](crate::simd::isa::LevelTask), run by [`Isa::run`](crate::simd::Isa::run) on the level of [`Bvh::isa`], so the
//! traversal below it is compiled once per level with that level's lane types
//! (Embree likewise compiles its kernels per ISA and picks them at run time).
//! Everything a task calls is `#[inline(always)]`, so it is compiled into the
//! level's entry point.
//!
//! Packets come and go in the caller's lane type (the `wide` types) and are
//! converted to the level's type of the same width on the way in and out, bit
//! for bit. Every level computes the same operations in the same order (no
//! fused multiply-adds), so every level gives the same hits.

use crate::accel::bvh::query::Scope;
use crate::accel::bvh::tree::Bvh;
use crate::accel::bvh::{occlusion, traverse_packet, traverse_single};
use crate::accel::stats::Counter;
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::SimdFloat;
use crate::simd::isa::{Level, level_task};

/// The nearest hit of `ray`.
#[inline(always)]
pub fn intersect<S: Counter>(bvh: &Bvh, ray: &Ray, stats: &mut S) -> Hit {
    bvh.on_level(single_nearest::Task::new(bvh, ray, stats))
}

/// Whether anything lies on `ray` within `[t_min, t_max]`.
#[inline(always)]
pub fn occluded<S: Counter>(bvh: &Bvh, ray: &Ray, stats: &mut S) -> bool {
    bvh.on_level(single_blocked::Task::new(bvh, ray, stats))
}

/// [`Accel::intersect_each_counted`](crate::accel::Accel::intersect_each_counted):
/// the rays one by one, all in one entry of the level's code.
#[inline(always)]
pub fn intersect_each<S: Counter>(bvh: &Bvh, rays: &[Ray], active: u32, hits: &mut [Hit], stats: &mut S) {
    bvh.on_level(each_nearest::Task::new(bvh, rays, active, hits, stats))
}

/// [`Accel::occluded_each_counted`](crate::accel::Accel::occluded_each_counted).
#[inline(always)]
pub fn occluded_each<S: Counter>(bvh: &Bvh, rays: &[Ray], active: u32, stats: &mut S) -> u32 {
    bvh.on_level(each_blocked::Task::new(bvh, rays, active, stats))
}

/// `$trace::<G>(args…)` with `G` the lane type of level `$L` as wide as `$F`,
/// its result converted back to `$F`'s lanes, bit for bit: the width switch
/// of every packet entry point. (A macro, since the lane type is chosen per
/// width at compile time and a closure cannot be generic over it.)
macro_rules! at_width {
    ($F:ty, $L:ty, $trace:ident($($arg:expr),*)) => {
        match <$F as SimdFloat>::LANES {
            4 => $trace::<<$L as Level>::F4>($($arg),*).convert(),
            8 => $trace::<<$L as Level>::F8>($($arg),*).convert(),
            16 => $trace::<<$L as Level>::F16>($($arg),*).convert(),
            _ => $trace::<$F>($($arg),*),
        }
    };
}
pub(crate) use at_width;

/// The nearest hits of the active lanes of `rays`, in the lanes `G`.
#[inline(always)]
fn nearest_in<G: SimdFloat>(
    bvh: &Bvh,
    rays: &RayPacket<impl SimdFloat>,
    stats: &mut impl Counter,
) -> HitPacket<G> {
    traverse_packet::intersect_packet(bvh, &rays.convert::<G>(), stats)
}

/// The occluded lanes of `rays` in `bvh`, a tree of `scope`, in the lanes `G`.
#[inline(always)]
fn occluded_in<G: SimdFloat>(
    bvh: &Bvh,
    rays: &RayPacket<impl SimdFloat>,
    scope: Scope,
    stats: &mut impl Counter,
) -> G {
    occlusion::occluded_packet(bvh, &rays.convert::<G>(), scope, stats)
}

/// The nearest hits of the rays of `rays` in `mask`, packed in the lanes `G`.
#[inline(always)]
fn nearest_of_rays<G: SimdFloat>(
    bvh: &Bvh,
    rays: &[Ray],
    mask: u32,
    stats: &mut impl Counter,
) -> HitPacket<G> {
    traverse_packet::intersect_packet(bvh, &RayPacket::<G>::from_rays_masked(rays, mask), stats)
}

/// The occluded rays of `rays` in `mask`, packed in the lanes `G`.
#[inline(always)]
fn occluded_of_rays<G: SimdFloat>(bvh: &Bvh, rays: &[Ray], mask: u32, stats: &mut impl Counter) -> G {
    occlusion::occluded_packet(
        bvh,
        &RayPacket::<G>::from_rays_masked(rays, mask),
        Scope::World,
        stats,
    )
}

/// The nearest hits of the active lanes of `rays`.
#[inline(always)]
pub fn intersect_packet<F: SimdFloat, S: Counter>(
    bvh: &Bvh,
    rays: &RayPacket<F>,
    stats: &mut S,
) -> HitPacket<F> {
    bvh.on_level(packet_nearest::Task::new(bvh, rays, stats))
}

/// The mask of active lanes of `rays` on which something lies within
/// `[t_min, t_max]`, in `bvh`, a tree of `scope`.
#[inline(always)]
pub fn occluded_packet<F: SimdFloat, S: Counter>(
    bvh: &Bvh,
    rays: &RayPacket<F>,
    scope: Scope,
    stats: &mut S,
) -> F {
    bvh.on_level(packet_blocked::Task::new(bvh, rays, scope, stats))
}

/// [`Accel::intersect_rays_counted`](crate::accel::Accel::intersect_rays_counted):
/// the packet is made in the level's lanes, inside its entry point.
#[inline(always)]
pub fn intersect_rays<F: SimdFloat, S: Counter>(
    bvh: &Bvh,
    rays: &[Ray],
    mask: u32,
    stats: &mut S,
) -> HitPacket<F> {
    bvh.on_level(rays_nearest::Task::<F, S>::new(bvh, rays, mask, stats))
}

/// [`Accel::occluded_rays_counted`](crate::accel::Accel::occluded_rays_counted),
/// as [`intersect_rays`].
#[inline(always)]
pub fn occluded_rays<F: SimdFloat, S: Counter>(bvh: &Bvh, rays: &[Ray], mask: u32, stats: &mut S) -> F {
    bvh.on_level(rays_blocked::Task::<F, S>::new(bvh, rays, mask, stats))
}

// Each query's task in a module of its own: the compiler places a task's
// entry points (`simd::isa::EntryPoint`, a blanket impl) in the codegen unit
// of the module that defines the task's type, so these modules are what
// lets the queries' levels compile on several cores at once (all in this
// module, one unit held most of the library's code).

/// [`intersect`]'s task.
mod single_nearest {
    use crate::accel::bvh::dispatch::*;
    level_task!(Task<'a, S: Counter>(bvh: &'a Bvh, ray: &'a Ray, stats: &'a mut S) -> Hit {
        traverse_single::intersect::<L::F8, S>(bvh, ray, stats)
    });
}

/// [`occluded`]'s task.
mod single_blocked {
    use crate::accel::bvh::dispatch::*;
    level_task!(Task<'a, S: Counter>(bvh: &'a Bvh, ray: &'a Ray, stats: &'a mut S) -> bool {
        occlusion::occluded::<L::F8, S>(bvh, ray, stats)
    });
}

/// [`intersect_each`]'s task.
mod each_nearest {
    use crate::accel::bvh::dispatch::*;
    level_task!(Task<'a, S: Counter>(
        bvh: &'a Bvh,
        rays: &'a [Ray],
        active: u32,
        hits: &'a mut [Hit],
        stats: &'a mut S,
    ) -> () {
        for (i, (ray, hit)) in rays.iter().zip(hits).enumerate() {
            if active >> i & 1 == 1 {
                stats.lane(i);
                traverse_single::intersect_into::<L::F8, S>(bvh, ray, hit, stats);
            }
        }
    });
}

/// [`occluded_each`]'s task.
mod each_blocked {
    use crate::accel::bvh::dispatch::*;
    level_task!(Task<'a, S: Counter>(bvh: &'a Bvh, rays: &'a [Ray], active: u32, stats: &'a mut S) -> u32 {
        let mut blocked = 0;
        for (i, ray) in rays.iter().enumerate() {
            if active >> i & 1 == 1 {
                stats.lane(i);
                blocked |= u32::from(occlusion::occluded::<L::F8, S>(bvh, ray, stats)) << i;
            }
        }
        blocked
    });
}

/// [`intersect_packet`]'s task.
mod packet_nearest {
    use crate::accel::bvh::dispatch::*;
    level_task!(Task<'a, F: SimdFloat, S: Counter>(
        bvh: &'a Bvh,
        rays: &'a RayPacket<F>,
        stats: &'a mut S,
    ) -> HitPacket<F> {
        at_width!(F, L, nearest_in(bvh, rays, stats))
    });
}

/// [`occluded_packet`]'s task.
mod packet_blocked {
    use crate::accel::bvh::dispatch::*;
    level_task!(Task<'a, F: SimdFloat, S: Counter>(
        bvh: &'a Bvh,
        rays: &'a RayPacket<F>,
        scope: Scope,
        stats: &'a mut S,
    ) -> F {
        at_width!(F, L, occluded_in(bvh, rays, scope, stats))
    });
}

/// [`intersect_rays`]'s task.
mod rays_nearest {
    use crate::accel::bvh::dispatch::*;
    level_task!(Task<'a, F: SimdFloat, S: Counter>(
        bvh: &'a Bvh,
        rays: &'a [Ray],
        mask: u32,
        stats: &'a mut S,
    ) -> HitPacket<F> {
        at_width!(F, L, nearest_of_rays(bvh, rays, mask, stats))
    });
}

/// [`occluded_rays`]'s task.
mod rays_blocked {
    use crate::accel::bvh::dispatch::*;
    level_task!(Task<'a, F: SimdFloat, S: Counter>(bvh: &'a Bvh, rays: &'a [Ray], mask: u32, stats: &'a mut S) -> F {
        at_width!(F, L, occluded_of_rays(bvh, rays, mask, stats))
    });
}
