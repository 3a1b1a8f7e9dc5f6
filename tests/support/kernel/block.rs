//! The agreement harness of block kernels (one ray against up to `F::LANES`
//! shapes at once, what BVH leaves run for single rays) with their scalar twins.

use std::fmt::Debug;

use glam::Vec3;
use raypack::packet::{HitPacket, RayPacket};
use raypack::ray::{Hit, Ray};
use raypack::rng::Rng;
use raypack::simd::SimdFloat;
use wide::f32x8;

use super::random_ray;

/// Rays per agreement run.
pub const RAYS: usize = 400_000;

/// A shape with a block kernel: the block at any width, its scalar twin, and
/// the packet kernel of a block lane.
pub trait BlockKernel {
    /// One lane's data.
    type Shape: Copy + Debug;
    /// What fills a lane that nothing can hit.
    const EMPTY: Self::Shape;
    /// The scalar kernel of one shape.
    fn scalar(shape: &Self::Shape, id: u32, ray: &Ray, hit: &mut Hit) -> bool;
    /// The block kernel at width `F` over `shapes`.
    fn block<F: SimdFloat>(shapes: &[(Self::Shape, u32)], ray: &Ray, hit: &mut Hit) -> bool;
    /// The packet kernel of one shape.
    fn packet(shape: &Self::Shape, id: u32, rays: &RayPacket<f32x8>, hits: &mut HitPacket<f32x8>);
    /// The packet kernel of lane `lane` of a 4-wide block over `shapes`.
    fn block_lane_packet(
        shapes: &[(Self::Shape, u32)],
        lane: usize,
        rays: &RayPacket<f32x8>,
        hits: &mut HitPacket<f32x8>,
    );
}

/// A record's fields bit for bit (NaN t included, which `==` never equals).
pub fn bits((hit, recorded): (Hit, bool)) -> ([u32; 4], bool) {
    (
        [hit.t.to_bits(), hit.prim, hit.u.to_bits(), hit.v.to_bits()],
        recorded,
    )
}

/// The record a ray brings into a leaf: nothing yet, or an earlier hit (some
/// with primitive indices that tie-break against the block's).
pub fn earlier_hit(rng: &mut Rng, ray: &Ray) -> Hit {
    let mut hit = Hit::none(ray);
    if rng.below(4) == 0 {
        hit.record(rng.range(0.0, 4.0), rng.below(20), 0.25, 0.5);
    }
    hit
}

/// The scalar kernel over `shapes` in the given order: what a leaf of records computes.
pub fn scalar<K: BlockKernel>(shapes: &[(K::Shape, u32)], ray: &Ray, prior: Hit) -> (Hit, bool) {
    let mut hit = prior;
    let mut recorded = false;
    for (shape, id) in shapes {
        recorded |= K::scalar(shape, *id, ray, &mut hit);
    }
    (hit, recorded)
}

/// The block kernel at width `F` over `shapes`.
pub fn block<K: BlockKernel, F: SimdFloat>(shapes: &[(K::Shape, u32)], ray: &Ray, prior: Hit) -> (Hit, bool) {
    let mut hit = prior;
    let recorded = K::block::<F>(shapes, ray, &mut hit);
    (hit, recorded)
}

/// Both kernels on `shapes` (4-wide block), checked bit for bit equal; the record.
pub fn both<K: BlockKernel>(shapes: &[(K::Shape, u32)], ray: &Ray, prior: Hit) -> Hit {
    let want = scalar::<K>(shapes, ray, prior);
    assert_eq!(
        bits(block::<K, wide::f32x4>(shapes, ray, prior)),
        bits(want),
        "{ray:?}"
    );
    want.0
}

/// On seeded random rays around the unit cube at the origin, every lane
/// position alone (the others empty), and whole blocks of `random_shape` in
/// both orders, give exactly the scalar records (bit for bit: the same arithmetic).
pub fn assert_block_agrees<K: BlockKernel, F: SimdFloat>(
    seed: u64,
    random_shape: impl Fn(&mut Rng) -> K::Shape,
) {
    let mut rng = Rng::new(seed);
    let (mut lane_hits, mut lane_tests) = (0usize, 0usize);
    for _ in 0..RAYS / F::LANES {
        let shapes: Vec<(K::Shape, u32)> = (0..F::LANES)
            .map(|_| (random_shape(&mut rng), rng.below(20)))
            .collect();
        for _ in 0..F::LANES {
            let ray = random_ray(&mut rng, Vec3::splat(-0.5), Vec3::splat(0.5));
            let prior = earlier_hit(&mut rng, &ray);
            // Lane by lane: shape i in lane i, every other lane empty.
            for (i, shape) in shapes.iter().enumerate() {
                let mut alone = vec![(K::EMPTY, 0); i];
                alone.push(*shape);
                let want = scalar::<K>(&[*shape], &ray, prior);
                assert_eq!(
                    bits(block::<K, F>(&alone, &ray, prior)),
                    bits(want),
                    "lane {i}, {shape:?}, {ray:?}, {prior:?}"
                );
                lane_tests += 1;
                lane_hits += want.1 as usize;
            }
            // The whole block, whichever order the scalar loop takes.
            let mut reversed = shapes.clone();
            reversed.reverse();
            let want = scalar::<K>(&shapes, &ray, prior);
            assert_eq!(
                bits(scalar::<K>(&reversed, &ray, prior)).0,
                bits(want).0,
                "{shapes:?}, {ray:?}"
            );
            for order in [&shapes, &reversed] {
                assert_eq!(
                    bits(block::<K, F>(order, &ray, prior)),
                    bits(want),
                    "{order:?}, {ray:?}, {prior:?}"
                );
            }
        }
    }
    // A run that never hits, or always does, proves nothing.
    let rate = lane_hits as f64 / lane_tests as f64;
    assert!(
        (0.05..0.95).contains(&rate),
        "hit rate {rate} is too extreme to be a test"
    );
}

/// A 4-wide block lane's packet kernel is the packet kernel of the shape in
/// it, on seeded random packets with random active lanes; an empty lane is
/// never hit.
pub fn assert_block_lanes_run_the_packet_kernel<K: BlockKernel>(
    seed: u64,
    random_shape: impl Fn(&mut Rng) -> K::Shape,
) {
    let mut rng = Rng::new(seed);
    for _ in 0..20_000 {
        let shapes: Vec<(K::Shape, u32)> = (0..4).map(|_| (random_shape(&mut rng), rng.below(20))).collect();
        let used = 1 + rng.below(4) as usize;
        let rays: Vec<Ray> = (0..8)
            .map(|_| random_ray(&mut rng, Vec3::splat(-0.5), Vec3::splat(0.5)))
            .collect();
        let packet = RayPacket::<f32x8>::from_rays_masked(&rays, rng.next_u32());
        for (lane, (shape, id)) in shapes.iter().enumerate() {
            let (mut want, mut got) = (HitPacket::none(&packet), HitPacket::none(&packet));
            K::packet(shape, *id, &packet, &mut want);
            K::block_lane_packet(&shapes[..used], lane, &packet, &mut got);
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
