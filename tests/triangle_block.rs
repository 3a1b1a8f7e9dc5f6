//! The triangle block kernel (one ray against up to `F::LANES` triangles at
//! once, what BVH leaves of triangles run for single rays) against its scalar
//! twin, the projected triangle kernel: lane by lane and whole blocks on 4·10⁵
//! seeded random rays with earlier hits, then hand-made cases (ties on shared
//! edges and equal t, vertices, parallel and grazing rays, unused and
//! degenerate lanes, NaN and infinite input).

mod common;

use common::{poisoned_rays, random_ray};
use glam::Vec3;
use raypack::geometry::triangle::{ProjectedTriangle, ProjectedTriangles};
use raypack::geometry::{Intersect, Triangle};
use raypack::packet::{HitPacket, RayPacket};
use raypack::ray::{Hit, Ray};
use raypack::rng::Rng;
use raypack::simd::SimdFloat;
use wide::{f32x4, f32x8};

const RAYS: usize = 400_000;

/// A random triangle around the origin: usually large enough that rays at
/// the unit cube often hit it, one in ten degenerate (collinear), one in ten tiny.
fn random_triangle(rng: &mut Rng) -> Triangle {
    let a = rng.point_in(Vec3::splat(-0.5), Vec3::splat(0.5));
    let kind = rng.below(10);
    let mut edge = |size: f32| size * rng.unit_vector();
    match kind {
        0 => Triangle::new(a, 2.0 * a, 3.0 * a),
        1 => Triangle::new(a, a + edge(1e-4), a + edge(1e-4)),
        _ => Triangle::new(a, a + edge(2.0), a + edge(2.0)),
    }
}

/// A record's fields bit for bit (NaN t included, which `==` never equals).
fn bits((hit, recorded): (Hit, bool)) -> ([u32; 4], bool) {
    (
        [hit.t.to_bits(), hit.prim, hit.u.to_bits(), hit.v.to_bits()],
        recorded,
    )
}

/// The record a ray brings into a leaf: nothing yet, or an earlier hit (some
/// with primitive indices that tie-break against the block's).
fn earlier_hit(rng: &mut Rng, ray: &Ray) -> Hit {
    let mut hit = Hit::none(ray);
    if rng.below(4) == 0 {
        hit.record(rng.range(0.0, 4.0), rng.below(20), 0.25, 0.5);
    }
    hit
}

/// The scalar kernel over `tris` in the given order: what a leaf of records computes.
fn scalar(tris: &[(ProjectedTriangle, u32)], ray: &Ray, prior: Hit) -> (Hit, bool) {
    let mut hit = prior;
    let mut recorded = false;
    for (t, id) in tris {
        recorded |= t.intersect(ray, *id, &mut hit);
    }
    (hit, recorded)
}

/// The block kernel at width `F` over `tris`.
fn block<F: SimdFloat>(tris: &[(ProjectedTriangle, u32)], ray: &Ray, prior: Hit) -> (Hit, bool) {
    let mut hit = prior;
    let recorded = ProjectedTriangles::<F>::new(tris).intersect(ray, &mut hit);
    (hit, recorded)
}

