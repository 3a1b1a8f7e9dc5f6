//! Hybrid traversal of the wide tree for incoherent packets: the packet walks
//! the wide nodes together, each child's box tested against all its lanes at
//! once, until a subtree is wanted by only a few lanes; those lanes then finish
//! it one after the other as single rays ([`traverse`](super::traverse_single)).
//! Embree's hybrid packets do the same (C. Benthin, I. Wald, S. Woop, M. Ernst,
//! W. R. Mark, "Combining single and packet-ray tracing for arbitrary ray
//! distributions on the Intel MIC architecture", IEEE TVCG 2012).
//!
//! Secondary rays from neighbouring pixels (shadow, ambient occlusion, diffuse
//! bounces) point every which way but start close together, so they share the
//! upper part of their paths: one load of a node serves all of them there, and
//! the lanes split up only near the leaves. The coherent packets of primary
//! rays keep to the binary tree ([`traverse_packet`](super::traverse_packet)).

use crate::accel::bvh::lanes::finish_lanes;
use crate::accel::bvh::query::{INTERLEAVE_FROM, PacketQuery};
use crate::accel::bvh::ray_box::{FAR_SCALE, SlabPacket};
use crate::accel::bvh::stack::{TraversalStack, WIDE_STACK_SLOTS};
use crate::accel::bvh::tree::Bvh;
use crate::accel::bvh::tree::TreeWidth;
use crate::accel::bvh::wide::{ChildRef, PacketTreeLanes, RayTreeLanes, WideNodeOf};
use crate::accel::stats::Counter;
use crate::simd::SimdFloat;

/// A subtree wanted by this many lanes or fewer is finished by them as single
/// rays: with so few lanes, a box test for all of them costs more than the
/// loads it shares (packets but coherent any-hit ones in the world's tree;
/// see [`LaneWalk::Shared`]).
pub const SINGLE_RAY_LANES: u32 = 2;

/// How a packet's lanes set out from the root of the wide tree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LaneWalk {
    /// Together, sharing each node's test until a subtree is wanted by
    /// `single_ray_lanes` lanes or fewer: [`SINGLE_RAY_LANES`] for secondary
    /// rays from nearby points; 0 (never apart) for coherent any-hit
    /// packets in a large tree, whose lanes mostly stay together down to
    /// the leaves.
    Shared {
        /// Lanes few enough to finish a subtree as single rays.
        single_ray_lanes: u32,
    },
    /// Each lane alone through the whole tree, one after the other: rays that
    /// share no node below the root, in a tree that stays in the caches.
    Apart,
    /// Each lane alone through the whole tree, up to
    /// [`INTERLEAVED`](crate::accel::bvh::query::INTERLEAVED) at once: rays
    /// that share no node below the root, in a tree whose loads miss the caches.
    ApartInterleaved,
}

/// A child still to visit: what it is, the lanes that met its box, and the
/// smallest of their entry t. 16 bytes.
#[derive(Clone, Copy)]
struct Pending {
    child: ChildRef,
    lanes: u32,
    t_entry: f32,
}

/// Traverse the wide tree from its root with the lanes of `lanes` (which met
/// the root's box) of the rays prepared in `slab`, setting out as `walk`
/// says (lanes apart for rays that share no node below the root, see
/// [`is_scattered`](crate::packet::RayPacket::is_scattered)).
/// This is the one place packets hand lanes to
/// [`finish_lanes`], so the single-ray walk is compiled once
/// into each packet query's entry point.
#[inline(always)]
pub fn traverse_hybrid<F: SimdFloat, Q: PacketQuery<F>, S: Counter>(
    bvh: &Bvh,
    slab: &SlabPacket<F>,
    lanes: F,
    walk: LaneWalk,
    query: &mut Q,
    stats: &mut S,
) {
    let mut stack = TraversalStack::<Pending, WIDE_STACK_SLOTS>::new();
    let mut next = ChildRef::ROOT;
    let mut active = lanes;
    // Lanes that share nothing are handed over at the root (nothing is pushed).
    let single_ray_lanes = match walk {
        LaneWalk::Shared { single_ray_lanes } => single_ray_lanes,
        LaneWalk::Apart | LaneWalk::ApartInterleaved => u32::MAX,
    };
    loop {
        let bits = active.bitmask();
        if bits.count_ones() <= single_ray_lanes {
            // Too few lanes left to share the work (or none shared at all).
            stats.fallback(u64::from(bits.count_ones()));
            if next == ChildRef::ROOT {
                // From the root (all lanes, or too few to share anything):
                // the single rays' own, wider tree.
                let interleaved = walk == LaneWalk::ApartInterleaved && bits.count_ones() >= INTERLEAVE_FROM;
                finish_lanes::<F, Q, RayTreeLanes, S>(query, bvh, bits, next, interleaved, stats);
            } else {
                // (Never interleaved: two walks overlap too little, see INTERLEAVE_FROM.)
                finish_lanes::<F, Q, PacketTreeLanes, S>(query, bvh, bits, next, false, stats);
            }
        } else if next.is_leaf() {
            if !next.is_empty() {
                stats.packet_node(active);
                query.leaf(bvh, next.contents(), active, stats);
            }
        } else {
            stats.packet_node(active);
            let node = &PacketTreeLanes::nodes(bvh)[next.node()];
            if Q::NEAREST_FIRST {
                push_nearest_first(bvh, slab, node, active, query.t_max(), &mut stack);
            } else {
                push_any_order(bvh, slab, node, active, query.t_max(), &mut stack);
            }
        }
        // Pop the next child some lane can still find a hit in.
        loop {
            let Some(pending) = stack.pop() else {
                return;
            };
            let live = query.live();
            let reach = query.t_max() * F::splat(FAR_SCALE);
            active = F::mask_from_bits(pending.lanes) & live & F::splat(pending.t_entry).le(reach);
            if active.any() {
                next = pending.child;
                break;
            }
        }
    }
}

