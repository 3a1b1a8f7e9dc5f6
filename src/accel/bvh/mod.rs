//! A bounding volume hierarchy over a scene's bounded primitives, built as a
//! binary tree of 32-byte nodes with binned SAH ([`build_sah`], [`node`]) and
//! also collapsed into 8-wide nodes ([`wide`], 4-wide without AVX) over the
//! same leaves. 8-ray packets traverse the binary tree ([`traverse_packet`]:
//! testing a packet against each box as soon as the tree branches culls more
//! than eight boxes at once would), single rays the wide tree
//! ([`traverse_single`], one SIMD test per node), and so do incoherent
//! packets ([`traverse_hybrid`], together while enough lanes share a node);
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
pub mod leaf;
pub mod node;
pub mod occlusion;
pub mod query;
pub mod ray_box;
pub mod stack;
pub mod traverse_hybrid;
pub mod traverse_packet;
pub mod traverse_single;
pub mod wide;

pub use build_sah::{BuildOptions, MAX_DEPTH};

/// Most bytes of a child [`Bvh::prefetch`] asks for.
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
use crate::simd::SimdFloat;
use leaf::{
    BLOCK_SIZE, LeafItem, LeafPrim, LeafRef, SphereBlock, TriangleBlock, block_lanes, intersect_blocks,
};
use node::{Node, NodeId, NodePair, ROOT};

/// A BVH (binary nodes for packets, wide nodes for single rays) owning a
/// reordered copy of the primitives it holds.
#[derive(Clone, Debug)]
pub struct Bvh {
    /// Node pairs; the root is node [`ROOT`] (pair 0, side 0).
    pairs: Vec<NodePair>,
    /// The same tree collapsed to wide nodes, which single rays traverse.
    wide: Vec<wide::WideNode>,
    /// The records of leaves that are neither all triangles nor all spheres,
    /// in leaf order (a leaf is a contiguous run).
    prims: Vec<LeafPrim>,
    /// The triangles of all-triangle leaves, in leaf order (a leaf is a contiguous run).
    triangle_blocks: Vec<TriangleBlock>,
    /// The spheres of all-sphere leaves, in leaf order (a leaf is a contiguous run).
    sphere_blocks: Vec<SphereBlock>,
    /// Primitives in the tree.
    bounded: usize,
    /// The primitives `prims` refers to rather than holds (see [`leaf`]).
    others: Vec<Primitive>,
    /// Primitives tested by every ray (no finite box).
    unbounded: Vec<Primitive>,
    /// Input index of each of `unbounded`.
    unbounded_ids: Vec<u32>,
    /// Degenerate triangles left out.
    skipped: usize,
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

/// What a leaf holds, which decides how it is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Holds {
    /// Triangles only: [`TriangleBlock`]s.
    Triangles,
    /// Spheres only: [`SphereBlock`]s.
    Spheres,
    /// Anything else: [`LeafPrim`] records.
    Mixed,
}

impl Holds {
    /// What the leaf of `prims` (not empty) holds.
    fn of<'a>(mut prims: impl Iterator<Item = &'a Primitive>) -> Self {
        let first = match prims.next() {
            Some(Primitive::Triangle(_)) => Holds::Triangles,
            Some(Primitive::Sphere(_)) => Holds::Spheres,
            _ => return Holds::Mixed,
        };
        let same = |p: &Primitive| match first {
            Holds::Triangles => matches!(p, Primitive::Triangle(_)),
            _ => matches!(p, Primitive::Sphere(_)),
        };
        if prims.all(same) { first } else { Holds::Mixed }
    }
}

impl Bvh {
    /// Build over `prims` with the default [`BuildOptions`].
    pub fn new(prims: &[Primitive]) -> Self {
        Self::with_options(prims, &BuildOptions::default())
    }

