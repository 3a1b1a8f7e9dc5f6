//! The triangle block kernel (one ray against up to `F::LANES` triangles at
//! once, what BVH leaves of triangles run for single rays) against its scalar
//! twin, the projected triangle kernel: lane by lane and whole blocks on 4·10⁵
//! seeded random rays with earlier hits, then hand-made cases (ties on shared
//! edges and equal t, vertices, parallel and grazing rays, unused and
//! degenerate lanes, NaN and infinite input).

use crate::support;
use crate::support::kernel::block::{
    BlockKernel, assert_block_agrees, assert_block_lanes_run_the_packet_kernel,
};
use crate::support::kernel::poisoned_rays;
use glam::Vec3;
use raypack::geometry::triangle::{MAX_BLOCK_ID, ProjectedTriangle, ProjectedTriangles};
use raypack::geometry::{BlockIntersect, Intersect, Triangle};
use raypack::packet::{HitPacket, RayPacket};
use raypack::ray::{Hit, Ray};
use raypack::rng::Rng;
use raypack::simd::SimdFloat;
use wide::{f32x4, f32x8};

/// The triangle block and its scalar twin, the projected triangle kernel.
struct Triangles;

impl BlockKernel for Triangles {
    type Shape = ProjectedTriangle;
    const EMPTY: ProjectedTriangle = ProjectedTriangle::ZERO_AREA;

    fn scalar(tri: &ProjectedTriangle, id: u32, ray: &Ray, hit: &mut Hit) -> bool {
        tri.intersect(ray, id, hit)
    }

    fn block<F: SimdFloat>(tris: &[(ProjectedTriangle, u32)], ray: &Ray, hit: &mut Hit) -> bool {
        ProjectedTriangles::<F>::new(tris).intersect(ray, hit)
    }

    fn packet(tri: &ProjectedTriangle, id: u32, rays: &RayPacket<f32x8>, hits: &mut HitPacket<f32x8>) {
        tri.intersect_packet(rays, id, hits);
    }

    fn block_lane_packet(
        tris: &[(ProjectedTriangle, u32)],
        lane: usize,
        rays: &RayPacket<f32x8>,
        hits: &mut HitPacket<f32x8>,
    ) {
        ProjectedTriangles::<f32x4>::new(tris).intersect_packet(lane, rays, hits);
    }
}

/// A random triangle around the origin: usually large enough that rays at
/// the unit cube often hit it, one in ten degenerate (collinear), one in ten tiny.
fn random_triangle(rng: &mut Rng) -> ProjectedTriangle {
    let a = rng.point_in(Vec3::splat(-0.5), Vec3::splat(0.5));
    let kind = rng.below(10);
    let mut edge = |size: f32| size * rng.unit_vector();
    let t = match kind {
        0 => Triangle::new(a, 2.0 * a, 3.0 * a),
        1 => Triangle::new(a, a + edge(1e-4), a + edge(1e-4)),
        _ => Triangle::new(a, a + edge(2.0), a + edge(2.0)),
    };
    *t.projected()
}

#[test]
fn block_of_four_agrees_with_the_scalar_kernel() {
    assert_block_agrees::<Triangles, f32x4>(1, random_triangle);
}

#[test]
fn block_of_eight_agrees_with_the_scalar_kernel() {
    assert_block_agrees::<Triangles, f32x8>(2, random_triangle);
}

/// A block lane's packet kernel is the packet kernel of the triangle in it.
#[test]
fn block_lanes_run_the_triangle_packet_kernel() {
    assert_block_lanes_run_the_packet_kernel::<Triangles>(3, random_triangle);
}

fn tri(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> ProjectedTriangle {
    *Triangle::new(Vec3::from(a), Vec3::from(b), Vec3::from(c)).projected()
}

fn ray(origin: [f32; 3], dir: [f32; 3]) -> Ray {
    Ray::unbounded(Vec3::from(origin), Vec3::from(dir))
}

/// Both kernels on `tris`, checked equal; the block's record.
fn both(tris: &[(ProjectedTriangle, u32)], ray: &Ray, prior: Hit) -> Hit {
    support::kernel::block::both::<Triangles>(tris, ray, prior)
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

/// A lane's dropped axis rides in the top bits of its primitive index: each
/// axis, next to the largest index a block holds, still tests on its own axis
/// and reports its own index (through the block and its lanes' packet kernel).
#[test]
fn every_dropped_axis_keeps_the_largest_indices_intact() {
    // Unit triangles facing x, y and z at distance 2, and rays along each axis.
    let facing = [
        tri([2.0, 0.0, 0.0], [2.0, 1.0, 0.0], [2.0, 0.0, 1.0]),
        tri([0.0, 2.0, 0.0], [0.0, 2.0, 1.0], [1.0, 2.0, 0.0]),
        tri([0.0, 0.0, 2.0], [1.0, 0.0, 2.0], [0.0, 1.0, 2.0]),
    ];
    let ids = [MAX_BLOCK_ID, MAX_BLOCK_ID - 1, 1 << 29];
    let tris: Vec<_> = facing.into_iter().zip(ids).collect();
    for (axis, id) in ids.into_iter().enumerate() {
        let (mut origin, mut dir) = ([0.25; 3], [0.0; 3]);
        (origin[axis], dir[axis]) = (0.0, 1.0);
        let r = ray(origin, dir);
        let hit = both(&tris, &r, Hit::none(&r));
        assert_eq!((hit.t, hit.prim), (2.0, id), "axis {axis}");
        let rays = RayPacket::<f32x8>::from_rays(&[r]);
        let mut hits = HitPacket::none(&rays);
        for lane in 0..tris.len() {
            ProjectedTriangles::<f32x4>::new(&tris).intersect_packet(lane, &rays, &mut hits);
        }
        assert_eq!(hits.hit(0).prim, id, "axis {axis}");
    }
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
