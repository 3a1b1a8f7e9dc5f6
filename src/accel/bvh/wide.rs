//! The wide views of the BVH: each node holds the boxes of up to 8 or 16
//! children in structure-of-arrays form, so one ray tests all of them with
//! one SIMD slab test (the layout of Embree's BVH4 and BVH8, Wald et al.,
//! "Embree: a kernel framework for efficient CPU ray tracing", SIGGRAPH 2014).
//! Each is made by collapsing the binary tree (each wide node takes a binary
//! node and opens its largest inner children until it is full), so all the
//! trees share leaves and primitive order.
//!
//! Two widths, for two walks:
//! - single rays walk a 16-wide tree ([`RayTreeLanes`]) from its root: an
//!   incoherent ray waits on each node it goes to, and 16-wide nodes make
//!   fewer of those waits than 8-wide ones (the dragon's tree is about
//!   log₁₆ rather than log₈ of its 70,000 leaves deep). A node is tested in
//!   halves of the instruction set's 8-lane type, which overlap; on large
//!   meshes single rays of every kind ran faster than on 8-wide nodes;
//! - packets walk an 8-wide tree ([`PacketTreeLanes`]) together and hand the
//!   lanes they leave to single-ray walks of the same tree
//!   (`traverse_hybrid`): a packet tests a node's children one by one, and
//!   on 16-wide nodes its packets ran slower.
//!
//! The widths are the same on every machine, so the trees do not depend on
//! the instruction set they are traced with.

use crate::accel::bvh::build_sah::MAX_DEPTH;
use crate::accel::bvh::leaf::LeafRef;
use crate::accel::bvh::node::{NodeId, NodePair, ROOT, node_in};
use crate::accel::bvh::ray_box::{FAR_SCALE, SlabRay, combine_by_bits, combine_ignoring_nan};
use crate::accel::bvh::stack::WIDE_STACK_SLOTS;
use crate::bounds::Aabb;
use crate::simd::{SimdFloat, SimdU32};

/// What a child slot of a wide node leads to: an inner wide node, or a leaf
/// (encoded as the binary tree's leaf node encodes it, see [`LeafRef`]). 8 bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ChildRef {
    /// Inner: index of the wide node. Leaf: its first primitive or block.
    index: u32,
    /// 0 for an inner node, else the leaf's count word.
    count: u32,
}

impl ChildRef {
    /// Wide node 0, which holds the root's children (or the root leaf).
    pub const ROOT: ChildRef = ChildRef { index: 0, count: 0 };

    /// The wide node `index`.
    #[inline(always)]
    pub fn inner(index: u32) -> Self {
        Self { index, count: 0 }
    }

    /// The leaf whose node has `first` and count word `word` (see [`LeafRef`]).
    #[inline(always)]
    pub fn leaf(first: u32, word: u32) -> Self {
        Self {
            index: first,
            count: word,
        }
    }

    /// True for a leaf, and for the empty slot (see [`ChildRef::is_empty`]).
    #[inline(always)]
    pub fn is_leaf(self) -> bool {
        self.count != 0
    }

    /// True for an empty slot of a wide node, which only rays with NaN or
    /// infinite input can meet; it holds no primitives.
    #[inline(always)]
    pub fn is_empty(self) -> bool {
        self.count == EMPTY_SLOT
    }

    /// Inner: the wide node's index.
    #[inline(always)]
    pub fn node(self) -> usize {
        self.index as usize
    }

    /// Leaf: what it holds.
    #[inline(always)]
    pub fn contents(self) -> LeafRef {
        LeafRef::decode(self.index, self.count)
    }
}

/// The lanes (children per node) of the wide tree single rays walk from its root.
pub type RayTreeLanes = wide::f32x16;

/// The lanes (children per node) of the wide tree packets walk, and the
/// single-ray walks they hand lanes to.
pub type PacketTreeLanes = wide::f32x8;

