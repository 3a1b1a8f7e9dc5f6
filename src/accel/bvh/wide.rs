//! The 4-wide view of the BVH for single rays: each node holds the boxes of up
//! to four children in structure-of-arrays form, so one ray tests all four with
//! one `f32x4` slab test (the layout of Embree's BVH4, Wald et al., "Embree: a
//! kernel framework for efficient CPU ray tracing", SIGGRAPH 2014). It is made
//! by collapsing the binary tree (each wide node takes a binary node and opens
//! its largest inner children until it has four), so both trees share leaves
//! and primitive order; packets traverse the binary tree, and hand lanes they
//! leave alone to the wide tree at the wide node made from the binary node
//! they are at.

use std::ops::Range;

use wide::f32x4;

use crate::accel::bvh::Bvh;
use crate::accel::bvh::node::{NodeId, ROOT};
use crate::accel::bvh::ray_box::{FAR_SCALE, SlabRay};
use crate::bounds::Aabb;
use crate::simd::SimdFloat;

/// What a child slot of a wide node leads to: an inner wide node, or a leaf's
/// run of primitives. 8 bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ChildRef {
    /// Inner: index of the wide node. Leaf: first primitive in leaf order.
    index: u32,
    /// 0 for an inner node, else the leaf's primitive count.
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

    /// The leaf of `count` primitives from `first` on.
    #[inline(always)]
    pub fn leaf(first: u32, count: u32) -> Self {
        Self { index: first, count }
    }

    /// True for a leaf.
    #[inline(always)]
    pub fn is_leaf(self) -> bool {
        self.count != 0
    }

    /// Inner: the wide node's index.
    #[inline(always)]
    pub fn node(self) -> usize {
        self.index as usize
    }

    /// Leaf: its primitives' positions in leaf order.
    #[inline(always)]
    pub fn prims(self) -> Range<usize> {
        self.index as usize..(self.index + self.count) as usize
    }
}

/// Up to four children's (padded) boxes in structure-of-arrays form, and what
/// each child is. 96 bytes of boxes + 32 of slots = 128 bytes, two cache lines.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct WideNode {
    /// `[min; max]` planes of the children along x, y, z: `bounds[axis][corner][child]`.
    bounds: [[[f32; 4]; 2]; 3],
    /// Per child: inner node index, or first primitive of a leaf.
    index: [u32; 4],
    /// Per child: 0 for an inner node, else the leaf's primitive count; `u32::MAX` for an empty slot.
    count: [u32; 4],
}

/// `count` of an empty slot.
const EMPTY_SLOT: u32 = u32::MAX;

impl WideNode {
    /// The node with every slot empty.
    const EMPTY: WideNode = WideNode {
        bounds: [[[f32::INFINITY; 4], [f32::NEG_INFINITY; 4]]; 3],
        index: [0; 4],
        count: [EMPTY_SLOT; 4],
    };

    /// What child `i` leads to; None for an empty slot.
    #[inline(always)]
    pub fn child(&self, i: usize) -> Option<ChildRef> {
        (self.count[i] != EMPTY_SLOT).then_some(ChildRef {
            index: self.index[i],
            count: self.count[i],
        })
    }

    /// The box of child `i` (empty for an empty slot).
    #[inline(always)]
    pub fn child_bounds(&self, i: usize) -> Aabb {
        let b = &self.bounds;
        Aabb::new(
            glam::Vec3::new(b[0][0][i], b[1][0][i], b[2][0][i]),
            glam::Vec3::new(b[0][1][i], b[1][1][i], b[2][1][i]),
        )
    }

    /// The slab test of `ray` against the four children's boxes: the mask of
    /// children met within `[t_min, t_max]` (bit `i` for child `i`) and their entry t.
    /// Lane `i` computes exactly what [`SlabRay::entry`] computes for child `i`.
    #[inline(always)]
    pub fn entry(&self, ray: &SlabRay, t_max: f32) -> (u32, [f32; 4]) {
        let plane = |axis: usize, corner: usize| {
            (f32x4::new(self.bounds[axis][corner]) - f32x4::splat(ray.origin[axis]))
                * f32x4::splat(ray.inv_dir[axis])
        };
        let near = |axis: usize| plane(axis, ray.entry_corner(axis));
        let far = |axis: usize| plane(axis, 1 - ray.entry_corner(axis));
        let t_near = near(0).fast_max(near(1).fast_max(near(2).fast_max(f32x4::splat(ray.t_min))));
        let t_far = far(0).fast_min(far(1).fast_min(far(2).fast_min(f32x4::splat(t_max))));
        let hit = SimdFloat::le(t_near, t_far * f32x4::splat(FAR_SCALE));
        (hit.bitmask(), t_near.to_array())
    }
}

/// The wide tree: its nodes, and for each binary node the wide node made
/// from it, if any.
pub struct Collapsed {
    /// Wide nodes; node 0 holds the root's children (or the root itself when
    /// it is a leaf; nothing for an empty tree).
    pub nodes: Vec<WideNode>,
    /// Per binary [`NodeId`]: the index of the wide node holding its children,
    /// or `u32::MAX` for leaves and for binary nodes opened inside a wide node.
    pub twin: Vec<u32>,
}

