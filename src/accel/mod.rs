//! Acceleration structures behind one small API, [`Accel`]: nearest hit and
//! any hit (occlusion), for single rays and for packets.
//!
//! [`BruteForce`] is the lecture's loop (every ray against every object) and the
//! reference every other structure is checked against; [`Bvh`] is the SAH
//! bounding volume hierarchy. [`AccelKind`] picks one (`--accel none|bvh`), and
//! [`CountedAccel`] and [`AccelWithStats`] run the same queries counting their cost.

pub mod brute_force;
pub mod bvh;
pub mod kind;
pub mod stats;

pub use brute_force::BruteForce;
pub use bvh::Bvh;
pub use kind::{AccelKind, AnyAccel};
pub use stats::{AccelWithStats, CountedAccel, TraversalStats};

use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::SimdFloat;

/// Ray queries over a set of primitives, indexed by their position in the scene.
pub trait Accel: Sync {
    /// The nearest hit of `ray` (the record's `ng` is not filled in).
    fn intersect(&self, ray: &Ray) -> Hit;

    /// The nearest hit of every active lane.
    fn intersect_packet<F: SimdFloat>(&self, rays: &RayPacket<F>) -> HitPacket<F>;

    /// Whether anything lies on `ray` in `[t_min, t_max]` (shadow rays).
    fn occluded(&self, ray: &Ray) -> bool;

    /// The mask of active lanes on which something lies in `[t_min, t_max]`.
    fn occluded_packet<F: SimdFloat>(&self, rays: &RayPacket<F>) -> F;
}