/// Every lane position alone (the others unused), and whole blocks in both
/// orders, give exactly the scalar records (bit for bit: the same arithmetic).
fn agrees_with_scalar<F: SimdFloat>(seed: u64) {
    let mut rng = Rng::new(seed);
    let (mut lane_hits, mut lane_tests) = (0usize, 0usize);
    for _ in 0..RAYS / F::LANES {
        let tris: Vec<(ProjectedTriangle, u32)> = (0..F::LANES)
            .map(|_| (*random_triangle(&mut rng).projected(), rng.below(20)))
            .collect();
        for _ in 0..F::LANES {
            let ray = random_ray(&mut rng, Vec3::splat(-0.5), Vec3::splat(0.5));
            let prior = earlier_hit(&mut rng, &ray);
            // Lane by lane: triangle i in lane i, every other lane unused.
            for (i, tri) in tris.iter().enumerate() {
                let mut alone = vec![(ProjectedTriangle::ZERO_AREA, 0); i];
                alone.push(*tri);
                let want = scalar(&[*tri], &ray, prior);
                assert_eq!(
                    bits(block::<F>(&alone, &ray, prior)),
                    bits(want),
                    "lane {i}, {tri:?}, {ray:?}, {prior:?}"
                );
                lane_tests += 1;
                lane_hits += want.1 as usize;
            }
            // The whole block, whichever order the scalar loop takes.
            let mut reversed = tris.clone();
            reversed.reverse();
            let want = scalar(&tris, &ray, prior);
            assert_eq!(
                bits(scalar(&reversed, &ray, prior)).0,
                bits(want).0,
                "{tris:?}, {ray:?}"
            );
            assert_eq!(
                bits(block::<F>(&tris, &ray, prior)),
                bits(want),
                "{tris:?}, {ray:?}, {prior:?}"
            );
            assert_eq!(
                bits(block::<F>(&reversed, &ray, prior)),
                bits(want),
                "{tris:?}, {ray:?}, {prior:?}"
            );
        }
    }
    // A run that never hits, or always does, proves nothing.
    let rate = lane_hits as f64 / lane_tests as f64;
    assert!(
        (0.05..0.95).contains(&rate),
        "hit rate {rate} is too extreme to be a test"
    );
}

#[test]
fn block_of_four_agrees_with_the_scalar_kernel() {
    agrees_with_scalar::<f32x4>(1);
}

#[test]
fn block_of_eight_agrees_with_the_scalar_kernel() {
    agrees_with_scalar::<f32x8>(2);
}

/// A block lane's packet kernel is the packet kernel of the triangle in it.
#[test]
fn block_lanes_run_the_triangle_packet_kernel() {
    let mut rng = Rng::new(3);
    for _ in 0..20_000 {
        let tris: Vec<(ProjectedTriangle, u32)> = (0..4)
            .map(|_| (*random_triangle(&mut rng).projected(), rng.below(20)))
            .collect();
        let used = 1 + rng.below(4) as usize;
        let blk = ProjectedTriangles::<f32x4>::new(&tris[..used]);
        let rays: Vec<Ray> = (0..8)
            .map(|_| random_ray(&mut rng, Vec3::splat(-0.5), Vec3::splat(0.5)))
            .collect();
        let packet = RayPacket::<f32x8>::from_rays_masked(&rays, rng.next_u32());
        for (lane, (tri, id)) in tris.iter().enumerate() {
            let (mut want, mut got) = (HitPacket::none(&packet), HitPacket::none(&packet));
            tri.intersect_packet(&packet, *id, &mut want);
            blk.intersect_packet(lane, &packet, &mut got);
            for r in 0..8 {
                let expected = if lane < used {
                    want.hit(r)
                } else {
                    HitPacket::none(&packet).hit(r)
                };
                assert_eq!(got.hit(r), expected, "lane {lane}, ray {r}");
            }
        }
    }
}