/// Pending children (the sum of `children − 1` over the wide nodes above) a
/// root-to-leaf path of a tree `width` wide may gather before the collapse
/// stops widening nodes. Past it, wide nodes get two children, adding one
/// pending entry per level, so no traversal holds more than this plus
/// `MAX_DEPTH` pending entries plus the `width` of the node being expanded:
/// the stack's slots less its spare. Trees of real scenes stay far below it
/// (a path of eight 16-wide nodes gathers at most 120; the budget is 147 for
/// 16 wide, 155 for 8); only pathological inputs get narrower nodes deep down.
pub const fn pending_budget(width: usize) -> usize {
    WIDE_STACK_SLOTS - 1 - width - MAX_DEPTH
}

/// Up to `F::LANES` children's (padded) boxes in structure-of-arrays form, and
/// what each child is. For `f32x4`: 96 bytes of boxes + 32 of slots = 128 bytes
/// (two cache lines); for `f32x8`: 192 + 64 = 256 bytes (four lines); for
/// `f32x16`: 384 + 128 = 512 bytes (eight lines).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct WideNodeOf<F: SimdFloat> {
    /// `[min; max]` planes of the children along x, y, z: `bounds[axis][corner][child]`.
    bounds: [[F::Array; 2]; 3],
    /// Per child: inner node index, or a leaf's first primitive or block.
    index: <F::U32 as SimdU32>::Array,
    /// Per child: 0 for an inner node, else the leaf's count word; `u32::MAX` for an empty slot.
    count: <F::U32 as SimdU32>::Array,
}

/// `count` of an empty slot.
const EMPTY_SLOT: u32 = u32::MAX;

impl<F: SimdFloat> WideNodeOf<F> {
    /// The node with every slot empty.
    fn empty() -> Self {
        let planes = |x: f32| {
            let mut a = F::Array::default();
            a.as_mut().fill(x);
            a
        };
        let mut count = <F::U32 as SimdU32>::Array::default();
        count.as_mut().fill(EMPTY_SLOT);
        Self {
            bounds: [[planes(f32::INFINITY), planes(f32::NEG_INFINITY)]; 3],
            index: Default::default(),
            count,
        }
    }

    /// What slot `i` holds, the empty slot included.
    #[inline(always)]
    pub fn slot(&self, i: usize) -> ChildRef {
        ChildRef {
            index: self.index.as_ref()[i],
            count: self.count.as_ref()[i],
        }
    }

    /// The box of child `i` (empty for an empty slot).
    #[inline(always)]
    pub fn child_bounds(&self, i: usize) -> Aabb {
        let plane = |axis: usize, corner: usize| self.bounds[axis][corner].as_ref()[i];
        Aabb::new(
            glam::Vec3::new(plane(0, 0), plane(1, 0), plane(2, 0)),
            glam::Vec3::new(plane(0, 1), plane(1, 1), plane(2, 1)),
        )
    }

    /// The slab test of `ray` against all children's boxes at once: the mask of
    /// children met within `[t_min, t_max]` (bit `i` for child `i`) and their entry t.
    /// Lane `i` computes exactly what [`SlabRay::entry`] computes for child `i`.
    /// `N` is the instruction set's lane type the node is tested in, in
    /// `F::LANES / N::LANES` independent parts (a 16-wide node in two halves
    /// of 8).
    #[inline(always)]
    pub fn entry<N: SimdFloat>(&self, ray: &SlabRay, t_max: f32) -> (u32, F::Array) {
        let mut bits = 0;
        let mut t = F::Array::default();
        for part in 0..F::LANES / N::LANES {
            let lanes = part * N::LANES..(part + 1) * N::LANES;
            let near = [
                self.near::<N>(ray, 0, part),
                self.near::<N>(ray, 1, part),
                self.near::<N>(ray, 2, part),
            ];
            let far = [
                self.far::<N>(ray, 0, part),
                self.far::<N>(ray, 1, part),
                self.far::<N>(ray, 2, part),
            ];
            let (t_min, t_max) = (N::splat(ray.t_min), N::splat(t_max * FAR_SCALE));
            // Integer min/max where no product can be NaN (a 1-cycle chain
            // where float min/max take 4 on Intel cores), else the float chain.
            let (t_near, t_far) = if ray.finite {
                combine_by_bits(near, far, t_min, t_max)
            } else {
                combine_ignoring_nan(near, far, t_min, t_max)
            };
            bits |= t_near.le(t_far).bitmask() << lanes.start;
            t.as_mut()[lanes].copy_from_slice(t_near.to_array().as_ref());
        }
        (bits, t)
    }

