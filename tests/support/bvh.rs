//! Shared checks of the BVH test files: a BVH must answer every query exactly
//! as brute force does.

use glam::Vec3;
use raypack::accel::{Accel, BruteForce, Bvh};
use raypack::bounds::Aabb;
use raypack::geometry::Primitive;
use raypack::packet::RayPacket;
use raypack::ray::{Hit, Ray};
use raypack::rng::Rng;
use raypack::scene::generate::random::framing_camera;
use raypack::simd::SimdFloat;
use wide::{f32x4, f32x8, f32x16};

/// The fields a kernel writes, bit for bit.
pub fn key(h: &Hit) -> (u32, u32, u32, u32) {
    (h.t.to_bits(), h.prim, h.u.to_bits(), h.v.to_bits())
}

/// The bounds of the bounded primitives, or the unit cube when there are none.
pub fn scene_bounds(prims: &[Primitive]) -> Aabb {
    let b = prims
        .iter()
        .filter_map(Primitive::bounds)
        .fold(Aabb::EMPTY, Aabb::union);
    if b.is_empty() || !b.min.is_finite() || !b.max.is_finite() {
        Aabb::new(Vec3::splat(-1.0), Vec3::ONE)
    } else {
        b
    }
}

/// `n` incoherent rays from the box grown by half its size: a quarter are
/// segments between two random points (finite `t_max`, like shadow rays), a
/// quarter start a little way out (`t_min > 0`).
pub fn random_rays(bounds: Aabb, n: usize, seed: u64) -> Vec<Ray> {
    let mut rng = Rng::new(seed);
    let grow = 0.5 * bounds.extent();
    let (lo, hi) = (bounds.min - grow, bounds.max + grow);
    (0..n)
        .map(|i| {
            let origin = rng.point_in(lo, hi);
            match i % 4 {
                0 => {
                    let to = rng.point_in(lo, hi);
                    let d = to - origin;
                    Ray::new(origin, d.normalize_or(Vec3::X), 0.0, d.length())
                }
                1 => Ray::new(
                    origin,
                    rng.unit_vector(),
                    rng.range(0.0, 0.3) * grow.length(),
                    f32::INFINITY,
                ),
                _ => Ray::unbounded(origin, rng.unit_vector()),
            }
        })
        .collect()
}

/// Primary rays of a framing camera at `width × height`, in 4×2 pixel packets.
pub fn primary_packets(bounds: Aabb, width: u32, height: u32) -> Vec<(Vec<Ray>, RayPacket<f32x8>)> {
    let camera = framing_camera(bounds, width, height);
    let mut out = Vec::new();
    for y in (0..height).step_by(2) {
        for x in (0..width).step_by(4) {
            let pixels: Vec<(u32, u32)> = (0..8).map(|k| (x + k % 4, y + k / 4)).collect();
            let packet = camera.pixel_packet::<f32x8>(&pixels);
            let rays = (0..8).map(|lane| packet.ray(lane)).collect();
            out.push((rays, packet));
        }
    }
    out
}

/// Compare one packet of width `F` lane by lane with the brute-force answers `expect`.
fn check_packet<F: SimdFloat>(bvh: &Bvh, rays: &[Ray], expect: &[Hit], what: &str) {
    let packet = RayPacket::<F>::from_rays(rays);
    let hits = bvh.intersect_packet(&packet);
    let occluded = bvh.occluded_packet(&packet).bitmask();
    for (lane, (ray, e)) in rays.iter().zip(expect).enumerate() {
        assert_eq!(
            key(&hits.hit(lane)),
            key(e),
            "{what}: packet{} lane {lane} {ray:?}",
            F::LANES
        );
        assert_eq!(
            occluded >> lane & 1 == 1,
            e.is_hit(),
            "{what}: occluded packet lane {lane} {ray:?}"
        );
    }
}

/// Every query of the BVH against brute force on `rays`, single and packet
/// (8 wide; every 16th packet also 4 and 16 wide); returns the hit count.
pub fn check_rays(prims: &[Primitive], bvh: &Bvh, rays: &[Ray], what: &str) -> usize {
    let brute = BruteForce::new(prims);
    let mut hits = 0;
    for (c, chunk) in rays.chunks(16).enumerate() {
        let expect: Vec<Hit> = chunk.iter().map(|r| brute.intersect(r)).collect();
        for (ray, e) in chunk.iter().zip(&expect) {
            let h = bvh.intersect(ray);
            assert_eq!(key(&h), key(e), "{what}: single {ray:?}");
            assert_eq!(bvh.occluded(ray), e.is_hit(), "{what}: occluded {ray:?}");
            assert_eq!(
                brute.occluded(ray),
                e.is_hit(),
                "{what}: brute-force occluded {ray:?}"
            );
            hits += usize::from(e.is_hit());
        }
        for (rs, es) in chunk.chunks(8).zip(expect.chunks(8)) {
            check_packet::<f32x8>(bvh, rs, es, what);
        }
        if c % 16 == 0 {
            check_packet::<f32x16>(bvh, chunk, &expect, what);
            check_packet::<f32x4>(bvh, &chunk[..4.min(chunk.len())], &expect, what);
        }
    }
    hits
}

/// The acceptance check of a scene: 10⁵ random rays and 10⁵ primary rays
/// (316 × 316 pixels in 4×2 packets), every answer equal to brute force's.
pub fn check_scene(name: &str, prims: &[Primitive], seed: u64) {
    let bvh = Bvh::new(prims);
    let bounds = scene_bounds(prims);
    let random = random_rays(bounds, 100_000, seed);
    let hits = check_rays(prims, &bvh, &random, &format!("{name} random"));
    assert!(
        hits > random.len() / 20 && hits < random.len() * 19 / 20,
        "{name}: {hits} hits of {} random rays: the test would prove little",
        random.len()
    );
    let brute = BruteForce::new(prims);
    let mut primary_hits = 0;
    let packets = primary_packets(bounds, 316, 316);
    for (rays, packet) in &packets {
        let hits = bvh.intersect_packet(packet);
        let occluded = bvh.occluded_packet(packet).bitmask();
        for (lane, ray) in rays.iter().enumerate() {
            let e = brute.intersect(ray);
            assert_eq!(key(&bvh.intersect(ray)), key(&e), "{name} primary single {ray:?}");
            assert_eq!(
                key(&hits.hit(lane)),
                key(&e),
                "{name} primary packet lane {lane} {ray:?}"
            );
            assert_eq!(
                occluded >> lane & 1 == 1,
                e.is_hit(),
                "{name} primary occluded {ray:?}"
            );
            primary_hits += usize::from(e.is_hit());
        }
    }
    assert!(
        primary_hits > packets.len(),
        "{name}: too few primary hits ({primary_hits})"
    );
}