fn tri(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> ProjectedTriangle {
    *Triangle::new(Vec3::from(a), Vec3::from(b), Vec3::from(c)).projected()
}

fn ray(origin: [f32; 3], dir: [f32; 3]) -> Ray {
    Ray::unbounded(Vec3::from(origin), Vec3::from(dir))
}

/// Both kernels on `tris`, checked equal; the block's record.
fn both(tris: &[(ProjectedTriangle, u32)], ray: &Ray, prior: Hit) -> Hit {
    let want = scalar(tris, ray, prior);
    assert_eq!(bits(block::<f32x4>(tris, ray, prior)), bits(want), "{ray:?}");
    want.0
}

#[test]
fn equal_t_goes_to_the_lower_index_in_any_lane() {
    let unit = tri([0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]);
    let r = ray([0.25, 0.25, 0.0], [0.0, 0.0, 1.0]);
    for tris in [[(unit, 7), (unit, 3)], [(unit, 3), (unit, 7)]] {
        assert_eq!(both(&tris, &r, Hit::none(&r)).prim, 3);
        // An earlier record at the same t keeps or loses its place by index.
        let mut earlier = Hit::none(&r);
        earlier.record(1.0, 5, 0.0, 0.0);
        assert_eq!(both(&tris, &r, earlier).prim, 3);
        earlier.record(1.0, 1, 0.0, 0.0);
        assert_eq!(both(&tris, &r, earlier).prim, 1);
    }
}

#[test]
fn shared_edges_and_vertices_are_hit() {
    // A quad of two triangles: its diagonal, a shared vertex and a corner.
    let quad = [
        (tri([0.0, 0.0, 2.0], [1.0, 0.0, 2.0], [1.0, 1.0, 2.0]), 4),
        (tri([0.0, 0.0, 2.0], [1.0, 1.0, 2.0], [0.0, 1.0, 2.0]), 9),
    ];
    for origin in [[0.5, 0.5, 0.0], [0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 0.0, 0.0]] {
        let r = ray(origin, [0.0, 0.0, 1.0]);
        let hit = both(&quad, &r, Hit::none(&r));
        assert_eq!(hit.t, 2.0, "{origin:?}");
    }
    // On the diagonal both triangles are hit at t = 2: the lower index reports.
    let r = ray([0.5, 0.5, 0.0], [0.0, 0.0, 1.0]);
    assert_eq!(both(&quad, &r, Hit::none(&r)).prim, 4);
}

#[test]
fn parallel_grazing_behind_and_out_of_range_rays_miss() {
    let t = [(tri([0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]), 0)];
    let misses = [
        ray([0.2, 0.2, 1.0], [1.0, 0.0, 0.0]), // in the triangle's plane
        ray([0.2, 0.2, 0.5], [0.0, 1.0, 0.0]), // parallel beside it
        ray([0.2, 0.2, 2.0], [0.0, 0.0, 1.0]), // triangle behind the origin
        Ray::new(Vec3::new(0.2, 0.2, 0.0), Vec3::Z, 0.0, 0.5), // beyond t_max
        Ray::new(Vec3::new(0.2, 0.2, 0.0), Vec3::Z, 1.5, 9.0), // before t_min
        ray([0.9, 0.9, 0.0], [0.0, 0.0, 1.0]), // beside the hypotenuse
    ];
    for r in misses {
        assert!(!both(&t, &r, Hit::none(&r)).is_hit(), "{r:?}");
    }
}

#[test]
fn unused_and_degenerate_lanes_are_never_hit() {
    let r = ray([0.0, 0.0, -5.0], [0.0, 0.0, 1.0]);
    assert!(!both(&[], &r, Hit::none(&r)).is_hit());
    let degenerate = [
        *Triangle::new(Vec3::ZERO, Vec3::X, 2.0 * Vec3::X).projected(),
        *Triangle::new(Vec3::ZERO, Vec3::ZERO, Vec3::Y).projected(),
        *Triangle::new(Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 0.0), Vec3::Y).projected(),
    ];
    let tris: Vec<_> = degenerate.iter().map(|&t| (t, 1)).collect();
    for origin in [[0.0, 0.0, -5.0], [0.5, 0.0, -5.0], [0.0, 0.5, -5.0]] {
        let r = ray(origin, [0.0, 0.0, 1.0]);
        assert!(!both(&tris, &r, Hit::none(&r)).is_hit(), "{origin:?}");
    }
}

#[test]
fn nan_and_infinite_rays_miss_without_panicking() {
    // Triangles around the origin, where the poisoned rays' clean version points.
    let tris = [
        (tri([-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]), 2),
        (tri([-1.0, 0.0, -1.0], [1.0, 0.0, -1.0], [0.0, 0.0, 1.0]), 6),
        (tri([0.0, -1.0, -1.0], [0.0, 1.0, -1.0], [0.0, 0.0, 1.0]), 8),
    ];
    for (r, must_miss) in poisoned_rays() {
        let hit = both(&tris, &r, Hit::none(&r));
        if must_miss {
            assert!(!hit.is_hit(), "{r:?}");
        } else if hit.is_hit() {
            assert!(hit.t.is_finite(), "{r:?}");
        }
    }
}