    // Functions rather than closures below: everything under a level's entry
    // point must inline (see `LevelTask`).

    /// For the children of part `part` (lanes `part·N::LANES..`), the t at
    /// which `ray` crosses the plane `corner` (0: min, 1: max) of `axis`,
    /// before scaling by `−1/d`: the origin less the plane (see [`SlabRay`]).
    #[inline(always)]
    fn plane<N: SimdFloat>(&self, ray: &SlabRay, axis: usize, corner: usize, part: usize) -> N {
        let mut planes = N::Array::default();
        let start = part * N::LANES;
        planes
            .as_mut()
            .copy_from_slice(&self.bounds[axis][corner].as_ref()[start..start + N::LANES]);
        N::splat(ray.origin[axis]) - N::from_array(planes)
    }

    /// Per child of part `part`, the t at which `ray` enters the slab of `axis`.
    #[inline(always)]
    fn near<N: SimdFloat>(&self, ray: &SlabRay, axis: usize, part: usize) -> N {
        // `& 1` tells the compiler the corner is 0 or 1, so it checks no bounds.
        self.plane::<N>(ray, axis, ray.entry_corner(axis) & 1, part) * N::splat(ray.neg_inv_dir[axis])
    }

    /// Per child of part `part`, the t at which `ray` leaves the slab of `axis` (scaled up).
    #[inline(always)]
    fn far<N: SimdFloat>(&self, ray: &SlabRay, axis: usize, part: usize) -> N {
        self.plane::<N>(ray, axis, (ray.entry_corner(axis) ^ 1) & 1, part)
            * N::splat(ray.neg_inv_dir_far[axis])
    }
}

/// Collapse the binary tree of node pairs `pairs` into wide nodes of
/// `F::LANES` children: node 0 holds the root's children (or the root itself
/// when it is a leaf; nothing for an `empty` tree).
pub fn collapse<F: SimdFloat>(pairs: &[NodePair], empty: bool) -> Vec<WideNodeOf<F>> {
    // Every wide node but the first stands for a binary inner node of its
    // own (one pair each), so the nodes never outgrow this: no copies as the
    // vector grows. The part not filled is never touched (no pages behind it)
    // and is given back at the end, in place.
    let mut nodes = Vec::with_capacity(1 + pairs.len());
    nodes.push(WideNodeOf::empty());
    if !empty {
        fill(pairs, ROOT, 0, 0, &mut nodes);
    }
    nodes.shrink_to_fit();
    nodes
}

/// The most children a wide node has.
const MAX_WIDTH: usize = RayTreeLanes::LANES;

/// The children a wide node gathers while it opens binary nodes: ids and,
/// for inner ones, surface areas (computed once each; −∞ for a leaf, which
/// is never opened). At most 16 (the widest tree's lanes).
struct Gathered {
    ids: [NodeId; MAX_WIDTH],
    areas: [f32; MAX_WIDTH],
    len: usize,
}

impl Gathered {
    fn push(&mut self, pairs: &[NodePair], id: NodeId) {
        let n = node_in(pairs, id);
        self.ids[self.len] = id;
        self.areas[self.len] = if n.is_leaf() {
            f32::NEG_INFINITY
        } else {
            Aabb::new(n.min, n.max).surface_area()
        };
        self.len += 1;
    }

    /// The inner child of largest area, if any (the last of equals).
    fn widest_inner(&self) -> Option<usize> {
        let mut best: Option<usize> = None;
        for i in 0..self.len {
            let inner = self.areas[i] != f32::NEG_INFINITY;
            if inner && best.is_none_or(|b| self.areas[i].total_cmp(&self.areas[b]).is_ge()) {
                best = Some(i);
            }
        }
        best
    }

    /// Remove child `i`, keeping the others' order.
    fn remove(&mut self, i: usize) -> NodeId {
        let id = self.ids[i];
        self.ids.copy_within(i + 1..self.len, i);
        self.areas.copy_within(i + 1..self.len, i);
        self.len -= 1;
        id
    }
}

