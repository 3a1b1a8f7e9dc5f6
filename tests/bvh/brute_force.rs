//! The lecture's brute-force loop: packet and scalar queries agree lane by lane
//! over a mixed scene, the nearest primitive wins, and any-hit agrees with nearest-hit.

use crate::support::kernel::random_ray;
use glam::{Mat4, Vec3};
use raypack::accel::{Accel, BruteForce};
use raypack::bench::kernels::star_polygon;
use raypack::geometry::{Intersect, Plane, Primitive, Sphere, Transformed, Triangle};
use raypack::packet::RayPacket8;
use raypack::ray::{Hit, Ray};
use raypack::rng::Rng;
use raypack::simd::SimdFloat;

/// Spheres, triangles, polygons, transformed spheres and one plane, at random.
fn mixed_scene(rng: &mut Rng, n: usize) -> Vec<Primitive> {
    let (lo, hi) = (Vec3::splat(-4.0), Vec3::splat(4.0));
    let mut prims: Vec<Primitive> = (0..n)
        .map(|i| {
            let c = rng.point_in(lo, hi);
            match i % 4 {
                0 => Primitive::Sphere(Sphere::new(c, rng.range(0.1, 0.8))),
                1 => Primitive::Triangle(Triangle::new(
                    c,
                    c + rng.point_in(-Vec3::ONE, Vec3::ONE),
                    c + rng.point_in(-Vec3::ONE, Vec3::ONE),
                )),
                2 => Primitive::Polygon(star_polygon()),
                _ => {
                    let m = Mat4::from_translation(c)
                        * Mat4::from_scale(rng.point_in(Vec3::splat(0.2), Vec3::ONE));
                    let s = Primitive::Sphere(Sphere::new(Vec3::ZERO, 1.0));
                    Primitive::Transformed(Box::new(Transformed::new(s, m).unwrap()))
                }
            }
        })
        .collect();
    prims.push(Primitive::Plane(Plane::implicit(0.0, 1.0, 0.0, 5.0).unwrap()));
    prims
}

#[test]
fn packet_and_scalar_brute_force_agree_and_find_the_nearest() {
    let mut rng = Rng::new(70);
    let prims = mixed_scene(&mut rng, 60);
    let accel = BruteForce::new(&prims);
    let mut hits = 0;
    for _ in 0..20_000 {
        let rays: Vec<Ray> = (0..8)
            .map(|_| random_ray(&mut rng, Vec3::splat(-4.0), Vec3::splat(4.0)))
            .collect();
        let packet = RayPacket8::from_rays(&rays);
        let packet_hits = accel.intersect_packet(&packet);
        let occluded = accel.occluded_packet(&packet).bitmask();
        for (i, ray) in rays.iter().enumerate() {
            let hit = accel.intersect(ray);
            let lane = packet_hits.hit(i);
            assert_eq!(lane.prim, hit.prim, "lane {i} of {ray:?}");
            assert!(lane.t == hit.t || (lane.t - hit.t).abs() <= 1e-5 * hit.t.abs());
            assert_eq!(accel.occluded(ray), hit.is_hit(), "any-hit vs nearest on {ray:?}");
            assert_eq!(occluded >> i & 1 == 1, hit.is_hit(), "packet any-hit on lane {i}");
            // Nearest: no primitive has an accepted hit before the reported one.
            for (j, p) in prims.iter().enumerate() {
                let mut single = Hit::none(ray);
                if p.intersect(ray, j as u32, &mut single) {
                    assert!(
                        single.t >= hit.t,
                        "primitive {j} is nearer: {} < {}",
                        single.t,
                        hit.t
                    );
                }
            }
            hits += hit.is_hit() as usize;
        }
    }
    assert!(hits > 20_000, "only {hits} hits");
}

#[test]
fn empty_scene_misses_everything() {
    let accel = BruteForce::new(&[]);
    let ray = Ray::unbounded(Vec3::ZERO, Vec3::Z);
    assert!(!accel.intersect(&ray).is_hit());
    assert!(!accel.occluded(&ray));
    let packet = RayPacket8::from_rays(&[ray; 8]);
    assert!(accel.occluded_packet(&packet).none());
}
