//! Any-hit traversal for shadow rays, single and packet: the traversal loops of
//! [`traverse_single`](super::traverse_single) and
//! [`traverse_packet`](super::traverse_packet) with a query that stops a ray at
//! the first primitive it hits anywhere in `[t_min, t_max]`.

use crate::accel::bvh::lanes::leaf_lane_by_lane;
use crate::accel::bvh::leaf::LeafRef;
use crate::accel::bvh::query::{LaneQueries, PacketQuery, RayQuery, Scope};
use crate::accel::bvh::traverse_packet::trace_packet;
use crate::accel::bvh::traverse_single::trace;
use crate::accel::bvh::tree::Bvh;
use crate::accel::stats::Counter;
use crate::geometry::{BlockRay, LazyBlockRay, LeafRay};
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::{Simd8, SimdFloat};

/// The any-hit query of one ray. `R` says when the ray is prepared for the
/// leaves' kernels (see [`Nearest`](super::traverse_single::Nearest)).
pub struct AnyHit<'a, R = LazyBlockRay<'a>> {
    /// The ray, held for the leaves' kernels.
    ray: R,
    /// A scratch record (kernels need one); its t stays `t_max` until the end.
    hit: &'a mut Hit,
}

impl<'a, R: LeafRay<'a>> AnyHit<'a, R> {
    /// The any-hit query of `ray`, with `hit` for the kernels' scratch record.
    #[inline(always)]
    fn new(ray: &'a Ray, hit: &'a mut Hit) -> Self {
        Self {
            ray: R::hold(ray),
            hit,
        }
    }
}

impl<'a, R: LeafRay<'a>> RayQuery for AnyHit<'a, R> {
    const NEAREST_FIRST: bool = false;

    #[inline(always)]
    fn t_max(&self) -> f32 {
        self.ray.ray().t_max
    }

    #[inline(always)]
    fn leaf<N: Simd8, S: Counter>(&mut self, bvh: &Bvh, leaf: LeafRef, stats: &mut S) -> bool {
        bvh.leaves()
            .intersect::<N, S>(leaf, self.ray.get(), self.hit, true, stats)
    }
}

/// Whether anything lies on `ray` within `[t_min, t_max]`, with the
/// instruction set's 8-lane type `N`.
#[inline(always)]
pub fn occluded<N: Simd8, S: Counter>(bvh: &Bvh, ray: &Ray, stats: &mut S) -> bool {
    let mut hit = Hit::none(ray);
    trace::<N, _, S>(bvh, ray, &mut AnyHit::<LazyBlockRay>::new(ray, &mut hit), stats)
}

/// The any-hit query of a packet: occluded lanes leave the packet.
struct AnyHitPacket<F: SimdFloat> {
    /// The rays, whose `active` mask is set to the lanes taking part at each leaf.
    rays: RayPacket<F>,
    /// Scratch records for the kernels.
    hits: HitPacket<F>,
    /// The lanes not yet found occluded.
    pending: F,
    /// Whose tree the packet walks.
    scope: Scope,
}

impl<F: SimdFloat> LaneQueries<F> for AnyHitPacket<F> {
    // A lane is handed over deep in the tree, sure to reach a leaf.
    type Lane<'a>
        = AnyHit<'a, BlockRay<'a>>
    where
        Self: 'a;

    #[inline(always)]
    fn rays(&self) -> &RayPacket<F> {
        &self.rays
    }

    #[inline(always)]
    fn start(&self, _: usize, ray: &Ray) -> Hit {
        Hit::none(ray)
    }

    #[inline(always)]
    fn query<'a>(&'a self, ray: &'a Ray, hit: &'a mut Hit) -> AnyHit<'a, BlockRay<'a>> {
        AnyHit::new(ray, hit)
    }

    #[inline(always)]
    fn end(&mut self, lane: usize, _: &Hit, occluded: bool) {
        if occluded {
            self.pending = self.pending.and_not(F::mask_from_bits(1 << lane));
        }
    }
}

impl<F: SimdFloat> PacketQuery<F> for AnyHitPacket<F> {
    const NEAREST_FIRST: bool = false;

    #[inline(always)]
    fn scope(&self) -> Scope {
        self.scope
    }

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
            leaf_lane_by_lane(self, bvh, leaf, bits, stats);
            return;
        }
        self.rays.active = active;
        for prim in bvh.leaves().items(leaf) {
            if self.rays.active.none() {
                break;
            }
            stats.packet_prim(self.rays.active);
            bvh.leaves().intersect_packet(prim, &self.rays, &mut self.hits);
            let hit = self.hits.hit_mask();
            self.pending = self.pending.and_not(hit);
            self.rays.active = self.rays.active.and_not(hit);
        }
    }
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
    stats.rays(u64::from(rays.active.bitmask().count_ones()));
    stats.packet();
    let mut query = AnyHitPacket {
        rays: *rays,
        hits: HitPacket::none(rays),
        pending: rays.active,
        scope,
    };
    trace_packet(bvh, rays, &mut query, stats);
    rays.active.and_not(query.pending)
}
