//! Where a BVH query picks its instruction set: each query is a
//! [`LevelTask`], run by [`Isa::run`](crate::simd::Isa::run) on the level of [`Bvh::isa`], so the
//! traversal below it is compiled once per level with that level's lane types
//! (Embree likewise compiles its kernels per ISA and picks them at run time).
//! Everything a task calls is `#[inline(always)]`, so it is compiled into the
//! level's entry point.
//!
//! Packets come and go in the caller's lane type (the `wide` types) and are
//! converted to the level's type of the same width on the way in and out, bit
//! for bit. Every level computes the same operations in the same order (no
//! fused multiply-adds), so every level gives the same hits.

use crate::accel::bvh::{Bvh, occlusion, traverse_packet, traverse_single};
use crate::accel::stats::Counter;
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::isa::{Level, LevelTask};
use crate::simd::{Simd8, SimdFloat};

/// Run `task` on the level of `bvh`.
#[inline(always)]
fn on_level<T: LevelTask>(bvh: &Bvh, task: T) -> T::Output {
    // SAFETY: a Bvh's level is one this CPU runs (`Bvh::set_isa` and
    // `Isa::default_level` check it).
    unsafe { bvh.isa().run(task) }
}

/// The nearest hit of `ray`.
#[inline(always)]
pub fn intersect<S: Counter>(bvh: &Bvh, ray: &Ray, stats: &mut S) -> Hit {
    struct Task<'a, S>(&'a Bvh, &'a Ray, &'a mut S);
    impl<S: Counter> LevelTask for Task<'_, S> {
        type Output = Hit;
        #[inline(always)]
        fn run<L: Level>(self) -> Hit {
            traverse_single::intersect::<L::F8, S>(self.0, self.1, self.2)
        }
    }
    on_level(bvh, Task(bvh, ray, stats))
}

/// Whether anything lies on `ray` within `[t_min, t_max]`.
#[inline(always)]
pub fn occluded<S: Counter>(bvh: &Bvh, ray: &Ray, stats: &mut S) -> bool {
    struct Task<'a, S>(&'a Bvh, &'a Ray, &'a mut S);
    impl<S: Counter> LevelTask for Task<'_, S> {
        type Output = bool;
        #[inline(always)]
        fn run<L: Level>(self) -> bool {
            occlusion::occluded::<L::F8, S>(self.0, self.1, self.2)
        }
    }
    on_level(bvh, Task(bvh, ray, stats))
}

/// [`Accel::intersect_each_counted`](crate::accel::Accel::intersect_each_counted):
/// the rays one by one, all in one entry of the level's code.
#[inline(always)]
pub fn intersect_each<S: Counter>(bvh: &Bvh, rays: &[Ray], active: u32, hits: &mut [Hit], stats: &mut S) {
    struct Task<'a, S>(&'a Bvh, &'a [Ray], u32, &'a mut [Hit], &'a mut S);
    impl<S: Counter> LevelTask for Task<'_, S> {
        type Output = ();
        #[inline(always)]
        fn run<L: Level>(self) {
            let Task(bvh, rays, active, hits, stats) = self;
            each_intersect::<L::F8, S>(bvh, rays, active, hits, stats);
        }
    }
    on_level(bvh, Task(bvh, rays, active, hits, stats))
}

/// [`Accel::occluded_each_counted`](crate::accel::Accel::occluded_each_counted).
#[inline(always)]
pub fn occluded_each<S: Counter>(bvh: &Bvh, rays: &[Ray], active: u32, stats: &mut S) -> u32 {
    struct Task<'a, S>(&'a Bvh, &'a [Ray], u32, &'a mut S);
    impl<S: Counter> LevelTask for Task<'_, S> {
        type Output = u32;
        #[inline(always)]
        fn run<L: Level>(self) -> u32 {
            let Task(bvh, rays, active, stats) = self;
            let mut blocked = 0;
            for (i, ray) in rays.iter().enumerate() {
                if active >> i & 1 == 1 {
                    stats.lane(i);
                    blocked |= u32::from(occlusion::occluded::<L::F8, S>(bvh, ray, stats)) << i;
                }
            }
            blocked
        }
    }
    on_level(bvh, Task(bvh, rays, active, stats))
}

/// The loop of [`intersect_each`].
#[inline(always)]
fn each_intersect<N: Simd8, S: Counter>(
    bvh: &Bvh,
    rays: &[Ray],
    active: u32,
    hits: &mut [Hit],
    stats: &mut S,
) {
    for (i, (ray, hit)) in rays.iter().zip(hits).enumerate() {
        if active >> i & 1 == 1 {
            stats.lane(i);
            traverse_single::intersect_into::<N, S>(bvh, ray, hit, stats);
        }
    }
}

