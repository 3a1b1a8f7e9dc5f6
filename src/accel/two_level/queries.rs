//! The top tree's queries: where a walk of the top tree meets a leaf, the
//! rays are brought into each of its instances and traced through the mesh's
//! structure. The top tree is a [`Bvh`] with no primitives of its own
//! ([`Bvh::over_boxes`]), so its single-ray, packet and hybrid traversals are
//! the ones every mesh gets, and its leaves come here.

use crate::accel::bvh::lanes::leaf_lane_by_lane;
use crate::accel::bvh::leaf::LeafRef;
use crate::accel::bvh::query::{LaneQueries, PacketQuery, RayQuery, Scope};
use crate::accel::bvh::tree::Bvh;
use crate::accel::stats::Counter;
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::{Simd8, SimdFloat, SimdU32};

use super::bottom::{BottomLevel, blocked_packet, nearest_packet};
use super::placed::Placed;

/// The instances that the top tree's leaves name (ranges of `placed`), and
/// the meshes' structures they place. 32 bytes.
pub(super) struct Instances<'a, B> {
    pub placed: &'a [Placed],
    pub meshes: &'a [B],
}

// Two references, whatever `B` is (a derive would ask `B: Copy`).
impl<B> Clone for Instances<'_, B> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<B> Copy for Instances<'_, B> {}

impl<B: BottomLevel> Instances<'_, B> {
    /// The instances of the top tree's leaf `leaf`.
    #[inline(always)]
    fn of(&self, leaf: LeafRef) -> &[Placed] {
        match leaf {
            LeafRef::Prims(range) => &self.placed[range],
            _ => unreachable!("the top tree's leaves are ranges of instances"),
        }
    }

    /// Trace `ray` through instance `p`, keeping the nearest of it and `hit`:
    /// with the mesh's walk compiled in here (`INLINE`), or through its own entry point.
    #[inline(always)]
    fn intersect_instance<N: Simd8, S: Counter, const INLINE: bool>(
        &self,
        p: &Placed,
        ray: &Ray,
        hit: &mut Hit,
        stats: &mut S,
    ) {
        let Some((local, s)) = p.object_ray(ray, hit.t) else {
            return;
        };
        let mesh = &self.meshes[p.mesh as usize];
        let mut found = Hit::none(&local);
        if INLINE {
            mesh.intersect_into_on::<N, S>(&local, &mut found, stats);
        } else {
            found = mesh.intersect_counted(&local, stats);
        }
        if !found.is_hit() {
            return;
        }
        let (t, id) = (found.t / s, p.first_id + found.prim);
        if hit.accepts(t, ray.t_min, id) {
            *hit = Hit { t, prim: id, ..found };
        }
    }

    /// Whether instance `p` blocks `ray` (`INLINE` as [`Self::intersect_instance`]).
    #[inline(always)]
    fn occludes<N: Simd8, S: Counter, const INLINE: bool>(
        &self,
        p: &Placed,
        ray: &Ray,
        stats: &mut S,
    ) -> bool {
        let Some((local, _)) = p.object_ray(ray, ray.t_max) else {
            return false;
        };
        let mesh = &self.meshes[p.mesh as usize];
        if INLINE {
            mesh.occluded_on::<N, S>(&local, stats)
        } else {
            mesh.occluded_counted(&local, stats)
        }
    }

    /// Trace the lanes `lanes` of `rays` through instance `p` as one packet,
    /// keeping the nearest of each lane's hit and `hits`.
    #[inline(always)]
    fn intersect_instance_packet<F: SimdFloat, S: Counter>(
        &self,
        p: &Placed,
        rays: &RayPacket<F>,
        lanes: F,
        hits: &mut HitPacket<F>,
        stats: &mut S,
    ) {
        let (local, s) = p.object_packet(rays, lanes, hits.t);
        let found = nearest_packet(&self.meshes[p.mesh as usize], &local, stats);
        let candidates = found.hit_mask() & local.active;
        if candidates.none() {
            return;
        }
        // Settle every lane at once by the tie rule ([`Hit::accepts`]): within
        // `[t_min, hit t]` and finite, and on an equal t the lower scene id.
        let t = found.t / s;
        let mut ids = found.prim.to_array();
        for id in ids.as_mut() {
            *id = id.wrapping_add(p.first_id);
        }
        let ids = F::U32::from_array(ids);
        let nearer = t.lt(hits.t) | (t.eq(hits.t) & ids.lt(hits.prim));
        let accept = candidates & t.ge(rays.t_min) & t.lt(F::splat(f32::INFINITY)) & nearer;
        if accept.none() {
            return;
        }
        hits.t = accept.select(t, hits.t);
        hits.prim = F::U32::select(accept, ids, hits.prim);
        hits.u = accept.select(found.u, hits.u);
        hits.v = accept.select(found.v, hits.v);
        hits.ng.x = accept.select(found.ng.x, hits.ng.x);
        hits.ng.y = accept.select(found.ng.y, hits.ng.y);
        hits.ng.z = accept.select(found.ng.z, hits.ng.z);
    }
}

/// The nearest-hit query of one ray through the instances, the meshes'
/// walks compiled in (`INLINE`: a single ray's query) or called (a packet's
/// lane, whose walks would otherwise be compiled in at every place a packet
/// hands lanes over).
pub(super) struct InstanceNearest<'a, B, const INLINE: bool> {
    pub instances: Instances<'a, B>,
    pub ray: &'a Ray,
    pub hit: &'a mut Hit,
}