/// The lanes of `active` in the packet `slab` that meet the box of child
/// `i` of `node` within their reach `t_max`, and their entry t.
///
/// A node's children are all tested before any is pushed (the empty slots
/// too, whose box no finite ray meets), and the children met are then
/// visited by their bits, so no branch asks whether a given child was met:
/// on incoherent packets that is a coin toss, which a branch per child
/// mispredicts.
#[inline(always)]
fn test_child<F: SimdFloat>(
    slab: &SlabPacket<F>,
    node: &WideNodeOf<PacketTreeLanes>,
    i: usize,
    active: F,
    t_max: F,
) -> (F, F) {
    let b = node.child_bounds(i);
    let (hit, t) = slab.entry(b.min, b.max, t_max);
    (hit & active, t)
}

/// Test the children of `node` against the lanes `active` of the packet
/// `slab` (reach `t_max`), and push those met with the lanes that met each,
/// by decreasing smallest entry t, so the nearest is popped first (a
/// nearest-hit query's order). The children are put in order by insertion:
/// placing each by its rank without a branch, as single rays do, cost
/// diffuse packets more than its mispredictions (docs/tried-not-kept.md).
#[inline(always)]
fn push_nearest_first<F: SimdFloat>(
    bvh: &Bvh,
    slab: &SlabPacket<F>,
    node: &WideNodeOf<PacketTreeLanes>,
    active: F,
    t_max: F,
    stack: &mut TraversalStack<Pending, WIDE_STACK_SLOTS>,
) {
    let mut lanes = [0u32; PacketTreeLanes::LANES];
    let mut entries = [F::splat(f32::INFINITY); PacketTreeLanes::LANES];
    let mut met = 0u32;
    for i in 0..PacketTreeLanes::LANES {
        let (hit, t) = test_child(slab, node, i, active, t_max);
        lanes[i] = hit.bitmask();
        entries[i] = hit.select(t, F::splat(f32::INFINITY));
        met |= u32::from(lanes[i] != 0) << i;
    }
    let base = stack.len();
    while met != 0 {
        let i = met.trailing_zeros() as usize;
        met &= met - 1;
        let child = node.slot(i);
        // Only rays with NaN or infinite input meet an empty slot.
        if child.is_empty() {
            continue;
        }
        bvh.prefetch::<PacketTreeLanes>(child);
        let t_entry = entries[i]
            .to_array()
            .as_ref()
            .iter()
            .fold(f32::INFINITY, |a, &b| a.min(b));
        stack.push(Pending {
            child,
            lanes: lanes[i],
            t_entry,
        });
        // Keep the run of this node's children sorted by decreasing entry t.
        let run = &mut stack.as_mut_slice()[base..];
        let mut k = run.len() - 1;
        while k > 0 && run[k - 1].t_entry < run[k].t_entry {
            run.swap(k - 1, k);
            k -= 1;
        }
    }
}

