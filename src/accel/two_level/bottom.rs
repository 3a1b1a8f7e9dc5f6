//! What an instance leads to: a bottom-level structure whose single-ray walk
//! can be compiled into the top level's instruction-set entry point, with
//! the lane types chosen there (a ray meeting twenty instances picks its
//! instruction set once, not twenty-one times). Packets entering an instance
//! go through the structure's own entry point ([`Accel`]): a packet's work
//! there dwarfs the call, and one copy of the packet walks per level is what
//! keeps the build time down.

use crate::accel::bvh::{occlusion, traverse_single};
use crate::accel::stats::Counter;
use crate::accel::{Accel, BruteForce, Bvh};
use crate::ray::{Hit, Ray};
use crate::simd::Simd8;

/// A structure a [`TwoLevel`](super::TwoLevel) holds per mesh, its single
/// rays queried with the top level's 8-lane type `N`.
pub trait BottomLevel: Accel {
    /// The nearest hit of `ray`, written into `hit` (whatever it held).
    fn intersect_into_on<N: Simd8, S: Counter>(&self, ray: &Ray, hit: &mut Hit, stats: &mut S);
    /// Whether anything lies on `ray` within `[t_min, t_max]`.
    fn occluded_on<N: Simd8, S: Counter>(&self, ray: &Ray, stats: &mut S) -> bool;
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
}

/// The reference: every primitive tested, whatever the lane types.
impl BottomLevel for BruteForce<'_> {
    fn intersect_into_on<N: Simd8, S: Counter>(&self, ray: &Ray, hit: &mut Hit, stats: &mut S) {
        *hit = self.intersect_counted(ray, stats);
    }

    fn occluded_on<N: Simd8, S: Counter>(&self, ray: &Ray, stats: &mut S) -> bool {
        self.occluded_counted(ray, stats)
    }
}
