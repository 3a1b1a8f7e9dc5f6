//! The sphere block kernel (one ray against up to `F::LANES` spheres at once,
//! what BVH leaves of spheres run for single rays) against its scalar twin,
//! the sphere kernel: lane by lane and whole blocks on 4·10⁵ seeded random rays
//! with earlier hits, then hand-made cases (tangent rays, rays from inside,
//! inside-only spheres, ties on equal t, spheres behind and out of range,
//! unused and NaN lanes, NaN and infinite input).

use crate::support::kernel::block::{
    BlockKernel, assert_block_agrees, assert_block_lanes_run_the_packet_kernel, both,
};
use crate::support::kernel::poisoned_rays;
use glam::Vec3;
use raypack::geometry::sphere::Spheres;
use raypack::geometry::{BlockIntersect, Intersect, Sphere};
use raypack::packet::{HitPacket, RayPacket};
use raypack::ray::{Hit, Ray};
use raypack::rng::Rng;
use raypack::simd::SimdFloat;
use wide::{f32x4, f32x8};

/// The sphere block and its scalar twin.
struct Spheres4;

impl BlockKernel for Spheres4 {
    type Shape = Sphere;
    // A NaN sphere: no ray crosses it, which is what the block's unused lanes say.
    const EMPTY: Sphere = Sphere {
        center: Vec3::ZERO,
        radius: f32::NAN,
        inside_only: false,
    };

    fn scalar(sphere: &Sphere, id: u32, ray: &Ray, hit: &mut Hit) -> bool {
        sphere.intersect(ray, id, hit)
    }

    fn block<F: SimdFloat>(spheres: &[(Sphere, u32)], ray: &Ray, hit: &mut Hit) -> bool {
        Spheres::<F>::new(spheres).intersect(ray, hit)
    }

    fn packet(sphere: &Sphere, id: u32, rays: &RayPacket<f32x8>, hits: &mut HitPacket<f32x8>) {
        sphere.intersect_packet(rays, id, hits);
    }

    fn block_lane_packet(
        spheres: &[(Sphere, u32)],
        lane: usize,
        rays: &RayPacket<f32x8>,
        hits: &mut HitPacket<f32x8>,
    ) {
        Spheres::<f32x4>::new(spheres).intersect_packet(lane, rays, hits);
    }
}

/// A random sphere around the origin: usually of a size that rays at the unit
/// cube often hit; one in ten tiny, one in ten inside-only, one in twenty so
/// large that most rays start inside it.
fn random_sphere(rng: &mut Rng) -> Sphere {
    let c = rng.point_in(Vec3::splat(-0.5), Vec3::splat(0.5));
    match rng.below(20) {
        0 | 1 => Sphere::new(c, 1e-4),
        2 | 3 => Sphere::inside_only(c, rng.range(0.1, 1.0)),
        4 => Sphere::new(c, 100.0),
        _ => Sphere::new(c, rng.range(0.1, 1.0)),
    }
}

#[test]
fn block_of_four_agrees_with_the_scalar_kernel() {
    assert_block_agrees::<Spheres4, f32x4>(11, random_sphere);
}

#[test]
fn block_of_eight_agrees_with_the_scalar_kernel() {
    assert_block_agrees::<Spheres4, f32x8>(12, random_sphere);
}

/// A block lane's packet kernel is the packet kernel of the sphere in it.
#[test]
fn block_lanes_run_the_sphere_packet_kernel() {
    assert_block_lanes_run_the_packet_kernel::<Spheres4>(13, random_sphere);
}

fn ray(origin: [f32; 3], dir: [f32; 3]) -> Ray {
    Ray::unbounded(Vec3::from(origin), Vec3::from(dir))
}

fn unit_at(z: f32) -> Sphere {
    Sphere::new(Vec3::new(0.0, 0.0, z), 1.0)
}

#[test]
fn tangent_rays_hit_and_rays_just_beside_miss() {
    let s = [(unit_at(0.0), 2)];
    // Closest approach exactly 1: D = 0, one root at t = 5.
    let r = ray([1.0, 0.0, -5.0], [0.0, 0.0, 1.0]);
    let hit = both::<Spheres4>(&s, &r, Hit::none(&r));
    assert_eq!((hit.t, hit.prim), (5.0, 2));
    let r = ray([1.001, 0.0, -5.0], [0.0, 0.0, 1.0]);
    assert!(!both::<Spheres4>(&s, &r, Hit::none(&r)).is_hit());
}

