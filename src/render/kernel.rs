//! How a batch of rays meets the scene: one ray at a time through the scalar
//! kernels, or as SIMD packets through the packet kernels.
//!
//! The renderer hands every query (primary, reflection, refraction, shadow) to a
//! [`TraceKernel`] as a batch of [`BATCH`](crate::render::batch::BATCH) rays with a lane mask, and shades the
//! results with the same scalar code whichever kernel traced them. Since the packet
//! kernels agree with their scalar twins lane by lane, both kernels then produce
//! the same hits, the same secondary rays and the same images.
//!
//! Every query reports its traversal work to the tile's [`TileCounter`],
//! after telling it which batch lanes it traces; with [`NoStats`] the counting
//! compiles away.
//!
//! [`NoStats`]: crate::accel::stats::NoStats

use std::marker::PhantomData;

use crate::accel::Accel;
use crate::ray::Hit;
use crate::render::batch::{Hits, Rays};
use crate::render::counting::TileCounter;
use crate::simd::{SimdFloat, SimdU32};

/// Nearest-hit and occlusion queries on batches of rays.
pub trait TraceKernel: Send + Sync + 'static {
    /// Nearest hits of the lanes in `active`; other lanes get [`Hit::none`].
    fn intersect<A: Accel, C: TileCounter>(accel: &A, rays: &Rays, active: u32, counter: &mut C) -> Hits;

    /// The mask of lanes in `active` whose ray is blocked in `[t_min, t_max]`.
    fn occluded<A: Accel, C: TileCounter>(accel: &A, rays: &Rays, active: u32, counter: &mut C) -> u32;
}

/// One ray at a time: [`Accel::intersect`] and [`Accel::occluded`].
///
/// [`Accel::intersect`]: crate::accel::Accel::intersect
/// [`Accel::occluded`]: crate::accel::Accel::occluded
#[derive(Clone, Copy, Debug, Default)]
pub struct ScalarKernel;

impl TraceKernel for ScalarKernel {
    #[inline]
    fn intersect<A: Accel, C: TileCounter>(accel: &A, rays: &Rays, active: u32, counter: &mut C) -> Hits {
        // Filled in place: the records are returned where the caller wants them.
        let mut out: Hits = std::array::from_fn(|i| Hit::none(&rays[i]));
        counter.batch_lanes(0);
        accel.intersect_each_counted(rays, active, &mut out, counter);
        out
    }

    #[inline]
    fn occluded<A: Accel, C: TileCounter>(accel: &A, rays: &Rays, active: u32, counter: &mut C) -> u32 {
        counter.batch_lanes(0);
        accel.occluded_each_counted(rays, active, counter)
    }
}

/// SIMD packets of `F::LANES` rays: [`Accel::intersect_packet`] and
/// [`Accel::occluded_packet`]. A batch is cut into `BATCH / F::LANES` packets
/// (two for `f32x8`, one for `f32x16`); lanes past the batch are inactive.
///
/// [`Accel::intersect_packet`]: crate::accel::Accel::intersect_packet
/// [`Accel::occluded_packet`]: crate::accel::Accel::occluded_packet
#[derive(Clone, Copy, Debug, Default)]
pub struct PacketKernel<F>(PhantomData<F>);

/// The engine's 8-wide packet kernel: two packets per batch.
pub type Packet8Kernel = PacketKernel<wide::f32x8>;

/// The 16-wide packet kernel: one packet per batch.
pub type Packet16Kernel = PacketKernel<wide::f32x16>;

impl<F: SimdFloat> TraceKernel for PacketKernel<F> {
    #[inline]
    fn intersect<A: Accel, C: TileCounter>(accel: &A, rays: &Rays, active: u32, counter: &mut C) -> Hits {
        let mut out: Hits = std::array::from_fn(|i| Hit::none(&rays[i]));
        for (c, chunk) in rays.chunks(F::LANES).enumerate() {
            let first = c * F::LANES;
            let mask = active >> first & ((1u32 << chunk.len()) - 1);
            if mask == 0 {
                continue;
            }
            counter.batch_lanes(first);
            let hits = accel.intersect_rays_counted::<F, C>(chunk, mask, counter);
            // Unpack each vector once rather than lane by lane.
            let (t, prim, u, v) = (
                hits.t.to_array(),
                hits.prim.to_array(),
                hits.u.to_array(),
                hits.v.to_array(),
            );
            for lane in (0..chunk.len()).filter(|lane| mask >> lane & 1 == 1) {
                let hit = &mut out[first + lane];
                hit.t = t.as_ref()[lane];
                hit.prim = prim.as_ref()[lane];
                hit.u = u.as_ref()[lane];
                hit.v = v.as_ref()[lane];
            }
        }
        out
    }

