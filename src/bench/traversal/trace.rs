//! The timed loops: the single rays of one kind ([`KindRays`]) in batches, or its
//! 8- or 16-ray packets (the [`PATHS`]), over any [`Accel`], tiles of [`TILE_RAYS`] spread over the
//! current rayon pool. They count hits, so that the work cannot be skipped.
//!
//! Every tile is one rayon task (`with_max_len(1)`), as the renderer's are, so
//! an idle thread steals whole tiles from a busy one. Left to rayon's
//! adaptive split, a set of a few hundred tiles was cut into about four runs
//! on two threads, each traced to its end by one thread, so the thread that
//! finished first waited for the other's last run: 2-thread rounds ran
//! 1.5–1.9× the 1-thread speed where a task per tile runs 2.0×, by more or
//! less on each engine and ray kind (docs/measurements.md, "Two threads: one
//! task per tile").

use rayon::prelude::*;

use crate::accel::Accel;
use crate::accel::stats::NoStats;
use crate::bench::rays::{KindRays, Query};
use crate::packet::RayPacket;
use crate::ray::{Hit, Ray};
use crate::render::batch::BATCH;
use crate::render::settings::KernelKind;
use crate::simd::SimdFloat;

/// Rays per tile: 16×16 pixels, 32 packets of 4×2 or 16 of 4×4.
pub const TILE_RAYS: usize = 256;

/// Trace the rays of `set` one by one with its kind's query, tiles spread over
/// the current rayon pool; returns how many hit. The rays go in batches of
/// [`BATCH`], as the renderer's scalar kernel hands them over: a BVH enters its
/// instruction set's code once per batch, not once per ray
/// ([`Accel::intersect_each_counted`]); an outside engine still takes them one
/// call per ray (`rtcIntersect1`).
pub fn trace_single(accel: &impl Accel, set: &KindRays) -> u64 {
    let query = set.kind.query();
    set.rays
        .par_chunks(TILE_RAYS)
        .with_max_len(1)
        .map(|tile| {
            tile.chunks(BATCH)
                .map(|rays| trace_batch(accel, rays, query))
                .sum::<u64>()
        })
        .sum()
}

/// Trace one batch of up to [`BATCH`] single rays (at least one) with
/// `query`, in one call of `accel`; returns how many hit.
#[inline]
pub fn trace_batch(accel: &impl Accel, rays: &[Ray], query: Query) -> u64 {
    let all = u32::MAX >> (32 - rays.len());
    match query {
        Query::Nearest => {
            // Every record is overwritten: the first ray's will do.
            let mut hits = [Hit::none(&rays[0]); BATCH];
            accel.intersect_each_counted(rays, all, &mut hits, &mut NoStats);
            hits[..rays.len()].iter().filter(|h| h.is_hit()).count() as u64
        }
        Query::AnyHit => u64::from(accel.occluded_each_counted(rays, all, &mut NoStats).count_ones()),
    }
}

/// Trace the 8-ray packets of `set` with its kind's query, tiles spread over
/// the current rayon pool; returns how many rays hit.
pub fn trace_packets(accel: &impl Accel, set: &KindRays) -> u64 {
    trace_packed(accel, &set.packets, set.kind.query())
}

/// The paths a ray set is traced by, in the order of every row's figures:
/// single rays, then 8- and 16-ray packets.
pub const PATHS: [KernelKind; 3] = [KernelKind::Scalar, KernelKind::Packet8, KernelKind::Packet16];

/// A path's name in the traversal bench's rows and figures: `single`,
/// `packet8`, `packet16`.
pub fn path_name(path: KernelKind) -> &'static str {
    match path {
        KernelKind::Scalar => "single",
        packets => packets.name(),
    }
}

/// Trace the rays of `set` by `path` (single rays, or its 8- or 16-ray
/// packets) with its kind's query; returns how many hit.
pub fn trace_path(accel: &impl Accel, set: &KindRays, path: KernelKind) -> u64 {
    match path {
        KernelKind::Scalar => trace_single(accel, set),
        KernelKind::Packet8 => trace_packets(accel, set),
        KernelKind::Packet16 => trace_packed(accel, &set.packets16, set.kind.query()),
    }
}

/// Trace `packets` with `query`, tiles spread over the current rayon pool;
/// returns how many rays hit.
fn trace_packed<F: SimdFloat>(accel: &impl Accel, packets: &[RayPacket<F>], query: Query) -> u64 {
    packets
        .par_chunks(TILE_RAYS / F::LANES)
        .with_max_len(1)
        .map(|tile| {
            tile.iter()
                .map(|p| {
                    let hit = match query {
                        Query::Nearest => accel.intersect_packet(p).hit_mask(),
                        Query::AnyHit => accel.occluded_packet(p),
                    };
                    u64::from(hit.bitmask().count_ones())
                })
                .sum::<u64>()
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::Bvh;
    use crate::bench::rays::RayKind;
    use crate::bench::traversal::TraversalSetup;

    #[test]
    fn single_rays_and_packets_agree_with_brute_force_on_every_kind() {
        let s = TraversalSetup::generated("mesh", 500, (40, 20), 100, &RayKind::ALL).expect("known kind");
        assert_eq!(s.rays_of(RayKind::Primary).expect("primary").rays.len(), 800);
        let bvh = Bvh::new(&s.scene.primitives);
        let brute = crate::accel::BruteForce::new(&s.scene.primitives);
        for set in &s.kinds {
            let hits = trace_single(&brute, set);
            assert_eq!(trace_single(&bvh, set), hits, "{:?}", set.kind);
            assert_eq!(trace_packets(&bvh, set), hits, "{:?}", set.kind);
            assert_eq!(trace_packets(&brute, set), hits, "{:?}", set.kind);
            assert_eq!(
                trace_path(&bvh, set, KernelKind::Packet16),
                hits,
                "{:?}",
                set.kind
            );
        }
    }
}