/// Collapse the binary tree of `bvh` into wide nodes.
pub fn collapse(bvh: &Bvh) -> Collapsed {
    let mut out = Collapsed {
        nodes: vec![WideNode::EMPTY],
        twin: vec![u32::MAX; 2 * bvh.pairs.len()],
    };
    if !bvh.prims.is_empty() {
        fill(bvh, ROOT, 0, &mut out);
    }
    out
}

/// Fill wide node `at` with the binary subtree under `id`, depth first.
fn fill(bvh: &Bvh, id: NodeId, at: usize, out: &mut Collapsed) {
    if !bvh.node(id).is_leaf() {
        out.twin[id as usize] = at as u32;
    }
    let area = |c: NodeId| {
        let n = bvh.node(c);
        Aabb::new(n.min, n.max).surface_area()
    };
    // Open the largest inner child until there are four children (or only leaves).
    let mut children: Vec<NodeId> = if bvh.node(id).is_leaf() {
        vec![id]
    } else {
        bvh.node(id).children().to_vec()
    };
    while children.len() < 4 {
        let widest = children
            .iter()
            .enumerate()
            .filter(|(_, c)| !bvh.node(**c).is_leaf())
            .max_by(|a, b| area(*a.1).total_cmp(&area(*b.1)))
            .map(|(i, _)| i);
        let Some(i) = widest else { break };
        let opened = children.remove(i);
        children.extend(bvh.node(opened).children());
    }
    let mut node = WideNode::EMPTY;
    let mut inner = Vec::new();
    for (i, &c) in children.iter().enumerate() {
        let n = bvh.node(c);
        for axis in 0..3 {
            node.bounds[axis][0][i] = n.min[axis];
            node.bounds[axis][1][i] = n.max[axis];
        }
        if n.is_leaf() {
            node.index[i] = n.first;
            node.count[i] = n.meta;
        } else {
            node.index[i] = out.nodes.len() as u32;
            node.count[i] = 0;
            out.nodes.push(WideNode::EMPTY);
            inner.push((c, node.index[i] as usize));
        }
    }
    out.nodes[at] = node;
    for (c, slot) in inner {
        fill(bvh, c, slot, out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::Bvh;
    use crate::bench::scenes;
    use crate::ray::Ray;
    use crate::rng::Rng;
    use glam::Vec3;

    /// Each lane of the 4-box test answers as the scalar slab test of that box:
    /// 2¹⁹ random rays against random nodes of 1 to 4 boxes (about 1.3·10⁶ box tests) (flat boxes, axis-parallel rays in box
    /// planes, empty slots included).
    #[test]
    fn four_box_test_agrees_with_scalar_slab_test_lane_by_lane() {
        let mut rng = Rng::new(5);
        let mut hits = 0;
        let n = 1 << 19;
        for _ in 0..n {
            let mut node = WideNode::EMPTY;
            let slots = 1 + rng.below(4) as usize;
            for i in 0..slots {
                let a = rng.point_in(Vec3::splat(-2.0), Vec3::splat(2.0));
                let mut b = rng.point_in(Vec3::splat(-2.0), Vec3::splat(2.0));
                if rng.below(8) == 0 {
                    b.y = a.y;
                }
                for axis in 0..3 {
                    node.bounds[axis][0][i] = a[axis].min(b[axis]);
                    node.bounds[axis][1][i] = a[axis].max(b[axis]);
                }
                node.count[i] = 1;
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
                origin[k] = node.bounds[k][rng.below(2) as usize][0];
            }
            let t_max = if rng.below(2) == 0 {
                f32::INFINITY
            } else {
                rng.range(0.0, 6.0)
            };
            let ray = Ray::new(origin, dir, rng.range(0.0, 0.5), t_max);
            let slab = SlabRay::new(&ray);
            let (bits, t) = node.entry(&slab, t_max);
            for (i, t_lane) in t.iter().enumerate().take(slots) {
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

    /// The wide tree covers exactly the binary tree's leaves, once each.
    #[test]
    fn collapse_keeps_every_leaf_once() {
        for prims in [
            scenes::random_mixed(3000, 1),
            scenes::random_spheres(1, 2),
            Vec::new(),
        ] {
            let bvh = Bvh::new(&prims);
            let mut covered = vec![0u32; bvh.prims.len()];
            let mut stack = vec![0usize];
            while let Some(i) = stack.pop() {
                let node = &bvh.wide[i];
                for c in 0..4 {
                    match node.count[c] {
                        EMPTY_SLOT => {}
                        0 => stack.push(node.index[c] as usize),
                        count => {
                            let first = node.index[c] as usize;
                            covered[first..first + count as usize]
                                .iter_mut()
                                .for_each(|x| *x += 1);
                        }
                    }
                }
            }
            assert!(covered.iter().all(|&x| x == 1));
        }
    }
}
