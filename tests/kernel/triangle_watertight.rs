//! The watertight triangle test (Woop, Benthin and Wald 2013): its block
//! kernel against its scalar twin lane by lane on 4·10⁵ seeded random rays,
//! its packet kernel likewise, the projected test's hits on rays away from
//! edges, hand-made edge cases, and watertightness itself: rays from inside
//! closed meshes through every shared vertex and edge midpoint all hit, under
//! every kernel.

use crate::support;
use crate::support::kernel::block::{
    BlockKernel, assert_block_agrees, assert_block_lanes_run_the_packet_kernel,
};
use crate::support::kernel::poisoned_rays;
use glam::{DVec3, Vec3};
use raypack::geometry::triangle::TriangleTest;
use raypack::geometry::triangle_watertight::{WatertightTriangle, WatertightTriangles};
use raypack::geometry::{BlockIntersect, Intersect, Triangle};
use raypack::packet::{HitPacket, RayPacket};
use raypack::ray::{Hit, NO_HIT, Ray};
use raypack::rng::Rng;
use raypack::scene::generate::closed_mesh::{ClosedMesh, ClosedShape};
use raypack::simd::SimdFloat;
use wide::{f32x4, f32x8};

/// The watertight block and its scalar twin.
struct Watertight;

impl BlockKernel for Watertight {
    type Shape = WatertightTriangle;
    const EMPTY: WatertightTriangle = WatertightTriangle::NEVER_HIT;

    fn scalar(tri: &WatertightTriangle, id: u32, ray: &Ray, hit: &mut Hit) -> bool {
        tri.intersect(ray, id, hit)
    }

    fn block<F: SimdFloat>(tris: &[(WatertightTriangle, u32)], ray: &Ray, hit: &mut Hit) -> bool {
        WatertightTriangles::<F>::new(tris).intersect(ray, hit)
    }

    fn packet(tri: &WatertightTriangle, id: u32, rays: &RayPacket<f32x8>, hits: &mut HitPacket<f32x8>) {
        tri.intersect_packet(rays, id, hits);
    }

    fn block_lane_packet(
        tris: &[(WatertightTriangle, u32)],
        lane: usize,
        rays: &RayPacket<f32x8>,
        hits: &mut HitPacket<f32x8>,
    ) {
        WatertightTriangles::<f32x4>::new(tris).intersect_packet(lane, rays, hits);
    }
}

/// A random triangle around the origin, as the projected test's block test
/// draws them (one in ten degenerate, one in ten tiny).
fn random_triangle(rng: &mut Rng) -> WatertightTriangle {
    let a = rng.point_in(Vec3::splat(-0.5), Vec3::splat(0.5));
    let kind = rng.below(10);
    let mut edge = |size: f32| size * rng.unit_vector();
    let t = match kind {
        0 => Triangle::new(a, 2.0 * a, 3.0 * a),
        1 => Triangle::new(a, a + edge(1e-4), a + edge(1e-4)),
        _ => Triangle::new(a, a + edge(2.0), a + edge(2.0)),
    };
    t.watertight()
}

#[test]
fn block_of_four_agrees_with_the_scalar_kernel() {
    assert_block_agrees::<Watertight, f32x4>(11, random_triangle);
}

#[test]
fn block_of_eight_agrees_with_the_scalar_kernel() {
    assert_block_agrees::<Watertight, f32x8>(12, random_triangle);
}

#[test]
fn block_lanes_run_the_triangle_packet_kernel() {
    assert_block_lanes_run_the_packet_kernel::<Watertight>(13, random_triangle);
}

/// The packet kernel of a triangle under either test is its scalar kernel
/// lane by lane (one triangle per dominant axis, and rays of every direction,
/// so every shear frame is taken).
#[test]
fn packet_kernel_agrees_with_the_scalar_kernel_under_both_tests() {
    let mut rng = Rng::new(14);
    for test in [TriangleTest::Watertight, TriangleTest::Barycentric] {
        for k in 0..30 {
            let tri = Triangle::new(
                rng.point_in(Vec3::splat(-1.0), Vec3::splat(1.0)),
                rng.point_in(Vec3::splat(-1.0), Vec3::splat(1.0)),
                rng.point_in(Vec3::splat(-1.0), Vec3::splat(1.0)),
            )
            .with_test(test);
            let seen = support::kernel::assert_packet_matches_scalar::<_, f32x8>(
                &tri,
                Vec3::splat(-1.0),
                Vec3::splat(1.0),
                4_000,
                100 + k,
            );
            assert!(seen.hits > 0, "{test:?}: triangle {k} never hit");
        }
    }
}

