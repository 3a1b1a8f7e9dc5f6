//! The binned SAH builder (I. Wald, "On fast construction of SAH-based bounding
//! volume hierarchies", IEEE Symposium on Interactive Ray Tracing, 2007).
//!
//! Top-down: at each node the primitives' centroids are dropped into `bins`
//! equal bins per axis; sweeping the bins from both sides gives the surface area
//! heuristic (MacDonald & Booth, 1990) of every bin boundary,
//!
//! ```text
//! cost(split) = C_trav + C_isect · (b(n_L)·A_L + b(n_R)·A_R) / A
//! cost(leaf)  = C_isect · b(n)
//! ```
//!
//! where `b(n) = ⌈n / block⌉` counts the leaf tests of `n` primitives: a single
//! ray tests a leaf's triangles [`BLOCK_SIZE`] at a time, so a leaf of eight
//! costs what a leaf of one does (Embree's builders price their `Triangle4`
//! leaves the same way).
//!
//! and the node becomes a leaf when that is cheaper than the best split and small
//! enough; otherwise its primitives are partitioned at the best boundary and both
//! halves are built, on two rayon tasks when the node is large. Where binning
//! cannot separate the primitives (all centroids in one point) or the tree grows
//! too deep, the node is split at the median centroid instead, which bounds the
//! depth by [`MAX_DEPTH`].

use glam::{Mat3A, UVec4, Vec3, Vec3A, Vec4};
use rayon::prelude::*;
use wide::f32x4;

use crate::accel::bvh::leaf::BLOCK_SIZE;
use crate::accel::bvh::node::{Node, NodePair};
use crate::bounds::Aabb;

/// How a BVH is built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuildOptions {
    /// SAH bins per axis, clamped to `[2, 32]` (8–32 is the useful range);
    /// a node of `n` primitives gets at most `4 + n / 20`.
    pub bins: usize,
    /// Largest leaf the SAH may choose; larger nodes are always split.
    /// 16 by default (two blocks of 8), 4 or 8 below [`LARGE_SCENE_PRIMITIVES`]
    /// ([`BuildOptions::for_primitives`]): on the largest meshes leaves of up to 16
    /// traced faster than one-block leaves on every ray kind, 16 and 32 alike,
    /// and the build is faster (figures: `docs/measurements.md`, "Constants").
    pub max_leaf_size: usize,
    /// SAH cost of visiting a node, relative to… (2 by default, 1 for small
    /// and medium scenes: with block leaves, 1 to 4 trace within noise of each other)
    pub traversal_cost: f32,
    /// …the cost of one leaf test, of up to `block_size` primitives.
    pub intersection_cost: f32,
    /// Primitives one leaf test covers ([`BLOCK_SIZE`]; 4 for small scenes of
    /// blocks, see [`SMALL_BLOCK_SCENE_PRIMITIVES`]; 1 prices each primitive alone).
    pub block_size: usize,
}

impl Default for BuildOptions {
    fn default() -> Self {
        Self {
            bins: 16,
            max_leaf_size: 16,
            traversal_cost: 2.0,
            intersection_cost: 1.0,
            block_size: BLOCK_SIZE,
        }
    }
}

/// How a scene's leaves are tested, which decides how large the SAH lets
/// them grow ([`BuildOptions::for_primitives`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LeafKind {
    /// Nearly every leaf can hold blocks of one kind (a triangle mesh, a
    /// cloud of spheres), each block tested by a single ray at once.
    Blocks,
    /// Some leaves hold records, tested one primitive at a time (cylinders,
    /// cones, a leaf mixing kinds).
    Records,
}

/// Scenes of blocks ([`LeafKind::Blocks`]) of fewer primitives than this get
/// leaves of up to one block (8), a node cost of 1 and leaves priced per
/// [`SMALL_SCENE_PRICED_BLOCK`] primitives, not per block.
///
/// A small tree stays in the caches, so a ray's time goes into tests rather
/// than loads. Priced per block, a leaf of 5–8 costs what one of 4 does and
/// is never split, though packets test each of its primitives against their
/// lanes; priced per 4 it is split where the split saves tests. That traces
/// small triangle scenes as fast as leaves of up to 4 (coherent packets 1–4%
/// slower, single rays and incoherent packets 0–14% faster) and builds them
/// up to 1.4× faster (figures: `docs/measurements.md`, "Constants").
pub const SMALL_BLOCK_SCENE_PRIMITIVES: usize = 1 << 14;

/// Primitives a leaf test of a small scene of blocks is priced at
/// ([`SMALL_BLOCK_SCENE_PRIMITIVES`]): half a block.
pub const SMALL_SCENE_PRICED_BLOCK: usize = 4;

/// Scenes with records ([`LeafKind::Records`]) of fewer primitives than this
/// get leaves of up to 4 and a node cost of 1. Records are tested one at a
/// time, so a larger leaf costs a test per primitive: leaves of up to 8
/// traced SPD rings and tree (cylinders, cones) 0.35–0.86× as fast, and the
/// tree at 32,767 cones and spheres 2–4× slower (figures:
/// `docs/measurements.md`, "Constants").
pub const SMALL_RECORD_SCENE_PRIMITIVES: usize = 1 << 15;

/// Scenes of fewer primitives than this, above the small ones, get leaves of
/// up to one block (8) and a node cost of 1, leaves priced per block. At
/// 2·10⁴–4·10⁴ triangles one-block leaves trace faster than leaves of up to
/// 4 or 16, and a node cost of 1 faster than 2 (figures:
/// `docs/measurements.md`, "Constants").
pub const MEDIUM_SCENE_PRIMITIVES: usize = 3 << 14;

