//! Traversal statistics and the `--accel` choice: counted queries return exactly
//! what plain queries return, and the counts mean what they say.

use crate::support;
use clap::ValueEnum;
use raypack::accel::{Accel, AccelKind, BruteForce, Bvh, TraversalCounter, TraversalStats};
use raypack::engines::{Engine, EngineOptions, WithAccel};
use raypack::packet::RayPacket8;
use raypack::ray::Ray;
use raypack::scene::generate::random;
use raypack::simd::SimdFloat;

#[test]
fn counted_queries_return_the_plain_answers() {
    let prims = random::random_mixed(2000, 21);
    let bounds = support::bvh::scene_bounds(&prims);
    let rays = support::bvh::random_rays(bounds, 4000, 22);
    let bvh = Bvh::new(&prims);
    let brute = BruteForce::new(&prims);
    let (mut s_bvh, mut s_brute) = (TraversalCounter::totals(), TraversalCounter::totals());
    for ray in &rays {
        let plain = support::bvh::key(&bvh.intersect(ray));
        assert_eq!(support::bvh::key(&bvh.intersect_counted(ray, &mut s_bvh)), plain);
        assert_eq!(
            support::bvh::key(&brute.intersect_counted(ray, &mut s_brute)),
            plain
        );
        assert_eq!(
            bvh.occluded_counted(ray, &mut TraversalCounter::totals()),
            bvh.occluded(ray)
        );
        assert_eq!(
            brute.occluded_counted(ray, &mut TraversalCounter::totals()),
            bvh.occluded(ray)
        );
    }
    for chunk in rays.chunks(8) {
        let p = RayPacket8::from_rays(chunk);
        let plain = bvh.intersect_packet(&p);
        let counted = bvh.intersect_packet_counted(&p, &mut TraversalCounter::totals());
        let brute_counted = brute.intersect_packet_counted(&p, &mut TraversalCounter::totals());
        for lane in 0..chunk.len() {
            assert_eq!(
                support::bvh::key(&counted.hit(lane)),
                support::bvh::key(&plain.hit(lane))
            );
            assert_eq!(
                support::bvh::key(&brute_counted.hit(lane)),
                support::bvh::key(&plain.hit(lane))
            );
        }
        let occluded = bvh.occluded_packet(&p).bitmask();
        let mut s = TraversalCounter::totals();
        assert_eq!(bvh.occluded_packet_counted(&p, &mut s).bitmask(), occluded);
        assert_eq!(brute.occluded_packet_counted(&p, &mut s).bitmask(), occluded);
    }
    let (s_bvh, s_brute) = (s_bvh.total(), s_brute.total());
    // Brute force tests every primitive once per ray and visits no node.
    assert_eq!(s_brute.rays, rays.len() as u64);
    assert_eq!(s_brute.prim_tests, (rays.len() * prims.len()) as u64);
    assert_eq!(s_brute.nodes_visited, 0);
    // The BVH visits nodes and tests a small fraction of the primitives.
    assert_eq!(s_bvh.rays, rays.len() as u64);
    assert!(s_bvh.nodes_visited >= rays.len() as u64);
    assert!(
        s_bvh.prims_per_ray() < prims.len() as f64 / 20.0,
        "{}",
        s_bvh.caption()
    );
    assert_eq!(s_bvh.simd_lane_slots, 0, "single rays make no SIMD steps");
}

#[test]
fn coherent_packets_fill_more_lanes_than_incoherent_ones() {
    let prims = random::bumpy_sphere(20_000, 23);
    let bvh = Bvh::new(&prims);
    let bounds = support::bvh::scene_bounds(&prims);
    let mut primary = TraversalCounter::totals();
    for (_, packet) in support::bvh::primary_packets(bounds, 256, 256) {
        bvh.intersect_packet_counted(&packet, &mut primary);
    }
    // Rays from one point per packet in random directions, as secondary rays
    // from neighbouring hit points are (rays from all over the scene share no
    // node, and walk as single rays from the root).
    let mut random = TraversalCounter::totals();
    for chunk in support::bvh::random_rays(bounds, 256 * 256, 24).chunks_mut(8) {
        let origin = chunk[0].origin;
        chunk.iter_mut().for_each(|ray| ray.origin = origin);
        bvh.intersect_packet_counted(&RayPacket8::from_rays(chunk), &mut random);
    }
    let (primary, random) = (primary.total(), random.total());
    assert_eq!(primary.rays, 256 * 256);
    assert_eq!(primary.packets, 256 * 256 / 8);
    let (p, r) = (primary.lane_utilisation(), random.lane_utilisation());
    assert!(p > 0.0 && p <= 1.0, "primary {p}");
    assert_eq!(primary.fallback_rays, 0, "coherent packets stay packets");
    // Incoherent packets walk the top of the wide tree together, with fewer
    // lanes taking part than coherent ones, and split into single rays below
    // (a lane may do so in more than one subtree).
    assert!(r > 0.0 && r < p, "random {r}, primary {p}");
    assert!(random.fallback_rays > 0);
    assert!(primary.simd_active_lanes <= primary.simd_lane_slots);
}

#[test]
fn accel_kind_parses_and_raypack_builds_either_structure() {
    assert_eq!(AccelKind::default(), AccelKind::Bvh);
    assert_eq!(AccelKind::from_str("none", false), Ok(AccelKind::None));
    assert_eq!(AccelKind::from_str("bvh", false), Ok(AccelKind::Bvh));
    assert!(AccelKind::from_str("kd", false).is_err());
    assert_eq!(AccelKind::Bvh.to_string(), "bvh");
    let prims = random::random_spheres(300, 25);
    let rays = support::bvh::random_rays(support::bvh::scene_bounds(&prims), 2000, 26);
    // The registry's raypack engine builds the kind asked for, and each traces as its own type.
    let traced = [AccelKind::None, AccelKind::Bvh].map(|accel| {
        let options = EngineOptions {
            accel,
            ..EngineOptions::default()
        };
        let built = Engine::Raypack.device(&options).unwrap().build(&prims).unwrap();
        assert_eq!(built.describe().structure, accel.name());
        assert_eq!(built.sah_cost().is_some(), accel == AccelKind::Bvh);
        built.visit(CountedHits(&rays))
    });
    let [(none_hits, none_stats), (bvh_hits, bvh_stats)] = traced;
    assert_eq!(none_hits, bvh_hits);
    assert!(none_hits.iter().any(|&(_, occluded)| occluded), "some rays hit");
    assert!(bvh_stats.prim_tests < none_stats.prim_tests / 10);
}

/// Each ray's nearest hit (as [`support::bvh::key`]) and occlusion, with the traversal's counts.
struct CountedHits<'r>(&'r [Ray]);

impl WithAccel<'_> for CountedHits<'_> {
    type Output = (Vec<((u32, u32, u32, u32), bool)>, TraversalStats);

    fn run<A: Accel>(self, accel: &A) -> Self::Output {
        let mut stats = TraversalCounter::totals();
        let hits = self
            .0
            .iter()
            .map(|ray| {
                let hit = accel.intersect_counted(ray, &mut stats);
                (support::bvh::key(&hit), accel.occluded(ray))
            })
            .collect();
        (hits, *stats.total())
    }
}