/// Away from its edges, the watertight test hits where the projected test
/// does, at the same t within a few ulps.
#[test]
fn hits_away_from_edges_agree_with_the_projected_test() {
    let mut rng = Rng::new(15);
    let (mut compared, mut hits) = (0, 0);
    for _ in 0..200_000 {
        let [a, b, c] = [(); 3].map(|_| rng.point_in(Vec3::splat(-1.0), Vec3::splat(1.0)));
        let tri = Triangle::new(a, b, c);
        let ray = support::kernel::random_ray(&mut rng, Vec3::splat(-1.0), Vec3::splat(1.0));
        let trace = |test| {
            let mut hit = Hit::none(&ray);
            tri.with_test(test).intersect(&ray, 0, &mut hit).then_some(hit)
        };
        let (w, p) = (trace(TriangleTest::Watertight), trace(TriangleTest::Barycentric));
        // Skip rays within a relative 10⁻⁴ of an edge, in either's barycentrics.
        let near_edge = |h: &Hit| h.u.min(h.v).min(1.0 - h.u - h.v).abs() < 1e-4;
        if w.iter().chain(&p).any(near_edge) {
            continue;
        }
        compared += 1;
        assert_eq!(w.is_some(), p.is_some(), "{ray:?} {tri:?}");
        if let (Some(w), Some(p)) = (w, p) {
            hits += 1;
            let scale = w.t.abs().max(1.0);
            assert!((w.t - p.t).abs() <= 1e-5 * scale, "{w:?} {p:?}");
            assert!(
                (w.u - p.u).abs() < 1e-3 && (w.v - p.v).abs() < 1e-3,
                "{w:?} {p:?}"
            );
        }
    }
    assert!(
        compared > 100_000 && hits > 5_000,
        "{compared} compared, {hits} hits"
    );
}

fn tri(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> WatertightTriangle {
    WatertightTriangle::new(Vec3::from(a), Vec3::from(b), Vec3::from(c))
}

fn ray(origin: [f32; 3], dir: [f32; 3]) -> Ray {
    Ray::unbounded(Vec3::from(origin), Vec3::from(dir))
}

fn both(tris: &[(WatertightTriangle, u32)], ray: &Ray) -> Hit {
    support::kernel::block::both::<Watertight>(tris, ray, Hit::none(ray))
}

#[test]
fn shared_edges_and_vertices_hit_and_the_lower_index_wins() {
    let quad = [
        (tri([0.0, 0.0, 2.0], [1.0, 0.0, 2.0], [1.0, 1.0, 2.0]), 9),
        (tri([0.0, 0.0, 2.0], [1.0, 1.0, 2.0], [0.0, 1.0, 2.0]), 4),
    ];
    for origin in [[0.5, 0.5, 0.0], [0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 0.0, 0.0]] {
        for dir in [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]] {
            let mut o = origin;
            if dir[2] < 0.0 {
                o[2] = 4.0;
            }
            let r = ray(o, dir);
            let hit = both(&quad, &r);
            assert_eq!(hit.t, 2.0, "{o:?} {dir:?}");
            // On the diagonal both triangles hit: the lower index is kept.
            if origin == [0.5, 0.5, 0.0] || origin == [0.0, 0.0, 0.0] || origin == [1.0, 1.0, 0.0] {
                assert_eq!(hit.prim, 4, "{o:?} {dir:?}");
            }
        }
    }
}

#[test]
fn barycentrics_name_the_second_and_third_vertex() {
    let t = tri([0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]);
    let hit = both(&[(t, 0)], &ray([0.25, 0.5, 0.0], [0.0, 0.0, 1.0]));
    assert_eq!((hit.t, hit.u, hit.v), (1.0, 0.25, 0.5));
}