/// Scenes of fewer primitives than this, and no fewer than
/// [`MEDIUM_SCENE_PRIMITIVES`], get leaves of up to one block (8) with the
/// default node cost (2); larger ones the defaults, leaves of up to two
/// blocks, whose fewer node loads win once the tree is far larger than the
/// caches. From 10⁵ to 2·10⁵ triangles one-block leaves trace faster on
/// every ray kind, at 10⁶ single rays lose 5–13% with them (figures:
/// `docs/measurements.md`, "Constants").
pub const LARGE_SCENE_PRIMITIVES: usize = 1 << 19;

impl BuildOptions {
    /// The options [`Bvh::new`](crate::accel::Bvh::new) builds `count`
    /// primitives whose leaves are `kind` with: the defaults, with smaller
    /// leaves for small scenes ([`SMALL_BLOCK_SCENE_PRIMITIVES`],
    /// [`SMALL_RECORD_SCENE_PRIMITIVES`]), leaves of up to one block below
    /// [`LARGE_SCENE_PRIMITIVES`], and a cheaper node below
    /// [`MEDIUM_SCENE_PRIMITIVES`].
    pub fn for_primitives(count: usize, kind: LeafKind) -> Self {
        let defaults = Self::default();
        let (max_leaf_size, traversal_cost, block_size) = match kind {
            LeafKind::Blocks if count < SMALL_BLOCK_SCENE_PRIMITIVES => {
                (BLOCK_SIZE, 1.0, SMALL_SCENE_PRICED_BLOCK)
            }
            LeafKind::Records if count < SMALL_RECORD_SCENE_PRIMITIVES => (4, 1.0, BLOCK_SIZE),
            _ if count < MEDIUM_SCENE_PRIMITIVES => (BLOCK_SIZE, 1.0, BLOCK_SIZE),
            _ if count < LARGE_SCENE_PRIMITIVES => (BLOCK_SIZE, defaults.traversal_cost, BLOCK_SIZE),
            _ => return defaults,
        };
        Self {
            max_leaf_size,
            traversal_cost,
            block_size,
            ..defaults
        }
    }
}

/// Most bins per axis (a power of two: [`bins_of`] masks with it).
const MAX_BINS: usize = 32;
const _: () = assert!(MAX_BINS.is_power_of_two());

/// Depth from which nodes are split at the median instead of by the SAH.
pub const SAH_DEPTH_LIMIT: usize = 60;

/// No leaf is deeper than this: SAH splits down to [`SAH_DEPTH_LIMIT`], then at
/// most 32 levels of median splits of a `u32` count of primitives.
pub const MAX_DEPTH: usize = SAH_DEPTH_LIMIT + 32;

/// Nodes with at least this many primitives build their two children in
/// parallel. Embree's builders hand subtrees of a thousand or so to their own
/// tasks too; at 4,096 a scene below that size built on one thread (a bunny
/// of 3,674 triangles took as long on two threads as on one).
const PARALLEL_MIN: usize = 1024;

/// The built hierarchy: node pairs (root in pair 0, side 0) and the primitive
/// order of the leaves (indices into the input boxes).
pub struct Built {
    /// The nodes.
    pub pairs: Vec<NodePair>,
    /// Leaf primitive `i` is input primitive `order[i]`.
    pub order: Vec<u32>,
}

/// Build over the primitive boxes `boxes` (finite, non-empty list).
pub fn build(boxes: &[Aabb], options: &BuildOptions) -> Built {
    let ctx = Context::new(options);
    let mut refs: Vec<PrimRef> = boxes
        .par_iter()
        .enumerate()
        .map(|(i, b)| PrimRef::new(Box3::new(b.min.into(), b.max.into()), i as u32))
        .collect();
    let (bounds, centroids) = refs
        .par_iter()
        .fold(
            || (Box3::EMPTY, Box3::EMPTY),
            |(b, c), r| (b.union(&r.bounds()), c.grow(r.centroid())),
        )
        .reduce(
            || (Box3::EMPTY, Box3::EMPTY),
            |(b1, c1), (b2, c2)| (b1.union(&b2), c1.union(&c2)),
        );
    let all = NodePrims {
        refs: &mut refs,
        first: 0,
        bounds,
        centroids,
    };
    let tree = ctx.subtree(all, 0, &mut BinScratch::new());
    // Flatten depth first: a node's children pair, then the left subtree, then the right.
    let mut pairs = Vec::with_capacity(1 + tree.inner_nodes());
    pairs.push(NodePair([Node::EMPTY; 2]));
    pairs[0].0[0] = emit(&tree, &mut pairs);
    Built {
        pairs,
        order: refs.iter().map(PrimRef::id).collect(),
    }
}

/// A box in SIMD-friendly form (glam's 16-byte `Vec3A`). 32 bytes.
#[derive(Clone, Copy, Debug)]
struct Box3 {
    min: Vec3A,
    max: Vec3A,
}

impl Box3 {
    const EMPTY: Box3 = Box3 {
        min: Vec3A::splat(f32::INFINITY),
        max: Vec3A::splat(f32::NEG_INFINITY),
    };

    #[inline(always)]
    fn new(min: Vec3A, max: Vec3A) -> Self {
        Self { min, max }
    }

