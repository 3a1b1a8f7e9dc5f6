//! What a BVH leaf stores. A leaf of triangles only (what meshes are made of)
//! holds them in [`TriangleBlock`]s of [`BLOCK_SIZE`] (8 with AVX, else 4), and
//! a leaf of spheres only in [`SphereBlock`]s alike, which a single ray tests at once
//! ([`ProjectedTriangles`], [`Spheres`]); any other leaf holds a run of
//! [`LeafPrim`]s: the kernel's data inline for spheres and triangles, a
//! reference to a full [`Primitive`] for the rest, and the input index hits
//! report. A leaf node's `first` and count word say which ([`LeafRef`]).
//!
//! Blocks take the branches out of the leaf: tested one by one, tiny triangles
//! hit or miss in no pattern a branch predictor learns, and on a 10⁶-triangle
//! mesh that cost single rays a quarter of their time; spheres in a dense
//! cloud behave alike.
//!
//! A [`Primitive`] is 88 bytes (the largest variant, a triangle with its
//! vertices); a leaf of three triangles stored that way spans five cache lines.
//! The triangle kernels read only the 40-byte [`ProjectedTriangle`], so a
//! [`LeafPrim`] is 48 bytes and the same leaf fits in three lines: the memory a
//! ray pulls in at the bottom of a large tree, where nearly every leaf is a
//! cache miss, roughly halves (the precomputed triangle records of Embree's
//! `Triangle4` leaves, Wald et al. 2014, serve the same purpose).

use std::ops::Range;

use crate::accel::stats::Counter;
use crate::geometry::sphere::Spheres;
use crate::geometry::triangle::{ProjectedTriangle, ProjectedTriangles, TriangleTest};
use crate::geometry::triangle_watertight::{WatertightTriangle, WatertightTriangles};
use crate::geometry::{BlockIntersect, BlockRay, Intersect, Primitive, Sphere};
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::{NodeLanes, SimdFloat};

/// The lanes of a [`TriangleBlock`] or [`SphereBlock`].
pub type BlockLanes = NodeLanes;

/// Primitives per block ([`TriangleBlock`], [`SphereBlock`]).
pub const BLOCK_SIZE: usize = BlockLanes::LANES;

/// Up to [`BLOCK_SIZE`] of a leaf's triangles, tested by one ray at once. 320
/// bytes (five cache lines) with 8 lanes.
pub type TriangleBlock = ProjectedTriangles<BlockLanes>;

/// Up to [`BLOCK_SIZE`] of a leaf's triangles under the watertight test,
/// tested by one ray at once. 320 bytes (five cache lines) with 8 lanes.
pub type WatertightBlock = WatertightTriangles<BlockLanes>;

/// Up to [`BLOCK_SIZE`] of a leaf's spheres, tested by one ray at once. 192
/// bytes (three cache lines).
pub type SphereBlock = Spheres<BlockLanes>;

/// Marks a leaf of [`TriangleBlock`]s in its node's count word.
const TRIANGLE_BLOCKS: u32 = 1 << 30;

/// Marks a leaf of [`SphereBlock`]s in its node's count word.
const SPHERE_BLOCKS: u32 = 1 << 29;

/// Marks a leaf of [`WatertightBlock`]s in its node's count word.
const WATERTIGHT_BLOCKS: u32 = 1 << 28;

/// Test `ray` against the first `count` primitives of `blocks` (every block
/// full but the last), counting each as a primitive test; true if a hit was
/// recorded. `any_hit` stops at the first block that records one. `N` is the
/// instruction set's type of the blocks' width.
#[inline(always)]
pub fn intersect_blocks<
    B: BlockIntersect,
    N: SimdFloat<Array = <B::Lanes as SimdFloat>::Array>,
    S: Counter,
>(
    blocks: &[B],
    count: usize,
    ray: &BlockRay,
    hit: &mut Hit,
    any_hit: bool,
    stats: &mut S,
) -> bool {
    let mut recorded = false;
    for (i, block) in blocks.iter().enumerate() {
        (0..(count - i * BLOCK_SIZE).min(BLOCK_SIZE)).for_each(|_| stats.prim());
        recorded |= block.intersect_with::<N>(ray, hit);
        if recorded && any_hit {
            break;
        }
    }
    recorded
}

