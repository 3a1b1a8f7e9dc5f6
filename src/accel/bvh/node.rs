//! The flat node layout of the binary BVH.
//!
//! Nodes live in pairs: the two children of an inner node sit side by side in one
//! 64-byte [`NodePair`], so the traversal loads both child boxes it tests from one
//! cache line. The root is the first node of pair 0 (the second is an unused empty
//! leaf). A node is named by a [`NodeId`], `2·pair + side`. The 32-byte node is the
//! layout of J. Bikker's tinybvh `BVHNode` ("How to build a BVH", 2022), with the
//! split axis of inner nodes kept for packet ordering.

use glam::Vec3;

use crate::accel::bvh::leaf::LeafRef;
use crate::bounds::Aabb;

/// Names a node: `2·pair + side`.
pub type NodeId = u32;

/// The root's id.
pub const ROOT: NodeId = 0;

/// Marks an inner node in [`Node::meta`]; the low two bits then hold the split axis.
const INNER: u32 = 1 << 31;

/// Relative padding of node boxes. Kernels compute hit points with rounding
/// errors of a few ulps of the coordinates involved; padding each box by
/// `2⁻¹⁹·|coordinate|` (about 32 ulps) keeps every hit a kernel can report inside
/// the box of its primitive, so culling never drops a hit brute force finds.
pub const BOX_PADDING: f32 = 1.0 / 524_288.0;

/// A BVH node. 32 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Node {
    /// Lower corner of the (padded) box.
    pub min: Vec3,
    /// Leaf: index of its first primitive or triangle block (see [`LeafRef`]).
    /// Inner: index of the [`NodePair`] holding the two children.
    pub first: u32,
    /// Upper corner of the (padded) box.
    pub max: Vec3,
    /// Leaf: primitive count, and whether they are triangle blocks (see
    /// [`LeafRef`]). Inner: bit 31 set, split axis in the low two bits.
    pub meta: u32,
}

/// The two children of an inner node, aligned to a 64-byte cache line. 64 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct NodePair(pub [Node; 2]);

impl Node {
    /// A leaf holding `count` primitives from `first` on.
    pub fn leaf(bounds: Aabb, first: u32, count: u32) -> Self {
        let (min, max) = padded(bounds);
        Self {
            min,
            first,
            max,
            meta: count,
        }
    }

    /// An inner node whose children are pair `pair`, split along `axis`
    /// (child 0 holds the lower centroids).
    pub fn inner(bounds: Aabb, pair: u32, axis: u32) -> Self {
        let (min, max) = padded(bounds);
        Self {
            min,
            first: pair,
            max,
            meta: INNER | axis,
        }
    }

    /// The empty leaf (the unused half of the root's pair, and the root of an empty BVH).
    pub const EMPTY: Node = Node {
        min: Vec3::splat(f32::INFINITY),
        first: 0,
        max: Vec3::splat(f32::NEG_INFINITY),
        meta: 0,
    };

    /// This node with its children's pair index moved up by `offset` (a
    /// leaf unchanged): how a subtree built apart, its pairs numbered from 0,
    /// is placed in the whole tree's array.
    #[inline]
    pub fn relocated(self, offset: u32) -> Self {
        if self.is_leaf() {
            self
        } else {
            Self {
                first: self.first + offset,
                ..self
            }
        }
    }

    /// True for a leaf.
    #[inline(always)]
    pub fn is_leaf(&self) -> bool {
        self.meta & INNER == 0
    }

    /// Leaf: what it holds (as built: the range of its primitives in build order).
    #[inline(always)]
    pub fn contents(&self) -> LeafRef {
        LeafRef::decode(self.first, self.meta)
    }

    /// Inner: the ids of the two children.
    #[inline(always)]
    pub fn children(&self) -> [NodeId; 2] {
        [2 * self.first, 2 * self.first + 1]
    }

    /// Inner: the split axis (0 = x, 1 = y, 2 = z).
    #[inline(always)]
    pub fn axis(&self) -> u32 {
        self.meta & 3
    }
}

/// The box grown by [`BOX_PADDING`] of each coordinate's magnitude.
fn padded(b: Aabb) -> (Vec3, Vec3) {
    (
        b.min - b.min.abs() * BOX_PADDING,
        b.max + b.max.abs() * BOX_PADDING,
    )
}

/// The node `id` of the pairs `pairs`.
#[inline(always)]
pub fn node_in(pairs: &[NodePair], id: NodeId) -> &Node {
    &pairs[(id >> 1) as usize].0[(id & 1) as usize]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_is_32_and_64_bytes() {
        assert_eq!(std::mem::size_of::<Node>(), 32);
        assert_eq!(std::mem::size_of::<NodePair>(), 64);
        assert_eq!(std::mem::align_of::<NodePair>(), 64);
    }

    #[test]
    fn leaf_and_inner_round_trip() {
        let b = Aabb::new(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(1.0, 0.0, 3.0));
        let leaf = Node::leaf(b, 7, 3);
        assert!(leaf.is_leaf());
        assert_eq!(leaf.contents(), LeafRef::Prims(7..10));
        assert!(leaf.min.x < -1.0 && leaf.max.x > 1.0 && leaf.min.y == 0.0 && leaf.min.z < 2.0);
        let inner = Node::inner(b, 5, 2);
        assert!(!inner.is_leaf());
        assert_eq!(inner.children(), [10, 11]);
        assert_eq!(inner.axis(), 2);
    }
}