    #[inline(always)]
    fn union(&self, o: &Box3) -> Box3 {
        Box3::new(self.min.min(o.min), self.max.max(o.max))
    }

    #[inline(always)]
    fn grow(&self, p: Vec3A) -> Box3 {
        Box3::new(self.min.min(p), self.max.max(p))
    }

    /// Surface area; 0 for the empty box.
    #[inline(always)]
    fn area(&self) -> f32 {
        let e = (self.max - self.min).max(Vec3A::ZERO);
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }

    fn to_aabb(self) -> Aabb {
        Aabb::new(Vec3::from(self.min), Vec3::from(self.max))
    }
}

/// A primitive's box and input index: what the builder sorts. The builder moves
/// these (not indices into the boxes), so its passes read memory in order. 32
/// bytes: the index rides in the spare fourth lane of the lower corner, as in
/// Embree's `PrimRef`, so a million of them stream a third less memory.
#[derive(Clone, Copy, Debug)]
struct PrimRef {
    /// Lower corner; `w` holds the input index's bits.
    lower: Vec4,
    /// Upper corner; `w` unused.
    upper: Vec4,
}

/// Added to an index to make the bits of a float of 1 or more (`1.0`'s bits;
/// see [`PrimRef::bounds`]).
const ID_BIAS: u32 = 0x3F80_0000;

impl PrimRef {
    #[inline(always)]
    fn new(bounds: Box3, id: u32) -> Self {
        Self {
            lower: bounds.min.extend(f32::from_bits(id.wrapping_add(ID_BIAS))),
            upper: bounds.max.extend(0.0),
        }
    }

    /// The box, its fourth lanes left as they are: `Vec3A` never reads them,
    /// and clearing them would cost a shuffle per corner. So the arithmetic
    /// on boxes and centroids runs on the index lane too, and neither that
    /// lane nor what is made of it may be subnormal, whose arithmetic takes
    /// a microcode assist of a hundred cycles or more (the build ran several
    /// times slower with raw indices, and as slow with indices read as the
    /// smallest normals, half of which is subnormal). Hence the index is
    /// stored as the bits of a float of at least 1 ([`ID_BIAS`]), for indices
    /// below 2³⁰; the next 2²³ read as infinities and NaNs (no assist either),
    /// and beyond those a few are subnormal again: slower, never wrong.
    #[inline(always)]
    fn bounds(&self) -> Box3 {
        Box3::new(Vec3A::from_vec4(self.lower), Vec3A::from_vec4(self.upper))
    }

    /// Index in the input boxes.
    #[inline(always)]
    fn id(&self) -> u32 {
        self.lower.w.to_bits().wrapping_sub(ID_BIAS)
    }

    /// Twice the centroid, `lower + upper`: the builder bins, partitions and
    /// sorts by it and keeps the centroid boxes of nodes in these units, one
    /// addition where the centroid itself takes two products more. Doubling
    /// is exact, so every bin, boundary and order is the one the centroid
    /// would give. Only boxes within a factor 2 of `f32::MAX` see their
    /// doubled centroid overflow: an axis whose centroid extent is then not
    /// finite is not binned ([`bin_scales`]), and a node falls back to the
    /// median split only where no axis can be binned.
    #[inline(always)]
    fn centroid(&self) -> Vec3A {
        Vec3A::from_vec4(self.centroid_lanes())
    }

    /// [`PrimRef::centroid`] in the first three lanes of all four (the
    /// fourth is the index's float, normal: see [`PrimRef::bounds`]); the
    /// binning reads it so, with no lane to clear.
    #[inline(always)]
    fn centroid_lanes(&self) -> Vec4 {
        self.lower + self.upper
    }
}

/// The tree while it is being built. Only the nodes large enough to build
/// their halves in parallel ([`PARALLEL_MIN`]) are boxed; the subtrees below
/// them are built by one thread straight into node pairs, depth first, as the
/// final array holds them ([`Subtree::Flat`]), and copied there in one piece.
/// (With every node boxed, a dragon build allocated, flattened and dropped 10⁵
/// small blocks scattered over the heap; building in pieces is faster on one
/// thread: figures in the commit that made it.)
enum Subtree {
    /// A subtree built in one piece: its root, and the pairs of its inner
    /// nodes, numbered from 0 within `pairs`.
    Flat { root: Node, pairs: Vec<NodePair> },
    /// A node whose halves were built as two tasks.
    Inner {
        bounds: Aabb,
        axis: u32,
        children: Box<[Subtree; 2]>,
        /// Inner nodes in this subtree, itself included: the node pairs it needs.
        inner_nodes: usize,
    },
}

impl Subtree {
    /// Inner nodes in this subtree.
    fn inner_nodes(&self) -> usize {
        match self {
            Subtree::Flat { pairs, .. } => pairs.len(),
            Subtree::Inner { inner_nodes, .. } => *inner_nodes,
        }
    }
}

/// Write `t`'s subtree into `pairs`, returning the node for `t` itself.
fn emit(t: &Subtree, pairs: &mut Vec<NodePair>) -> Node {
    match t {
        Subtree::Flat { root, pairs: flat } => {
            // Pair i of the piece becomes pair `offset + i`.
            let offset = pairs.len() as u32;
            pairs.extend(flat.iter().map(|p| NodePair(p.0.map(|n| n.relocated(offset)))));
            root.relocated(offset)
        }
        Subtree::Inner {
            bounds,
            axis,
            children,
            ..
        } => {
            let pair = pairs.len();
            pairs.push(NodePair([Node::EMPTY; 2]));
            let left = emit(&children[0], pairs);
            let right = emit(&children[1], pairs);
            pairs[pair] = NodePair([left, right]);
            Node::inner(*bounds, pair as u32, *axis)
        }
    }
}

