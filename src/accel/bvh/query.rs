//! What a traversal does where it meets primitives, apart from how it walks
//! the tree: a query decides what happens in a leaf and how far each ray still
//! looks. One traversal loop per tree and ray kind serves every query
//! (nearest hit, any hit), as in madmann91's `bvh` library, whose traversal
//! takes the leaf test as a parameter.

use crate::accel::bvh::Bvh;
use crate::accel::bvh::leaf::LeafRef;
use crate::accel::bvh::wide::{ChildRef, TreeWidth};
use crate::accel::stats::Counter;
use crate::simd::{Simd8, SimdFloat};

/// What a single-ray traversal does in leaves, and how far it looks.
pub trait RayQuery {
    /// Whether children are visited nearest first. Nearest-hit queries gain
    /// from it (a near hit culls the far children); an any-hit query stops at
    /// whatever it meets first, so it saves the ordering.
    const NEAREST_FIRST: bool = true;

    /// The largest t still of interest (the current hit's t for nearest-hit queries).
    fn t_max(&self) -> f32;

    /// Test the primitives of `leaf` (blocks with the 8-lane type `N`); true
    /// ends the traversal.
    fn leaf<N: Simd8, S: Counter>(&mut self, bvh: &Bvh, leaf: LeafRef, stats: &mut S) -> bool;
}

/// What a packet traversal does in leaves, and how far each lane looks.
pub trait PacketQuery<F: SimdFloat> {
    /// Whether children are visited nearest first (see [`RayQuery::NEAREST_FIRST`]).
    const NEAREST_FIRST: bool = true;

    /// Per lane, the largest t still of interest.
    fn t_max(&self) -> F;

    /// The lanes still being traced.
    fn live(&self) -> F;

    /// Test the leaf primitives `prims` on the lanes of `mask`.
    fn leaf<S: Counter>(&mut self, bvh: &Bvh, leaf: LeafRef, mask: F, stats: &mut S);

    /// Trace the lanes of the mask `lanes` through the subtree of the wide
    /// tree of width `W` under `start` (whose box they met) as single rays (reporting each
    /// to [`Counter::lane`]), with `F`'s 8-lane type: up to [`INTERLEAVED`] at
    /// once ([`traverse_interleaved`]) with `interleaved`, else one after the other.
    ///
    /// [`traverse_interleaved`]: crate::accel::bvh::traverse_single::traverse_interleaved
    fn finish_lanes<W: TreeWidth, S: Counter>(
        &mut self,
        bvh: &Bvh,
        lanes: u32,
        start: ChildRef,
        interleaved: bool,
        stats: &mut S,
    );
}

/// Most rays [`traverse_interleaved`](crate::accel::bvh::traverse_single::traverse_interleaved)
/// walks at once.
pub const INTERLEAVED: usize = 8;

/// Lanes that walk interleaved rather than one after the other, at least
/// (where [`PacketQuery::finish_lanes`] is asked to interleave). Two
/// interleaved walks cost more than their overlap saved: the hybrid
/// traversal's one- and two-lane subtrees of the dragon's ambient-occlusion
/// rays went 0.96× as fast as single rays, against 1.14× walked one after the
/// other.
pub const INTERLEAVE_FROM: u32 = 3;

/// The lanes of the mask `lanes`, lowest first.
pub fn lane_bits(mut lanes: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        let lane = (lanes != 0).then(|| lanes.trailing_zeros() as usize)?;
        lanes &= lanes - 1;
        Some(lane)
    })
}

/// The lanes of the mask `lanes` in groups of up to [`INTERLEAVED`], lowest
/// first: each group's lanes (the unused entries repeat its first) and count.
pub fn lane_groups(lanes: u32) -> impl Iterator<Item = ([usize; INTERLEAVED], usize)> {
    let mut rest = lane_bits(lanes).peekable();
    std::iter::from_fn(move || {
        let first = *rest.peek()?;
        let mut group = [first; INTERLEAVED];
        let mut count = 0;
        while count < INTERLEAVED
            && let Some(lane) = rest.next()
        {
            group[count] = lane;
            count += 1;
        }
        Some((group, count))
    })
}
