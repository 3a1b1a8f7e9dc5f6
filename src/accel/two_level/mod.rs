//! A two-level structure for scenes with instances: one bottom-level
//! structure per mesh, built once however often the mesh is placed, and a
//! top-level BVH over the instances' world boxes.
//!
//! A ray that reaches an instance is brought into the mesh's space with M⁻¹
//! (lecture section 7: transform the ray, not the object) and traced through
//! the mesh's structure; where the mesh holds only triangles and polygons the
//! direction keeps its length, so t is the same in both spaces, and where a
//! kernel needs a unit direction (spheres, cones) it is renormalised and t
//! scaled back, as [`Transformed`](crate::geometry::Transformed) does. A packet
//! enters an instance as one packet (its active lanes, all under the same
//! M⁻¹), so coherent rays stay coherent inside. Hits carry the scene's ids
//! ([`Scene::locate`](crate::scene::Scene::locate)): an instance's first id
//! plus the mesh primitive's index, and ties between instances go to the lower
//! id as they do between primitives.
//!
//! The scene's own primitives are one more bottom structure that every ray
//! visits first, untransformed; instances whose mesh holds a plane (which no
//! box bounds) are the top tree's unbounded leaf, visited next.
//!
//! The top tree is a [`Bvh`] over the instances' boxes with no primitives of
//! its own ([`Bvh::over_boxes`]): single rays walk its wide nodes, packets its
//! binary or hybrid traversal, and its leaves hand the rays to the instances
//! (`queries.rs`). A single ray picks its instruction set once, at the top,
//! and the meshes' walks are compiled into that entry point ([`BottomLevel`]),
//! as Embree traces an instance's BVH inside the same ISA kernel.

mod bottom;
mod placed;
mod queries;

pub use bottom::BottomLevel;

use rayon::prelude::*;

use crate::accel::Accel;
use crate::accel::bvh::Bvh;
use crate::accel::bvh::build_sah::{BuildOptions, LeafKind};
use crate::accel::bvh::dispatch::at_width;
use crate::accel::bvh::query::Scope;
use crate::accel::bvh::traverse_packet::trace_packet;
use crate::accel::bvh::traverse_single::trace;
use crate::accel::stats::Counter;
use crate::bounds::Aabb;
use crate::geometry::Primitive;
use crate::geometry::transformed::Affine;
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::scene::Scene;
use crate::simd::isa::{Level, level_task};
use crate::simd::{Simd8, SimdFloat};

use placed::Placed;
use queries::{InstanceAnyHit, InstanceAnyHitPacket, InstanceNearest, InstanceNearestPacket, Instances};

/// Instances over bottom structures of type `B` (raypack's [`Bvh`], or
/// [`BruteForce`](crate::accel::BruteForce) as a reference), under a top
/// [`Bvh`] over their world boxes. 32 bytes plus the lists and the top tree.
pub struct TwoLevel<B> {
    /// The scene's own primitives (ids from 0), untransformed.
    own: B,
    /// One bottom structure per mesh.
    meshes: Vec<B>,
    /// The instances: those the top tree bounds in its leaf order, then
    /// those no box bounds (its unbounded leaf).
    placed: Vec<Placed>,
    /// The top tree, whose leaves are ranges of `placed`.
    top: Bvh,
}

/// Most instances in one top-level leaf: one, so that the top tree's box
/// test culls each instance before its ray is transformed and its walk set
/// up (a bottom walk costs far more than a box test). Against leaves of 2,
/// 6–7% fewer instructions per single ray and 1–6% per packet ray on
/// `gen:forest:1000` (callgrind, every ray kind).
const TOP_LEAF_SIZE: usize = 1;

impl<B: Accel + Send> TwoLevel<B> {
    /// Build over `scene`: `bottom` makes the structure of the scene's own
    /// primitives and of each mesh's (in parallel across meshes), then the
    /// top tree is built over the instances' world boxes.
    pub fn new<'p>(scene: &'p Scene, bottom: impl Fn(&'p [Primitive]) -> B + Sync) -> Self {
        let meshes = scene.instances.meshes();
        let own = bottom(&scene.primitives);
        let structures: Vec<B> = meshes.par_iter().map(|m| bottom(&m.primitives)).collect();
        let unit: Vec<bool> = meshes.iter().map(|m| m.needs_unit_directions()).collect();
        // Each mesh's box, or None where a plane leaves it unbounded.
        let mesh_boxes: Vec<Option<Aabb>> = meshes
            .par_iter()
            .map(|m| (!m.has_unbounded()).then(|| m.bounds()))
            .collect();
        let own_ids = scene.primitives.len() as u32;
        let (mut bounded, mut boxes, mut unbounded) = (Vec::new(), Vec::new(), Vec::new());
        for instance in scene.instances.list() {
            let placed = Placed {
                to_object: Affine::from_mat4(&instance.to_object),
                mesh: instance.mesh,
                first_id: own_ids + instance.first,
                unit: unit[instance.mesh as usize],
            };
            match mesh_boxes[instance.mesh as usize].map(|b| instance.bounds(b)) {
                Some(b) if b.is_empty() => {}
                Some(b) if b.min.is_finite() && b.max.is_finite() => {
                    bounded.push(placed);
                    boxes.push(b);
                }
                _ => unbounded.push(placed),
            }
        }
        // Build the top tree and lay the instances out in its leaf order,
        // the unbounded ones after them.
        let options = BuildOptions {
            max_leaf_size: TOP_LEAF_SIZE,
            block_size: 1,
            ..BuildOptions::for_primitives(boxes.len(), LeafKind::Records)
        };
        let (top, order) = Bvh::over_boxes(&boxes, unbounded.len(), &options);
        let placed = order
            .iter()
            .map(|&k| bounded[k as usize])
            .chain(unbounded)
            .collect();
        Self {
            own,
            meshes: structures,
            placed,
            top,
        }
    }
}