/// The best split found by binning: bins `0..=last_left` along `axis` go left.
struct Split {
    axis: usize,
    last_left: usize,
    cost: f32,
    /// The boxes of the two sides: the unions of their bins' boxes, which are
    /// the unions of their primitives' boxes.
    boxes: [Box3; 2],
}

/// The bins of one node's split search, kept from node to node so that each
/// clears only the bins it uses: most nodes are small and use few of them.
/// The sweeps price the three axes at once, lane by lane (as Embree's binner
/// does), so what they read per bin is laid out in lanes x, y, z. 4.6 KB.
struct BinScratch {
    /// Per axis, the box of each bin's primitives.
    boxes: [[Box3; MAX_BINS]; 3],
    /// Per bin, its primitives along each axis (lanes x, y, z; w stays 0).
    counts: [UVec4; MAX_BINS],
    /// The leaf tests `b(n)` of bins `i..` together, per axis (0 where they
    /// hold nothing), for the sweep.
    right_tests: [Vec4; MAX_BINS],
    /// The SAH weight `b(n)·A` of bins `i..` together, per axis.
    right_weight: [Vec4; MAX_BINS],
}

impl BinScratch {
    fn new() -> Self {
        Self {
            boxes: [[Box3::EMPTY; MAX_BINS]; 3],
            counts: [UVec4::ZERO; MAX_BINS],
            right_tests: [Vec4::ZERO; MAX_BINS],
            right_weight: [Vec4::ZERO; MAX_BINS],
        }
    }

    /// Clear the first `n_bins` bins and fill them with `refs`: on each axis,
    /// a primitive's box joins the bin of its centroid (offset by `origin`,
    /// scaled by `scale`, as [`bins_of`] places it), whose count goes up by
    /// one. A node of twice [`BINNING_TASK_MIN`] primitives or more is binned
    /// in parallel, in halves whose bins are then joined (unions and sums, so
    /// the bins are the same as one pass makes): near the root, where the
    /// node is large and no other task runs beside it.
    fn fill(&mut self, refs: &[PrimRef], n_bins: usize, origin: Vec4, scale: Vec4) {
        if refs.len() >= 2 * BINNING_TASK_MIN {
            let (a, b) = refs.split_at(refs.len() / 2);
            let mut other = BinScratch::new();
            rayon::join(
                || self.fill(a, n_bins, origin, scale),
                || other.fill(b, n_bins, origin, scale),
            );
            for axis in 0..3 {
                for (bin, theirs) in self.boxes[axis][..n_bins].iter_mut().zip(&other.boxes[axis]) {
                    *bin = bin.union(theirs);
                }
            }
            for (count, theirs) in self.counts[..n_bins].iter_mut().zip(&other.counts) {
                *count += *theirs;
            }
            return;
        }
        for axis_boxes in self.boxes.iter_mut() {
            axis_boxes[..n_bins].fill(Box3::EMPTY);
        }
        self.counts[..n_bins].fill(UVec4::ZERO);
        for r in refs {
            let k = bins_of(n_bins, r.centroid_lanes(), origin, scale);
            for (axis, &k) in k.iter().enumerate() {
                let bin = &mut self.boxes[axis][k];
                *bin = bin.union(&r.bounds());
                self.counts[k][axis] += 1;
            }
        }
    }
}

/// The fewest primitives one task bins ([`BinScratch::fill`]): below twice
/// this, a node is binned in one pass (a rayon task and a second set of bins
/// cost about as much as binning a few hundred primitives).
const BINNING_TASK_MIN: usize = 4096;

/// The surface areas of three boxes, in lanes x, y, z (0 in w): each lane
/// exactly what [`Box3::area`] computes, three boxes for the price of one.
#[inline(always)]
fn areas(boxes: &[Box3; 3]) -> Vec4 {
    let extent = |b: &Box3| (b.max - b.min).max(Vec3A::ZERO);
    // Transpose the extents so that lane `axis` holds box `axis`'s.
    let e = Mat3A::from_cols(extent(&boxes[0]), extent(&boxes[1]), extent(&boxes[2])).transpose();
    let (x, y, z) = (e.x_axis, e.y_axis, e.z_axis);
    (2.0 * (x * y + y * z + z * x)).extend(0.0)
}

/// The builder's settings.
struct Context {
    bins: usize,
    max_leaf: usize,
    c_trav: f32,
    c_isect: f32,
    /// Primitives per leaf test.
    block: usize,
    /// `log2(block)` when `block` is a power of two (always, by default): the
    /// sweeps price two splits per bin boundary, and a shift is a cycle where
    /// a division is tens.
    block_shift: Option<u32>,
}

/// The primitives of a node being built: `refs` are primitives
/// `first..first + refs.len()` of the final order, with box `bounds` and
/// centroid box `centroids`.
struct NodePrims<'a> {
    refs: &'a mut [PrimRef],
    first: u32,
    bounds: Box3,
    centroids: Box3,
}

impl<'a> NodePrims<'a> {
    /// The node as a leaf.
    fn leaf(&self) -> Node {
        Node::leaf(self.bounds.to_aabb(), self.first, self.refs.len() as u32)
    }