impl<B: BottomLevel, const INLINE: bool> RayQuery for InstanceNearest<'_, B, INLINE> {
    #[inline(always)]
    fn t_max(&self) -> f32 {
        self.hit.t
    }

    #[inline(always)]
    fn leaf<N: Simd8, S: Counter>(&mut self, _: &Bvh, leaf: LeafRef, stats: &mut S) -> bool {
        for p in self.instances.of(leaf) {
            self.instances
                .intersect_instance::<N, S, INLINE>(p, self.ray, self.hit, stats);
        }
        false
    }
}

/// The any-hit query of one ray through the instances (`INLINE` as
/// [`InstanceNearest`]'s).
pub(super) struct InstanceAnyHit<'a, B, const INLINE: bool> {
    pub instances: Instances<'a, B>,
    pub ray: &'a Ray,
}

impl<B: BottomLevel, const INLINE: bool> RayQuery for InstanceAnyHit<'_, B, INLINE> {
    const NEAREST_FIRST: bool = false;

    #[inline(always)]
    fn t_max(&self) -> f32 {
        self.ray.t_max
    }

    #[inline(always)]
    fn leaf<N: Simd8, S: Counter>(&mut self, _: &Bvh, leaf: LeafRef, stats: &mut S) -> bool {
        for p in self.instances.of(leaf) {
            if self.instances.occludes::<N, S, INLINE>(p, self.ray, stats) {
                return true;
            }
        }
        false
    }
}

/// The nearest-hit query of a packet through the instances: lanes that meet
/// an instance together enter it as one packet.
pub(super) struct InstanceNearestPacket<'a, B, F: SimdFloat> {
    pub instances: Instances<'a, B>,
    pub rays: RayPacket<F>,
    pub hits: &'a mut HitPacket<F>,
}

impl<B: BottomLevel, F: SimdFloat> LaneQueries<F> for InstanceNearestPacket<'_, B, F> {
    type Lane<'a>
        = InstanceNearest<'a, B, false>
    where
        Self: 'a;

    #[inline(always)]
    fn rays(&self) -> &RayPacket<F> {
        &self.rays
    }

    #[inline(always)]
    fn start(&self, lane: usize, _: &Ray) -> Hit {
        self.hits.hit(lane)
    }

    #[inline(always)]
    fn query<'a>(&'a self, ray: &'a Ray, hit: &'a mut Hit) -> InstanceNearest<'a, B, false> {
        InstanceNearest {
            instances: self.instances,
            ray,
            hit,
        }
    }

    #[inline(always)]
    fn end(&mut self, lane: usize, hit: &Hit, _: bool) {
        self.hits.set_hit(lane, hit);
    }
}

impl<B: BottomLevel, F: SimdFloat> PacketQuery<F> for InstanceNearestPacket<'_, B, F> {
    #[inline(always)]
    fn t_max(&self) -> F {
        self.hits.t
    }

    #[inline(always)]
    fn live(&self) -> F {
        self.rays.active
    }

    #[inline(always)]
    fn leaf<S: Counter>(&mut self, top: &Bvh, leaf: LeafRef, mask: F, stats: &mut S) {
        let bits = mask.bitmask();
        if bits.count_ones() == 1 {
            // One lane: its own single-ray query, no packet set-up per instance.
            leaf_lane_by_lane(self, top, leaf, bits, stats);
            return;
        }
        for p in self.instances.of(leaf) {
            self.instances
                .intersect_instance_packet(p, &self.rays, mask, self.hits, stats);
        }
    }
}

/// The any-hit query of a packet through the instances: blocked lanes leave it.
pub(super) struct InstanceAnyHitPacket<'a, B, F: SimdFloat> {
    pub instances: Instances<'a, B>,
    pub rays: RayPacket<F>,
    /// The lanes not yet found blocked.
    pub pending: F,
}

impl<B: BottomLevel, F: SimdFloat> LaneQueries<F> for InstanceAnyHitPacket<'_, B, F> {
    type Lane<'a>
        = InstanceAnyHit<'a, B, false>
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
    fn query<'a>(&'a self, ray: &'a Ray, _: &'a mut Hit) -> InstanceAnyHit<'a, B, false> {
        InstanceAnyHit {
            instances: self.instances,
            ray,
        }
    }

    #[inline(always)]
    fn end(&mut self, lane: usize, _: &Hit, blocked: bool) {
        if blocked {
            self.pending = self.pending.and_not(F::mask_from_bits(1 << lane));
        }
    }
}

impl<B: BottomLevel, F: SimdFloat> PacketQuery<F> for InstanceAnyHitPacket<'_, B, F> {
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
    fn leaf<S: Counter>(&mut self, top: &Bvh, leaf: LeafRef, mask: F, stats: &mut S) {
        let bits = (mask & self.pending).bitmask();
        if bits.count_ones() == 1 {
            leaf_lane_by_lane(self, top, leaf, bits, stats);
            return;
        }
        for p in self.instances.of(leaf) {
            let open = mask & self.pending;
            if open.none() {
                break;
            }
            let (local, _) = p.object_packet(&self.rays, open, self.rays.t_max);
            let blocked = blocked_packet(
                &self.instances.meshes[p.mesh as usize],
                &local,
                Scope::Instance,
                stats,
            );
            self.pending = self.pending.and_not(blocked & local.active);
        }
    }
}
