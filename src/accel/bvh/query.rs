//! What a traversal does where it meets primitives, apart from how it walks
//! the tree: a query decides what happens in a leaf and how far each ray still
//! looks. One traversal loop per tree and ray kind serves every query
//! (nearest hit, any hit), as in madmann91's `bvh` library, whose traversal
//! takes the leaf test as a parameter.

use crate::accel::bvh::leaf::LeafRef;
use crate::accel::bvh::tree::Bvh;
use crate::accel::stats::Counter;
use crate::packet::RayPacket;
use crate::ray::{Hit, Ray};
use crate::simd::{Simd8, SimdFloat};

/// What a single-ray traversal does in leaves, and how far it looks.
pub trait RayQuery {
    /// Whether children are visited nearest first. Nearest-hit queries gain
    /// from it (a near hit culls the far children); an any-hit query stops at
    /// whatever it meets first, so it saves the ordering. A query that is not
    /// nearest first must keep its [`t_max`](Self::t_max) fixed: the walk
    /// does not cull what it pushed again.
    const NEAREST_FIRST: bool = true;

    /// The largest t still of interest (the current hit's t for nearest-hit queries).
    fn t_max(&self) -> f32;

    /// Test the primitives of `leaf` (blocks with the 8-lane type `N`); true
    /// ends the traversal.
    fn leaf<N: Simd8, S: Counter>(&mut self, bvh: &Bvh, leaf: LeafRef, stats: &mut S) -> bool;
}

/// A packet query whose lanes can each run as a single-ray query: what the
/// lane-by-lane leaf test of few-lane leaves and the single-ray finish of the
/// lanes a packet leaves alone need of it (both written once, in
/// [`lanes`](crate::accel::bvh::lanes), for nearest and any hit).
pub trait LaneQueries<F: SimdFloat> {
    /// The single-ray query a lane runs.
    type Lane<'a>: RayQuery
    where
        Self: 'a;

    /// The packet's rays.
    fn rays(&self) -> &RayPacket<F>;

    /// The record lane `lane` (whose ray is `ray`) starts from.
    fn start(&self, lane: usize, ray: &Ray) -> Hit;

    /// The single-ray query of `ray` keeping its record in `hit`.
    fn query<'a>(&'a self, ray: &'a Ray, hit: &'a mut Hit) -> Self::Lane<'a>;

    /// Take lane `lane`'s result back: its record, and whether its query ended early.
    fn end(&mut self, lane: usize, hit: &Hit, ended_early: bool);
}

/// What a packet traversal does in leaves, and how far each lane looks.
pub trait PacketQuery<F: SimdFloat>: LaneQueries<F> {
    /// Whether children are visited nearest first (see [`RayQuery::NEAREST_FIRST`]).
    const NEAREST_FIRST: bool = true;

    /// Whose tree the packet walks (the walk of coherent any-hit packets
    /// depends on it, see [`traverse_packet`](crate::accel::bvh::traverse_packet)).
    #[inline(always)]
    fn scope(&self) -> Scope {
        Scope::World
    }

    /// Per lane, the largest t still of interest.
    fn t_max(&self) -> F;

    /// The lanes still being traced.
    fn live(&self) -> F;

    /// Test the leaf primitives `prims` on the lanes of `mask`.
    fn leaf<S: Counter>(&mut self, bvh: &Bvh, leaf: LeafRef, mask: F, stats: &mut S);
}

/// Whose tree a packet walks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scope {
    /// The world's: a scene's own tree, or the top tree over its instances.
    World,
    /// An instance's mesh, entered from a top tree (by the lanes that met
    /// the instance, one mesh after another).
    Instance,
}

/// Most rays [`traverse_interleaved`](crate::accel::bvh::traverse_single::traverse_interleaved)
/// walks at once.
pub const INTERLEAVED: usize = 8;

/// Lanes that walk interleaved rather than one after the other, at least
/// (where [`finish_lanes`](crate::accel::bvh::lanes::finish_lanes) is asked
/// to interleave). Two interleaved walks cost more than their overlap saves
/// (measured on the hybrid traversal's one- and two-lane subtrees of
/// ambient-occlusion rays).
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