    /// The two children of `division` (made of these primitives, reordered).
    fn split(self, division: &Division) -> [NodePrims<'a>; 2] {
        let mid = division.left_count;
        let [(lb, lc), (rb, rc)] = division.children;
        let (l, r) = self.refs.split_at_mut(mid);
        [
            NodePrims {
                refs: l,
                first: self.first,
                bounds: lb,
                centroids: lc,
            },
            NodePrims {
                refs: r,
                first: self.first + mid as u32,
                bounds: rb,
                centroids: rc,
            },
        ]
    }
}

/// How a node's primitives are divided between its children.
struct Division {
    axis: usize,
    /// Primitives going left (they come first in the node's range).
    left_count: usize,
    /// Boxes and centroid boxes of the two children.
    children: [(Box3, Box3); 2],
}

impl Context {
    fn new(options: &BuildOptions) -> Self {
        let block = options.block_size.max(1);
        Self {
            bins: options.bins.clamp(2, MAX_BINS),
            max_leaf: options.max_leaf_size.max(1),
            c_trav: options.traversal_cost,
            c_isect: options.intersection_cost,
            block,
            block_shift: block.is_power_of_two().then(|| block.trailing_zeros()),
        }
    }

    /// Leaf tests of `n` primitives: `⌈n / block⌉`.
    #[inline(always)]
    fn tests(&self, n: usize) -> f32 {
        match self.block_shift {
            Some(shift) => ((n + self.block - 1) >> shift) as f32,
            None => n.div_ceil(self.block) as f32,
        }
    }

    /// [`Context::tests`] of each lane of `n` (counts below 2³¹).
    #[inline(always)]
    fn tests_lanes(&self, n: UVec4) -> Vec4 {
        match self.block_shift {
            // Below 2³¹ the signed conversion (one instruction for all four
            // lanes) rounds as `usize as f32` does.
            Some(shift) => ((n + UVec4::splat(self.block as u32 - 1)) >> shift)
                .as_ivec4()
                .as_vec4(),
            None => Vec4::from_array(n.to_array().map(|n| self.tests(n as usize))),
        }
    }

    /// How to divide the node holding `refs`, whose box is `bounds` and
    /// centroid box `centroids`, at `depth`: None for a leaf. The primitives
    /// are reordered so that the left child's come first.
    fn divide(
        &self,
        refs: &mut [PrimRef],
        bounds: &Box3,
        centroids: &Box3,
        depth: usize,
        scratch: &mut BinScratch,
    ) -> Option<Division> {
        let n = refs.len();
        if n <= 1 {
            return None;
        }
        // A split costs at least C_trav (its children's term is not negative),
        // so a node that may be a leaf and costs no more as one is a leaf
        // without pricing any split: with the default costs, every node of up
        // to `max_leaf` primitives, half of all the nodes the build visits.
        let leaf_cost = self.c_isect * self.tests(n);
        if n <= self.max_leaf && self.c_isect >= 0.0 && leaf_cost <= self.c_trav {
            return None;
        }
        // Bins in proportion to the node's primitives (4 + n/20, Embree's
        // binner scales them so too): the sweeps over bins cost as much as
        // binning a node of few primitives, and its split gains little from
        // fine boundaries. With up to `n` bins instead, the split search
        // took a third more instructions for no better trees (SAH costs of
        // the SPD triangle scenes within 1%, gears' 3% higher).
        let bins = self.bins.min(4 + n / 20);
        let split = if depth < SAH_DEPTH_LIMIT {
            self.best_split(refs, bins, bounds, centroids, scratch)
        } else {
            None
        };
        match split {
            Some(s) if n > self.max_leaf || s.cost < leaf_cost => Some(partition(refs, bins, centroids, &s)),
            _ if n <= self.max_leaf => None,
            _ => Some(median_split(refs, centroids)),
        }
    }

    /// Build the node of `prims`: the halves of a large node on two rayon
    /// tasks, a smaller one in one piece ([`Context::flat`]).
    fn subtree(&self, prims: NodePrims<'_>, depth: usize, scratch: &mut BinScratch) -> Subtree {
        if prims.refs.len() < PARALLEL_MIN {
            let mut pairs = Vec::new();
            let root = self.flat(prims, depth, scratch, &mut pairs);
            return Subtree::Flat { root, pairs };
        }
        let Some(division) = self.divide(prims.refs, &prims.bounds, &prims.centroids, depth, scratch) else {
            return Subtree::Flat {
                root: prims.leaf(),
                pairs: Vec::new(),
            };
        };
        let bounds = prims.bounds.to_aabb();
        let [l, r] = prims.split(&division);
        // The right half may run on another thread: it gets bins of its own.
        let (a, b) = rayon::join(
            || self.subtree(l, depth + 1, scratch),
            || self.subtree(r, depth + 1, &mut BinScratch::new()),
        );
        Subtree::Inner {
            bounds,
            axis: division.axis as u32,
            inner_nodes: 1 + a.inner_nodes() + b.inner_nodes(),
            children: Box::new([a, b]),
        }
    }

    /// Build the node of `prims` on this thread, its inner nodes' pairs
    /// pushed onto `pairs` depth first (a node's children, then the left
    /// subtree, then the right); returns the node.
    fn flat(
        &self,
        prims: NodePrims<'_>,
        depth: usize,
        scratch: &mut BinScratch,
        pairs: &mut Vec<NodePair>,
    ) -> Node {
        let Some(division) = self.divide(prims.refs, &prims.bounds, &prims.centroids, depth, scratch) else {
            return prims.leaf();
        };
        let bounds = prims.bounds.to_aabb();
        let [l, r] = prims.split(&division);
        let pair = pairs.len();
        pairs.push(NodePair([Node::EMPTY; 2]));
        let left = self.flat(l, depth + 1, scratch, pairs);
        let right = self.flat(r, depth + 1, scratch, pairs);
        pairs[pair] = NodePair([left, right]);
        Node::inner(bounds, pair as u32, division.axis as u32)
    }

