//! Hand-made rays where engines are most likely to differ: tangent, grazing,
//! parallel, starting inside, limited by the interval, through shared edges and
//! vertices, degenerate shapes, non-finite input; plus occlusion and the 4- and
//! 16-wide packet paths. Each is traced by raypack (brute force) and Embree.

use std::sync::Arc;

use glam::{Mat4, Vec3};
use raypack::accel::{Accel, BruteForce};
use raypack::compare::{AgreementOptions, DisagreementKind, random_rays};
use raypack::embree::{Device, EmbreeScene};
use raypack::geometry::{Plane, Polygon, Primitive, Sphere, Transformed, Triangle};
use raypack::packet::RayPacket;
use raypack::ray::{NO_HIT, Ray};
use raypack::scene::generate::test_scenes;
use raypack::simd::SimdFloat;
use wide::{f32x4, f32x8, f32x16};

fn device() -> Arc<Device> {
    Arc::new(Device::with_default_config().expect("Embree device"))
}

/// Both engines' `(t, prim)` for `ray`.
fn both(prims: &[Primitive], ray: &Ray) -> ((f32, u32), (f32, u32)) {
    let embree = EmbreeScene::new(device(), prims).unwrap();
    let a = BruteForce::new(prims).intersect(ray);
    let b = embree.intersect(ray);
    ((a.t, a.prim), (b.t, b.prim))
}

fn close(a: f32, b: f32) -> bool {
    (a - b).abs() <= 1e-5 * a.abs().max(1.0)
}

#[test]
fn spheres_from_outside_inside_and_past_the_interval() {
    let s = [Primitive::Sphere(Sphere::new(Vec3::ZERO, 1.0))];
    // From outside: the near root.
    let ((ta, pa), (tb, pb)) = both(&s, &Ray::unbounded(Vec3::new(0.0, 0.0, 5.0), Vec3::NEG_Z));
    assert!(
        (pa, pb) == (0, 0) && close(ta, 4.0) && close(tb, 4.0),
        "{ta} {tb}"
    );
    // From inside: the far root.
    let ((ta, pa), (tb, pb)) = both(&s, &Ray::unbounded(Vec3::new(0.0, 0.0, 0.5), Vec3::NEG_Z));
    assert!(
        (pa, pb) == (0, 0) && close(ta, 1.5) && close(tb, 1.5),
        "{ta} {tb}"
    );
    // t_min past the near root: the far root.
    let ((ta, _), (tb, _)) = both(&s, &Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::NEG_Z, 4.5, 100.0));
    assert!(close(ta, 6.0) && close(tb, 6.0), "{ta} {tb}");
    // t_max before the sphere: a miss, t stays t_max.
    let ((ta, pa), (tb, pb)) = both(&s, &Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::NEG_Z, 0.0, 3.0));
    assert_eq!(((ta, pa), (tb, pb)), ((3.0, NO_HIT), (3.0, NO_HIT)));
    // Behind the origin: a miss.
    let (a, b) = both(&s, &Ray::unbounded(Vec3::new(0.0, 0.0, 5.0), Vec3::Z));
    assert_eq!((a.1, b.1), (NO_HIT, NO_HIT));
}

#[test]
fn near_tangent_rays_agree_away_from_the_exact_tangent() {
    // Rays passing the unit sphere at distance 1 ± δ: for δ above float
    // resolution both engines agree; only at the exact tangent may they differ.
    let s = [Primitive::Sphere(Sphere::new(Vec3::ZERO, 1.0))];
    for delta in [1e-3f32, 1e-4, -1e-4, -1e-3] {
        let ray = Ray::unbounded(Vec3::new(1.0 + delta, 0.0, 5.0), Vec3::NEG_Z);
        let ((_, pa), (_, pb)) = both(&s, &ray);
        assert_eq!(pa, pb, "offset {delta}");
        assert_eq!(pa == 0, delta < 0.0, "offset {delta}");
    }
}