#[test]
fn parallel_grazing_degenerate_and_behind_miss() {
    let t = tri([0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]);
    let cases = [
        // In the triangle's plane, through it and along an edge.
        ray([-1.0, 0.25, 1.0], [1.0, 0.0, 0.0]),
        ray([-1.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
        // Just outside an edge and a vertex.
        ray([0.5, -1e-6, 0.0], [0.0, 0.0, 1.0]),
        ray([1.0 + 1e-6, 0.0, 0.0], [0.0, 0.0, 1.0]),
        // Behind the origin.
        ray([0.25, 0.25, 2.0], [0.0, 0.0, 1.0]),
    ];
    for r in cases {
        assert_eq!(both(&[(t, 0)], &r).prim, NO_HIT, "{r:?}");
    }
    // Zero-area triangles (collinear, a repeated vertex) are never hit.
    for flat in [
        tri([0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [2.0, 0.0, 1.0]),
        tri([0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 1.0, 1.0]),
    ] {
        let r = ray([0.5, 0.0, 0.0], [0.0, 0.0, 1.0]);
        assert_eq!(both(&[(flat, 0)], &r).prim, NO_HIT);
    }
    // As a primitive, a degenerate triangle is never hit under either test,
    // not even along the segment it lies on.
    let flat = Triangle::new(Vec3::ZERO, Vec3::X, 2.0 * Vec3::X);
    for test in [TriangleTest::Watertight, TriangleTest::Barycentric] {
        let r = ray([0.5, 0.0, -1.0], [0.0, 0.0, 1.0]);
        assert!(
            !flat.with_test(test).intersect(&r, 0, &mut Hit::none(&r)),
            "{test:?}"
        );
    }
}

#[test]
fn poisoned_rays_miss_under_both_tests() {
    for test in [TriangleTest::Watertight, TriangleTest::Barycentric] {
        let t = Triangle::new(
            Vec3::new(-1.0, -1.0, 1.0),
            Vec3::new(2.0, -1.0, 1.0),
            Vec3::new(0.0, 2.0, 1.0),
        )
        .with_test(test);
        support::kernel::assert_poisoned_rays_miss(test.name(), &t);
        for (r, must_miss) in poisoned_rays() {
            let got = both(&[(t.watertight(), 0)], &r);
            assert!(!(must_miss && got.prim != NO_HIT), "{r:?}: {got:?}");
        }
    }
}

/// Rays from inside each closed mesh through its vertices and edge
/// midpoints (1,500 of them, evenly spread), at the origin, far from it and
/// tiny: every one hits, in the scalar, the packet and the block kernel
/// (leaf-sized blocks of the mesh's triangles). The projected test, run on
/// the same rays, is counted but not held to it. (`raypack robustness` aims
/// at every one, through the BVH.)
#[test]
fn rays_through_shared_edges_and_vertices_never_slip_through() {
    for shape in ClosedShape::ALL {
        for (scale, offset) in [(1.0, DVec3::ZERO), (1.0, DVec3::splat(1e3)), (1e-4, DVec3::ZERO)] {
            let mesh = ClosedMesh::new(shape, scale, offset);
            let tris: Vec<Triangle> = mesh
                .triangles
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
                    Triangle::new(a, b, c).with_test(TriangleTest::Watertight)
                })
                .collect();
            let blocks: Vec<WatertightTriangles<f32x8>> = tris
                .chunks(8)
                .enumerate()
                .map(|(k, c)| {
                    let lanes: Vec<_> = c
                        .iter()
                        .enumerate()
                        .map(|(i, t)| (t.watertight(), (8 * k + i) as u32))
                        .collect();
                    WatertightTriangles::new(&lanes)
                })
                .collect();
            let mut targets: Vec<DVec3> = mesh.vertices.iter().map(|v| v.as_dvec3()).collect();
            targets.extend(mesh.edges().iter().map(|([a, b], _)| {
                (mesh.vertices[*a as usize].as_dvec3() + mesh.vertices[*b as usize].as_dvec3()) / 2.0
            }));
            let mut projected_leaks = 0;
            let step = targets.len().div_ceil(1_500);
            for target in targets.into_iter().step_by(step) {
                let origin = mesh.inside_towards(target);
                let r = Ray::unbounded(origin.as_vec3(), (target - origin).normalize().as_vec3());
                let mut scalar = Hit::none(&r);
                for (i, t) in tris.iter().enumerate() {
                    t.intersect(&r, i as u32, &mut scalar);
                }
                assert_ne!(
                    scalar.prim, NO_HIT,
                    "{shape:?} ×{scale} +{offset}: scalar leak at {target}"
                );
                let mut block = Hit::none(&r);
                for b in &blocks {
                    b.intersect(&r, &mut block);
                }
                assert_eq!(block.prim, scalar.prim, "{shape:?}: block kernel at {target}");
                let packet = RayPacket::<f32x8>::from_rays(&[r; 8]);
                let mut hits = HitPacket::none(&packet);
                for (i, t) in tris.iter().enumerate() {
                    t.intersect_packet(&packet, i as u32, &mut hits);
                }
                assert_eq!(
                    hits.hit(3).prim,
                    scalar.prim,
                    "{shape:?}: packet kernel at {target}"
                );
                let mut projected = Hit::none(&r);
                for (i, t) in tris.iter().enumerate() {
                    t.with_test(TriangleTest::Barycentric)
                        .intersect(&r, i as u32, &mut projected);
                }
                projected_leaks += usize::from(projected.prim == NO_HIT);
            }
            eprintln!("{shape:?} ×{scale} +{offset}: projected test leaked {projected_leaks}");
        }
    }
}
