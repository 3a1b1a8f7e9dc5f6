//! A bounding volume hierarchy over a scene's bounded primitives, built as a
//! binary tree of 32-byte nodes with binned SAH ([`build_sah`], [`node`]) and
//! also collapsed into 16-wide and 8-wide nodes ([`wide`]) over the same
//! leaves. 8-ray packets traverse the binary tree ([`traverse_packet`]:
//! testing a packet against each box as soon as the tree branches culls more
//! than eight boxes at once would), single rays the 16-wide tree
//! ([`traverse_single`], one SIMD test per node), and incoherent packets the
//! 8-wide one ([`traverse_hybrid`], together while enough lanes share a node,
//! then as single rays; rays from all over the scene as single rays interleaved);
//! shadow rays use either ([`occlusion`]). Leaves call the primitives' own
//! kernels; a leaf of triangles or of spheres holds them in a block a single
//! ray tests at once ([`leaf`]).
//!
//! Primitives without a finite box (infinite planes, and anything whose box
//! overflows) are kept outside the tree and tested directly by every ray;
//! degenerate triangles, which no ray can hit, are left out. Hits report the
//! primitive's index in the input slice, so a BVH and [`BruteForce`] give the
//! same records.
//!
//! ```
//! use raypack::accel::{Accel, BruteForce, Bvh, TraversalCounter};
//! use raypack::scene::generate::random::random_spheres;
//! use raypack::packet::RayPacket8;
//! use raypack::ray::Ray;
//! use glam::Vec3;
//!
//! let prims = random_spheres(1000, 1);
//! let bvh = Bvh::new(&prims);
//! let ray = Ray::unbounded(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
//! let hit = bvh.intersect(&ray);
//! assert_eq!(hit, BruteForce::new(&prims).intersect(&ray));
//!
//! // Eight rays at once, with the cost counted.
//! let mut stats = TraversalCounter::totals();
//! let hits = bvh.intersect_packet_counted(&RayPacket8::from_rays(&[ray; 8]), &mut stats);
//! assert_eq!(hits.hit(7), hit);
//! println!("{}", stats.total().caption()); // e.g. "9.0 nodes/ray, 1.0 prims/ray, lanes 100%"
//! ```
//!
//! [`BruteForce`]: crate::accel::BruteForce

pub mod build_sah;
pub mod builder;
pub mod dispatch;
pub mod lanes;
pub mod leaf;
pub mod leaf_store;
pub mod node;
pub mod occlusion;
pub mod query;
pub mod ray_box;
pub mod stack;
pub mod traverse_hybrid;
pub mod traverse_packet;
pub mod traverse_single;
pub mod tree;
pub mod wide;

pub use build_sah::{
    BuildOptions, LARGE_SCENE_PRIMITIVES, LeafKind, MAX_DEPTH, MEDIUM_SCENE_PRIMITIVES,
    SMALL_BLOCK_SCENE_PRIMITIVES, SMALL_RECORD_SCENE_PRIMITIVES, SMALL_SCENE_PRICED_BLOCK,
};
pub use tree::{Bvh, BvhInfo};

use crate::accel::Accel;
use crate::accel::bvh::query::Scope;
use crate::accel::stats::Counter;
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::SimdFloat;

// The query entry points are generic over the counter already.
impl Accel for Bvh {
    #[inline]
    fn intersect_counted<S: Counter>(&self, ray: &Ray, stats: &mut S) -> Hit {
        dispatch::intersect(self, ray, stats)
    }

    #[inline]
    fn intersect_packet_counted<F: SimdFloat, S: Counter>(
        &self,
        rays: &RayPacket<F>,
        stats: &mut S,
    ) -> HitPacket<F> {
        dispatch::intersect_packet(self, rays, stats)
    }

    #[inline]
    fn occluded_counted<S: Counter>(&self, ray: &Ray, stats: &mut S) -> bool {
        dispatch::occluded(self, ray, stats)
    }

    #[inline]
    fn intersect_rays_counted<F: SimdFloat, S: Counter>(
        &self,
        rays: &[Ray],
        mask: u32,
        stats: &mut S,
    ) -> HitPacket<F> {
        dispatch::intersect_rays(self, rays, mask, stats)
    }

    #[inline]
    fn occluded_rays_counted<F: SimdFloat, S: Counter>(&self, rays: &[Ray], mask: u32, stats: &mut S) -> F {
        dispatch::occluded_rays(self, rays, mask, stats)
    }

    #[inline]
    fn intersect_each_counted<S: Counter>(&self, rays: &[Ray], active: u32, hits: &mut [Hit], stats: &mut S) {
        dispatch::intersect_each(self, rays, active, hits, stats)
    }

    #[inline]
    fn occluded_each_counted<S: Counter>(&self, rays: &[Ray], active: u32, stats: &mut S) -> u32 {
        dispatch::occluded_each(self, rays, active, stats)
    }

    #[inline]
    fn occluded_packet_counted<F: SimdFloat, S: Counter>(&self, rays: &RayPacket<F>, stats: &mut S) -> F {
        dispatch::occluded_packet(self, rays, Scope::World, stats)
    }
}