#[test]
fn triangles_parallel_grazing_degenerate_and_edges() {
    let t = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y);
    let prims = [Primitive::Triangle(t)];
    // In the triangle's plane: parallel, no hit in either.
    let (a, b) = both(&prims, &Ray::unbounded(Vec3::new(-1.0, 0.2, 0.0), Vec3::X));
    assert_eq!((a.1, b.1), (NO_HIT, NO_HIT));
    // Steeply grazing but inside: both hit.
    let dir = Vec3::new(1.0, 0.0, -1e-3).normalize();
    let (a, b) = both(&prims, &Ray::unbounded(Vec3::new(-99.7, 0.25, 0.1), dir));
    assert_eq!((a.1, b.1), (0, 0));
    assert!(close(a.0, b.0), "{} {}", a.0, b.0);
    // Through the interior of an edge and through a vertex: edges count as inside in both.
    for p in [
        Vec3::new(0.5, 0.0, 0.0),
        Vec3::new(0.0, 0.5, 0.0),
        Vec3::new(0.0, 0.0, 0.0),
    ] {
        let (a, b) = both(&prims, &Ray::unbounded(p + Vec3::Z, Vec3::NEG_Z));
        assert_eq!((a.1, b.1), (0, 0), "through {p}");
    }
    // A degenerate triangle is hit by neither (Embree never sees it).
    let flat = [Primitive::Triangle(Triangle::new(
        Vec3::ZERO,
        Vec3::X,
        2.0 * Vec3::X,
    ))];
    let (a, b) = both(&flat, &Ray::unbounded(Vec3::new(0.5, 0.0, 1.0), Vec3::NEG_Z));
    assert_eq!((a.1, b.1), (NO_HIT, NO_HIT));
}

/// Rays straight at a closed mesh's vertices and edge midpoints, each passing
/// exactly through a point that several triangles share.
fn rays_through_shared_points(prims: &[Primitive]) -> Vec<Ray> {
    let mut rays = Vec::new();
    for p in prims {
        let Primitive::Triangle(t) = p else { unreachable!() };
        let [a, b, c] = t.vertices();
        for target in [a, 0.5 * (a + b), 0.5 * (b + c)] {
            let origin = 3.0 * target.normalize() + Vec3::new(0.01, 0.02, 0.0);
            rays.push(Ray::unbounded(origin, (target - origin).normalize()));
        }
    }
    rays
}

#[test]
fn shared_edges_and_vertices_are_ties_and_robust_embree_is_watertight() {
    // Both engines hit the surface at the same t and may pick any triangle that
    // shares the point: raypack the lowest index (its tie rule), Embree whichever
    // its traversal meets first. Those are ties. A ray that slips through the
    // shared point hits the far side of the mesh instead: a leak, seen as a
    // "different primitive" with the larger t. Neither raypack (its triangles
    // keep a margin of 2^-20 beyond their edges) nor Embree's robust mode leaks.
    let prims = test_scenes::uv_sphere_mesh(Vec3::ZERO, 2.0, 400);
    let rays = rays_through_shared_points(&prims);
    let raypack = BruteForce::new(&prims);
    let a: Vec<_> = rays.iter().map(|r| raypack.intersect(r)).collect();
    for (name, embree) in [
        ("robust", EmbreeScene::robust(device(), &prims).unwrap()),
        ("default", EmbreeScene::new(device(), &prims).unwrap()),
    ] {
        let b: Vec<_> = rays.iter().map(|r| embree.intersect(r)).collect();
        let options = AgreementOptions {
            keep: usize::MAX,
            ..Default::default()
        };
        let g = raypack::compare::Agreement::compare(&prims, &rays, &a, &b, options);
        let (mut raypack_leaks, mut embree_leaks) = (0, 0);
        for d in &g.disagreements {
            if d.kind == DisagreementKind::DifferentPrimitive {
                // The near surface lies at about 1 from the origin, the far side at about 5.
                assert!(
                    d.a.0.min(d.b.0) < 1.1 && d.a.0.max(d.b.0) > 4.5,
                    "not a leak: {d:?}"
                );
                if d.a.0 > d.b.0 {
                    raypack_leaks += 1
                } else {
                    embree_leaks += 1
                }
            }
        }
        eprintln!(
            "{} rays through shared points, Embree {name}: {} same, {} ties, leaks: raypack {raypack_leaks}, Embree {embree_leaks}",
            g.rays, g.same_primitive, g.ties
        );
        assert!(g.ties > g.rays / 10, "many rays pass through shared points");
        assert_eq!(g.only_a + g.only_b, 0, "the mesh is closed: every ray hits it");
        assert_eq!(raypack_leaks, 0, "raypack's triangles are watertight here");
        if embree.is_robust() {
            assert_eq!(embree_leaks, 0, "robust Embree is watertight");
        }
    }
}