    #[inline]
    fn occluded<A: Accel, C: TileCounter>(accel: &A, rays: &Rays, active: u32, counter: &mut C) -> u32 {
        let mut blocked = 0;
        for (c, chunk) in rays.chunks(F::LANES).enumerate() {
            let first = c * F::LANES;
            let mask = active >> first & ((1u32 << chunk.len()) - 1);
            if mask != 0 {
                counter.batch_lanes(first);
                let lanes = accel.occluded_rays_counted::<F, C>(chunk, mask, counter);
                blocked |= (lanes.bitmask() & mask) << first;
            }
        }
        blocked
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::accel::BruteForce;
    use crate::accel::stats::NoStats;
    use crate::geometry::{Primitive, Sphere};
    use crate::ray::Ray;
    use crate::render::batch::{ALL_LANES, BATCH};
    use crate::rng::Rng;

    fn cloud(rng: &mut Rng) -> Vec<Primitive> {
        (0..24)
            .map(|_| {
                let c = rng.point_in(Vec3::splat(-3.0), Vec3::splat(3.0));
                Primitive::Sphere(Sphere::new(c, rng.range(0.2, 0.8)))
            })
            .collect()
    }

    /// Every kernel (and a 4-wide packet kernel) gives the same records and
    /// occlusion masks, lane by lane; inactive lanes are never hit or blocked.
    fn check(accel: &BruteForce, rays: &Rays, active: u32) {
        let a = ScalarKernel::intersect(accel, rays, active, &mut NoStats);
        assert_eq!(
            a,
            Packet8Kernel::intersect(accel, rays, active, &mut NoStats),
            "{rays:?} {active:b}"
        );
        assert_eq!(
            a,
            Packet16Kernel::intersect(accel, rays, active, &mut NoStats),
            "{rays:?} {active:b}"
        );
        assert_eq!(
            a,
            PacketKernel::<wide::f32x4>::intersect(accel, rays, active, &mut NoStats)
        );
        let blocked = ScalarKernel::occluded(accel, rays, active, &mut NoStats);
        assert_eq!(
            blocked,
            Packet8Kernel::occluded(accel, rays, active, &mut NoStats),
            "{rays:?}"
        );
        assert_eq!(
            blocked,
            Packet16Kernel::occluded(accel, rays, active, &mut NoStats),
            "{rays:?}"
        );
        assert_eq!(
            blocked,
            PacketKernel::<wide::f32x4>::occluded(accel, rays, active, &mut NoStats)
        );
        assert_eq!(blocked & !active, 0);
        for i in (0..BATCH).filter(|i| active >> i & 1 == 0) {
            assert_eq!(a[i], Hit::none(&rays[i]));
        }
    }

    /// 10⁶ random rays aimed at a cloud of spheres, with random lane masks and
    /// random `[t_min, t_max]` (some starting inside spheres).
    #[test]
    fn scalar_and_packet_batches_agree_lane_by_lane() {
        let mut rng = Rng::new(7);
        let prims = cloud(&mut rng);
        let accel = BruteForce::new(&prims);
        for _ in 0..1_000_000 / BATCH {
            let rays: Rays = std::array::from_fn(|_| {
                let o = 8.0 * rng.unit_vector();
                let d = (rng.point_in(Vec3::splat(-3.0), Vec3::splat(3.0)) - o).normalize();
                Ray::new(o, d, rng.range(0.0, 8.0), rng.range(2.0, 20.0))
            });
            check(&accel, &rays, rng.below(1 << BATCH));
        }
    }

    /// Hand-made lanes: tangent, inside, empty interval, NaN and infinite input.
    #[test]
    fn scalar_and_packet_batches_agree_on_edge_cases() {
        let prims = vec![Primitive::Sphere(Sphere::new(Vec3::ZERO, 1.0))];
        let accel = BruteForce::new(&prims);
        let edge_cases = [
            Ray::unbounded(Vec3::new(-5.0, 1.0, 0.0), Vec3::X), // tangent
            Ray::unbounded(Vec3::ZERO, Vec3::Y),                // inside
            Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z, 3.0, 2.0), // empty interval
            Ray::unbounded(Vec3::NAN, Vec3::X),
            Ray::unbounded(Vec3::new(0.0, 0.0, 5.0), Vec3::NAN),
            Ray::unbounded(Vec3::splat(f32::INFINITY), -Vec3::X),
            Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z, 0.0, 3.9), // stops short
            Ray::unbounded(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z),     // head-on
        ];
        // Twice over: in each half of the batch (each 8-wide packet).
        let rays: Rays = std::array::from_fn(|i| edge_cases[i % edge_cases.len()]);
        for active in [ALL_LANES, 0, 0xaaaa, 0x5555, 0x00ff, 0xff00] {
            check(&accel, &rays, active);
        }
        let hits = ScalarKernel::intersect(&accel, &rays, ALL_LANES, &mut NoStats);
        assert_eq!(hits[1].t, 1.0);
        assert_eq!(hits[7].t, 4.0);
        assert!(!hits[2].is_hit() && !hits[3].is_hit() && !hits[6].is_hit());
        assert_eq!(
            ScalarKernel::occluded(&accel, &rays, ALL_LANES, &mut NoStats) & 0b1100_0110,
            0b1000_0010
        );
    }
}
