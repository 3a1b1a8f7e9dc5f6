//! Degenerate inputs: empty scenes, a single primitive, primitives all in one
//! point, zero-size boxes, degenerate triangles, huge coordinates, unbalanced
//! scenes, non-finite rays. Each must build, never panic, and answer exactly as
//! brute force does.

use crate::support;
use glam::{Mat4, Vec3};
use raypack::accel::bvh::{BuildOptions, LeafKind, MAX_DEPTH};
use raypack::accel::{Accel, BruteForce, Bvh};
use raypack::geometry::plane::Plane;
use raypack::geometry::{Primitive, Sphere, Transformed, Triangle};
use raypack::packet::RayPacket8;
use raypack::ray::{NO_HIT, Ray};
use raypack::rng::Rng;
use raypack::scene::generate::random;
use raypack::simd::SimdFloat;

fn sphere(c: Vec3, r: f32) -> Primitive {
    Primitive::Sphere(Sphere::new(c, r))
}

fn tri(a: Vec3, b: Vec3, c: Vec3) -> Primitive {
    Primitive::Triangle(Triangle::new(a, b, c))
}

/// Random rays around `bounds`, checked against brute force; returns the hit count.
fn check(name: &str, prims: &[Primitive], n: usize) -> usize {
    let bvh = Bvh::new(prims);
    let rays = support::bvh::random_rays(support::bvh::scene_bounds(prims), n, 7);
    support::bvh::check_rays(prims, &bvh, &rays, name)
}

#[test]
fn empty_scene_hits_nothing() {
    let bvh = Bvh::new(&[]);
    let ray = Ray::unbounded(Vec3::ZERO, Vec3::Z);
    assert_eq!(bvh.intersect(&ray).prim, NO_HIT);
    assert!(!bvh.occluded(&ray));
    let packet = RayPacket8::from_rays(&[ray; 8]);
    assert!(bvh.intersect_packet(&packet).hit_mask().none());
    assert!(bvh.occluded_packet(&packet).none());
    let info = bvh.info();
    assert_eq!((info.primitives, info.nodes, info.unbounded), (0, 0, 0));
    assert!(bvh.bounds().is_empty());
}

#[test]
fn single_primitives() {
    let hit = check("one sphere", &[sphere(Vec3::ZERO, 0.5)], 20_000);
    assert!(hit > 1000);
    check("one triangle", &[tri(Vec3::ZERO, Vec3::X, Vec3::Y)], 20_000);
    // A lone plane and a transformed plane: unbounded, outside the tree.
    let plane = Plane::implicit(0.0, 1.0, 0.0, 0.0).unwrap();
    let tilted = Transformed::new(Primitive::Plane(plane), Mat4::from_rotation_x(0.3)).unwrap();
    let prims = [Primitive::Plane(plane), Primitive::Transformed(Box::new(tilted))];
    assert!(check("planes only", &prims, 20_000) > 1000);
    assert_eq!(Bvh::new(&prims).info().unbounded, 2);
}

#[test]
fn primitives_all_in_one_point() {
    // Identical spheres: every hit is a tie, which the lowest index must win.
    let same: Vec<Primitive> = (0..100).map(|_| sphere(Vec3::splat(0.25), 0.5)).collect();
    let bvh = Bvh::new(&same);
    let hit = bvh.intersect(&Ray::unbounded(Vec3::new(0.25, 0.25, -3.0), Vec3::Z));
    assert_eq!((hit.prim, hit.t), (0, 2.75));
    check("identical spheres", &same, 20_000);
    // Zero-radius spheres and identical triangles, all sharing one point or place.
    let points: Vec<Primitive> = (0..50).map(|_| sphere(Vec3::ONE, 0.0)).collect();
    check("point spheres", &points, 20_000);
    let tris: Vec<Primitive> = (0..50)
        .map(|_| tri(Vec3::ZERO, Vec3::X, Vec3::Y))
        .chain((0..50).map(|_| sphere(Vec3::ZERO, 0.0)))
        .collect();
    check("identical triangles", &tris, 20_000);
    // Triangles beside spheres: leaves of records, no larger than their tier allows.
    let records = BuildOptions::for_primitives(tris.len(), LeafKind::Records);
    assert!(Bvh::new(&tris).info().max_leaf_size <= records.max_leaf_size);
}

