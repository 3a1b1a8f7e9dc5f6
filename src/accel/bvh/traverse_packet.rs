//! 8-ray (any width) packet traversal: the packet descends as one while any lane
//! meets a node's box (I. Wald, P. Slusallek, C. Benthin, M. Wagner, "Interactive
//! rendering with coherent ray tracing", Eurographics 2001).
//!
//! - Each node is tested against all lanes with one SIMD slab test; only the lanes
//!   that met the parent take part, each against its own current hit t, which
//!   shrinks lane by lane as hits are found.
//! - Children are visited near first by the packet's majority direction along the
//!   node's split axis; a far child is pushed with its lanes' entry t, and lanes
//!   whose hit has come closer than that are dropped when it is popped.
//! - An incoherent packet ([`RayPacket::is_coherent`]) walks the wide tree instead, as a
//!   packet while enough lanes share a subtree and as single rays below
//!   ([`traverse_hybrid`]), faster than tracing its lanes as single rays from
//!   the root, which was faster than dragging sparse packets down the binary
//!   tree. Coherent nearest-hit packets never fall back (see [`RayPacket::is_coherent`]).
//! - A coherent any-hit packet (shadow rays from a pixel block to one light)
//!   in the world's tree ([`Scope::World`]) walks the binary tree too where
//!   the tree is small ([`BINARY_ANY_HIT_PRIMITIVES`]), and the wide tree as
//!   one packet to the leaves where it is large. In an instance's mesh, and for
//!   incoherent any-hit packets, it takes the hybrid walk (figures:
//!   `docs/measurements.md`, "Constants").
//! - A packet of rays from all over the scene ([`RayPacket::is_scattered`]) shares no
//!   node below the root: its lanes walk the wide tree as single rays,
//!   interleaved so that their cache misses overlap
//!   ([`traverse_interleaved`](crate::accel::bvh::traverse_single::traverse_interleaved)).
//!   So do the lanes of every other incoherent packet in a tree larger than
//!   the machine's last-level cache ([`Bvh::outgrows_cache`]): there a walk
//!   waits on memory at most steps, and the overlap of eight walks' misses
//!   gains more than the shared node tests of the hybrid walk save.
//!
//! One loop serves nearest-hit and any-hit queries ([`PacketQuery`]).

use crate::accel::bvh::lanes::leaf_lane_by_lane;
use crate::accel::bvh::leaf::LeafRef;
use crate::accel::bvh::node::{NodeId, ROOT};
use crate::accel::bvh::query::{LaneQueries, PacketQuery, Scope};
use crate::accel::bvh::ray_box::{FAR_SCALE, SlabPacket};
use crate::accel::bvh::stack::{BINARY_STACK_SLOTS, TraversalStack};
use crate::accel::bvh::traverse_hybrid::{LaneWalk, SINGLE_RAY_LANES, traverse_hybrid};
use crate::accel::bvh::traverse_single::Nearest;
use crate::accel::bvh::tree::Bvh;
use crate::accel::stats::Counter;
use crate::geometry::BlockRay;
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::SimdFloat;

/// Bit `k` set when most active lanes point down axis `k`: the packet then
/// visits the upper child of a node split along `k` first.
#[inline(always)]
pub fn majority_negative<F: SimdFloat>(rays: &RayPacket<F>) -> u32 {
    let active = rays.active.bitmask().count_ones();
    let mut bits = 0;
    for k in 0..3 {
        let negative = (rays.dir.axis(k).lt(F::splat(0.0)) & rays.active)
            .bitmask()
            .count_ones();
        bits |= u32::from(2 * negative > active) << k;
    }
    bits
}

/// Coherent any-hit packets in the world's tree walk the binary tree of
/// fewer primitives than this, and the wide tree without single-ray
/// fallback of more: the binary walk's extra node visits cost more than its
/// cheaper steps save in a tree that leaves the caches (figures:
/// `docs/measurements.md`, "Constants").
pub const BINARY_ANY_HIT_PRIMITIVES: usize = 1 << 17;

