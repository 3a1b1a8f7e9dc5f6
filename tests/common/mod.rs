//! Shared helpers of the integration tests: seeded random rays, the lane-by-lane
//! comparison of a shape's packet kernel with its scalar kernel, and scene comparisons.
#![allow(dead_code)]

use glam::Vec3;
use raypack::geometry::{Intersect, Primitive};
use raypack::packet::{HitPacket, RayPacket};
use raypack::ray::{Hit, NO_HIT, Ray};
use raypack::rng::Rng;
use raypack::scene::Scene;
use raypack::simd::SimdFloat;

/// A random ray around the box `[lo, hi]`: aimed at it from outside, started
/// inside it, or random; with random intervals now and then.
pub fn random_ray(rng: &mut Rng, lo: Vec3, hi: Vec3) -> Ray {
    let center = 0.5 * (lo + hi);
    let size = (hi - lo).length().max(1e-3);
    let (origin, target) = match rng.below(4) {
        // From a sphere around the box towards a point of the box.
        0 | 1 => (center + 2.0 * size * rng.unit_vector(), rng.point_in(lo, hi)),
        // From inside the box.
        2 => (rng.point_in(lo, hi), rng.point_in(lo - size, hi + size)),
        // Anywhere near, in any direction.
        _ => (
            rng.point_in(lo - size, hi + size),
            rng.point_in(lo - size, hi + size),
        ),
    };
    let dir = (target - origin).try_normalize().unwrap_or(Vec3::Z);
    let (t_min, t_max) = match rng.below(4) {
        0 => (rng.range(0.0, size), rng.range(size, 4.0 * size)),
        1 => (1e-4, f32::INFINITY),
        _ => (0.0, f32::INFINITY),
    };
    Ray::new(origin, dir, t_min, t_max)
}

/// A record a kernel may meet: empty, or an earlier hit on a lower or higher
/// primitive index at some t (exercises the "closer" and tie rules).
pub fn prior_hit(rng: &mut Rng, ray: &Ray, size: f32) -> Hit {
    let mut hit = Hit::none(ray);
    if rng.below(3) == 0 {
        hit.t = rng.range(0.0, 3.0 * size).min(ray.t_max);
        hit.prim = rng.below(10);
        hit.u = 0.25;
        hit.v = 0.5;
    }
    hit
}

/// Counts of one agreement run.
#[derive(Debug, Default)]
pub struct Agreement {
    /// Lanes compared (active and inactive).
    pub lanes: usize,
    /// Active lanes on which the scalar kernel recorded a hit.
    pub hits: usize,
}

/// Trace `n` random rays (in packets of `F::LANES`, about a quarter of the lanes
/// inactive) with both kernels of `shape` as primitive 5, and assert that every
/// lane agrees: hit or miss, primitive, t to 1e-5 relative, u and v; inactive
/// lanes keep their record bit for bit.
pub fn assert_packet_matches_scalar<K: Intersect, F: SimdFloat>(
    name: &str,
    shape: &K,
    lo: Vec3,
    hi: Vec3,
    n: usize,
    seed: u64,
) -> Agreement {
    const PRIM: u32 = 5;
    let mut rng = Rng::new(seed);
    let size = (hi - lo).length();
    let mut stats = Agreement::default();
    let lanes = F::LANES;
    for _ in 0..n.div_ceil(lanes) {
        let rays: Vec<Ray> = (0..lanes).map(|_| random_ray(&mut rng, lo, hi)).collect();
        let priors: Vec<Hit> = rays.iter().map(|r| prior_hit(&mut rng, r, size)).collect();
        let mask = rng.next_u32() | rng.next_u32(); // ~75% of lanes active
        let packet = RayPacket::<F>::from_rays_masked(&rays, mask);
        let mut hits = HitPacket::none(&packet);
        for (i, h) in priors.iter().enumerate() {
            hits.set_hit(i, h);
        }
        shape.intersect_packet(&packet, PRIM, &mut hits);
        for i in 0..lanes {
            stats.lanes += 1;
            let got = hits.hit(i);
            if mask >> i & 1 == 0 {
                assert!(
                    got.t.to_bits() == priors[i].t.to_bits() && got.prim == priors[i].prim,
                    "{name}: inactive lane {i} changed: {got:?} vs {:?} for {:?}",
                    priors[i],
                    rays[i]
                );
                continue;
            }
            let mut want = priors[i];
            let updated = shape.intersect(&rays[i], PRIM, &mut want);
            stats.hits += updated as usize;
            let same_t = got.t == want.t
                || (got.t - want.t).abs() <= 1e-5 * want.t.abs().max(got.t.abs())
                || (got.t.is_nan() && want.t.is_nan());
            assert!(
                got.prim == want.prim && same_t,
                "{name}: lane {i} disagrees: packet {got:?}, scalar {want:?} (updated: {updated}) for {:?}",
                rays[i]
            );
            if updated {
                assert!(
                    (got.u - want.u).abs() <= 1e-4 && (got.v - want.v).abs() <= 1e-4,
                    "{name}: lane {i} (u, v) differ: packet {got:?}, scalar {want:?}"
                );
                assert!(
                    want.t.is_finite() && want.prim == PRIM,
                    "{name}: bad record {want:?}"
                );
            } else {
                assert!(want.prim == priors[i].prim || want.prim == NO_HIT);
            }
        }
    }
    stats
}

