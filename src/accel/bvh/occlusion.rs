//! Any-hit traversal for shadow rays, single and packet: the traversal loops of
//! [`traverse_single`](super::traverse_single) and
//! [`traverse_packet`](super::traverse_packet) with a query that stops a ray at
//! the first primitive it hits anywhere in `[t_min, t_max]`.

use glam::Vec3;

use crate::accel::bvh::Bvh;
use crate::accel::bvh::leaf::LeafRef;

use crate::accel::bvh::query::{INTERLEAVED, PacketQuery, RayQuery, lane_bits, lane_groups};
use crate::accel::bvh::ray_box::SlabRay;
use crate::accel::bvh::traverse_packet::trace_packet;
use crate::accel::bvh::traverse_single::{trace, traverse, traverse_interleaved};
use crate::accel::bvh::wide::{ChildRef, TreeWidth};
use crate::accel::stats::Counter;
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::{Simd8, SimdFloat};

/// The any-hit query of one ray.
struct AnyHit<'a> {
    ray: &'a Ray,
    /// A scratch record (kernels need one); its t stays `t_max` until the end.
    hit: Hit,
}

impl RayQuery for AnyHit<'_> {
    const NEAREST_FIRST: bool = false;

    #[inline(always)]
    fn t_max(&self) -> f32 {
        self.ray.t_max
    }

    #[inline(always)]
    fn leaf<N: Simd8, S: Counter>(&mut self, bvh: &Bvh, leaf: LeafRef, stats: &mut S) -> bool {
        bvh.leaves
            .intersect::<N, S>(leaf, self.ray, &mut self.hit, true, stats)
    }
}

/// Whether anything lies on `ray` within `[t_min, t_max]`, with the
/// instruction set's 8-lane type `N`.
#[inline(always)]
pub fn occluded<N: Simd8, S: Counter>(bvh: &Bvh, ray: &Ray, stats: &mut S) -> bool {
    let mut query = AnyHit {
        ray,
        hit: Hit::none(ray),
    };
    trace::<N, _, S>(bvh, ray, &mut query, stats)
}

/// The any-hit query of a packet: occluded lanes leave the packet.
struct AnyHitPacket<F: SimdFloat> {
    /// The rays, whose `active` mask is set to the lanes taking part at each leaf.
    rays: RayPacket<F>,
    /// Scratch records for the kernels.
    hits: HitPacket<F>,
    /// The lanes not yet found occluded.
    pending: F,
}

impl<F: SimdFloat> PacketQuery<F> for AnyHitPacket<F> {
    const NEAREST_FIRST: bool = false;

    #[inline(always)]
    fn t_max(&self) -> F {
        self.rays.t_max
    }

    #[inline(always)]
    fn live(&self) -> F {
        self.pending
    }

    #[inline(always)]
    fn leaf<S: Counter>(&mut self, bvh: &Bvh, leaf: LeafRef, mask: F, stats: &mut S) {
        let active = mask & self.pending;
        let bits = active.bitmask();
        if leaf.tested_lane_by_lane(bits.count_ones()) {
            // Each lane's own single-ray query, as in `finish_lanes`.
            for lane in lane_bits(bits) {
                stats.lane(lane);
                let ray = self.rays.ray(lane);
                let mut query = AnyHit {
                    ray: &ray,
                    hit: Hit::none(&ray),
                };
                if query.leaf::<F::Lanes8, S>(bvh, leaf.clone(), stats) {
                    self.pending = self.pending.and_not(F::mask_from_bits(1 << lane));
                }
            }
            return;
        }
        self.rays.active = active;
        for prim in bvh.leaves.items(leaf) {
            if self.rays.active.none() {
                break;
            }
            stats.packet_prim(self.rays.active);
            bvh.leaves.intersect_packet(prim, &self.rays, &mut self.hits);
            let hit = self.hits.hit_mask();
            self.pending = self.pending.and_not(hit);
            self.rays.active = self.rays.active.and_not(hit);
        }
    }

    #[inline(always)]
    fn finish_lanes<W: TreeWidth, S: Counter>(
        &mut self,
        bvh: &Bvh,
        lanes: u32,
        start: ChildRef,
        interleaved: bool,
        stats: &mut S,
    ) {
        if !interleaved {
            for lane in lane_bits(lanes) {
                stats.lane(lane);
                let ray = self.rays.ray(lane);
                let mut query = AnyHit {
                    ray: &ray,
                    hit: Hit::none(&ray),
                };
                if traverse::<F::Lanes8, W, _, S>(bvh, start, &SlabRay::new(&ray), &mut query, stats) {
                    self.pending = self.pending.and_not(F::mask_from_bits(1 << lane));
                }
            }
            return;
        }
        for (group, count) in lane_groups(lanes) {
            // (Loops, not closures: SIMD code must inline into the entry point.)
            let mut rays = [Ray::unbounded(Vec3::ZERO, Vec3::ZERO); INTERLEAVED];
            for k in 0..count {
                rays[k] = self.rays.ray(group[k]);
            }
            let mut walks: [(usize, SlabRay, AnyHit); INTERLEAVED] = std::array::from_fn(|k| {
                let ray = &rays[k];
                let query = AnyHit {
                    ray,
                    hit: Hit::none(ray),
                };
                (group[k], SlabRay::new(ray), query)
            });
            let occluded = traverse_interleaved::<F::Lanes8, W, _, S>(bvh, start, &mut walks[..count], stats);
            let bits = group[..count]
                .iter()
                .enumerate()
                .fold(0, |bits, (k, lane)| bits | ((occluded >> k & 1) << lane));
            self.pending = self.pending.and_not(F::mask_from_bits(bits));
        }
    }
}

/// The mask of active lanes of `rays` on which something lies within `[t_min, t_max]`.
#[inline(always)]
pub fn occluded_packet<F: SimdFloat, S: Counter>(bvh: &Bvh, rays: &RayPacket<F>, stats: &mut S) -> F {
    stats.rays(u64::from(rays.active.bitmask().count_ones()));
    stats.packet();
    let mut query = AnyHitPacket {
        rays: *rays,
        hits: HitPacket::none(rays),
        pending: rays.active,
    };
    trace_packet(bvh, rays, &mut query, stats);
    rays.active.and_not(query.pending)
}