/// Test the children of `node` against the lanes `active` of the packet
/// `slab` (reach `t_max`), and push those met with the lanes that met each,
/// in slot order (an any-hit query's: no order, and the lanes' reach does
/// not shrink).
#[inline(always)]
fn push_any_order<F: SimdFloat>(
    bvh: &Bvh,
    slab: &SlabPacket<F>,
    node: &WideNodeOf<PacketTreeLanes>,
    active: F,
    t_max: F,
    stack: &mut TraversalStack<Pending, WIDE_STACK_SLOTS>,
) {
    let mut lanes = [0u32; PacketTreeLanes::LANES];
    let mut met = 0u32;
    for (i, child_lanes) in lanes.iter_mut().enumerate() {
        *child_lanes = test_child(slab, node, i, active, t_max).0.bitmask();
        met |= u32::from(*child_lanes != 0) << i;
    }
    while met != 0 {
        let i = met.trailing_zeros() as usize;
        met &= met - 1;
        let child = node.slot(i);
        bvh.prefetch::<PacketTreeLanes>(child);
        let entry = Pending {
            child,
            lanes: lanes[i],
            t_entry: f32::NEG_INFINITY,
        };
        // Only rays with NaN or infinite input meet an empty slot.
        stack.push_if(entry, !child.is_empty());
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use crate::accel::{Accel, Bvh, TraversalCounter, TraversalStats};
    use crate::packet::RayPacket8;
    use crate::ray::Ray;
    use crate::rng::Rng;
    use crate::scene::generate::random;
    use crate::simd::SimdFloat;

    /// A packet of 8 rays from points near one point of `bvh`'s box in random
    /// directions (as ambient occlusion and diffuse bounces make), some
    /// bounded, in one packet of four with a lane off; the rays and the mask.
    fn nearby_rays(rng: &mut Rng, bvh: &Bvh) -> (Vec<Ray>, u32) {
        let bounds = bvh.bounds();
        let centre = rng.point_in(bounds.min, bounds.max);
        let spread = 0.02 * (bounds.max - bounds.min).length();
        let rays = (0..8)
            .map(|_| {
                let origin = centre + rng.point_in(Vec3::splat(-spread), Vec3::splat(spread));
                let t_max = if rng.below(2) == 0 {
                    f32::INFINITY
                } else {
                    rng.range(0.0, 4.0 * spread)
                };
                Ray::new(origin, rng.unit_vector(), 1e-4, t_max)
            })
            .collect();
        (rays, if rng.below(4) == 0 { 0b1011_1111 } else { 0xff })
    }

    /// Trace `packets` as packets, nearest hit and any hit: every active
    /// lane's answers are its single ray's, bit for bit. The packets' counts.
    fn packets_answer_as_single_rays(bvh: &Bvh, packets: &[(Vec<Ray>, u32)]) -> TraversalStats {
        let mut stats = TraversalCounter::totals();
        for (rays, active) in packets {
            let packet = RayPacket8::from_rays_masked(rays, *active);
            assert!(!packet.is_coherent() && !packet.is_scattered(&bvh.bounds()));
            let hits = bvh.intersect_packet_counted(&packet, &mut stats);
            let occluded = bvh.occluded_packet_counted(&packet, &mut stats).bitmask();
            for (lane, ray) in rays.iter().enumerate().filter(|(l, _)| active >> l & 1 == 1) {
                assert_eq!(hits.hit(lane), bvh.intersect(ray), "lane {lane} of {rays:?}");
                assert_eq!(
                    occluded >> lane & 1 == 1,
                    bvh.occluded(ray),
                    "lane {lane} of {rays:?}"
                );
            }
        }
        *stats.total()
    }

    /// Packets of nearby rays (`nearby_rays`) on meshes, sphere clouds and
    /// mixed scenes answer as their single rays, and they do walk shared
    /// nodes before they split into single rays.
    #[test]
    fn incoherent_packets_answer_as_their_single_rays() {
        let mut rng = Rng::new(11);
        for prims in [
            random::bumpy_sphere(20_000, 3),
            random::random_spheres(5_000, 4),
            random::random_mixed(5_000, 5),
        ] {
            let bvh = Bvh::new(&prims);
            let packets: Vec<_> = (0..2_000).map(|_| nearby_rays(&mut rng, &bvh)).collect();
            let stats = packets_answer_as_single_rays(&bvh, &packets);
            assert!(stats.simd_steps > 0 && stats.fallback_rays > 0, "{stats:?}");
        }
    }

    /// The same packets in a tree judged larger than the last-level cache
    /// (`Bvh::outgrows_cache`) share no step: each lane walks alone from the
    /// root, and still answers as its single ray; judged to fit, they share.
    #[test]
    fn incoherent_packets_in_a_tree_outgrowing_the_cache_walk_apart() {
        let mut rng = Rng::new(31);
        let mut bvh = Bvh::new(&random::bumpy_sphere(20_000, 3));
        let packets: Vec<_> = (0..300).map(|_| nearby_rays(&mut rng, &bvh)).collect();
        for (cache, apart) in [(0, true), (usize::MAX, false)] {
            bvh.set_cache_bytes(cache);
            assert_eq!(bvh.outgrows_cache(), apart);
            let stats = packets_answer_as_single_rays(&bvh, &packets);
            assert!(stats.fallback_rays > 0, "{stats:?}");
            assert_eq!(stats.simd_steps == 0, apart, "{stats:?}");
        }
    }
}
