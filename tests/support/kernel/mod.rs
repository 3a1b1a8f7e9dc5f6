//! Shared helpers of the integration tests: seeded random rays, the lane-by-lane
//! comparison of a shape's packet kernel with its scalar kernel, and scene comparisons.

pub mod block;

use glam::Vec3;
use raypack::bounds::Aabb;
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

pub const PRIM: u32 = 5;

/// What an agreement run saw, so a test can check it was not vacuous.
#[derive(Debug, Default)]
pub struct Agreement {
    /// Active lanes compared.
    pub active: usize,
    /// Active lanes on which the kernel recorded a hit.
    pub hits: usize,
    /// Inactive lanes checked to be untouched.
    pub inactive: usize,
}

/// Random rays around a box: half start on a sphere a few box sizes away and aim
/// at a point of the (slightly grown) box, half start inside the grown box with
/// a random direction. A quarter get a random positive `t_min`, a quarter a
/// finite `t_max`.
pub fn rays_around(rng: &mut Rng, bounds: Aabb, n: usize) -> Vec<Ray> {
    let size = bounds.extent().length().max(1e-3);
    let lo = bounds.min - 0.25 * size;
    let hi = bounds.max + 0.25 * size;
    (0..n)
        .map(|_| {
            let (origin, dir) = if rng.f32() < 0.5 {
                let origin = bounds.center() + rng.range(1.0, 20.0) * size * rng.unit_vector();
                (origin, (rng.point_in(lo, hi) - origin).normalize())
            } else {
                (rng.point_in(lo, hi), rng.unit_vector())
            };
            let t_min = if rng.f32() < 0.25 {
                rng.range(0.0, size)
            } else {
                0.0
            };
            let t_max = if rng.f32() < 0.25 {
                rng.range(0.0, 10.0 * size)
            } else {
                f32::INFINITY
            };
            Ray::new(origin, dir, t_min, t_max)
        })
        .collect()
}

/// A prior record for a lane: mostly empty, sometimes an earlier hit of a
/// lower or higher primitive index at a random distance (so the kernel must
/// respect `hit.t` and the tie rule).
fn prior_record(rng: &mut Rng, ray: &Ray, scale: f32) -> Hit {
    let mut hit = Hit::none(ray);
    if rng.f32() < 0.25 {
        let prim = if rng.f32() < 0.5 { PRIM - 1 } else { PRIM + 1 };
        hit.record(rng.range(0.0, 20.0 * scale), prim, 0.25, 0.5);
    }
    hit
}

/// Check `kernel`'s packet kernel at width `F` against its scalar kernel on
/// `rays`, with random active masks and prior records. Panics on the first
/// lane that differs: hit versus miss, primitive, `t` beyond 1e-5 relative,
/// `(u, v)` beyond 1e-5, or a touched inactive lane.
pub fn check<K: Intersect, F: SimdFloat>(kernel: &K, rays: &[Ray], scale: f32, rng: &mut Rng) -> Agreement {
    let mut seen = Agreement::default();
    for chunk in rays.chunks_exact(F::LANES) {
        let mask = rng.next_u32() | rng.next_u32(); // about 3/4 of the lanes active
        let packet = RayPacket::<F>::from_rays_masked(chunk, mask);
        let priors: Vec<Hit> = chunk.iter().map(|r| prior_record(rng, r, scale)).collect();
        let mut hits = HitPacket::none(&packet);
        for (i, prior) in priors.iter().enumerate() {
            hits.set_hit(i, prior);
        }
        kernel.intersect_packet(&packet, PRIM, &mut hits);
        for (i, (ray, prior)) in chunk.iter().zip(&priors).enumerate() {
            let got = hits.hit(i);
            if !packet.is_active(i) {
                assert_eq!(got, *prior, "inactive lane {i} was changed, ray {ray:?}");
                seen.inactive += 1;
                continue;
            }
            let mut want = *prior;
            let recorded = kernel.intersect(ray, PRIM, &mut want);
            seen.active += 1;
            seen.hits += recorded as usize;
            assert_eq!(
                got.prim, want.prim,
                "lane {i}: primitive differs, ray {ray:?}, prior {prior:?}"
            );
            let t_ok = got.t == want.t || (got.t - want.t).abs() <= 1e-5 * want.t.abs();
            assert!(t_ok, "lane {i}: t {} vs scalar {}, ray {ray:?}", got.t, want.t);
            assert!(
                (got.u - want.u).abs() <= 1e-5 && (got.v - want.v).abs() <= 1e-5,
                "lane {i}: (u, v) ({}, {}) vs scalar ({}, {}), ray {ray:?}",
                got.u,
                got.v,
                want.u,
                want.v
            );
        }
    }
    seen
}

/// True when `hit` is the empty record of `ray`.
pub fn is_miss(hit: &Hit) -> bool {
    hit.prim == NO_HIT
}

/// A ray over `[0, ∞)` from `origin` along the normalised `dir`.
pub fn ray(origin: Vec3, dir: Vec3) -> Ray {
    Ray::unbounded(origin, dir.normalize())
}

/// The scalar kernel's hit distance on `ray`, if any.
pub fn scalar_t<K: Intersect>(kernel: &K, ray: &Ray) -> Option<f32> {
    let mut hit = Hit::none(ray);
    kernel.intersect(ray, PRIM, &mut hit).then_some(hit.t)
}

/// The 8-wide packet kernel's hit distance on `ray` (alone in lane 0), if any.
pub fn packet_t<K: Intersect>(kernel: &K, ray: &Ray) -> Option<f32> {
    let packet = RayPacket::<wide::f32x8>::from_rays(&[*ray]);
    let mut hits = HitPacket::none(&packet);
    kernel.intersect_packet(&packet, PRIM, &mut hits);
    let hit = hits.hit(0);
    (!is_miss(&hit)).then_some(hit.t)
}

/// Both kernels' hit distance on `ray`, after checking they agree exactly.
pub fn both_t<K: Intersect>(kernel: &K, ray: &Ray) -> Option<f32> {
    let (s, p) = (scalar_t(kernel, ray), packet_t(kernel, ray));
    assert_eq!(s, p, "scalar and packet kernels differ on {ray:?}");
    s
}

/// Trace `n` random rays from [`random_ray`] around `[lo, hi]` through both
/// kernels of `shape` with [`check`].
pub fn assert_packet_matches_scalar<K: Intersect, F: SimdFloat>(
    shape: &K,
    lo: Vec3,
    hi: Vec3,
    n: usize,
    seed: u64,
) -> Agreement {
    let mut rng = Rng::new(seed);
    let rays: Vec<Ray> = (0..n).map(|_| random_ray(&mut rng, lo, hi)).collect();
    check::<K, F>(shape, &rays, (hi - lo).length(), &mut rng)
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