/// What a leaf holds: decoded from its node's `first` and count word, which
/// the binary and the wide tree encode alike.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum LeafRef {
    /// Positions in the BVH's [`LeafPrim`] list.
    Prims(Range<usize>),
    /// Positions in the BVH's [`TriangleBlock`] list, holding `count` triangles
    /// (every block full but the last).
    Triangles {
        /// The blocks.
        blocks: Range<usize>,
        /// Triangles in them.
        count: usize,
    },
    /// Positions in the BVH's [`WatertightBlock`] list, holding `count`
    /// triangles (every block full but the last).
    Watertight {
        /// The blocks.
        blocks: Range<usize>,
        /// Triangles in them.
        count: usize,
    },
    /// Positions in the BVH's [`SphereBlock`] list, holding `count` spheres
    /// (every block full but the last).
    Spheres {
        /// The blocks.
        blocks: Range<usize>,
        /// Spheres in them.
        count: usize,
    },
}

/// A packet's lanes test a leaf of triangle blocks one after the other, each
/// with the single ray's block kernel, rather than all at once with the
/// packet kernel, when `lanes × blocks × LANE_BLOCK_COST ≤ triangles`
/// ([`LeafRef::tested_lane_by_lane`]): the packet kernel takes one test per
/// triangle whatever the lanes taking part, the block kernel one per lane and
/// block, and a lane's test of a block costs about two packet tests. Where
/// packets meet a leaf with few lanes (the edges of a primary packet's
/// footprint, shadow rays), primary and shadow packets of large meshes ran
/// faster so, small meshes alike; sphere leaves lost and stay packet-wise
/// (figures: `docs/measurements.md`, "Constants").
pub const LANE_BLOCK_COST: usize = 2;

impl LeafRef {
    /// True when `lanes` lanes of a packet are to test this leaf one after the
    /// other with the block kernel (see [`LANE_BLOCK_COST`]).
    #[inline(always)]
    pub fn tested_lane_by_lane(&self, lanes: u32) -> bool {
        match self {
            LeafRef::Triangles { blocks, count } | LeafRef::Watertight { blocks, count } => {
                lanes as usize * blocks.len() * LANE_BLOCK_COST <= *count
            }
            LeafRef::Spheres { .. } | LeafRef::Prims(_) => false,
        }
    }

    /// Decode a leaf node's `first` and count word.
    #[inline(always)]
    pub fn decode(first: u32, word: u32) -> Self {
        let kind = word & (TRIANGLE_BLOCKS | SPHERE_BLOCKS | WATERTIGHT_BLOCKS);
        let (first, count) = (first as usize, (word & !kind) as usize);
        let blocks = first..first + count.div_ceil(BLOCK_SIZE);
        match kind {
            TRIANGLE_BLOCKS => LeafRef::Triangles { blocks, count },
            SPHERE_BLOCKS => LeafRef::Spheres { blocks, count },
            WATERTIGHT_BLOCKS => LeafRef::Watertight { blocks, count },
            _ => LeafRef::Prims(first..first + count),
        }
    }

    /// The `first` and count word that decode to this leaf.
    pub fn encode(&self) -> (u32, u32) {
        match self {
            LeafRef::Prims(range) => (range.start as u32, range.len() as u32),
            LeafRef::Triangles { blocks, count } => (blocks.start as u32, *count as u32 | TRIANGLE_BLOCKS),
            LeafRef::Spheres { blocks, count } => (blocks.start as u32, *count as u32 | SPHERE_BLOCKS),
            LeafRef::Watertight { blocks, count } => (blocks.start as u32, *count as u32 | WATERTIGHT_BLOCKS),
        }
    }

    /// Primitives in the leaf.
    #[inline(always)]
    pub fn count(&self) -> usize {
        match self {
            LeafRef::Prims(range) => range.len(),
            LeafRef::Triangles { count, .. }
            | LeafRef::Watertight { count, .. }
            | LeafRef::Spheres { count, .. } => *count,
        }
    }
}