/// Fill wide node `at` with the binary subtree under `id`, depth first;
/// `pending` is the path's pending count above it (see [`pending_budget`]).
fn fill<F: SimdFloat>(
    pairs: &[NodePair],
    id: NodeId,
    at: usize,
    pending: usize,
    out: &mut Vec<WideNodeOf<F>>,
) {
    // Open the largest inner child until the node is full (or only leaves),
    // starting from `id` itself: a leaf stays the node's one child, an inner
    // node is opened first.
    let width = if pending + F::LANES - 1 <= pending_budget(F::LANES) {
        F::LANES
    } else {
        2
    };
    let mut children = Gathered {
        ids: [0; MAX_WIDTH],
        areas: [0.0; MAX_WIDTH],
        len: 0,
    };
    children.push(pairs, id);
    while children.len < width {
        let Some(i) = children.widest_inner() else { break };
        let opened = children.remove(i);
        for c in node_in(pairs, opened).children() {
            children.push(pairs, c);
        }
    }
    let mut node = WideNodeOf::<F>::empty();
    // The inner children, as (binary node, wide node) to fill after this one.
    let mut inner = [(0, 0); MAX_WIDTH];
    let mut inner_count = 0;
    for (i, &c) in children.ids[..children.len].iter().enumerate() {
        let n = node_in(pairs, c);
        for axis in 0..3 {
            node.bounds[axis][0].as_mut()[i] = n.min[axis];
            node.bounds[axis][1].as_mut()[i] = n.max[axis];
        }
        let (index, count) = if n.is_leaf() {
            (n.first, n.meta)
        } else {
            out.push(WideNodeOf::empty());
            inner[inner_count] = (c, out.len() - 1);
            inner_count += 1;
            (out.len() as u32 - 1, 0)
        };
        node.index.as_mut()[i] = index;
        node.count.as_mut()[i] = count;
    }
    out[at] = node;
    for &(c, slot) in &inner[..inner_count] {
        fill(pairs, c, slot, pending + children.len - 1, out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::Bvh;
    use crate::accel::bvh::tree::TreeWidth;
    use crate::geometry::Primitive;
    use crate::ray::Ray;
    use crate::rng::Rng;
    use crate::scene::generate::random;
    use glam::Vec3;

    /// Each lane of the wide box test answers as the scalar slab test of that
    /// box: 2¹⁹ random rays against random nodes of 1 to 4 (`f32x4`), 1 to 8
    /// (`f32x8`) or 1 to 16 boxes (`f32x16`, tested in halves of `f32x8` as
    /// single rays test it) (flat boxes, axis-parallel rays in box planes,
    /// empty slots included).
    #[test]
    fn wide_box_test_agrees_with_scalar_slab_test_lane_by_lane() {
        box_test_agrees::<wide::f32x4, wide::f32x4>();
        box_test_agrees::<wide::f32x8, wide::f32x8>();
        box_test_agrees::<wide::f32x16, wide::f32x8>();
    }

    fn box_test_agrees<F: SimdFloat, N: SimdFloat>() {
        let mut rng = Rng::new(5);
        let mut hits = 0;
        let n = 1 << 19;
        for _ in 0..n {
            let mut node = WideNodeOf::<F>::empty();
            let slots = 1 + rng.below(F::LANES as u32) as usize;
            for i in 0..slots {
                let a = rng.point_in(Vec3::splat(-2.0), Vec3::splat(2.0));
                let mut b = rng.point_in(Vec3::splat(-2.0), Vec3::splat(2.0));
                if rng.below(8) == 0 {
                    b.y = a.y;
                }
                for axis in 0..3 {
                    node.bounds[axis][0].as_mut()[i] = a[axis].min(b[axis]);
                    node.bounds[axis][1].as_mut()[i] = a[axis].max(b[axis]);
                }
                node.count.as_mut()[i] = 1;
            }
            let mut origin = rng.point_in(Vec3::splat(-4.0), Vec3::splat(4.0));
            let mut dir = (node.child_bounds(0).center() - origin).normalize_or(Vec3::X);
            if rng.below(2) == 0 {
                dir = rng.unit_vector();
            }
            if rng.below(8) == 0 {
                let k = rng.below(3) as usize;
                dir[k] = if rng.below(2) == 0 { 0.0 } else { -0.0 };
                dir = dir.normalize_or(Vec3::Z);
                origin[k] = node.bounds[k][rng.below(2) as usize].as_ref()[0];
            }
            let t_max = if rng.below(2) == 0 {
                f32::INFINITY
            } else {
                rng.range(0.0, 6.0)
            };
            let ray = Ray::new(origin, dir, rng.range(0.0, 0.5), t_max);
            let slab = SlabRay::new(&ray);
            let (bits, t) = node.entry::<N>(&slab, t_max);
            for (i, t_lane) in t.as_ref().iter().enumerate().take(slots) {
                let b = node.child_bounds(i);
                let scalar = slab.entry(b.min, b.max, t_max);
                assert_eq!(bits >> i & 1 == 1, scalar.is_some(), "{ray:?} vs {b:?}");
                if let Some(ts) = scalar {
                    assert_eq!(t_lane.to_bits(), ts.to_bits());
                    hits += 1;
                }
            }
            assert_eq!(bits >> slots, 0, "empty slots are never met by finite rays");
        }
        assert!(hits > n / 4, "{hits} hits: too few for a meaningful test");
    }

    /// The most stack entries a single-ray traversal of `bvh`'s tree of
    /// width `F` can hold: over every path, the pending children of the
    /// nodes above plus the node's own.
    fn stack_need<F: TreeWidth>(bvh: &Bvh, at: usize, pending: usize) -> usize {
        let node = &F::nodes(bvh)[at];
        let children: Vec<ChildRef> = (0..F::LANES)
            .map(|i| node.slot(i))
            .filter(|c| !c.is_empty())
            .collect();
        let below = children
            .iter()
            .filter(|c| !c.is_leaf())
            .map(|c| stack_need::<F>(bvh, c.node(), pending + children.len() - 1));
        below.fold(pending + children.len(), usize::max)
    }

    /// Traversal stays within the stack on balanced and on peeled-off trees
    /// (spheres growing geometrically, where SAH splits one off at a time).
    #[test]
    fn traversal_fits_in_the_stack() {
        let peeled: Vec<crate::geometry::Primitive> = (0..400)
            .map(|k| {
                let x = 1.15f32.powi(k);
                crate::geometry::Primitive::Sphere(crate::geometry::Sphere::new(
                    Vec3::new(x, 0.0, 0.0),
                    0.3 * x,
                ))
            })
            .collect();
        for prims in [random::random_mixed(20_000, 1), peeled] {
            let bvh = Bvh::new(&prims);
            for need in [
                stack_need::<RayTreeLanes>(&bvh, 0, 0),
                stack_need::<PacketTreeLanes>(&bvh, 0, 0),
            ] {
                assert!(need < WIDE_STACK_SLOTS, "needs {need} entries");
            }
        }
    }

    /// Both wide trees cover every bounded primitive exactly once (a polygon
    /// once per watertight piece), in leaves of primitive records and of
    /// triangle blocks alike.
    #[test]
    fn collapse_keeps_every_leaf_once() {
        covers_every_leaf_once::<RayTreeLanes>();
        covers_every_leaf_once::<PacketTreeLanes>();
    }

    fn covers_every_leaf_once<F: TreeWidth>() {
        for prims in [
            random::random_mixed(3000, 1),
            random::bumpy_sphere(3000, 1),
            random::random_spheres(1, 2),
            Vec::new(),
        ] {
            let bvh = Bvh::new(&prims);
            let mut covered = vec![0u32; prims.len()];
            let mut stack = vec![0usize];
            while let Some(i) = stack.pop() {
                let node = &F::nodes(&bvh)[i];
                for c in 0..F::LANES {
                    let slot = node.slot(c);
                    if slot.is_empty() {
                        continue;
                    }
                    if !slot.is_leaf() {
                        stack.push(slot.node());
                        continue;
                    }
                    for p in bvh.leaves.items(slot.contents()) {
                        covered[p.id() as usize] += 1;
                    }
                }
            }
            let most = |p: &Primitive| match p {
                Primitive::Polygon(p) => p.watertight_pieces().map_or(1, |pieces| pieces.len() as u32),
                _ => 1,
            };
            assert!(covered.iter().zip(&prims).all(|(&x, p)| x <= most(p)));
            assert_eq!(covered.iter().sum::<u32>() as usize, bvh.info().primitives);
        }
    }
}