#[test]
fn flat_boxes_and_exact_vertex_edge_hits() {
    // A grid of triangles in z = 0: every box is flat, and rays straight down
    // through grid points hit shared vertices and edges (ties between neighbours).
    let n = 20;
    let mut prims = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let p = |di: i32, dj: i32| Vec3::new((i as i32 + di) as f32, (j as i32 + dj) as f32, 0.0);
            prims.push(tri(p(0, 0), p(1, 0), p(1, 1)));
            prims.push(tri(p(0, 0), p(1, 1), p(0, 1)));
        }
    }
    let bvh = Bvh::new(&prims);
    let mut rays = Vec::new();
    for i in 0..=2 * n {
        for j in 0..=2 * n {
            let o = Vec3::new(i as f32 * 0.5, j as f32 * 0.5, 5.0);
            rays.push(Ray::unbounded(o, -Vec3::Z));
            // In the grid's plane, parallel to it: no kernel reports a hit.
            rays.push(Ray::unbounded(Vec3::new(o.x, o.y, 0.0), Vec3::X));
            rays.push(Ray::unbounded(Vec3::new(-1.0, o.y, 0.0), Vec3::X));
        }
    }
    let hits = support::bvh::check_rays(&prims, &bvh, &rays, "flat grid");
    assert!(hits >= (2 * n - 1) * (2 * n - 1), "{hits}");
    support::bvh::check_rays(
        &prims,
        &bvh,
        &support::bvh::random_rays(support::bvh::scene_bounds(&prims), 20_000, 3),
        "grid",
    );
}

#[test]
fn degenerate_triangles_are_left_out() {
    let mut prims = random::random_triangles(200, 9);
    prims.push(tri(Vec3::ZERO, Vec3::X, 2.0 * Vec3::X)); // collinear
    prims.push(tri(Vec3::ONE, Vec3::ONE, Vec3::ONE)); // one point
    prims.push(tri(Vec3::NAN, Vec3::X, Vec3::Y)); // non-finite
    let bvh = Bvh::new(&prims);
    assert_eq!(bvh.info().skipped, 3);
    assert_eq!(bvh.info().primitives, 200);
    check("with degenerate triangles", &prims, 20_000);
}

/// `prims` moved by `offset` and scaled by `scale` (spheres and triangles).
fn placed(prims: &[Primitive], scale: f32, offset: Vec3) -> Vec<Primitive> {
    let f = |p: Vec3| scale * p + offset;
    prims
        .iter()
        .map(|p| match p {
            Primitive::Sphere(s) => sphere(f(s.center), scale * s.radius),
            Primitive::Triangle(t) => {
                let [a, b, c] = t.vertices();
                tri(f(a), f(b), f(c))
            }
            other => other.clone(),
        })
        .collect()
}

#[test]
fn huge_coordinates() {
    let mut base = random::random_spheres(300, 10);
    base.extend(random::random_triangles(300, 11));
    // Far from the origin: coordinates of 10⁶ with features of 0.1.
    check(
        "offset 1e6",
        &placed(&base, 1.0, Vec3::new(1e6, -1e6, 1e6)),
        20_000,
    );
    // Large everywhere: 10¹⁸.
    check("scaled 1e18", &placed(&base, 1e18, Vec3::ZERO), 20_000);
    // Near f32::MAX: box areas overflow to infinity, so SAH costs are useless and
    // the builder must fall back to median splits.
    let bvh_huge = placed(&base, 1e37, Vec3::ZERO);
    check("scaled 1e37", &bvh_huge, 20_000);
    // Boxes that overflow (sphere of radius f32::MAX) go outside the tree.
    let mut overflowing = base.clone();
    overflowing.push(sphere(Vec3::splat(3e38), 3e38));
    assert_eq!(Bvh::new(&overflowing).info().unbounded, 1);
    check("overflowing box", &overflowing, 20_000);
}

