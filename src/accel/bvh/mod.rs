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
//! use raypack::accel::{Accel, BruteForce, Bvh, TraversalStats};
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
//! let mut stats = TraversalStats::default();
//! let hits = bvh.intersect_packet_counted(&RayPacket8::from_rays(&[ray; 8]), &mut stats);
//! assert_eq!(hits.hit(7), hit);
//! println!("{}", stats.caption()); // e.g. "9.0 nodes/ray, 1.0 prims/ray, lanes 100%"
//! ```
//!
//! [`BruteForce`]: crate::accel::BruteForce

pub mod build_sah;
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
pub mod wide;

pub use build_sah::{BuildOptions, MAX_DEPTH, SMALL_SCENE_PRIMITIVES};

/// Most bytes of a leaf [`Bvh::prefetch`] asks for (a wide node is prefetched whole).
const PREFETCH_BYTES: usize = 256;

/// Ask the CPU to load the cache line holding `p` (a hint: any address is fine).
#[inline(always)]
fn prefetch_line(p: *const u8) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch is a hint that never faults, whatever the address.
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(p.cast::<i8>());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}

use rayon::prelude::*;

use crate::accel::Accel;
use crate::accel::stats::Counter;
use crate::bounds::Aabb;
use crate::geometry::Primitive;
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::isa::IsaError;
use crate::simd::{Isa, SimdFloat};
use leaf::LeafRef;
use leaf_store::LeafStore;
use node::{Node, NodeId, NodePair, ROOT};
use wide::{PacketTreeLanes, RayTreeLanes, TreeWidth, WideNodeOf};

impl TreeWidth for RayTreeLanes {
    #[inline(always)]
    fn nodes(bvh: &Bvh) -> &[WideNodeOf<Self>] {
        &bvh.ray_tree
    }
}

impl TreeWidth for PacketTreeLanes {
    #[inline(always)]
    fn nodes(bvh: &Bvh) -> &[WideNodeOf<Self>] {
        &bvh.packet_tree
    }
}

/// A BVH (binary nodes for packets, wide nodes for single rays) owning a
/// reordered copy of the primitives it holds.
#[derive(Clone, Debug)]
pub struct Bvh {
    /// Node pairs; the root is node [`ROOT`] (pair 0, side 0).
    pairs: Vec<NodePair>,
    /// The same tree collapsed to 16-wide nodes, which single rays traverse.
    ray_tree: Vec<wide::WideNodeOf<RayTreeLanes>>,
    /// The same tree collapsed to 8-wide nodes, which incoherent packets traverse.
    packet_tree: Vec<wide::WideNodeOf<PacketTreeLanes>>,
    /// The primitives, which the leaves of both trees name.
    leaves: LeafStore,
    /// The leaf of the primitives with no finite box, tested by every ray.
    unbounded: LeafRef,
    /// Primitives in the tree.
    bounded: usize,
    /// Degenerate triangles left out.
    skipped: usize,
    /// The instruction set queries run on ([`dispatch`]).
    isa: Isa,
}

/// Figures about a built BVH, for reports.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct BvhInfo {
    /// Primitives in the tree.
    pub primitives: usize,
    /// Primitives outside the tree, tested by every ray (planes).
    pub unbounded: usize,
    /// Degenerate triangles left out (no ray can hit them).
    pub skipped: usize,
    /// Nodes (inner and leaves).
    pub nodes: usize,
    /// Leaves.
    pub leaves: usize,
    /// Depth of the deepest leaf (the root has depth 0).
    pub max_depth: usize,
    /// Largest leaf.
    pub max_leaf_size: usize,
    /// SAH cost of the tree with unit node and primitive costs, relative to the root's area.
    pub sah_cost: f64,
    /// Memory of nodes and primitive copies, in bytes.
    pub bytes: usize,
}

impl Bvh {
    /// Build over `prims` with the [`BuildOptions`] for their number
    /// ([`BuildOptions::for_primitives`]).
    pub fn new(prims: &[Primitive]) -> Self {
        Self::with_options(prims, &BuildOptions::for_primitives(prims.len()))
    }