    /// The cheapest SAH split over all axes and bin boundaries, if any separates the primitives.
    fn best_split(
        &self,
        refs: &[PrimRef],
        n_bins: usize,
        bounds: &Box3,
        centroids: &Box3,
        scratch: &mut BinScratch,
    ) -> Option<Split> {
        let scale = bin_scales(n_bins, centroids);
        if scale == Vec3A::ZERO {
            return None;
        }
        // Fill the bins of all three axes in one pass over the primitives.
        // The fourth lanes (origin 0, scale 0) make a bin that `bins_of` drops.
        scratch.fill(refs, n_bins, centroids.min.extend(0.0), scale.extend(0.0));
        let BinScratch {
            boxes,
            counts,
            right_tests,
            right_weight,
        } = scratch;
        // Right-to-left sweep, all axes at once: the leaf tests and SAH
        // weight of bins `i..`.
        let mut right = [Box3::EMPTY; 3];
        let mut count = UVec4::ZERO;
        for i in (1..n_bins).rev() {
            for axis in 0..3 {
                right[axis] = right[axis].union(&boxes[axis][i]);
            }
            count += counts[i];
            right_tests[i] = self.tests_lanes(count);
            right_weight[i] = right_tests[i] * areas(&right);
        }
        // Left-to-right sweep, pricing the boundary after bin `i` on every
        // axis; each lane keeps its cheapest boundary, the first of equal
        // costs. A boundary with nothing on one side is no split, and `<` is
        // false for NaN costs (infinite areas): such splits are never chosen.
        let (c_trav, c_isect, inv_area) = (
            Vec4::splat(self.c_trav),
            Vec4::splat(self.c_isect),
            Vec4::splat(1.0 / bounds.area()),
        );
        let mut left = [Box3::EMPTY; 3];
        let mut count = UVec4::ZERO;
        let (mut best_cost, mut best_bin) = (Vec4::INFINITY, Vec4::ZERO);
        for i in 0..n_bins - 1 {
            for axis in 0..3 {
                left[axis] = left[axis].union(&boxes[axis][i]);
            }
            count += counts[i];
            let tests = self.tests_lanes(count);
            let weighted = tests * areas(&left) + right_weight[i + 1];
            let cost = c_trav + c_isect * weighted * inv_area;
            let better =
                cost.cmplt(best_cost) & tests.cmpgt(Vec4::ZERO) & right_tests[i + 1].cmpgt(Vec4::ZERO);
            best_cost = Vec4::select(better, cost, best_cost);
            best_bin = Vec4::select(better, Vec4::splat(i as f32), best_bin);
        }
        // The cheapest axis (the first of equal costs) of those binned.
        let mut best: Option<(f32, usize, usize)> = None;
        for axis in 0..3 {
            let cost = best_cost[axis];
            if scale[axis] != 0.0 && cost < best.map_or(f32::INFINITY, |(b, _, _)| b) {
                best = Some((cost, axis, best_bin[axis] as usize));
            }
        }
        let (cost, axis, last_left) = best.filter(|(cost, _, _)| cost.is_finite())?;
        let side = |boxes: &[Box3]| boxes.iter().fold(Box3::EMPTY, |b, bin| b.union(bin));
        let (l, r) = boxes[axis][..n_bins].split_at(last_left + 1);
        Some(Split {
            axis,
            last_left,
            cost,
            boxes: [side(l), side(r)],
        })
    }
}

/// Reorder `refs` so the primitives left of split `s` come first, measuring
/// both sides' centroid boxes on the way (their boxes come with the split).
fn partition(refs: &mut [PrimRef], bins: usize, centroids: &Box3, s: &Split) -> Division {
    // Left when the centroid's bin along the split's axis is at most
    // `last_left`: its position in bins, computed as `bins_of` does, is below
    // `last_left + 1` (an integer, so the compare is exact, and the top bin's
    // clamp never matters: `last_left + 1` is at most the top bin). All three
    // lanes are compared at once, and the axis's bit read from the mask.
    let (origin, scale) = (centroids.min, bin_scales(bins, centroids));
    let boundary = Vec3A::splat((s.last_left + 1) as f32);
    let goes_left = |c: Vec3A| ((c - origin) * scale).cmplt(boundary).bitmask() >> s.axis & 1 == 1;
    let mut centroid_boxes = [Box3::EMPTY; 2];
    let mut add = |side: usize, c: Vec3A| {
        centroid_boxes[side] = centroid_boxes[side].grow(c);
    };
    // Hoare's scheme: walk in from both ends and swap only misplaced pairs.
    let (mut i, mut j) = (0, refs.len());
    loop {
        while i < j {
            let c = refs[i].centroid();
            if !goes_left(c) {
                break;
            }
            add(0, c);
            i += 1;
        }
        while i < j {
            let c = refs[j - 1].centroid();
            if goes_left(c) {
                break;
            }
            add(1, c);
            j -= 1;
        }
        if i == j {
            break;
        }
        // refs[i] belongs right and refs[j − 1] left, so they are two elements.
        add(1, refs[i].centroid());
        add(0, refs[j - 1].centroid());
        refs.swap(i, j - 1);
        i += 1;
        j -= 1;
    }
    Division {
        axis: s.axis,
        left_count: i,
        children: [0, 1].map(|side| (s.boxes[side], centroid_boxes[side])),
    }
}

