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
//! visits first, untransformed; so are instances whose mesh holds a plane
//! (which no box bounds).

use rayon::prelude::*;

use crate::accel::Accel;
use crate::accel::bvh::build_sah::{self, BuildOptions};
use crate::accel::bvh::leaf::LeafRef;
use crate::accel::bvh::node::{Node, NodeId, NodePair, ROOT, node_in};
use crate::accel::bvh::ray_box::{SlabPacket, SlabRay};
use crate::accel::bvh::stack::{BINARY_STACK_SLOTS, TraversalStack};
use crate::accel::stats::Counter;
use crate::bounds::Aabb;
use crate::geometry::Primitive;
use crate::geometry::transformed::Affine;
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::scene::Scene;
use crate::simd::{SimdFloat, V3};

/// An instance as the walk reads it. 56 bytes.
#[derive(Clone, Copy, Debug)]
struct Placed {
    /// M⁻¹.
    to_object: Affine,
    /// The mesh's bottom structure.
    mesh: u32,
    /// The scene id of the mesh's primitive 0 in this instance.
    first_id: u32,
    /// Whether the mesh's kernels need unit directions.
    unit: bool,
}

impl Placed {
    /// `ray` in the mesh's space over `[t_min, t_max]`, and the factor from
    /// world to object t (1 unless the direction was renormalised); None where
    /// M⁻¹ leaves no usable direction.
    #[inline(always)]
    fn object_ray(&self, ray: &Ray, t_max: f32) -> Option<(Ray, f32)> {
        let origin = self.to_object.point(ray.origin);
        let dir = self.to_object.vector(ray.dir);
        let s = if self.unit { dir.length() } else { 1.0 };
        if !(s > 0.0 && s < f32::INFINITY) {
            return None;
        }
        let local = Ray {
            origin,
            dir: dir / s,
            t_min: ray.t_min * s,
            t_max: t_max * s,
        };
        Some((local, s))
    }

    /// The packet in the mesh's space, its lanes `lanes` active and bounded
    /// by the hits so far, and the factor from world to object t per lane.
    #[inline(always)]
    fn object_packet<F: SimdFloat>(&self, rays: &RayPacket<F>, lanes: F, t_max: F) -> (RayPacket<F>, F) {
        let origin = self.to_object.point_packet(&rays.origin);
        let d = self.to_object.vector_packet(&rays.dir);
        let (dir, s, usable) = if self.unit {
            let s = d.dot(d).sqrt();
            let usable = s.gt(F::splat(0.0)) & s.lt(F::splat(f32::INFINITY));
            let dir = V3 {
                x: d.x / s,
                y: d.y / s,
                z: d.z / s,
            };
            (dir, s, usable)
        } else {
            (d, F::splat(1.0), F::all_true())
        };
        let local = RayPacket {
            origin,
            dir,
            t_min: rays.t_min * s,
            t_max: t_max * s,
            active: lanes & usable,
        };
        (local, s)
    }
}

/// Instances over bottom structures of type `B` (raypack's [`Bvh`](crate::accel::Bvh),
/// or [`BruteForce`](crate::accel::BruteForce) as a reference). The top tree
/// is the binary SAH tree of [`build_sah`] over instance boxes, its leaves
/// ranges of `placed`. 136 bytes plus the lists.
pub struct TwoLevel<B> {
    /// The scene's own primitives (ids from 0), untransformed.
    own: B,
    /// One bottom structure per mesh.
    meshes: Vec<B>,
    /// The instances the top tree bounds, in its leaf order.
    placed: Vec<Placed>,
    /// The instances no box bounds (their mesh holds a plane): every ray visits them.
    unbounded: Vec<Placed>,
    /// The top tree's node pairs (root in pair 0, side 0).
    top: Vec<NodePair>,
}

/// Most instances in one top-level leaf: instances mostly overlap less than
/// triangles do, and a bottom walk costs far more than a box test.
const TOP_LEAF_SIZE: usize = 2;

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
        // Build the top tree and lay the instances out in its leaf order.
        let (top, placed) = if boxes.is_empty() {
            (vec![NodePair([Node::EMPTY; 2])], Vec::new())
        } else {
            let options = BuildOptions {
                max_leaf_size: TOP_LEAF_SIZE,
                block_size: 1,
                ..BuildOptions::for_primitives(boxes.len())
            };
            let built = build_sah::build(&boxes, &options);
            let placed = built.order.iter().map(|&k| bounded[k as usize]).collect();
            (built.pairs, placed)
        };
        Self {
            own,
            meshes: structures,
            placed,
            unbounded,
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

    /// Instances under the top tree, and those every ray visits.
    pub fn instance_counts(&self) -> (usize, usize) {
        (self.placed.len(), self.unbounded.len())
    }

    /// The top tree's bounds.
    pub fn top_bounds(&self) -> Aabb {
        let root = node_in(&self.top, ROOT);
        Aabb {
            min: root.min,
            max: root.max,
        }
    }

    /// The instances of the top-tree leaf `node`.
    #[inline(always)]
    fn leaf_instances(&self, node: &Node) -> &[Placed] {
        match node.contents() {
            LeafRef::Prims(range) => &self.placed[range],
            _ => unreachable!("the top tree's leaves are ranges of instances"),
        }
    }
}