/// Traverse the whole tree with the lanes of `query.live()`.
#[inline(always)]
pub fn traverse_packet<F: SimdFloat, Q: PacketQuery<F>, S: Counter>(
    bvh: &Bvh,
    rays: &RayPacket<F>,
    query: &mut Q,
    stats: &mut S,
) {
    if bvh.is_empty() {
        return;
    }
    let slab = SlabPacket::new(rays);
    let upper_first = majority_negative(rays);
    let (root_mask, _) = slab.node_entry(bvh.node(ROOT), query.t_max());
    let mut mask = root_mask & query.live();
    if mask.none() {
        return;
    }
    let coherent = rays.is_coherent();
    // Coherent any-hit packets in the world's tree keep together: down the
    // binary tree in a small one, never apart in the wide one of a large
    // one. In an instance's mesh their lanes part at its surface (a forest's
    // shadow rays through its canopies), where the hybrid walk's fallback wins.
    let world_shadow = !Q::NEAREST_FIRST && coherent && query.scope() == Scope::World;
    let binary = coherent && (Q::NEAREST_FIRST || (world_shadow && bvh.len() < BINARY_ANY_HIT_PRIMITIVES));
    if !binary {
        // Incoherent rays part ways too soon for the binary tree, and other
        // any-hit rays, which need no order, meet fewer nodes in the wide one. Rays
        // from all over the scene share nothing below the root: they walk it
        // as single rays, interleaved where the tree is large. So do the
        // lanes of secondary rays in a tree larger than the last-level cache,
        // where a shared node test saves less than the overlap of the lanes'
        // misses gains. Else the hybrid traversal shares what the lanes do share.
        let walk = if rays.is_scattered(&bvh.bounds()) {
            if bvh.interleaves_scattered() {
                LaneWalk::ApartInterleaved
            } else {
                LaneWalk::Apart
            }
        } else if !world_shadow && bvh.outgrows_cache() {
            LaneWalk::ApartInterleaved
        } else {
            LaneWalk::Shared {
                single_ray_lanes: if world_shadow { 0 } else { SINGLE_RAY_LANES },
            }
        };
        traverse_hybrid(bvh, &slab, mask, walk, query, stats);
        return;
    }
    // Far children still to visit, with their lanes' entry t (NaN in the other lanes).
    let mut stack = TraversalStack::<(NodeId, F), BINARY_STACK_SLOTS>::new();
    let mut id = ROOT;
    loop {
        loop {
            stats.packet_node(mask);
            let node = bvh.node(id);
            if node.is_leaf() {
                query.leaf(bvh, node.contents(), mask, stats);
                break;
            }
            let [a, b] = node.children();
            let [box_a, box_b] = &bvh.pair(node.first).0;
            let t_max = query.t_max();
            let (mask_a, t_a) = slab.node_entry(box_a, t_max);
            let (mask_b, t_b) = slab.node_entry(box_b, t_max);
            let (mask_a, mask_b) = (mask_a & mask, mask_b & mask);
            match (mask_a.any(), mask_b.any()) {
                (true, true) => {
                    let b_first = upper_first >> node.axis() & 1 == 1;
                    let (near, near_mask, far, far_mask, t_far) = if b_first {
                        (b, mask_b, a, mask_a, t_a)
                    } else {
                        (a, mask_a, b, mask_b, t_b)
                    };
                    stack.push((far, far_mask.select(t_far, F::splat(f32::NAN))));
                    id = near;
                    mask = near_mask;
                }
                (true, false) => {
                    id = a;
                    mask = mask_a;
                }
                (false, true) => {
                    id = b;
                    mask = mask_b;
                }
                (false, false) => break,
            }
        }
        // Pop the next far child some lane can still find a hit in.
        loop {
            let Some((far, t_entry)) = stack.pop() else {
                return;
            };
            if query.live().none() {
                return;
            }
            mask = t_entry.le(query.t_max() * F::splat(FAR_SCALE)) & query.live();
            if mask.any() {
                id = far;
                break;
            }
        }
    }
}

/// The nearest-hit query of a packet.
pub struct NearestPacket<'a, F: SimdFloat> {
    /// The rays, whose `active` mask is set to the lanes taking part at each leaf.
    rays: RayPacket<F>,
    /// The lanes being traced.
    live: F,
    /// The hit records.
    hits: &'a mut HitPacket<F>,
}

impl<F: SimdFloat> LaneQueries<F> for NearestPacket<'_, F> {
    // A lane is handed over deep in the tree, sure to reach a leaf.
    type Lane<'a>
        = Nearest<'a, BlockRay<'a>>
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
    fn query<'a>(&'a self, ray: &'a Ray, hit: &'a mut Hit) -> Nearest<'a, BlockRay<'a>> {
        Nearest::new(ray, hit)
    }

    #[inline(always)]
    fn end(&mut self, lane: usize, hit: &Hit, _: bool) {
        self.hits.set_hit(lane, hit);
    }
}