#[test]
fn rays_from_inside_and_inside_only_spheres_take_the_far_root() {
    let r = ray([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
    assert_eq!(both::<Spheres4>(&[(unit_at(0.0), 0)], &r, Hit::none(&r)).t, 1.0);
    let r = ray([0.0, 0.0, -5.0], [0.0, 0.0, 1.0]);
    assert_eq!(both::<Spheres4>(&[(unit_at(0.0), 0)], &r, Hit::none(&r)).t, 4.0);
    let inside_only = Sphere::inside_only(Vec3::ZERO, 1.0);
    assert_eq!(both::<Spheres4>(&[(inside_only, 0)], &r, Hit::none(&r)).t, 6.0);
    // Beside a normal sphere in the same block, each lane keeps its own rule.
    let mixed = [(inside_only, 0), (unit_at(1.0), 1)]; // its front at t = 5
    assert_eq!(both::<Spheres4>(&mixed, &r, Hit::none(&r)).prim, 1);
}

#[test]
fn equal_t_goes_to_the_lower_index_in_any_lane() {
    let r = ray([0.0, 0.0, -5.0], [0.0, 0.0, 1.0]);
    for spheres in [
        [(unit_at(0.0), 7), (unit_at(0.0), 3)],
        [(unit_at(0.0), 3), (unit_at(0.0), 7)],
    ] {
        assert_eq!(both::<Spheres4>(&spheres, &r, Hit::none(&r)).prim, 3);
        // An earlier record at the same t keeps or loses its place by index.
        let mut earlier = Hit::none(&r);
        earlier.record(4.0, 5, 0.0, 0.0);
        assert_eq!(both::<Spheres4>(&spheres, &r, earlier).prim, 3);
        earlier.record(4.0, 1, 0.0, 0.0);
        assert_eq!(both::<Spheres4>(&spheres, &r, earlier).prim, 1);
    }
}

#[test]
fn spheres_behind_and_out_of_range_miss() {
    let s = [(unit_at(5.0), 0)];
    let misses = [
        ray([0.0, 0.0, 10.0], [0.0, 0.0, 1.0]),  // sphere behind the origin
        Ray::new(Vec3::ZERO, Vec3::Z, 0.0, 3.5), // before the sphere
        Ray::new(Vec3::ZERO, Vec3::Z, 6.5, f32::INFINITY), // past it
        ray([0.0, 2.0, 0.0], [0.0, 0.0, 1.0]),   // beside it, parallel to its axis
    ];
    for r in misses {
        assert!(!both::<Spheres4>(&s, &r, Hit::none(&r)).is_hit(), "{r:?}");
    }
    // t_min between the roots: the far one.
    let r = Ray::new(Vec3::ZERO, Vec3::Z, 4.5, f32::INFINITY);
    assert_eq!(both::<Spheres4>(&s, &r, Hit::none(&r)).t, 6.0);
}

#[test]
fn unused_and_nan_lanes_are_never_hit() {
    let r = ray([0.0, 0.0, -5.0], [0.0, 0.0, 1.0]);
    assert!(!both::<Spheres4>(&[], &r, Hit::none(&r)).is_hit());
    let broken = [
        (Sphere::new(Vec3::new(f32::NAN, 0.0, 0.0), 1.0), 1),
        (Sphere::new(Vec3::ZERO, f32::NAN), 2),
        (Sphere::new(Vec3::new(0.0, f32::INFINITY, 0.0), 1.0), 3),
    ];
    assert!(!both::<Spheres4>(&broken, &r, Hit::none(&r)).is_hit());
}

#[test]
fn nan_and_infinite_rays_miss_without_panicking() {
    // Spheres around the origin, where the poisoned rays' clean version points.
    let spheres = [
        (unit_at(0.0), 2),
        (Sphere::inside_only(Vec3::new(0.0, 0.0, 0.5), 2.0), 6),
        (Sphere::new(Vec3::new(0.1, 0.2, 0.0), 0.05), 8),
    ];
    for (r, must_miss) in poisoned_rays() {
        let hit = both::<Spheres4>(&spheres, &r, Hit::none(&r));
        if must_miss {
            assert!(!hit.is_hit(), "{r:?}");
        } else if hit.is_hit() {
            assert!(hit.t.is_finite(), "{r:?}");
        }
    }
}