    /// Build over `prims`; a hit's primitive index is the position in `prims`.
    pub fn with_options(prims: &[Primitive], options: &BuildOptions) -> Self {
        // The primitives' boxes, in parallel; then sort them into the tree's,
        // the unbounded and the skipped.
        let usable = |b: Aabb| b.min.is_finite() && b.max.is_finite() && !b.is_empty();
        let all_boxes: Vec<Option<Aabb>> = prims
            .par_iter()
            .map(|p| p.bounds().filter(|b| usable(*b)))
            .collect();
        let mut boxes = Vec::with_capacity(prims.len());
        let mut bounded_ids = Vec::with_capacity(prims.len());
        let (mut unbounded, mut unbounded_ids, mut skipped) = (Vec::new(), Vec::new(), 0);
        for (i, (p, b)) in prims.iter().zip(all_boxes).enumerate() {
            match b {
                Some(b) => {
                    boxes.push(b);
                    bounded_ids.push(i as u32);
                }
                _ if matches!(p, Primitive::Triangle(t) if t.is_degenerate()) => skipped += 1,
                _ => {
                    unbounded.push(p.clone());
                    unbounded_ids.push(i as u32);
                }
            }
        }
        let (mut pairs, order) = if boxes.is_empty() {
            (vec![NodePair([Node::EMPTY; 2])], Vec::new())
        } else {
            let built = build_sah::build(&boxes, options);
            (built.pairs, built.order)
        };
        // Store each leaf's primitives, in build order: as triangle or sphere
        // blocks if they are all triangles or all spheres, else as records; the
        // leaf nodes then point there.
        let mut leaves: Vec<&mut Node> = pairs
            .iter_mut()
            .flat_map(|pair| &mut pair.0)
            .filter(|n| n.is_leaf() && n.meta != 0)
            .collect();
        leaves.sort_unstable_by_key(|n| n.first);
        let input = |k: &u32| {
            let id = bounded_ids[*k as usize];
            (&prims[id as usize], id)
        };
        let range_of = |node: &Node| match node.contents() {
            LeafRef::Prims(range) => range,
            _ => unreachable!("the build makes leaves of primitive ranges"),
        };
        // What each leaf holds, in parallel: the primitives are read in leaf
        // order, far from their input order, so this mostly waits on memory.
        let holds: Vec<Holds> = leaves
            .par_iter()
            .map(|node| Holds::of(order[range_of(node)].iter().map(|k| input(k).0)))
            .collect();
        // Lay the blocks out leaf by leaf, each block a run of leaf primitives.
        let (mut leaf_prims, mut others) = (Vec::new(), Vec::new());
        let (mut triangle_runs, mut sphere_runs) = (Vec::new(), Vec::new());
        for (node, holds) in leaves.iter_mut().zip(holds) {
            let range = range_of(node);
            let count = range.len();
            let runs = || {
                range
                    .clone()
                    .step_by(BLOCK_SIZE)
                    .map(move |start| start..(start + BLOCK_SIZE).min(range.end))
            };
            let leaf = match holds {
                Holds::Triangles => {
                    let at = triangle_runs.len();
                    triangle_runs.extend(runs());
                    LeafRef::Triangles {
                        blocks: at..triangle_runs.len(),
                        count,
                    }
                }
                Holds::Spheres => {
                    let at = sphere_runs.len();
                    sphere_runs.extend(runs());
                    LeafRef::Spheres {
                        blocks: at..sphere_runs.len(),
                        count,
                    }
                }
                Holds::Mixed => {
                    let at = leaf_prims.len();
                    for k in &order[range] {
                        let (prim, id) = input(k);
                        leaf_prims.push(LeafPrim::new(prim, id, &mut others));
                    }
                    LeafRef::Prims(at..leaf_prims.len())
                }
            };
            (node.first, node.meta) = leaf.encode();
        }
        // Fill the blocks in parallel, in place (an indexed collect).
        let triangle_blocks: Vec<TriangleBlock> = triangle_runs
            .par_iter()
            .map(|run| {
                // A block's lanes on the stack (the last repeated into unused slots).
                let lanes: [_; BLOCK_SIZE] =
                    std::array::from_fn(|i| match input(&order[run.start + i.min(run.len() - 1)]) {
                        (Primitive::Triangle(t), id) => (*t.projected(), id),
                        _ => unreachable!("a triangle leaf holds triangles"),
                    });
                TriangleBlock::new(&lanes[..run.len()])
            })
            .collect();
        let sphere_blocks: Vec<SphereBlock> = sphere_runs
            .par_iter()
            .map(|run| {
                let lanes: [_; BLOCK_SIZE] =
                    std::array::from_fn(|i| match input(&order[run.start + i.min(run.len() - 1)]) {
                        (Primitive::Sphere(s), id) => (*s, id),
                        _ => unreachable!("a sphere leaf holds spheres"),
                    });
                SphereBlock::new(&lanes[..run.len()])
            })
            .collect();
        let mut bvh = Self {
            pairs,
            wide: Vec::new(),
            prims: leaf_prims,
            triangle_blocks,
            sphere_blocks,
            bounded: order.len(),
            others,
            unbounded,
            unbounded_ids,
            skipped,
        };
        let collapsed = wide::collapse(&bvh);
        bvh.wide = collapsed.nodes;
        bvh
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

    /// Start loading what `child` leads to into the cache: the wide node's
    /// lines, or the first lines of the leaf's blocks.
    #[inline(always)]
    pub fn prefetch(&self, child: wide::ChildRef) {
        let (start, bytes) = if !child.is_leaf() {
            let node = self.wide.as_ptr().wrapping_add(child.node());
            (node.cast::<u8>(), size_of::<wide::WideNode>())
        } else {
            match child.contents() {
                LeafRef::Triangles { blocks, .. } => (
                    self.triangle_blocks
                        .as_ptr()
                        .wrapping_add(blocks.start)
                        .cast::<u8>(),
                    blocks.len() * size_of::<TriangleBlock>(),
                ),
                LeafRef::Spheres { blocks, .. } => (
                    self.sphere_blocks
                        .as_ptr()
                        .wrapping_add(blocks.start)
                        .cast::<u8>(),
                    blocks.len() * size_of::<SphereBlock>(),
                ),
                LeafRef::Prims(_) => return,
            }
        };
        for line in (0..bytes.min(PREFETCH_BYTES)).step_by(64) {
            prefetch_line(start.wrapping_add(line));
        }
    }

    /// True when no primitive is in the tree.
    #[inline(always)]
    pub fn is_empty(&self) -> bool {
        self.bounded == 0
    }

    /// Test `ray` against the primitives of `leaf`, recording hits in `hit`;
    /// returns true if one was recorded. `any_hit` stops at the first.
    #[inline(always)]
    pub fn intersect_leaf<S: Counter>(
        &self,
        leaf: LeafRef,
        ray: &Ray,
        hit: &mut Hit,
        any_hit: bool,
        stats: &mut S,
    ) -> bool {
        match leaf {
            LeafRef::Triangles { blocks, count } => {
                intersect_blocks(&self.triangle_blocks[blocks], count, ray, hit, any_hit, stats)
            }
            LeafRef::Spheres { blocks, count } => {
                intersect_blocks(&self.sphere_blocks[blocks], count, ray, hit, any_hit, stats)
            }
            LeafRef::Prims(range) => {
                let mut recorded = false;
                for prim in &self.prims[range] {
                    stats.prim();
                    recorded |= prim.intersect(&self.others, ray, hit);
                    if recorded && any_hit {
                        break;
                    }
                }
                recorded
            }
        }
    }

    /// Call `f` with each primitive of `leaf` in turn until it returns false.
    #[inline(always)]
    pub fn for_each_leaf_prim(&self, leaf: LeafRef, mut f: impl FnMut(LeafItem<'_>) -> bool) {
        // `all` stops at the first false.
        match leaf {
            LeafRef::Triangles { blocks, count } => block_lanes(&self.triangle_blocks[blocks], count)
                .all(|(block, lane)| f(LeafItem::TriangleLane(block, lane))),
            LeafRef::Spheres { blocks, count } => block_lanes(&self.sphere_blocks[blocks], count)
                .all(|(block, lane)| f(LeafItem::SphereLane(block, lane))),
            LeafRef::Prims(range) => self.prims[range].iter().all(|prim| f(LeafItem::Record(prim))),
        };
    }

    /// The packet kernel of a leaf's primitive.
    #[inline(always)]
    pub fn intersect_leaf_prim_packet<F: SimdFloat>(
        &self,
        prim: LeafItem<'_>,
        rays: &RayPacket<F>,
        hits: &mut HitPacket<F>,
    ) {
        prim.intersect_packet(&self.others, rays, hits);
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
            unbounded: self.unbounded.len(),
            skipped: self.skipped,
            nodes: 0,
            leaves: 0,
            max_depth: 0,
            max_leaf_size: 0,
            sah_cost: 0.0,
            bytes: self.pairs.len() * size_of::<NodePair>()
                + self.wide.len() * size_of::<wide::WideNode>()
                + self.prims.len() * size_of::<LeafPrim>()
                + self.triangle_blocks.len() * size_of::<TriangleBlock>()
                + self.sphere_blocks.len() * size_of::<SphereBlock>()
                + self.others.len() * size_of::<Primitive>(),
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
    fn intersect_counted<S: Counter>(&self, ray: &Ray, stats: &mut S) -> Hit {
        traverse_single::intersect(self, ray, stats)
    }

    fn intersect_packet_counted<F: SimdFloat, S: Counter>(
        &self,
        rays: &RayPacket<F>,
        stats: &mut S,
    ) -> HitPacket<F> {
        traverse_packet::intersect_packet(self, rays, stats)
    }

    fn occluded_counted<S: Counter>(&self, ray: &Ray, stats: &mut S) -> bool {
        occlusion::occluded(self, ray, stats)
    }

    fn occluded_packet_counted<F: SimdFloat, S: Counter>(&self, rays: &RayPacket<F>, stats: &mut S) -> F {
        occlusion::occluded_packet(self, rays, stats)
    }
}