/// Per axis, bins per unit of centroid extent (0 where the axis cannot be binned).
fn bin_scales(bins: usize, centroids: &Box3) -> Vec3A {
    let extent = centroids.max - centroids.min;
    let scale = Vec3A::splat(bins as f32) / extent;
    Vec3A::select(
        extent.cmpgt(Vec3A::ZERO) & scale.is_finite_mask(),
        scale,
        Vec3A::ZERO,
    )
}

/// The bin of every axis for centroid `c` (lanes x, y, z; the fourth ignored),
/// with the node's centroid box starting at `min` and bins per unit `scale`.
#[inline(always)]
fn bins_of(bins: usize, c: Vec4, min: Vec4, scale: Vec4) -> [usize; 3] {
    // Clamp in floating point (the top boundary falls in the last bin), then
    // truncate the lanes in one instruction (cvttps2dq): they are in range,
    // so the saturating `f32 as i32` casts' compare and select per lane would
    // buy nothing. Four lanes, as the centroid comes: a `Vec3A` would have its
    // fourth lane cleared first, three instructions a primitive.
    let k = ((c - min) * scale).clamp(Vec4::ZERO, Vec4::splat((bins - 1) as f32));
    let [x, y, z, _] = f32x4::new(k.to_array()).fast_trunc_int().to_array();
    // The mask changes no index (all are below `bins` ≤ MAX_BINS) and spares
    // the bins' bounds checks.
    [x, y, z].map(|k| k as usize & (MAX_BINS - 1))
}

