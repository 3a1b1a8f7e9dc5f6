//! Inside-only spheres (NFF's negative radius): only the far root is visible and
//! the normal points inwards; packet and scalar kernels agree lane by lane.

use crate::support;
use crate::support::kernel::{Agreement, both_t, ray, rays_around};
use glam::Vec3;
use raypack::geometry::{Primitive, Sphere};
use raypack::ray::{Hit, Ray};
use raypack::rng::Rng;
use wide::{f32x4, f32x8, f32x16};

fn dome() -> Sphere {
    Sphere::inside_only(Vec3::new(1.0, 2.0, 3.0), 2.0)
}

#[test]
fn construction_keeps_a_positive_radius_and_the_flag() {
    let s = Sphere::inside_only(Vec3::ZERO, -3.0);
    assert_eq!(s.radius, 3.0);
    assert!(s.inside_only);
    assert!(!Sphere::new(Vec3::ZERO, -3.0).inside_only);
    assert_eq!(s.bounds(), Sphere::new(Vec3::ZERO, 3.0).bounds());
}

#[test]
fn from_outside_the_front_is_invisible_and_the_back_is_hit() {
    let s = dome();
    let r = ray(Vec3::new(1.0, 2.0, -7.0), Vec3::Z);
    // An ordinary sphere shows its front at t = 8, the inside-only one its back at t = 12.
    assert_eq!(both_t(&Sphere::new(s.center, s.radius), &r), Some(8.0));
    assert_eq!(both_t(&s, &r), Some(12.0));
    // With the back beyond t_max nothing is seen, not even the front.
    assert_eq!(both_t(&s, &Ray::new(r.origin, r.dir, 0.0, 11.0)), None);
    // Pointing away: nothing.
    assert_eq!(both_t(&s, &ray(r.origin, -Vec3::Z)), None);
}

#[test]
fn from_inside_the_far_wall_is_hit() {
    let s = dome();
    for dir in [Vec3::X, -Vec3::Y, Vec3::new(1.0, 1.0, 1.0)] {
        let t = both_t(&s, &ray(s.center, dir)).unwrap();
        assert!((t - 2.0).abs() < 1e-6, "{t}");
    }
    // Past the far wall (t_min beyond it) there is nothing left to see.
    assert_eq!(both_t(&s, &Ray::new(s.center, Vec3::X, 2.5, f32::INFINITY)), None);
}

#[test]
fn tangent_rays_hit_and_normals_point_inwards() {
    let s = dome();
    let t = both_t(&s, &ray(Vec3::new(-9.0, 4.0, 3.0), Vec3::X)).unwrap();
    assert!((t - 10.0).abs() < 1e-5, "{t}");
    let mut rng = Rng::new(5);
    for r in rays_around(&mut rng, s.bounds(), 2000) {
        if let Some(t) = both_t(&s, &r) {
            let p = r.at(t);
            let n = Primitive::Sphere(s).geometric_normal(&r, &Hit { t, ..Hit::none(&r) });
            assert!((n.length() - 1.0).abs() < 1e-4);
            assert!(n.dot(p - s.center) < 0.0, "normal {n} at {p} points outwards");
            // At the far root the ray is leaving the sphere: it runs outwards.
            assert!(r.dir.dot(p - s.center) >= -1e-3, "{r:?} hit a near root at {p}");
        }
    }
}

#[test]
fn packet_kernels_agree_with_scalar_on_a_million_random_rays() {
    let mut rng = Rng::new(0x5EED);
    let mut total = Agreement::default();
    for _ in 0..250 {
        let s = Sphere::inside_only(
            rng.point_in(Vec3::splat(-5.0), Vec3::splat(5.0)),
            rng.range(0.1, 3.0),
        );
        let rays = rays_around(&mut rng, s.bounds(), 4096);
        let seen = support::kernel::check::<_, f32x8>(&s, &rays, 2.0 * s.radius, &mut rng);
        total.active += seen.active;
        total.hits += seen.hits;
        total.inactive += seen.inactive;
        support::kernel::check::<_, f32x4>(&s, &rays[..256], 2.0 * s.radius, &mut rng);
        support::kernel::check::<_, f32x16>(&s, &rays[..256], 2.0 * s.radius, &mut rng);
    }
    assert!(total.active + total.inactive >= 1_000_000, "{total:?}");
    let hit_rate = total.hits as f64 / total.active as f64;
    assert!((0.05..0.95).contains(&hit_rate), "hit rate {hit_rate}");
}

#[test]
fn non_finite_rays_miss() {
    let s = dome();
    let good = ray(s.center, Vec3::X);
    for r in [
        Ray {
            origin: Vec3::NAN,
            ..good
        },
        Ray {
            dir: Vec3::new(f32::INFINITY, 0.0, 0.0),
            ..good
        },
        Ray {
            t_min: f32::NAN,
            ..good
        },
    ] {
        assert_eq!(both_t(&s, &r), None, "{r:?}");
    }
}