impl<F: SimdFloat> PacketQuery<F> for NearestPacket<'_, F> {
    #[inline(always)]
    fn t_max(&self) -> F {
        self.hits.t
    }

    #[inline(always)]
    fn live(&self) -> F {
        self.live
    }

    #[inline(always)]
    fn leaf<S: Counter>(&mut self, bvh: &Bvh, leaf: LeafRef, mask: F, stats: &mut S) {
        let bits = mask.bitmask();
        if leaf.tested_lane_by_lane(bits.count_ones()) {
            leaf_lane_by_lane(self, bvh, leaf, bits, stats);
            return;
        }
        self.rays.active = mask;
        for prim in bvh.leaves().items(leaf) {
            stats.packet_prim(mask);
            bvh.leaves().intersect_packet(prim, &self.rays, self.hits);
        }
    }
}

/// Run `query` for the packet `rays` over the whole BVH: the leaf of
/// unbounded primitives first, on every active lane, then the tree for the
/// lanes still live.
#[inline(always)]
pub fn trace_packet<F: SimdFloat, Q: PacketQuery<F>, S: Counter>(
    bvh: &Bvh,
    rays: &RayPacket<F>,
    query: &mut Q,
    stats: &mut S,
) {
    if let Some(leaf) = bvh.unbounded_leaf() {
        query.leaf(bvh, leaf, rays.active, stats);
    }
    if query.live().any() {
        traverse_packet(bvh, rays, query, stats);
    }
}