    /// Build over `prims`; a hit's primitive index is the position in `prims`.
    pub fn with_options(prims: &[Primitive], options: &BuildOptions) -> Self {
        // The primitives' boxes, in parallel, the empty box for one the tree
        // cannot hold (not finite, or empty).
        let usable = |b: Aabb| b.min.is_finite() && b.max.is_finite() && !b.is_empty();
        let mut boxes: Vec<Aabb> = prims
            .par_iter()
            .map(|p| p.bounds().filter(|b| usable(*b)).unwrap_or(Aabb::EMPTY))
            .collect();
        // Where some cannot be held, sort the primitives into the tree's, the
        // unbounded and the skipped; the tree's then have ids of their own.
        // (Mostly all can: then a tree index is an input index.)
        let (mut bounded_ids, mut unbounded_ids, mut skipped) = (None, Vec::new(), 0);
        if boxes.par_iter().any(Aabb::is_empty) {
            let mut ids = Vec::with_capacity(prims.len());
            let mut kept = 0;
            for (i, p) in prims.iter().enumerate() {
                let b = boxes[i];
                if !b.is_empty() {
                    boxes[kept] = b;
                    kept += 1;
                    ids.push(i as u32);
                } else if matches!(p, Primitive::Triangle(t) if t.is_degenerate()) {
                    skipped += 1;
                } else {
                    unbounded_ids.push(i as u32);
                }
            }
            boxes.truncate(kept);
            bounded_ids = Some(ids);
        }
        let (mut pairs, order) = if boxes.is_empty() {
            (vec![NodePair([Node::EMPTY; 2])], Vec::new())
        } else {
            let built = build_sah::build(&boxes, options);
            (built.pairs, built.order)
        };
        // Store each leaf's primitives; the leaf nodes then point there.
        let mut leaves: Vec<&mut Node> = pairs
            .iter_mut()
            .flat_map(|pair| &mut pair.0)
            .filter(|n| n.is_leaf() && n.meta != 0)
            .collect();
        leaves.sort_unstable_by_key(|n| n.first);
        let input = |k: u32| {
            let id = bounded_ids.as_ref().map_or(k, |ids| ids[k as usize]);
            (&prims[id as usize], id)
        };
        let mut store = LeafStore::build(&mut leaves, &order, input);
        let unbounded = store.push_records(unbounded_ids.iter().map(|&id| (&prims[id as usize], id)));
        let mut bvh = Self {
            pairs,
            ray_tree: Vec::new(),
            packet_tree: Vec::new(),
            leaves: store,
            unbounded,
            bounded: order.len(),
            skipped,
            isa: Isa::default_level(),
        };
        bvh.ray_tree = wide::collapse(&bvh);
        bvh.packet_tree = wide::collapse(&bvh);
        bvh
    }

    /// Bytes of what single rays read: the 16-wide nodes and the leaves.
    #[inline(always)]
    pub fn walked_bytes(&self) -> usize {
        size_of_val(self.ray_tree.as_slice()) + self.leaves.bytes()
    }

    /// The instruction set queries run on: [`Isa::default_level`] when built.
    pub fn isa(&self) -> Isa {
        self.isa
    }

    /// Run queries on `isa` from now on; an error if this CPU cannot run it.
    pub fn set_isa(&mut self, isa: Isa) -> Result<(), IsaError> {
        if !isa.is_available() {
            return Err(IsaError::Unavailable(isa));
        }
        self.isa = isa;
        Ok(())
    }

    /// The node `id`.
    #[inline(always)]
    pub fn node(&self, id: NodeId) -> &Node {
        &self.pairs[(id >> 1) as usize].0[(id & 1) as usize]
    }

    /// The node pair `pair` (the children of an inner node whose `first` is `pair`).
    #[inline(always)]
    pub fn pair(&self, pair: u32) -> &NodePair {
        &self.pairs[pair as usize]
    }

    /// Start loading what `child` (of the tree of width `F`) leads to into
    /// the cache: the wide node's lines, or the first lines of the leaf's blocks.
    #[inline(always)]
    pub fn prefetch<F: TreeWidth>(&self, child: wide::ChildRef) {
        let (start, bytes) = if !child.is_leaf() {
            let node = F::nodes(self).as_ptr().wrapping_add(child.node());
            (node.cast::<u8>(), size_of::<wide::WideNodeOf<F>>())
        } else {
            match self.leaves.block_bytes(child.contents()) {
                Some((blocks, bytes)) => (blocks, bytes.min(PREFETCH_BYTES)),
                None => return,
            }
        };
        for line in (0..bytes).step_by(64) {
            prefetch_line(start.wrapping_add(line));
        }
    }

    /// True when no primitive is in the tree.
    #[inline(always)]
    pub fn is_empty(&self) -> bool {
        self.bounded == 0
    }

    /// The leaf of the primitives with no finite box (planes), which every
    /// ray visits before the tree; None when there are none.
    #[inline(always)]
    pub fn unbounded_leaf(&self) -> Option<LeafRef> {
        (self.unbounded.count() > 0).then(|| self.unbounded.clone())
    }

    /// The (padded) box of the whole tree; empty when no primitive is bounded.
    pub fn bounds(&self) -> Aabb {
        if self.is_empty() {
            return Aabb::EMPTY;
        }
        let root = self.node(ROOT);
        Aabb::new(root.min, root.max)
    }

    /// Node counts, depth and SAH cost.
    pub fn info(&self) -> BvhInfo {
        let mut info = BvhInfo {
            primitives: self.bounded,
            unbounded: self.unbounded.count(),
            skipped: self.skipped,
            nodes: 0,
            leaves: 0,
            max_depth: 0,
            max_leaf_size: 0,
            sah_cost: 0.0,
            bytes: size_of_val(self.pairs.as_slice())
                + size_of_val(self.ray_tree.as_slice())
                + size_of_val(self.packet_tree.as_slice())
                + self.leaves.bytes(),
        };
        if self.is_empty() {
            return info;
        }
        let area = |n: &Node| f64::from(Aabb::new(n.min, n.max).surface_area());
        let root_area = area(self.node(ROOT));
        let mut stack = vec![(ROOT, 0usize)];
        while let Some((id, depth)) = stack.pop() {
            let n = self.node(id);
            info.nodes += 1;
            info.max_depth = info.max_depth.max(depth);
            let weight = area(n) / root_area;
            if n.is_leaf() {
                info.leaves += 1;
                let count = n.contents().count();
                info.max_leaf_size = info.max_leaf_size.max(count);
                info.sah_cost += weight * count as f64;
            } else {
                info.sah_cost += weight;
                stack.extend(n.children().map(|c| (c, depth + 1)));
            }
        }
        info
    }
}

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
        dispatch::occluded_packet(self, rays, stats)
    }
}