impl<B> TwoLevel<B> {
    /// The scene's own primitives' structure.
    pub fn own(&self) -> &B {
        &self.own
    }

    /// Each mesh's structure.
    pub fn meshes(&self) -> &[B] {
        &self.meshes
    }

    /// The top tree over the instances.
    pub fn top(&self) -> &Bvh {
        &self.top
    }

    /// Instances under the top tree, and those every ray visits.
    pub fn instance_counts(&self) -> (usize, usize) {
        let unbounded = self.top.unbounded_leaf().map_or(0, |leaf| leaf.count());
        (self.placed.len() - unbounded, unbounded)
    }

    /// The top tree's bounds (empty when no instance has a box).
    pub fn top_bounds(&self) -> Aabb {
        self.top.bounds()
    }

    /// What the top tree's leaves lead to, for its queries.
    #[inline(always)]
    fn instances(&self) -> Instances<'_, B> {
        Instances {
            placed: &self.placed,
            meshes: &self.meshes,
        }
    }
}

impl<B: BottomLevel> TwoLevel<B> {
    /// The nearest hit of `ray` into `hit`, with the level's 8-lane type `N`:
    /// the scene's own primitives, then the instances the top walk reaches.
    #[inline(always)]
    fn intersect_on<N: Simd8, S: Counter>(&self, ray: &Ray, hit: &mut Hit, stats: &mut S) {
        self.own.intersect_into_on::<N, S>(ray, hit, stats);
        let query = &mut InstanceNearest::<B, true> {
            instances: self.instances(),
            ray,
            hit,
        };
        trace::<N, _, S>(&self.top, ray, query, stats);
    }

    /// Whether anything blocks `ray`, with the level's 8-lane type `N`.
    #[inline(always)]
    fn occluded_on<N: Simd8, S: Counter>(&self, ray: &Ray, stats: &mut S) -> bool {
        self.own.occluded_on::<N, S>(ray, stats)
            || trace::<N, _, S>(
                &self.top,
                ray,
                &mut InstanceAnyHit::<B, true> {
                    instances: self.instances(),
                    ray,
                },
                stats,
            )
    }

    /// The nearest hits of the packet's active lanes, in the level's lanes `G`.
    #[inline(always)]
    fn intersect_packet_on<G: SimdFloat, S: Counter>(
        &self,
        rays: &RayPacket<G>,
        stats: &mut S,
    ) -> HitPacket<G> {
        let mut hits = bottom::nearest_packet(&self.own, rays, stats);
        let query = &mut InstanceNearestPacket {
            instances: self.instances(),
            rays: *rays,
            hits: &mut hits,
        };
        trace_packet(&self.top, rays, query, stats);
        hits
    }

    /// The blocked lanes of the packet, in the level's lanes `G`.
    #[inline(always)]
    fn occluded_packet_on<G: SimdFloat, S: Counter>(&self, rays: &RayPacket<G>, stats: &mut S) -> G {
        let blocked = bottom::blocked_packet(&self.own, rays, Scope::World, stats) & rays.active;
        let query = &mut InstanceAnyHitPacket {
            instances: self.instances(),
            rays: *rays,
            pending: rays.active.and_not(blocked),
        };
        if query.pending.any() {
            trace_packet(&self.top, rays, query, stats);
        }
        rays.active.and_not(query.pending)
    }
}

/// Count `rays` rays (and a packet, for a packet) starting at the top level,
/// then run `walk` with the meshes' walks inside instances not counting them
/// again (a ray meeting five instances is one ray).
#[inline(always)]
fn counted_once<S: Counter, T>(stats: &mut S, rays: u64, packet: bool, walk: impl FnOnce(&mut S) -> T) -> T {
    if packet {
        stats.packet();
    }
    stats.rays(rays);
    stats.enter_instance();
    let result = walk(stats);
    stats.leave_instance();
    result
}

/// The level entry points of the queries ([`LevelTask`](crate::simd::isa::LevelTask)s): everything below
/// them is `#[inline(always)]`, compiled once per instruction set.
mod tasks {
    use super::*;

    // Each task in a module of its own, for the codegen units (as the BVH's,
    // `accel/bvh/dispatch.rs`).
    pub(crate) use each_blocked::EachBlocked;
    pub(crate) use each_nearest::Each;
    pub(crate) use packet_blocked::PacketBlocked;
    pub(crate) use packet_nearest::Packet;

