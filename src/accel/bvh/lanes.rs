//! A packet's lanes run as single-ray queries, written once for nearest-hit
//! and any-hit packets ([`LaneQueries`]): the lane-by-lane test of a leaf met
//! by few lanes ([`leaf_lane_by_lane`]) and the single-ray walk of the lanes a
//! packet leaves alone below a node ([`finish_lanes`]).

use std::mem::MaybeUninit;

use glam::Vec3;

use crate::accel::bvh::leaf::LeafRef;
use crate::accel::bvh::query::{INTERLEAVED, LaneQueries, RayQuery, lane_bits, lane_groups};
use crate::accel::bvh::ray_box::SlabRay;
use crate::accel::bvh::traverse_single::{traverse, traverse_interleaved};
use crate::accel::bvh::tree::Bvh;
use crate::accel::bvh::tree::TreeWidth;
use crate::accel::bvh::wide::ChildRef;
use crate::accel::stats::Counter;
use crate::ray::{Hit, Ray};
use crate::simd::SimdFloat;
use crate::simd::isa::level_task;

/// Test `leaf` on each lane of the mask `lanes` with the lane's own
/// single-ray query (reporting each to [`Counter::lane`]).
#[inline(always)]
pub fn leaf_lane_by_lane<F: SimdFloat, Q: LaneQueries<F>, S: Counter>(
    query: &mut Q,
    bvh: &Bvh,
    leaf: LeafRef,
    lanes: u32,
    stats: &mut S,
) {
    for lane in lane_bits(lanes) {
        stats.lane(lane);
        let ray = query.rays().ray(lane);
        let mut hit = query.start(lane, &ray);
        let ended = query
            .query(&ray, &mut hit)
            .leaf::<F::Lanes8, S>(bvh, leaf.clone(), stats);
        query.end(lane, &hit, ended);
    }
}

/// [`traverse_interleaved`] of `walks` under `start`, in an entry point of its
/// own on the tree's level: the walks' stacks, 24 KiB, stay out of the frame
/// of every packet query, which would be probed page by page at each call,
/// and a packet entering an instance makes one (docs/measurements.md, "The
/// interleaved walks' own entry point").
#[inline(always)]
fn interleaved_walks<R: RayQuery, W: TreeWidth, S: Counter>(
    bvh: &Bvh,
    start: ChildRef,
    walks: &mut [(usize, SlabRay, R)],
    stats: &mut S,
) -> u32 {
    bvh.on_level(interleaved::Task::<R, W, S>::new(bvh, start, walks, stats))
}

/// [`interleaved_walks`]' task (a module of its own: the codegen unit of its
/// entry points).
mod interleaved {
    use crate::accel::bvh::lanes::*;
    level_task!(Task<'a, R: RayQuery, W: TreeWidth, S: Counter>(
        bvh: &'a Bvh,
        start: ChildRef,
        walks: &'a mut [(usize, SlabRay, R)],
        stats: &'a mut S,
    ) -> u32 {
        traverse_interleaved::<L::F8, W, R, S>(bvh, start, walks, stats)
    });
}

/// Trace the lanes of the mask `lanes` through the subtree of the wide tree
/// of width `W` under `start` (whose box they met) as single rays (reporting
/// each to [`Counter::lane`]), with `F`'s 8-lane type: up to [`INTERLEAVED`]
/// at once with `interleaved` ([`traverse_interleaved`], in an entry point of
/// its own), else one after the other.
#[inline(always)]
pub fn finish_lanes<F: SimdFloat, Q: LaneQueries<F>, W: TreeWidth, S: Counter>(
    query: &mut Q,
    bvh: &Bvh,
    lanes: u32,
    start: ChildRef,
    interleaved: bool,
    stats: &mut S,
) {
    if !interleaved {
        for lane in lane_bits(lanes) {
            stats.lane(lane);
            let ray = query.rays().ray(lane);
            let mut hit = query.start(lane, &ray);
            let slab = SlabRay::new(&ray);
            let ended =
                traverse::<F::Lanes8, W, _, S>(bvh, start, &slab, &mut query.query(&ray, &mut hit), stats);
            query.end(lane, &hit, ended);
        }
        return;
    }
    for (group, count) in lane_groups(lanes) {
        // (Loops, not closures over SIMD values: they must inline into the entry point.)
        let mut rays = [Ray::unbounded(Vec3::ZERO, Vec3::ZERO); INTERLEAVED];
        let mut hits = [Hit::none(&rays[0]); INTERLEAVED];
        for k in 0..count {
            rays[k] = query.rays().ray(group[k]);
            hits[k] = query.start(group[k], &rays[k]);
        }
        // The walks of the group's lanes only, made by a plain loop: a
        // closure (`array::from_fn`) stayed a function of its own, outside
        // the entry point, made all eight walks and cost a call each.
        let mut walks = [const { MaybeUninit::<(usize, SlabRay, Q::Lane<'_>)>::uninit() }; INTERLEAVED];
        for (k, (walk, hit)) in walks.iter_mut().zip(hits.iter_mut()).take(count).enumerate() {
            walk.write((group[k], SlabRay::new(&rays[k]), query.query(&rays[k], hit)));
        }
        // SAFETY: the loop wrote the first `count` walks (`lane_groups` gives
        // at most INTERLEAVED lanes); a query left undropped only leaks.
        let made: &mut [(usize, SlabRay, Q::Lane<'_>)] =
            unsafe { std::slice::from_raw_parts_mut(walks.as_mut_ptr().cast(), count) };
        let ended = interleaved_walks::<_, W, S>(bvh, start, made, stats);
        for (k, &lane) in group[..count].iter().enumerate() {
            query.end(lane, &hits[k], ended >> k & 1 == 1);
        }
    }
}