#[test]
fn planes_self_crossing_polygons_and_transformed_planes_go_through_raypack_kernels() {
    let bowtie = Polygon::new(&[Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0), Vec3::X, Vec3::Y]).unwrap();
    let plane = Primitive::Plane(Plane::implicit(0.0, 1.0, 0.0, 3.0).unwrap());
    let moved_plane = Transformed::new(
        plane.clone(),
        Mat4::from_rotation_x(0.3) * Mat4::from_translation(Vec3::Z),
    )
    .unwrap();
    let prims = vec![
        plane,
        Primitive::Polygon(bowtie),
        Primitive::Transformed(Box::new(moved_plane)),
    ];
    let embree = EmbreeScene::new(device(), &prims).unwrap();
    assert_eq!(embree.stats().user, 3);
    let raypack = BruteForce::new(&prims);
    for ray in random_rays(
        raypack::bounds::Aabb::new(Vec3::splat(-2.0), Vec3::splat(2.0)),
        20_000,
        3,
    ) {
        let (a, b) = (raypack.intersect(&ray), embree.intersect(&ray));
        // The same kernels run in both: bit-identical results.
        assert_eq!((a.t, a.prim), (b.t, b.prim), "{ray:?}");
    }
    // A ray parallel to the plane y = −3 misses it in both.
    let parallel = Ray::unbounded(Vec3::new(0.0, -3.0, 50.0), Vec3::X);
    assert_eq!(
        embree.intersect(&parallel).prim,
        raypack.intersect(&parallel).prim
    );
}

#[test]
fn non_finite_rays_miss_in_both_engines() {
    let scene = test_scenes::by_name("mixed", 100, 2).unwrap();
    let embree = EmbreeScene::new(device(), &scene.primitives).unwrap();
    let raypack = BruteForce::new(&scene.primitives);
    let nan = f32::NAN;
    let rays = [
        Ray::unbounded(Vec3::new(nan, 0.0, 0.0), Vec3::Z),
        Ray::unbounded(Vec3::ZERO, Vec3::new(0.0, nan, 1.0)),
        Ray::unbounded(Vec3::new(f32::INFINITY, 0.0, 0.0), Vec3::NEG_X),
        Ray::new(Vec3::new(0.0, 0.0, 20.0), Vec3::NEG_Z, nan, f32::INFINITY),
        Ray::new(Vec3::new(0.0, 0.0, 20.0), Vec3::NEG_Z, 5.0, 1.0),
    ];
    for ray in &rays {
        assert_eq!(raypack.intersect(ray).prim, NO_HIT, "{ray:?}");
        assert_eq!(embree.intersect(ray).prim, NO_HIT, "{ray:?}");
        assert!(!embree.occluded(ray));
    }
    let packet = RayPacket::<f32x8>::from_rays(&rays);
    assert!(embree.intersect_packet(&packet).hit_mask().none());
    assert!(embree.occluded_packet(&packet).none());
}

fn packets_match_single_rays<F: SimdFloat>(embree: &EmbreeScene, rays: &[Ray]) {
    for (k, chunk) in rays.chunks(F::LANES).enumerate() {
        let packet = RayPacket::<F>::from_rays(chunk);
        let hits = embree.intersect_packet(&packet);
        let occluded = embree.occluded_packet(&packet).bitmask();
        for (i, ray) in chunk.iter().enumerate() {
            let single = embree.intersect(ray);
            let lane = hits.hit(i);
            assert_eq!(lane.prim, single.prim, "{}-wide packet {k} lane {i}", F::LANES);
            assert!(
                close(lane.t, single.t) || !single.is_hit(),
                "{} vs {}",
                lane.t,
                single.t
            );
            assert_eq!(
                occluded >> i & 1 == 1,
                embree.occluded(ray),
                "{}-wide packet {k} lane {i}",
                F::LANES
            );
        }
    }
}

#[test]
fn every_packet_width_and_occlusion_agree_with_single_rays_and_raypack() {
    let scene = test_scenes::by_name("mixed", 300, 4).unwrap();
    let embree = EmbreeScene::new(device(), &scene.primitives).unwrap();
    let raypack = BruteForce::new(&scene.primitives);
    let rays = random_rays(scene.bounds(), 20_000, 8);
    packets_match_single_rays::<f32x4>(&embree, &rays);
    packets_match_single_rays::<f32x8>(&embree, &rays);
    packets_match_single_rays::<f32x16>(&embree, &rays);
    // Occlusion (shadow rays over part of each ray) agrees with raypack's.
    let shadow: Vec<Ray> = rays
        .iter()
        .map(|r| Ray::new(r.origin, r.dir, 1e-3, 3.0))
        .collect();
    let disagree = shadow
        .iter()
        .filter(|r| raypack.occluded(r) != embree.occluded(r))
        .count();
    assert!(
        disagree * 10_000 <= shadow.len(),
        "{disagree} occlusion disagreements"
    );
    assert!(shadow.iter().filter(|r| embree.occluded(r)).count() > shadow.len() / 10);
}