/// The nearest hits of the active lanes of `rays`.
#[inline(always)]
pub fn intersect_packet<F: SimdFloat, S: Counter>(
    bvh: &Bvh,
    rays: &RayPacket<F>,
    stats: &mut S,
) -> HitPacket<F> {
    struct Task<'a, F: SimdFloat, S>(&'a Bvh, &'a RayPacket<F>, &'a mut S);
    impl<F: SimdFloat, S: Counter> LevelTask for Task<'_, F, S> {
        type Output = HitPacket<F>;
        #[inline(always)]
        fn run<L: Level>(self) -> HitPacket<F> {
            let Task(bvh, rays, stats) = self;
            match F::LANES {
                4 => traverse_packet::intersect_packet(bvh, &rays.convert::<L::F4>(), stats).convert(),
                8 => traverse_packet::intersect_packet(bvh, &rays.convert::<L::F8>(), stats).convert(),
                16 => traverse_packet::intersect_packet(bvh, &rays.convert::<L::F16>(), stats).convert(),
                _ => traverse_packet::intersect_packet(bvh, rays, stats),
            }
        }
    }
    on_level(bvh, Task(bvh, rays, stats))
}

/// The mask of active lanes of `rays` on which something lies within `[t_min, t_max]`.
#[inline(always)]
pub fn occluded_packet<F: SimdFloat, S: Counter>(bvh: &Bvh, rays: &RayPacket<F>, stats: &mut S) -> F {
    struct Task<'a, F: SimdFloat, S>(&'a Bvh, &'a RayPacket<F>, &'a mut S);
    impl<F: SimdFloat, S: Counter> LevelTask for Task<'_, F, S> {
        type Output = F;
        #[inline(always)]
        fn run<L: Level>(self) -> F {
            let Task(bvh, rays, stats) = self;
            match F::LANES {
                4 => occlusion::occluded_packet(bvh, &rays.convert::<L::F4>(), stats).convert(),
                8 => occlusion::occluded_packet(bvh, &rays.convert::<L::F8>(), stats).convert(),
                16 => occlusion::occluded_packet(bvh, &rays.convert::<L::F16>(), stats).convert(),
                _ => occlusion::occluded_packet(bvh, rays, stats),
            }
        }
    }
    on_level(bvh, Task(bvh, rays, stats))
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
    struct Task<'a, S>(&'a Bvh, &'a [Ray], u32, &'a mut S);
    impl<S: Counter> Task<'_, S> {
        #[inline(always)]
        fn trace<G: SimdFloat>(self) -> HitPacket<G> {
            let Task(bvh, rays, mask, stats) = self;
            traverse_packet::intersect_packet(bvh, &RayPacket::<G>::from_rays_masked(rays, mask), stats)
        }
    }
    struct Width<'a, F, S>(Task<'a, S>, std::marker::PhantomData<F>);
    impl<F: SimdFloat, S: Counter> LevelTask for Width<'_, F, S> {
        type Output = HitPacket<F>;
        #[inline(always)]
        fn run<L: Level>(self) -> HitPacket<F> {
            match F::LANES {
                4 => self.0.trace::<L::F4>().convert(),
                8 => self.0.trace::<L::F8>().convert(),
                16 => self.0.trace::<L::F16>().convert(),
                _ => self.0.trace::<F>(),
            }
        }
    }
    on_level(
        bvh,
        Width::<F, S>(Task(bvh, rays, mask, stats), std::marker::PhantomData),
    )
}

/// [`Accel::occluded_rays_counted`](crate::accel::Accel::occluded_rays_counted),
/// as [`intersect_rays`].
#[inline(always)]
pub fn occluded_rays<F: SimdFloat, S: Counter>(bvh: &Bvh, rays: &[Ray], mask: u32, stats: &mut S) -> F {
    struct Task<'a, S>(&'a Bvh, &'a [Ray], u32, &'a mut S);
    impl<S: Counter> Task<'_, S> {
        #[inline(always)]
        fn trace<G: SimdFloat>(self) -> G {
            let Task(bvh, rays, mask, stats) = self;
            occlusion::occluded_packet(bvh, &RayPacket::<G>::from_rays_masked(rays, mask), stats)
        }
    }
    struct Width<'a, F, S>(Task<'a, S>, std::marker::PhantomData<F>);
    impl<F: SimdFloat, S: Counter> LevelTask for Width<'_, F, S> {
        type Output = F;
        #[inline(always)]
        fn run<L: Level>(self) -> F {
            match F::LANES {
                4 => self.0.trace::<L::F4>().convert(),
                8 => self.0.trace::<L::F8>().convert(),
                16 => self.0.trace::<L::F16>().convert(),
                _ => self.0.trace::<F>(),
            }
        }
    }
    on_level(
        bvh,
        Width::<F, S>(Task(bvh, rays, mask, stats), std::marker::PhantomData),
    )
}