impl<B: Accel> TwoLevel<B> {
    /// Trace `ray` through instance `p`, keeping the nearest of it and `hit`.
    #[inline(always)]
    fn intersect_instance<S: Counter>(&self, p: &Placed, ray: &Ray, hit: &mut Hit, stats: &mut S) {
        let Some((local, s)) = p.object_ray(ray, hit.t) else {
            return;
        };
        let found = self.meshes[p.mesh as usize].intersect_counted(&local, stats);
        if !found.is_hit() {
            return;
        }
        let (t, id) = (found.t / s, p.first_id + found.prim);
        if hit.accepts(t, ray.t_min, id) {
            *hit = Hit { t, prim: id, ..found };
        }
    }

    /// Whether instance `p` blocks `ray`.
    #[inline(always)]
    fn occludes<S: Counter>(&self, p: &Placed, ray: &Ray, stats: &mut S) -> bool {
        p.object_ray(ray, ray.t_max)
            .is_some_and(|(local, _)| self.meshes[p.mesh as usize].occluded_counted(&local, stats))
    }

    /// Trace the lanes `lanes` of `rays` through instance `p`, keeping the
    /// nearest of each lane's hit and `hits`.
    #[inline(always)]
    fn intersect_instance_packet<F: SimdFloat, S: Counter>(
        &self,
        p: &Placed,
        rays: &RayPacket<F>,
        lanes: F,
        hits: &mut HitPacket<F>,
        stats: &mut S,
    ) {
        let (local, s) = p.object_packet(rays, lanes, hits.t);
        let found = self.meshes[p.mesh as usize].intersect_packet_counted(&local, stats);
        let mut candidates = (found.hit_mask() & local.active).bitmask();
        if candidates == 0 {
            return;
        }
        // Settle lane by lane: a packet meets few instances per lane, and the
        // tie rule needs each lane's id.
        let t = (found.t / s).to_array();
        let t_min = rays.t_min.to_array();
        while candidates != 0 {
            let i = candidates.trailing_zeros() as usize;
            candidates &= candidates - 1;
            let (mut hit, mine) = (hits.hit(i), found.hit(i));
            let (t, id) = (t.as_ref()[i], p.first_id + mine.prim);
            if hit.accepts(t, t_min.as_ref()[i], id) {
                hit = Hit { t, prim: id, ..mine };
                hits.set_hit(i, &hit);
            }
        }
    }

    /// The top tree's leaves that the ray's box walk reaches, nearest first,
    /// each handed to `leaf` with the walk's current `t_max`; `leaf` returns
    /// the new `t_max` (or `None` to stop).
    #[inline(always)]
    fn walk<S: Counter>(
        &self,
        ray: &Ray,
        mut t_max: f32,
        stats: &mut S,
        mut leaf: impl FnMut(&[Placed], f32, &mut S) -> Option<f32>,
    ) {
        let slab = SlabRay::new(ray);
        let mut stack = TraversalStack::<(NodeId, f32), BINARY_STACK_SLOTS>::new();
        let root = node_in(&self.top, ROOT);
        let Some(entry) = slab.node_entry(root, t_max) else {
            return;
        };
        stack.push((ROOT, entry));
        while let Some((id, entry)) = stack.pop() {
            if entry > t_max {
                continue;
            }
            let node = node_in(&self.top, id);
            stats.node();
            if node.is_leaf() {
                match leaf(self.leaf_instances(node), t_max, stats) {
                    Some(t) => t_max = t,
                    None => return,
                }
                continue;
            }
            // Visit the nearer child first; push the farther one under it.
            let [a, b] = node.children();
            let (ea, eb) = (
                slab.node_entry(node_in(&self.top, a), t_max),
                slab.node_entry(node_in(&self.top, b), t_max),
            );
            match (ea, eb) {
                (Some(ta), Some(tb)) => {
                    let (near, far) = if ta <= tb {
                        ((a, ta), (b, tb))
                    } else {
                        ((b, tb), (a, ta))
                    };
                    stack.push(far);
                    stack.push(near);
                }
                (Some(ta), None) => stack.push((a, ta)),
                (None, Some(tb)) => stack.push((b, tb)),
                (None, None) => {}
            }
        }
    }