/// The nearest hits of the active lanes of `rays`.
#[inline(always)]
pub fn intersect_packet<F: SimdFloat, S: Counter>(
    bvh: &Bvh,
    rays: &RayPacket<F>,
    stats: &mut S,
) -> HitPacket<F> {
    stats.rays(u64::from(rays.active.bitmask().count_ones()));
    stats.packet();
    let mut hits = HitPacket::none(rays);
    if rays.active.none() {
        return hits;
    }
    let mut query = NearestPacket {
        rays: *rays,
        live: rays.active,
        hits: &mut hits,
    };
    trace_packet(bvh, rays, &mut query, stats);
    hits
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bounds::Aabb;
    use crate::rng::Rng;

    /// Packets of random rays from all over a tree, walked as single rays
    /// (interleaved in a large tree, one after the other in a small one; 8 and
    /// 16 lanes, any two or more on, some rays bounded): every lane's nearest
    /// hit and occlusion are its single ray's, bit for bit, and so are the
    /// nodes visited and primitives tested, summed over the lanes.
    #[test]
    fn scattered_packets_answer_and_count_as_their_single_rays() {
        scattered_packets_agree::<wide::f32x8>();
        scattered_packets_agree::<wide::f32x16>();
    }

    /// Coherent packets of any-hit rays, as shadow rays from a pixel block's
    /// hits to one light make (some bounded at the light, some not, a lane
    /// or two off): in the world's small tree they walk the binary tree, in
    /// a large one the wide tree without falling back, in an instance's mesh
    /// the hybrid walk; every lane's occlusion is its single ray's in each.
    #[test]
    fn coherent_any_hit_packets_answer_as_their_single_rays() {
        use crate::accel::bvh::dispatch::occluded_packet;
        use crate::accel::bvh::query::Scope;
        use crate::accel::{Accel, Bvh, TraversalCounter};
        use crate::packet::RayPacket8;
        use crate::scene::generate::random;
        use glam::Vec3;
        let mut rng = Rng::new(13);
        for (prims, small) in [
            (random::bumpy_sphere(3_000, 3), true),
            (random::bumpy_sphere(150_000, 4), false),
        ] {
            let bvh = Bvh::new(&prims);
            assert_eq!(
                bvh.len() < BINARY_ANY_HIT_PRIMITIVES,
                small,
                "{} primitives",
                prims.len()
            );
            let bounds = bvh.bounds();
            let diagonal = (bounds.max - bounds.min).length();
            let mut fallbacks = [0; 2];
            let mut coherent = 0;
            for _ in 0..600 {
                let light = bounds.max + 2.0 * diagonal * rng.unit_vector();
                let centre = rng.point_in(bounds.min, bounds.max);
                let spread = 0.01 * diagonal;
                let rays: Vec<Ray> = (0..8)
                    .map(|_| {
                        let origin = centre + rng.point_in(Vec3::splat(-spread), Vec3::splat(spread));
                        let to_light = light - origin;
                        let t_max = if rng.below(3) == 0 {
                            f32::INFINITY
                        } else {
                            to_light.length()
                        };
                        Ray::new(origin, to_light.normalize(), 1e-4, t_max)
                    })
                    .collect();
                let active = if rng.below(4) == 0 { 0b0111_1011 } else { 0xff };
                let packet = RayPacket8::from_rays_masked(&rays, active);
                coherent += usize::from(packet.is_coherent());
                for (scope, fallback) in [Scope::World, Scope::Instance].into_iter().zip(&mut fallbacks) {
                    let mut stats = TraversalCounter::totals();
                    let occluded = occluded_packet(&bvh, &packet, scope, &mut stats).bitmask();
                    *fallback += stats.total().fallback_rays;
                    for (lane, ray) in rays.iter().enumerate().filter(|(l, _)| active >> l & 1 == 1) {
                        assert_eq!(
                            occluded >> lane & 1 == 1,
                            bvh.occluded(ray),
                            "{scope:?}, lane {lane} of {rays:?}"
                        );
                    }
                }
            }
            assert!(coherent > 500, "{coherent} of 600 packets coherent");
            // The world's packets keep their lanes together; an instance's part.
            assert_eq!(fallbacks[0], 0, "world");
            assert!(fallbacks[1] > 0, "instance");
        }
    }

    fn scattered_packets_agree<F: SimdFloat>() {
        use crate::accel::TraversalCounter;
        use crate::accel::{Accel, Bvh};
        use crate::scene::generate::random;
        let mut rng = Rng::new(12);
        for prims in [
            random::bumpy_sphere(150_000, 3),
            random::random_spheres(250_000, 4),
            random::random_mixed(150_000, 5),
            random::bumpy_sphere(2_000, 6),
        ] {
            let bvh = Bvh::new(&prims);
            let large = bvh.interleaves_scattered();
            assert_eq!(large, prims.len() > 2_000, "{} bytes", bvh.walked_bytes());
            let bounds = bvh.bounds();
            // Origins off the box's faces: a ray from a face out of the box
            // misses the packet's root test, but a single ray counts the root.
            let margin = 0.01 * (bounds.max - bounds.min);
            let inside = Aabb::new(bounds.min + margin, bounds.max - margin);
            let (mut packet_stats, mut single_stats) =
                (TraversalCounter::totals(), TraversalCounter::totals());
            let mut scattered = 0;
            for _ in 0..500 {
                let rays: Vec<Ray> = (0..F::LANES)
                    .map(|_| {
                        let t_max = if rng.below(3) == 0 {
                            rng.range(0.01, 0.5)
                        } else {
                            f32::INFINITY
                        };
                        Ray::new(
                            rng.point_in(inside.min, inside.max),
                            rng.unit_vector(),
                            1e-4,
                            t_max,
                        )
                    })
                    .collect();
                let all = u32::MAX >> (32 - F::LANES);
                // Two lanes or more: one lane alone is a coherent packet.
                let active = if rng.below(2) == 0 {
                    all
                } else {
                    rng.below(all + 1) | 0b11
                };
                let packet = RayPacket::<F>::from_rays_masked(&rays, active);
                // (Rarely, a few lanes' origins lie close together.)
                if !packet.is_scattered(&bounds) {
                    continue;
                }
                scattered += 1;
                let hits = bvh.intersect_packet_counted(&packet, &mut packet_stats);
                let occluded = bvh.occluded_packet_counted(&packet, &mut packet_stats).bitmask();
                for (lane, ray) in rays.iter().enumerate().filter(|(l, _)| active >> l & 1 == 1) {
                    assert_eq!(
                        hits.hit(lane),
                        bvh.intersect_counted(ray, &mut single_stats),
                        "lane {lane} of {rays:?}"
                    );
                    assert_eq!(
                        occluded >> lane & 1 == 1,
                        bvh.occluded_counted(ray, &mut single_stats),
                        "lane {lane} of {rays:?}"
                    );
                }
            }
            assert!(scattered > 450, "{scattered} of 500 packets scattered");
            let (packet_stats, single_stats) = (packet_stats.total(), single_stats.total());
            assert_eq!(packet_stats.nodes_visited, single_stats.nodes_visited);
            assert_eq!(packet_stats.prim_tests, single_stats.prim_tests);
            if bvh.info().unbounded == 0 {
                // (Planes are tested by the packet, and may settle lanes.)
                assert_eq!(
                    packet_stats.fallback_rays, packet_stats.rays,
                    "every lane walks alone"
                );
                assert_eq!(packet_stats.simd_steps, 0, "{packet_stats:?}");
            }
        }
    }
}