#[test]
fn unbalanced_scene_stays_within_the_stack() {
    // Spheres growing geometrically along x: SAH splits peel them off one by one.
    let prims: Vec<Primitive> = (0..400)
        .map(|k| {
            let x = 1.15f32.powi(k);
            sphere(Vec3::new(x, 0.0, 0.0), 0.3 * x)
        })
        .collect();
    let bvh = Bvh::new(&prims);
    let depth = bvh.info().max_depth;
    assert!(depth <= MAX_DEPTH, "depth {depth}");
    let mut rays = Vec::new();
    let mut rng = Rng::new(4);
    for k in 0..400 {
        let x = 1.15f32.powi(k);
        for _ in 0..20 {
            let origin = Vec3::new(x * rng.range(0.5, 1.5), x * rng.range(-1.0, 1.0), -3.0 * x);
            rays.push(Ray::unbounded(
                origin,
                (Vec3::new(x, 0.0, 0.0) - origin).normalize(),
            ));
        }
    }
    assert!(support::bvh::check_rays(&prims, &bvh, &rays, "unbalanced") > rays.len() / 2);
}

#[test]
fn every_build_option_gives_the_same_answers() {
    let prims = random::random_mixed(400, 12);
    let rays = support::bvh::random_rays(support::bvh::scene_bounds(&prims), 10_000, 5);
    for (bins, max_leaf_size) in [(8, 1), (32, 16), (2, 4), (16, 64)] {
        let options = BuildOptions {
            bins,
            max_leaf_size,
            ..BuildOptions::default()
        };
        let bvh = Bvh::with_options(&prims, &options);
        assert!(bvh.info().max_leaf_size <= max_leaf_size.max(1));
        support::bvh::check_rays(&prims, &bvh, &rays, &format!("bins {bins} leaf {max_leaf_size}"));
    }
}

#[test]
fn non_finite_and_degenerate_rays_answer_like_brute_force() {
    let prims = random::random_mixed(200, 13);
    let bvh = Bvh::new(&prims);
    let brute = BruteForce::new(&prims);
    let (nan, inf) = (f32::NAN, f32::INFINITY);
    let rays = [
        Ray::unbounded(Vec3::new(nan, 0.0, 0.0), Vec3::Z),
        Ray::unbounded(Vec3::ZERO, Vec3::new(nan, 0.0, 1.0)),
        Ray::unbounded(Vec3::new(0.0, 0.0, -inf), Vec3::Z),
        Ray::unbounded(Vec3::new(0.0, 0.0, -5.0), Vec3::new(0.0, 0.0, inf)),
        Ray::unbounded(Vec3::new(0.0, 0.0, -5.0), Vec3::ZERO),
        Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z, nan, inf),
        Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z, 0.0, nan),
        Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z, 3.0, 2.0), // empty interval
        Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z, 0.0, 0.0),
        Ray::unbounded(Vec3::new(0.0, 0.0, -5.0), Vec3::Z), // a normal ray among them
    ];
    for ray in &rays {
        assert_eq!(
            support::bvh::key(&bvh.intersect(ray)),
            support::bvh::key(&brute.intersect(ray)),
            "{ray:?}"
        );
        assert_eq!(bvh.occluded(ray), brute.occluded(ray), "{ray:?}");
    }
    for chunk in rays.chunks(8) {
        let p = RayPacket8::from_rays(chunk);
        let (hits, bits) = (bvh.intersect_packet(&p), bvh.occluded_packet(&p).bitmask());
        for (lane, ray) in chunk.iter().enumerate() {
            assert_eq!(
                support::bvh::key(&hits.hit(lane)),
                support::bvh::key(&brute.intersect(ray)),
                "{ray:?}"
            );
            assert_eq!(bits >> lane & 1 == 1, brute.occluded(ray), "{ray:?}");
        }
    }
}