/// One primitive of a leaf, wherever it is stored, for the packet kernels
/// (which test a leaf's primitives one at a time).
#[derive(Clone, Copy, Debug)]
pub enum LeafItem<'a> {
    /// A record.
    Record(&'a LeafPrim),
    /// Lane `.1` of a triangle block.
    TriangleLane(&'a TriangleBlock, usize),
    /// Lane `.1` of a watertight triangle block.
    WatertightLane(&'a WatertightBlock, usize),
    /// Lane `.1` of a sphere block.
    SphereLane(&'a SphereBlock, usize),
}

impl LeafItem<'_> {
    /// Index in the input slice.
    pub fn id(self) -> u32 {
        match self {
            LeafItem::Record(p) => p.id,
            LeafItem::TriangleLane(block, lane) => block.id(lane),
            LeafItem::WatertightLane(block, lane) => block.id(lane),
            LeafItem::SphereLane(block, lane) => block.id(lane),
        }
    }

    /// The packet kernel of the primitive (`others` is the BVH's list of other primitives).
    #[inline(always)]
    pub fn intersect_packet<F: SimdFloat>(
        self,
        others: &[Primitive],
        rays: &RayPacket<F>,
        hits: &mut HitPacket<F>,
    ) {
        match self {
            LeafItem::Record(p) => p.intersect_packet(others, rays, hits),
            LeafItem::TriangleLane(block, lane) => block.intersect_packet(lane, rays, hits),
            LeafItem::WatertightLane(block, lane) => block.intersect_packet(lane, rays, hits),
            LeafItem::SphereLane(block, lane) => block.intersect_packet(lane, rays, hits),
        }
    }
}

/// A leaf's primitive. 48 bytes.
#[derive(Clone, Debug, PartialEq)]
pub struct LeafPrim {
    /// The shape's kernel data.
    shape: LeafShape,
    /// Index in the input slice, reported by hits.
    id: u32,
}

/// A leaf primitive's kernel data. 44 bytes.
#[derive(Clone, Debug, PartialEq)]
enum LeafShape {
    /// A triangle's projected-barycentric constants.
    Triangle(ProjectedTriangle),
    /// A triangle under the watertight test.
    Watertight(WatertightTriangle),
    /// A sphere.
    Sphere(Sphere),
    /// Any other shape: its index in the BVH's list of other primitives.
    Other(u32),
}

impl LeafPrim {
    /// The leaf record of `prim`, input index `id`; shapes kept whole are
    /// appended to `others`.
    pub fn new(prim: &Primitive, id: u32, others: &mut Vec<Primitive>) -> Self {
        let shape = match prim {
            Primitive::Triangle(t) => match t.test() {
                TriangleTest::Barycentric => LeafShape::Triangle(*t.projected()),
                TriangleTest::Watertight => LeafShape::Watertight(t.watertight()),
            },
            Primitive::Sphere(s) => LeafShape::Sphere(*s),
            other => {
                others.push(other.clone());
                LeafShape::Other(others.len() as u32 - 1)
            }
        };
        Self { shape, id }
    }

    /// The leaf record of watertight triangle `t`, input index `id`.
    pub fn watertight(t: WatertightTriangle, id: u32) -> Self {
        Self {
            shape: LeafShape::Watertight(t),
            id,
        }
    }

    /// Index in the input slice.
    pub fn id(&self) -> u32 {
        self.id
    }

    /// The scalar kernel of the shape (`others` is the BVH's list of other primitives).
    #[inline(always)]
    pub fn intersect(&self, others: &[Primitive], ray: &Ray, hit: &mut Hit) -> bool {
        match &self.shape {
            LeafShape::Triangle(t) => t.intersect(ray, self.id, hit),
            LeafShape::Watertight(t) => t.intersect(ray, self.id, hit),
            LeafShape::Sphere(s) => s.intersect(ray, self.id, hit),
            LeafShape::Other(i) => others[*i as usize].intersect(ray, self.id, hit),
        }
    }

    /// The packet kernel of the shape.
    #[inline(always)]
    pub fn intersect_packet<F: SimdFloat>(
        &self,
        others: &[Primitive],
        rays: &RayPacket<F>,
        hits: &mut HitPacket<F>,
    ) {
        match &self.shape {
            LeafShape::Triangle(t) => t.intersect_packet(rays, self.id, hits),
            LeafShape::Watertight(t) => t.intersect_packet(rays, self.id, hits),
            LeafShape::Sphere(s) => s.intersect_packet(rays, self.id, hits),
            LeafShape::Other(i) => others[*i as usize].intersect_packet(rays, self.id, hits),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    use crate::geometry::{Cone, Triangle};

    /// Few lanes test a leaf of triangle blocks one by one, many together;
    /// leaves of spheres and of records always together.
    #[test]
    fn few_lanes_test_triangle_blocks_lane_by_lane() {
        let full = LeafRef::Triangles {
            blocks: 3..5,
            count: 2 * BLOCK_SIZE,
        };
        let lanes = (2 * BLOCK_SIZE / (2 * LANE_BLOCK_COST)) as u32;
        assert!(full.tested_lane_by_lane(1) && full.tested_lane_by_lane(lanes));
        assert!(!full.tested_lane_by_lane(lanes + 1));
        let small = LeafRef::Triangles {
            blocks: 0..1,
            count: 2,
        };
        assert!(small.tested_lane_by_lane(1) && !small.tested_lane_by_lane(2));
        let spheres = LeafRef::Spheres {
            blocks: 0..1,
            count: BLOCK_SIZE,
        };
        assert!(!spheres.tested_lane_by_lane(1) && !LeafRef::Prims(0..8).tested_lane_by_lane(1));
    }

    #[test]
    fn record_is_48_bytes_and_blocks_fill_whole_cache_lines() {
        // 10 rows of lanes for triangles, 6 for spheres, rounded up to 64 bytes.
        assert_eq!(size_of::<LeafPrim>(), 48);
        assert_eq!(
            size_of::<TriangleBlock>(),
            (10 * 4 * BLOCK_SIZE).next_multiple_of(64)
        );
        assert_eq!(
            size_of::<SphereBlock>(),
            (6 * 4 * BLOCK_SIZE).next_multiple_of(64)
        );
    }

    #[test]
    fn leaf_refs_round_trip_through_the_node_words() {
        // Block leaves of 1, a full block, and a block and a bit.
        let blocks = |first: usize, count: usize| first..first + count.div_ceil(BLOCK_SIZE);
        for leaf in [
            LeafRef::Prims(0..0),
            LeafRef::Prims(7..10),
            LeafRef::Triangles {
                blocks: blocks(3, 1),
                count: 1,
            },
            LeafRef::Triangles {
                blocks: blocks(3, BLOCK_SIZE),
                count: BLOCK_SIZE,
            },
            LeafRef::Triangles {
                blocks: blocks(12, BLOCK_SIZE + 1),
                count: BLOCK_SIZE + 1,
            },
            LeafRef::Spheres {
                blocks: blocks(0, 1),
                count: 1,
            },
            LeafRef::Spheres {
                blocks: blocks(9, 2 * BLOCK_SIZE),
                count: 2 * BLOCK_SIZE,
            },
        ] {
            let (first, word) = leaf.encode();
            assert_eq!(LeafRef::decode(first, word), leaf);
        }
    }

    #[test]
    fn each_shape_reports_what_the_primitive_reports() {
        let prims = [
            Primitive::Triangle(Triangle::new(
                Vec3::new(-1.0, -1.0, 0.0),
                Vec3::new(1.0, -1.0, 0.0),
                Vec3::Y,
            )),
            Primitive::Sphere(Sphere::new(Vec3::new(0.0, 0.0, 2.0), 0.5)),
            Primitive::Cone(
                Cone::new(Vec3::new(0.0, -1.0, 4.0), 1.0, Vec3::new(0.0, 1.0, 4.0), 0.5).unwrap(),
            ),
        ];
        let mut others = Vec::new();
        let leaves: Vec<LeafPrim> = prims
            .iter()
            .enumerate()
            .map(|(i, p)| LeafPrim::new(p, 10 + i as u32, &mut others))
            .collect();
        assert_eq!(others.len(), 1);
        for (i, (p, leaf)) in prims.iter().zip(&leaves).enumerate() {
            assert_eq!(leaf.id(), 10 + i as u32);
            let ray = Ray::unbounded(Vec3::new(0.1, 0.2, -5.0), Vec3::Z);
            let (mut want, mut got) = (Hit::none(&ray), Hit::none(&ray));
            assert_eq!(
                leaf.intersect(&others, &ray, &mut got),
                p.intersect(&ray, leaf.id(), &mut want)
            );
            assert_eq!(got, want);
            assert!(got.is_hit(), "shape {i}");
            let rays = RayPacket::<wide::f32x8>::from_rays(&[ray; 8]);
            let (mut want, mut got) = (HitPacket::none(&rays), HitPacket::none(&rays));
            leaf.intersect_packet(&others, &rays, &mut got);
            p.intersect_packet(&rays, leaf.id(), &mut want);
            assert_eq!(got.hit(3), want.hit(3));
        }
    }
}
