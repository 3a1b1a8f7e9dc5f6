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
//! - When no more than [`SINGLE_RAY_LANES`] lanes are left in a subtree, they
//!   finish it as single rays, which is cheaper than dragging an empty packet along.
//!
//! One loop serves nearest-hit and any-hit queries ([`PacketQuery`]).

use crate::accel::bvh::node::{Node, NodeId, ROOT};
use crate::accel::bvh::ray_box::{FAR_SCALE, SlabPacket, SlabRay};
use crate::accel::bvh::traverse_single::{Nearest, traverse};
use crate::accel::bvh::{Bvh, STACK_SIZE};
use crate::accel::stats::Counter;
use crate::geometry::Intersect;
use crate::packet::{HitPacket, RayPacket};
use crate::simd::SimdFloat;

/// A subtree with this many lanes or fewer left is finished by single-ray traversal.
pub const SINGLE_RAY_LANES: u32 = 2;

/// What a packet traversal does in leaves, and how far each lane looks.
pub trait PacketQuery<F: SimdFloat> {
    /// Per lane, the largest t still of interest.
    fn t_max(&self) -> F;

    /// The lanes still being traced.
    fn live(&self) -> F;

    /// Test the primitives of `leaf` on the lanes of `mask`.
    fn leaf<S: Counter>(&mut self, bvh: &Bvh, leaf: &Node, mask: F, stats: &mut S);

    /// Finish lane `lane` in the subtree under `start` as a single ray.
    fn finish_single<S: Counter>(&mut self, bvh: &Bvh, start: NodeId, lane: usize, stats: &mut S);
}

/// Bit `k` set when most active lanes point down axis `k`: the packet then
/// visits the upper child of a node split along `k` first.
#[inline]
pub fn majority_negative<F: SimdFloat>(rays: &RayPacket<F>) -> u32 {
    let active = rays.active.bitmask().count_ones();
    (0..3).fold(0, |bits, k| {
        let negative = (rays.dir.axis(k).lt(F::splat(0.0)) & rays.active)
            .bitmask()
            .count_ones();
        bits | (u32::from(2 * negative > active) << k)
    })
}

/// Traverse the whole tree with the lanes of `query.live()`.
#[inline]
pub fn traverse_packet<F: SimdFloat, Q: PacketQuery<F>, S: Counter>(
    bvh: &Bvh,
    rays: &RayPacket<F>,
    query: &mut Q,
    stats: &mut S,
) {
    if bvh.prims.is_empty() {
        return;
    }
    let slab = SlabPacket::new(rays);
    let upper_first = majority_negative(rays);
    let (root_mask, _) = slab.node_entry(bvh.node(ROOT), query.t_max());
    let mut mask = root_mask & query.live();
    if mask.none() {
        return;
    }
    // Far children still to visit, with their lanes' entry t (NaN in the other lanes).
    let mut stack_ids = [0 as NodeId; STACK_SIZE];
    let mut stack_t = [F::splat(0.0); STACK_SIZE];
    let mut sp = 0;
    let mut id = ROOT;
    loop {
        loop {
            let lanes = mask.bitmask();
            if lanes.count_ones() <= SINGLE_RAY_LANES {
                stats.fallback(u64::from(lanes.count_ones()));
                let mut bits = lanes;
                while bits != 0 {
                    stats.lane(bits.trailing_zeros() as usize);
                    query.finish_single(bvh, id, bits.trailing_zeros() as usize, stats);
                    bits &= bits - 1;
                }
                break;
            }
            stats.packet_node(mask);
            let node = bvh.node(id);
            if node.is_leaf() {
                query.leaf(bvh, node, mask, stats);
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
                    stack_ids[sp] = far;
                    stack_t[sp] = far_mask.select(t_far, F::splat(f32::NAN));
                    sp += 1;
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
            if sp == 0 || query.live().none() {
                return;
            }
            sp -= 1;
            mask = stack_t[sp].le(query.t_max() * F::splat(FAR_SCALE)) & query.live();
            if mask.any() {
                id = stack_ids[sp];
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
    fn leaf<S: Counter>(&mut self, bvh: &Bvh, leaf: &Node, mask: F, stats: &mut S) {
        self.rays.active = mask;
        for i in leaf.prims() {
            stats.packet_prim(mask);
            bvh.prims[i].intersect_packet(&self.rays, bvh.prim_ids[i], self.hits);
        }
    }

    fn finish_single<S: Counter>(&mut self, bvh: &Bvh, start: NodeId, lane: usize, stats: &mut S) {
        let ray = self.rays.ray(lane);
        let mut hit = self.hits.hit(lane);
        let mut query = Nearest {
            ray: &ray,
            hit: &mut hit,
        };
        traverse(bvh, start, &SlabRay::new(&ray), &mut query, stats);
        self.hits.set_hit(lane, &hit);
    }
}

/// The nearest hits of the active lanes of `rays`.
#[inline]
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
    for (p, &id) in bvh.unbounded.iter().zip(&bvh.unbounded_ids) {
        stats.packet_prim(rays.active);
        p.intersect_packet(rays, id, &mut hits);
    }
    let mut query = NearestPacket {
        rays: *rays,
        live: rays.active,
        hits: &mut hits,
    };
    traverse_packet(bvh, rays, &mut query, stats);
    hits
}