/// Split at the median centroid of the widest centroid axis.
fn median_split(refs: &mut [PrimRef], centroids: &Box3) -> Division {
    let e = centroids.max - centroids.min;
    let axis = if e.x >= e.y && e.x >= e.z {
        0
    } else if e.y >= e.z {
        1
    } else {
        2
    };
    let mid = refs.len() / 2;
    refs.select_nth_unstable_by(mid, |a, b| a.centroid()[axis].total_cmp(&b.centroid()[axis]));
    let side = |rs: &[PrimRef]| {
        rs.iter().fold((Box3::EMPTY, Box3::EMPTY), |(b, c), r| {
            (b.union(&r.bounds()), c.grow(r.centroid()))
        })
    };
    Division {
        axis,
        left_count: mid,
        children: [side(&refs[..mid]), side(&refs[mid..])],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn partition_follows_the_split_and_measures_both_sides() {
        let refs: Vec<PrimRef> = (0..100)
            .map(|i| {
                let p = Vec3A::new(i as f32, (i % 7) as f32, 0.0);
                PrimRef::new(Box3::new(p, p + Vec3A::ONE), i)
            })
            .collect();
        let centroids = refs.iter().fold(Box3::EMPTY, |a, r| a.grow(r.centroid()));
        let mut sorted = refs.clone();
        let d = partition(
            &mut sorted,
            10,
            &centroids,
            &Split {
                axis: 0,
                last_left: 2,
                cost: 0.0,
                boxes: [Box3::EMPTY; 2],
            },
        );
        // Centroids x = 0.5..99.5 in 10 bins of 9.9: bins 0..=2 hold x < 30.2, ids 0..=29.
        // (The builder's centroid boxes are in doubled centroids: `PrimRef::centroid`.)
        assert_eq!(d.left_count, 30);
        assert!(sorted[..30].iter().all(|r| r.id() < 30));
        assert!(sorted[30..].iter().all(|r| r.id() >= 30));
        assert_eq!(d.children[0].1.max.x, 2.0 * 29.5);
        assert_eq!(d.children[1].1.min.x, 2.0 * 30.5);
        assert_eq!(d.children[1].1.max.x, 2.0 * 99.5);
        let mut ids: Vec<u32> = sorted.iter().map(PrimRef::id).collect();
        ids.sort();
        assert_eq!(ids, (0..100).collect::<Vec<_>>());
    }

    #[test]
    fn the_split_and_the_partition_measure_both_sides_exactly() {
        // Random boxes; the chosen split's boxes and the partition's centroid
        // boxes must be those of the primitives each side gets.
        let mut rng = crate::rng::Rng::new(3);
        let refs: Vec<PrimRef> = (0..1000)
            .map(|i| {
                let p = Vec3A::from(rng.point_in(Vec3::ZERO, Vec3::splat(10.0)));
                let e = Vec3A::from(rng.point_in(Vec3::ZERO, Vec3::ONE));
                PrimRef::new(Box3::new(p, p + e), i)
            })
            .collect();
        let measure = |rs: &[PrimRef]| {
            rs.iter().fold((Box3::EMPTY, Box3::EMPTY), |(b, c), r| {
                (b.union(&r.bounds()), c.grow(r.centroid()))
            })
        };
        let (bounds, centroids) = measure(&refs);
        let ctx = Context::new(&BuildOptions::default());
        let split = ctx
            .best_split(&refs, 16, &bounds, &centroids, &mut BinScratch::new())
            .expect("random boxes can be split");
        let mut sorted = refs.clone();
        let d = partition(&mut sorted, 16, &centroids, &split);
        assert!(d.left_count > 0 && d.left_count < refs.len());
        let same = |a: (Box3, Box3), b: (Box3, Box3)| {
            [a.0.min, a.0.max, a.1.min, a.1.max] == [b.0.min, b.0.max, b.1.min, b.1.max]
        };
        assert!(same(d.children[0], measure(&sorted[..d.left_count])));
        assert!(same(d.children[1], measure(&sorted[d.left_count..])));
    }

    /// The split search one axis and one boundary at a time, in scalars:
    /// what the lane-by-lane sweeps must choose. Returns the cost, axis,
    /// last left bin and the two sides' boxes.
    fn best_split_one_axis_at_a_time(
        ctx: &Context,
        refs: &[PrimRef],
        n_bins: usize,
        bounds: &Box3,
        centroids: &Box3,
    ) -> Option<(f32, usize, usize, [Box3; 2])> {
        let scale = bin_scales(n_bins, centroids);
        let (origin, scale_lanes) = (centroids.min.extend(0.0), scale.extend(0.0));
        let mut bins = [[(Box3::EMPTY, 0usize); MAX_BINS]; 3];
        for r in refs {
            let k = bins_of(n_bins, r.centroid_lanes(), origin, scale_lanes);
            for axis in 0..3 {
                let bin = &mut bins[axis][k[axis]];
                *bin = (bin.0.union(&r.bounds()), bin.1 + 1);
            }
        }
        let union = |bins: &[(Box3, usize)]| {
            bins.iter()
                .fold((Box3::EMPTY, 0), |(b, n), (bin, m)| (b.union(bin), n + m))
        };
        let mut best: Option<(f32, usize, usize, [Box3; 2])> = None;
        for axis in (0..3).filter(|&axis| scale[axis] != 0.0) {
            for last_left in 0..n_bins - 1 {
                let (l, r) = bins[axis][..n_bins].split_at(last_left + 1);
                let ((lb, ln), (rb, rn)) = (union(l), union(r));
                if ln == 0 || rn == 0 {
                    continue;
                }
                let weighted = ctx.tests(ln) * lb.area() + ctx.tests(rn) * rb.area();
                let cost = ctx.c_trav + ctx.c_isect * weighted * (1.0 / bounds.area());
                if cost < best.as_ref().map_or(f32::INFINITY, |b| b.0) {
                    best = Some((cost, axis, last_left, [lb, rb]));
                }
            }
        }
        best.filter(|b| b.0.is_finite())
    }

    #[test]
    fn the_sweeps_choose_the_split_one_axis_at_a_time_chooses() {
        let mut rng = crate::rng::Rng::new(11);
        let mut cases = 0;
        for case in 0..3000 {
            let n = 2 + rng.below(300) as usize;
            let n_bins = 2 + case % 15;
            // Flat along an axis now and then (one centroid coordinate for
            // all), clustered or spread, boxes thin and thick; block sizes of
            // 8 (shifts), 1 and 3 (divisions).
            let flat = case % 4;
            let spread = if case % 3 == 0 { 0.01 } else { 10.0 };
            let options = BuildOptions {
                block_size: [8, 1, 3][case % 3],
                traversal_cost: [1.0, 2.0][case % 2],
                ..BuildOptions::default()
            };
            let ctx = Context::new(&options);
            let refs: Vec<PrimRef> = (0..n)
                .map(|i| {
                    let mut p = Vec3A::from(rng.point_in(Vec3::ZERO, Vec3::splat(spread)));
                    if flat < 3 {
                        p[flat] = 1.5;
                    }
                    let e = Vec3A::from(rng.point_in(Vec3::ZERO, Vec3::splat(spread * 0.1)));
                    PrimRef::new(Box3::new(p, p + e), i as u32)
                })
                .collect();
            let (bounds, centroids) = refs.iter().fold((Box3::EMPTY, Box3::EMPTY), |(b, c), r| {
                (b.union(&r.bounds()), c.grow(r.centroid()))
            });
            let want = best_split_one_axis_at_a_time(&ctx, &refs, n_bins, &bounds, &centroids);
            let got = ctx
                .best_split(&refs, n_bins, &bounds, &centroids, &mut BinScratch::new())
                .map(|s| (s.cost, s.axis, s.last_left, s.boxes));
            let key = |b: &Option<(f32, usize, usize, [Box3; 2])>| {
                b.as_ref().map(|(cost, axis, last, [l, r])| {
                    (
                        cost.to_bits(),
                        *axis,
                        *last,
                        [l.min, l.max, r.min, r.max].map(|v| v.to_array()),
                    )
                })
            };
            assert_eq!(key(&got), key(&want), "case {case}: {n} boxes, {n_bins} bins");
            cases += usize::from(want.is_some());
        }
        // Most cases have a split to find.
        assert!(cases > 2500, "{cases}");
    }

    #[test]
    fn indices_ride_as_floats_far_from_subnormal() {
        for id in [0, 1, 12345, 1 << 23, (1 << 24) + 7, (1 << 30) - 1] {
            let r = PrimRef::new(Box3::new(Vec3A::ZERO, Vec3A::ONE), id);
            assert_eq!(r.id(), id);
            // The centroid's arithmetic on it must stay normal too.
            let w = r.lower.w;
            assert!(w >= 1.0 && r.centroid_lanes().w.is_normal(), "{id}: {w:e}");
        }
        let r = PrimRef::new(Box3::new(Vec3A::ZERO, Vec3A::ONE), u32::MAX);
        assert_eq!(r.id(), u32::MAX);
    }
}