    mod each_nearest {
        use super::*;
        level_task!(
            /// Nearest hits of the rays of `active`, one by one, into `hits`.
            Each<'a, B: BottomLevel, S: Counter>(
                two_level: &'a TwoLevel<B>,
                rays: &'a [Ray],
                active: u32,
                hits: &'a mut [Hit],
                stats: &'a mut S,
            ) -> () {
                for (i, (ray, hit)) in rays.iter().zip(hits).enumerate() {
                    if active >> i & 1 == 1 {
                        stats.lane(i);
                        *hit = Hit::none(ray);
                        two_level.intersect_on::<L::F8, S>(ray, hit, stats);
                    }
                }
            }
        );
    }

    mod each_blocked {
        use super::*;
        level_task!(
            /// The blocked rays of `active`, one by one.
            EachBlocked<'a, B: BottomLevel, S: Counter>(
                two_level: &'a TwoLevel<B>,
                rays: &'a [Ray],
                active: u32,
                stats: &'a mut S,
            ) -> u32 {
                let mut blocked = 0;
                for (i, ray) in rays.iter().enumerate() {
                    if active >> i & 1 == 1 {
                        stats.lane(i);
                        blocked |= u32::from(two_level.occluded_on::<L::F8, S>(ray, stats)) << i;
                    }
                }
                blocked
            }
        );
    }

    mod packet_nearest {
        use super::*;
        level_task!(
            /// The nearest hits of a packet, in the level's lanes of its width.
            Packet<'a, B: BottomLevel, F: SimdFloat, S: Counter>(
                two_level: &'a TwoLevel<B>,
                rays: &'a RayPacket<F>,
                stats: &'a mut S,
            ) -> HitPacket<F> {
                at_width!(F, L, nearest_in(two_level, rays, stats))
            }
        );
    }

    mod packet_blocked {
        use super::*;
        level_task!(
            /// The blocked lanes of a packet, in the level's lanes of its width.
            PacketBlocked<'a, B: BottomLevel, F: SimdFloat, S: Counter>(
                two_level: &'a TwoLevel<B>,
                rays: &'a RayPacket<F>,
                stats: &'a mut S,
            ) -> F {
                at_width!(F, L, blocked_in(two_level, rays, stats))
            }
        );
    }

    #[inline(always)]
    fn nearest_in<G: SimdFloat>(
        two_level: &TwoLevel<impl BottomLevel>,
        rays: &RayPacket<impl SimdFloat>,
        stats: &mut impl Counter,
    ) -> HitPacket<G> {
        two_level.intersect_packet_on(&rays.convert::<G>(), stats)
    }

    #[inline(always)]
    fn blocked_in<G: SimdFloat>(
        two_level: &TwoLevel<impl BottomLevel>,
        rays: &RayPacket<impl SimdFloat>,
        stats: &mut impl Counter,
    ) -> G {
        two_level.occluded_packet_on(&rays.convert::<G>(), stats)
    }
}

impl<B: BottomLevel> Accel for TwoLevel<B> {
    fn intersect_counted<S: Counter>(&self, ray: &Ray, stats: &mut S) -> Hit {
        let mut hit = Hit::none(ray);
        let hits = std::slice::from_mut(&mut hit);
        counted_once(stats, 1, false, |stats| {
            self.top
                .on_level(tasks::Each::new(self, std::slice::from_ref(ray), 1, hits, stats))
        });
        hit
    }

    fn intersect_packet_counted<F: SimdFloat, S: Counter>(
        &self,
        rays: &RayPacket<F>,
        stats: &mut S,
    ) -> HitPacket<F> {
        let lanes = u64::from(rays.active.bitmask().count_ones());
        counted_once(stats, lanes, true, |stats| {
            self.top.on_level(tasks::Packet::new(self, rays, stats))
        })
    }

    fn occluded_counted<S: Counter>(&self, ray: &Ray, stats: &mut S) -> bool {
        let ray = std::slice::from_ref(ray);
        counted_once(stats, 1, false, |stats| {
            self.top.on_level(tasks::EachBlocked::new(self, ray, 1, stats)) == 1
        })
    }

    fn occluded_packet_counted<F: SimdFloat, S: Counter>(&self, rays: &RayPacket<F>, stats: &mut S) -> F {
        let lanes = u64::from(rays.active.bitmask().count_ones());
        counted_once(stats, lanes, true, |stats| {
            self.top.on_level(tasks::PacketBlocked::new(self, rays, stats))
        })
    }

    fn intersect_each_counted<S: Counter>(&self, rays: &[Ray], active: u32, hits: &mut [Hit], stats: &mut S) {
        let count = u64::from(active.count_ones());
        counted_once(stats, count, false, |stats| {
            self.top
                .on_level(tasks::Each::new(self, rays, active, hits, stats))
        });
    }

    fn occluded_each_counted<S: Counter>(&self, rays: &[Ray], active: u32, stats: &mut S) -> u32 {
        let count = u64::from(active.count_ones());
        counted_once(stats, count, false, |stats| {
            self.top
                .on_level(tasks::EachBlocked::new(self, rays, active, stats))
        })
    }
}