/// Rays with a NaN or infinite component, each with whether it must miss: NaN
/// anywhere, or an infinite origin or direction component, is a miss; an
/// infinite `t_max` is an ordinary unbounded ray and `t_min = −∞` a legal interval.
pub fn poisoned_rays() -> Vec<(Ray, bool)> {
    let mut rays = Vec::new();
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        for field in 0..8 {
            let mut v = [0.1f32, 0.2, 5.0, 0.05, 0.02, -1.0, 0.0, f32::INFINITY];
            v[field] = bad;
            let must_miss = bad.is_nan() || field < 6;
            let ray = Ray::new(
                Vec3::new(v[0], v[1], v[2]),
                Vec3::new(v[3], v[4], v[5]),
                v[6],
                v[7],
            );
            rays.push((ray, must_miss));
        }
        rays.push((Ray::new(Vec3::splat(bad), Vec3::splat(bad), bad, bad), true));
    }
    rays
}

/// Assert that both kernels of `shape` (placed around the origin, where the
/// clean version of the poisoned rays points) handle every poisoned ray without
/// panicking, agree with each other, miss where they must, and never record a
/// NaN or infinite t.
pub fn assert_poisoned_rays_miss<K: Intersect>(name: &str, shape: &K) {
    for (ray, must_miss) in poisoned_rays() {
        let mut hit = Hit::none(&ray);
        let updated = shape.intersect(&ray, 0, &mut hit);
        assert!(
            !(must_miss && updated),
            "{name}: scalar hit poisoned ray {ray:?}: {hit:?}"
        );
        assert!(
            !updated || hit.t.is_finite(),
            "{name}: scalar recorded {hit:?} for {ray:?}"
        );
        let packet = RayPacket::<wide::f32x8>::from_rays(&[ray; 8]);
        let mut hits = HitPacket::none(&packet);
        shape.intersect_packet(&packet, 0, &mut hits);
        for i in 0..8 {
            let h = hits.hit(i);
            assert_eq!(h.prim, hit.prim, "{name}: packet and scalar differ on {ray:?}");
            assert!(
                h.prim == NO_HIT || h.t.is_finite(),
                "{name}: packet recorded {h:?} for {ray:?}"
            );
        }
    }
}

/// Assert two scenes hold the same primitives, in the same order, with the
/// same materials.
#[track_caller]
pub fn assert_same_geometry(a: &Scene, b: &Scene) {
    assert_eq!(a.primitives.len(), b.primitives.len(), "primitive counts differ");
    for (i, (p, q)) in a.primitives.iter().zip(&b.primitives).enumerate() {
        assert_eq!(p, q, "primitive {i} differs");
    }
    assert_eq!(a.material_of, b.material_of);
    assert_eq!(a.materials, b.materials);
}

/// The vertices of a triangle primitive.
#[track_caller]
pub fn triangle_vertices(p: &Primitive) -> [Vec3; 3] {
    match p {
        Primitive::Triangle(t) => t.vertices(),
        other => panic!("expected a triangle, got {other:?}"),
    }
}