    /// The packet's walk of the top tree, lanes dropping out where they miss
    /// a node's box (or, for any hit, once blocked); `leaf` gets each reached
    /// leaf with the lanes that reach it.
    #[inline(always)]
    fn walk_packet<F: SimdFloat, S: Counter>(
        &self,
        rays: &RayPacket<F>,
        t_max: impl Fn() -> F,
        active: impl Fn() -> F,
        stats: &mut S,
        mut leaf: impl FnMut(&[Placed], F, &mut S),
    ) {
        let slab = SlabPacket::new(rays);
        let mut stack = TraversalStack::<NodeId, BINARY_STACK_SLOTS>::new();
        stack.push(ROOT);
        while let Some(id) = stack.pop() {
            let node = node_in(&self.top, id);
            let (meets, _) = slab.node_entry(node, t_max());
            let lanes = meets & active();
            if lanes.none() {
                continue;
            }
            stats.packet_node(lanes);
            if node.is_leaf() {
                leaf(self.leaf_instances(node), lanes, stats);
                continue;
            }
            // Near child first, by the first lane's direction along the split axis.
            let [a, b] = node.children();
            let first = lanes.bitmask().trailing_zeros() as usize;
            let axis = node.axis() as usize;
            let backwards = rays.dir.lane(first)[axis] < 0.0;
            let (near, far) = if backwards { (b, a) } else { (a, b) };
            stack.push(far);
            stack.push(near);
        }
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

impl<B: Accel> Accel for TwoLevel<B> {
    fn intersect_counted<S: Counter>(&self, ray: &Ray, stats: &mut S) -> Hit {
        counted_once(stats, 1, false, |stats| self.intersect_walk(ray, stats))
    }

    fn intersect_packet_counted<F: SimdFloat, S: Counter>(
        &self,
        rays: &RayPacket<F>,
        stats: &mut S,
    ) -> HitPacket<F> {
        let lanes = u64::from(rays.active.bitmask().count_ones());
        counted_once(stats, lanes, true, |stats| {
            self.intersect_packet_walk(rays, stats)
        })
    }

    fn occluded_counted<S: Counter>(&self, ray: &Ray, stats: &mut S) -> bool {
        counted_once(stats, 1, false, |stats| self.occluded_walk(ray, stats))
    }

    fn occluded_packet_counted<F: SimdFloat, S: Counter>(&self, rays: &RayPacket<F>, stats: &mut S) -> F {
        let lanes = u64::from(rays.active.bitmask().count_ones());
        counted_once(stats, lanes, true, |stats| self.occluded_packet_walk(rays, stats))
    }
}

impl<B: Accel> TwoLevel<B> {
    /// The nearest hit of `ray`: the scene's own primitives, then every instance it reaches.
    #[inline(always)]
    fn intersect_walk<S: Counter>(&self, ray: &Ray, stats: &mut S) -> Hit {
        let mut hit = self.own.intersect_counted(ray, stats);
        for p in &self.unbounded {
            self.intersect_instance(p, ray, &mut hit, stats);
        }
        self.walk(ray, hit.t, stats, |instances, _, stats| {
            for p in instances {
                self.intersect_instance(p, ray, &mut hit, stats);
            }
            Some(hit.t)
        });
        hit
    }

    /// The nearest hits of the packet's lanes.
    #[inline(always)]
    fn intersect_packet_walk<F: SimdFloat, S: Counter>(
        &self,
        rays: &RayPacket<F>,
        stats: &mut S,
    ) -> HitPacket<F> {
        let hits = std::cell::Cell::new(self.own.intersect_packet_counted(rays, stats));
        let visit = |p: &Placed, lanes: F, stats: &mut S| {
            let mut h = hits.get();
            self.intersect_instance_packet(p, rays, lanes, &mut h, stats);
            hits.set(h);
        };
        for p in &self.unbounded {
            visit(p, rays.active, stats);
        }
        self.walk_packet(
            rays,
            || hits.get().t,
            || rays.active,
            stats,
            |instances, lanes, stats| instances.iter().for_each(|p| visit(p, lanes, stats)),
        );
        hits.get()
    }

    /// Whether anything blocks `ray`.
    #[inline(always)]
    fn occluded_walk<S: Counter>(&self, ray: &Ray, stats: &mut S) -> bool {
        if self.own.occluded_counted(ray, stats)
            || self.unbounded.iter().any(|p| self.occludes(p, ray, stats))
        {
            return true;
        }
        let mut blocked = false;
        self.walk(ray, ray.t_max, stats, |instances, t_max, stats| {
            blocked = instances.iter().any(|p| self.occludes(p, ray, stats));
            (!blocked).then_some(t_max)
        });
        blocked
    }

    /// The blocked lanes of the packet.
    #[inline(always)]
    fn occluded_packet_walk<F: SimdFloat, S: Counter>(&self, rays: &RayPacket<F>, stats: &mut S) -> F {
        let blocked = std::cell::Cell::new(self.own.occluded_packet_counted(rays, stats) & rays.active);
        let visit = |p: &Placed, lanes: F, stats: &mut S| {
            let (local, _) = p.object_packet(rays, lanes, rays.t_max);
            let hit = self.meshes[p.mesh as usize].occluded_packet_counted(&local, stats);
            blocked.set(blocked.get() | (hit & local.active));
        };
        for p in &self.unbounded {
            visit(p, rays.active.and_not(blocked.get()), stats);
        }
        self.walk_packet(
            rays,
            || rays.t_max,
            || rays.active.and_not(blocked.get()),
            stats,
            |instances, lanes, stats| {
                for p in instances {
                    let open = lanes.and_not(blocked.get());
                    if open.none() {
                        break;
                    }
                    visit(p, open, stats);
                }
            },
        );
        blocked.get()
    }
}
