//! The BVH's data: the binary tree of node pairs, the same tree collapsed
//! into 16- and 8-wide nodes, and the leaves' primitives ([`Bvh`]), with the
//! reads every traversal makes of them. Built by [`builder`](super::builder);
//! walked by the traversals above it.

use crate::accel::bvh::leaf::LeafRef;
use crate::accel::bvh::leaf_store::LeafStore;
use crate::accel::bvh::node::{Node, NodeId, NodePair, ROOT, node_in};
use crate::accel::bvh::wide::{ChildRef, PacketTreeLanes, RayTreeLanes, WideNodeOf};
use crate::bounds::Aabb;
use crate::environment::last_level_cache;
use crate::simd::isa::{IsaError, LevelTask};
use crate::simd::{Isa, SimdFloat};

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

/// Ask the CPU to load the `lines` cache lines from `start` (a constant
/// where inlined, so the loop unrolls).
#[inline(always)]
fn prefetch_lines(start: *const u8, lines: usize) {
    for line in 0..lines {
        prefetch_line(start.wrapping_add(64 * line));
    }
}

/// A width of wide tree that a [`Bvh`] holds, and where it keeps its nodes.
pub trait TreeWidth: SimdFloat {
    /// The nodes of `bvh`'s tree of this width (node 0 holds the root's children).
    fn nodes(bvh: &Bvh) -> &[WideNodeOf<Self>];
}

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
    pub(super) pairs: Vec<NodePair>,
    /// The same tree collapsed to 16-wide nodes, which single rays traverse.
    pub(super) ray_tree: Vec<WideNodeOf<RayTreeLanes>>,
    /// The same tree collapsed to 8-wide nodes, which incoherent packets traverse.
    pub(super) packet_tree: Vec<WideNodeOf<PacketTreeLanes>>,
    /// The primitives, which the leaves of both trees name.
    pub(super) leaves: LeafStore,
    /// The leaf of the primitives with no finite box, tested by every ray.
    pub(super) unbounded: LeafRef,
    /// Primitives in the tree.
    pub(super) bounded: usize,
    /// Degenerate triangles left out.
    pub(super) skipped: usize,
    /// The instruction set queries run on ([`dispatch`]).
    pub(super) isa: Isa,
    /// Bytes of cache the walks may count on ([`Bvh::outgrows_cache`]).
    pub(super) cache_bytes: usize,
    /// [`Bvh::walked_bytes`], summed once the wide trees are built: packet
    /// queries ask for it to choose their walk.
    pub(super) walked_bytes: usize,
}

/// Scattered packets in trees smaller than this (wide nodes and leaves,
/// [`Bvh::walked_bytes`]) walk their lanes one after the other rather than
/// interleaved: interleaved walks hide cache misses, and a tree this small
/// mostly stays in the caches (a few times a core's L2), so only their
/// set-up would count: interleaved walks lose to single rays on small scenes
/// and win on large ones (figures: `docs/measurements.md`, "Constants").
pub const INTERLEAVE_MIN_BYTES: usize = 4 << 20;

/// The last-level cache assumed where the kernel shows no L3 (or no cache
/// at all): the 32 MiB L3 of the AMD EPYC machines measured (Zen 3, 4 and 5).
pub const ASSUMED_CACHE_BYTES: usize = 32 << 20;

/// The bytes of this machine's L3 (or deeper) cache, or [`ASSUMED_CACHE_BYTES`]:
/// a virtual machine that shows only its L2 still has an L3 behind it.
pub(super) fn machine_cache_bytes() -> usize {
    last_level_cache()
        .filter(|c| c.level >= 3)
        .map_or(ASSUMED_CACHE_BYTES, |c| c.bytes)
}

/// Figures about a built BVH, for reports.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct BvhInfo {
    /// Items in the tree: the primitives, each polygon tested as watertight
    /// pieces counted as its pieces.
    pub primitives: usize,
    /// Primitives outside the tree, tested by every ray (planes).
    pub unbounded: usize,
    /// Degenerate triangles and polygons left out (no ray can hit them).
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
    /// Bytes of what single rays read: the 16-wide nodes and the leaves.
    #[inline(always)]
    pub fn walked_bytes(&self) -> usize {
        self.walked_bytes
    }

    /// Whether what single rays read ([`Bvh::walked_bytes`]) is more than the
    /// machine's last-level cache holds, so that a walk waits on memory at
    /// most steps: incoherent packets then walk their lanes apart,
    /// interleaved (see `traverse_packet`).
    #[inline(always)]
    pub fn outgrows_cache(&self) -> bool {
        self.walked_bytes > self.cache_bytes
    }

    /// The bytes of last-level cache [`Bvh::outgrows_cache`] counts on: the
    /// machine's when built, or [`Bvh::set_cache_bytes`]'.
    pub fn cache_bytes(&self) -> usize {
        self.cache_bytes
    }

    /// Whether the lanes of scattered packets (rays from all over the scene)
    /// walk interleaved, which hides cache misses, rather than one after the
    /// other: trees of at least [`INTERLEAVE_MIN_BYTES`] walked.
    #[inline(always)]
    pub fn interleaves_scattered(&self) -> bool {
        self.walked_bytes >= INTERLEAVE_MIN_BYTES
    }

    /// Judge [`Bvh::outgrows_cache`] as on a machine whose last-level cache
    /// holds `bytes` (tests, and measurements of the rule).
    pub fn set_cache_bytes(&mut self, bytes: usize) {
        self.cache_bytes = bytes;
    }

    /// The instruction set queries run on: [`Isa::default_level`] when built.
    pub fn isa(&self) -> Isa {
        self.isa
    }

    /// Run `task` on this tree's instruction set ([`Bvh::isa`]): the one
    /// place a query enters the level's code.
    #[inline(always)]
    pub(crate) fn on_level<T: LevelTask>(&self, task: T) -> T::Output {
        // SAFETY: a Bvh's level is one this CPU runs (`Bvh::set_isa` and
        // `Isa::default_level` check it).
        unsafe { self.isa.run(task) }
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
        node_in(&self.pairs, id)
    }

    /// Every leaf's primitives, which the leaves of both trees name.
    #[inline(always)]
    pub fn leaves(&self) -> &LeafStore {
        &self.leaves
    }

    /// The node pair `pair` (the children of an inner node whose `first` is `pair`).
    #[inline(always)]
    pub fn pair(&self, pair: u32) -> &NodePair {
        &self.pairs[pair as usize]
    }

    /// Start loading what `child` (of the tree of width `F`) leads to into
    /// the cache: the wide node's lines, or the first lines of the leaf's blocks.
    #[inline(always)]
    pub fn prefetch<F: TreeWidth>(&self, child: ChildRef) {
        // A fixed number of lines each way, so that the loops unroll into
        // bare prefetches: a leaf's lines past its blocks are a hint that
        // costs a little bandwidth, where a count computed per child cost
        // some thirty instructions at every push.
        if !child.is_leaf() {
            let node = F::nodes(self).as_ptr().wrapping_add(child.node()).cast::<u8>();
            prefetch_lines(node, size_of::<WideNodeOf<F>>() / 64);
        } else if let Some(blocks) = self.leaves.block_start(child.contents()) {
            prefetch_lines(blocks, PREFETCH_BYTES / 64);
        }
    }

    /// True when no primitive is in the tree.
    #[inline(always)]
    pub fn is_empty(&self) -> bool {
        self.bounded == 0
    }

    /// Primitives in the tree (a polygon tested as watertight pieces counts
    /// as its pieces).
    #[inline(always)]
    pub fn len(&self) -> usize {
        self.bounded
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
