//! Where a BVH's leaves keep their primitives, apart from the trees that point
//! at them: triangle blocks, sphere blocks and [`LeafPrim`] records, each list
//! in leaf order (a leaf is a contiguous run of one list, named by a
//! [`LeafRef`]). The traversals never look inside: they hand a [`LeafRef`] to
//! a query, which asks the store to test it (as madmann91's `bvh` hands leaves
//! to a callback). The primitives without a box (planes) are one more leaf of
//! records, which every ray visits before the tree.

use std::ops::Range;

use glam::Vec3;
use rayon::prelude::*;

use crate::accel::bvh::leaf::{
    BLOCK_SIZE, LeafItem, LeafPrim, LeafRef, SphereBlock, TriangleBlock, WatertightBlock, intersect_blocks,
};
use crate::accel::bvh::node::Node;
use crate::accel::stats::Counter;
use crate::geometry::triangle::{MAX_BLOCK_ID, ProjectedTriangle, TriangleTest};
use crate::geometry::triangle_watertight::WatertightTriangle;
use crate::geometry::{BlockRay, Primitive, Sphere};
use crate::packet::{HitPacket, RayPacket};
use crate::ray::Hit;
use crate::simd::{Simd8, SimdFloat};

/// The leaves' primitives. 120 bytes plus the lists.
#[derive(Clone, Debug, Default)]
pub struct LeafStore {
    /// The records of leaves that are neither all triangles nor all spheres.
    records: Vec<LeafPrim>,
    /// The triangles of all-triangle leaves under the projected test.
    triangle_blocks: Vec<TriangleBlock>,
    /// The triangles of all-triangle leaves under the watertight test.
    watertight_blocks: Vec<WatertightBlock>,
    /// The spheres of all-sphere leaves.
    sphere_blocks: Vec<SphereBlock>,
    /// The primitives `records` refer to rather than hold (see [`LeafPrim`]).
    others: Vec<Primitive>,
}

/// One item of a BVH's tree: a primitive, or a watertight piece of a
/// polygon, a triangle standing in for part of its polygon (whose index its
/// hits report). A piece is stored in the leaves as the watertight triangle
/// it is, with no [`Primitive`] made of it.
#[derive(Clone, Copy, Debug)]
pub enum TreeItem<'p> {
    /// A primitive, stored as itself.
    Primitive(&'p Primitive),
    /// A polygon's piece (not degenerate: the polygon drops those).
    Piece(&'p [Vec3; 3]),
}

impl TreeItem<'_> {
    /// The test a triangle's kernels run (a piece's is the watertight
    /// test); None for any other shape.
    #[inline]
    fn triangle_test(self) -> Option<TriangleTest> {
        match self {
            TreeItem::Primitive(Primitive::Triangle(t)) => Some(t.test()),
            TreeItem::Piece(_) => Some(TriangleTest::Watertight),
            TreeItem::Primitive(_) => None,
        }
    }

    /// The watertight triangle of a triangle or piece.
    #[inline]
    fn watertight(self) -> Option<WatertightTriangle> {
        match self {
            TreeItem::Primitive(Primitive::Triangle(t)) => Some(t.watertight()),
            TreeItem::Piece(&[a, b, c]) => Some(WatertightTriangle::new(a, b, c)),
            TreeItem::Primitive(_) => None,
        }
    }
}

/// What a leaf holds, which decides how it is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Holds {
    /// Triangles only, all under one test: [`TriangleBlock`]s or [`WatertightBlock`]s.
    Triangles(TriangleTest),
    /// Spheres only: [`SphereBlock`]s.
    Spheres,
    /// Anything else: [`LeafPrim`] records.
    Mixed,
}

impl Holds {
    /// What a leaf of `item` alone, with input index `id`, would hold:
    /// triangles go into blocks only if their indices fit one ([`MAX_BLOCK_ID`]).
    #[inline]
    pub fn alone(item: TreeItem<'_>, id: u32) -> Self {
        match item {
            TreeItem::Primitive(Primitive::Sphere(_)) => Holds::Spheres,
            item => match item.triangle_test() {
                Some(test) if id <= MAX_BLOCK_ID => Holds::Triangles(test),
                _ => Holds::Mixed,
            },
        }
    }

    /// What a leaf (not empty) holds whose items alone would hold `each`:
    /// what they agree on, records if they differ.
    fn of(mut each: impl Iterator<Item = Holds>) -> Self {
        let first = each.next().unwrap_or(Holds::Mixed);
        if each.all(|h| h == first) {
            first
        } else {
            Holds::Mixed
        }
    }
}

impl LeafStore {
    /// Store the primitives of the leaf nodes `leaves` (sorted by `first`),
    /// whose ranges index `order`, and point each node at its store: blocks if
    /// a leaf holds only triangles or only spheres, else records. `input(k)` is
    /// the item at `order` entry `k` and its input index, `holds(k)` what it
    /// would hold alone ([`Holds::alone`]; read from a compact array, where
    /// the items are scattered over memory).
    pub fn build<'p>(
        leaves: &mut [&mut Node],
        order: &[u32],
        input: impl Fn(u32) -> (TreeItem<'p>, u32) + Sync,
        holds: impl Fn(u32) -> Holds + Sync,
    ) -> Self {
        let range_of = |node: &Node| match node.contents() {
            LeafRef::Prims(range) => range,
            _ => unreachable!("the build makes leaves of primitive ranges"),
        };
        // What each leaf holds, from what its items would hold alone: a byte
        // each, where the items themselves, read in leaf order far from their
        // input order, would mostly wait on memory.
        let holds: Vec<Holds> = leaves
            .par_iter()
            .map(|node| Holds::of(order[range_of(node)].iter().map(|&k| holds(k))))
            .collect();
        // Lay the blocks out leaf by leaf, each block a run of leaf primitives.
        let mut store = Self::default();
        let (mut triangle_runs, mut watertight_runs, mut sphere_runs) = (Vec::new(), Vec::new(), Vec::new());
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
                Holds::Triangles(TriangleTest::Barycentric) => {
                    let at = triangle_runs.len();
                    triangle_runs.extend(runs());
                    LeafRef::Triangles {
                        blocks: at..triangle_runs.len(),
                        count,
                    }
                }
                Holds::Triangles(TriangleTest::Watertight) => {
                    let at = watertight_runs.len();
                    watertight_runs.extend(runs());
                    LeafRef::Watertight {
                        blocks: at..watertight_runs.len(),
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
                Holds::Mixed => store.push_records(order[range].iter().map(|&k| input(k))),
            };
            (node.first, node.meta) = leaf.encode();
        }
        // Fill the blocks in parallel, each from its run of leaf primitives.
        store.triangle_blocks = fill_blocks(&triangle_runs, order, &input, |item| match item {
            TreeItem::Primitive(Primitive::Triangle(t)) => Some(*t.projected()),
            _ => None,
        });
        store.watertight_blocks = fill_blocks(&watertight_runs, order, &input, TreeItem::watertight);
        store.sphere_blocks = fill_blocks(&sphere_runs, order, &input, |item| match item {
            TreeItem::Primitive(Primitive::Sphere(s)) => Some(*s),
            _ => None,
        });
        store
    }

    /// Append a leaf of records for `items` (item, input index).
    pub fn push_records<'p>(&mut self, items: impl Iterator<Item = (TreeItem<'p>, u32)>) -> LeafRef {
        let at = self.records.len();
        for (item, id) in items {
            let record = match item {
                TreeItem::Primitive(prim) => LeafPrim::new(prim, id, &mut self.others),
                TreeItem::Piece(&[a, b, c]) => LeafPrim::watertight(WatertightTriangle::new(a, b, c), id),
            };
            self.records.push(record);
        }
        LeafRef::Prims(at..self.records.len())
    }

    /// Test `ray` against the primitives of `leaf`, recording hits in `hit`;
    /// returns true if one was recorded. `any_hit` stops at the first. `N` is
    /// the instruction set's type of the blocks' width.
    #[inline(always)]
    pub fn intersect<N: Simd8, S: Counter>(
        &self,
        leaf: LeafRef,
        ray: &BlockRay,
        hit: &mut Hit,
        any_hit: bool,
        stats: &mut S,
    ) -> bool {
        match leaf {
            LeafRef::Triangles { blocks, count } => {
                intersect_blocks::<_, N, S>(&self.triangle_blocks[blocks], count, ray, hit, any_hit, stats)
            }
            LeafRef::Watertight { blocks, count } => {
                intersect_blocks::<_, N, S>(&self.watertight_blocks[blocks], count, ray, hit, any_hit, stats)
            }
            LeafRef::Spheres { blocks, count } => {
                intersect_blocks::<_, N, S>(&self.sphere_blocks[blocks], count, ray, hit, any_hit, stats)
            }
            LeafRef::Prims(range) => {
                let mut recorded = false;
                for prim in &self.records[range] {
                    stats.prim();
                    recorded |= prim.intersect(&self.others, ray.ray, hit);
                    if recorded && any_hit {
                        break;
                    }
                }
                recorded
            }
        }
    }

    /// The primitives of `leaf`, one at a time. (An iterator rather than a
    /// callback: the loop body stays in the caller, compiled with the
    /// caller's instruction set, see `dispatch`.)
    #[inline(always)]
    pub fn items(&self, leaf: LeafRef) -> LeafItems<'_> {
        match leaf {
            LeafRef::Triangles { blocks, count } => {
                LeafItems::Triangles(BlockLanes::new(&self.triangle_blocks[blocks], count))
            }
            LeafRef::Watertight { blocks, count } => {
                LeafItems::Watertight(BlockLanes::new(&self.watertight_blocks[blocks], count))
            }
            LeafRef::Spheres { blocks, count } => {
                LeafItems::Spheres(BlockLanes::new(&self.sphere_blocks[blocks], count))
            }
            LeafRef::Prims(range) => LeafItems::Records(self.records[range].iter()),
        }
    }

    /// The packet kernel of a leaf's primitive.
    #[inline(always)]
    pub fn intersect_packet<F: SimdFloat>(
        &self,
        prim: LeafItem<'_>,
        rays: &RayPacket<F>,
        hits: &mut HitPacket<F>,
    ) {
        prim.intersect_packet(&self.others, rays, hits);
    }

    /// Where `leaf`'s blocks start, for a prefetch; None for records, which
    /// are read one by one.
    #[inline(always)]
    pub fn block_start(&self, leaf: LeafRef) -> Option<*const u8> {
        fn start<B>(list: &[B], blocks: Range<usize>) -> Option<*const u8> {
            Some(list.as_ptr().wrapping_add(blocks.start).cast::<u8>())
        }
        match leaf {
            LeafRef::Triangles { blocks, .. } => start(&self.triangle_blocks, blocks),
            LeafRef::Watertight { blocks, .. } => start(&self.watertight_blocks, blocks),
            LeafRef::Spheres { blocks, .. } => start(&self.sphere_blocks, blocks),
            LeafRef::Prims(_) => None,
        }
    }

    /// Memory of the stored primitives, in bytes.
    pub fn bytes(&self) -> usize {
        self.records.len() * size_of::<LeafPrim>()
            + self.triangle_blocks.len() * size_of::<TriangleBlock>()
            + self.watertight_blocks.len() * size_of::<WatertightBlock>()
            + self.sphere_blocks.len() * size_of::<SphereBlock>()
            + self.others.len() * size_of::<Primitive>()
    }
}

/// A block of lanes holding `T`s, built from their primitive indices.
trait FromLanes<T> {
    /// The block of `lanes` (shape, primitive index).
    fn from_lanes(lanes: &[(T, u32)]) -> Self;
}

impl FromLanes<ProjectedTriangle> for TriangleBlock {
    fn from_lanes(lanes: &[(ProjectedTriangle, u32)]) -> Self {
        Self::new(lanes)
    }
}

impl FromLanes<WatertightTriangle> for WatertightBlock {
    fn from_lanes(lanes: &[(WatertightTriangle, u32)]) -> Self {
        Self::new(lanes)
    }
}

impl FromLanes<Sphere> for SphereBlock {
    fn from_lanes(lanes: &[(Sphere, u32)]) -> Self {
        Self::new(lanes)
    }
}

/// One block per run of `order` positions, filled in parallel and in place
/// (an indexed collect): `shape` reads each primitive's lane data, which a
/// block's leaf always has. A block's lanes go on the stack first. Only the
/// run's own are made: leaves of small and medium scenes often fill part of
/// a block, and making each unused lane's shape too (a watertight
/// triangle's shear constants) took a tenth of a build whose leaves held up
/// to 4.
fn fill_blocks<'p, T: Copy + Send, B: FromLanes<T> + Send>(
    runs: &[Range<usize>],
    order: &[u32],
    input: &(impl Fn(u32) -> (TreeItem<'p>, u32) + Sync),
    shape: impl Fn(TreeItem<'p>) -> Option<T> + Sync,
) -> Vec<B> {
    runs.par_iter()
        .map(|run| {
            let lane = |k: usize| {
                let (prim, id) = input(order[k]);
                (
                    shape(prim).expect("a block's leaf holds its kind of primitive"),
                    id,
                )
            };
            // The first lane's copies hold the other slots until their own
            // lanes replace them; `from_lanes` reads only the run's.
            let mut lanes = [lane(run.start); BLOCK_SIZE];
            for (slot, k) in lanes.iter_mut().zip(run.clone()).skip(1) {
                *slot = lane(k);
            }
            B::from_lanes(&lanes[..run.len()])
        })
        .collect()
}

/// The primitives of a leaf, one at a time ([`LeafStore::items`]).
pub enum LeafItems<'a> {
    /// Records.
    Records(std::slice::Iter<'a, LeafPrim>),
    /// The lanes of triangle blocks.
    Triangles(BlockLanes<'a, TriangleBlock>),
    /// The lanes of watertight triangle blocks.
    Watertight(BlockLanes<'a, WatertightBlock>),
    /// The lanes of sphere blocks.
    Spheres(BlockLanes<'a, SphereBlock>),
}

/// The first `count` lanes of a leaf's blocks (every block full but the
/// last), one at a time: each block and the lane in it.
pub struct BlockLanes<'a, B> {
    /// The blocks.
    blocks: &'a [B],
    /// The next lane, counted over all blocks.
    next: usize,
    /// Lanes in use.
    count: usize,
}

impl<'a, B> BlockLanes<'a, B> {
    /// The first `count` lanes of `blocks`.
    #[inline(always)]
    fn new(blocks: &'a [B], count: usize) -> Self {
        Self {
            blocks,
            next: 0,
            count,
        }
    }
}

impl<'a, B> Iterator for BlockLanes<'a, B> {
    type Item = (&'a B, usize);

    #[inline(always)]
    fn next(&mut self) -> Option<(&'a B, usize)> {
        if self.next == self.count {
            return None;
        }
        let lane = self.next;
        self.next += 1;
        Some((&self.blocks[lane / BLOCK_SIZE], lane % BLOCK_SIZE))
    }
}

impl<'a> Iterator for LeafItems<'a> {
    type Item = LeafItem<'a>;

    #[inline(always)]
    fn next(&mut self) -> Option<LeafItem<'a>> {
        match self {
            LeafItems::Records(records) => records.next().map(LeafItem::Record),
            LeafItems::Triangles(lanes) => lanes.next().map(|(b, i)| LeafItem::TriangleLane(b, i)),
            LeafItems::Watertight(lanes) => lanes.next().map(|(b, i)| LeafItem::WatertightLane(b, i)),
            LeafItems::Spheres(lanes) => lanes.next().map(|(b, i)| LeafItem::SphereLane(b, i)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Sphere, Triangle};
    use glam::Vec3;

    /// Triangles go into blocks only while their indices fit a block's lanes
    /// (the top bits carry each lane's axis); past that their leaf holds records.
    #[test]
    fn triangle_indices_past_a_block_lane_go_to_records() {
        let tri = Primitive::Triangle(Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y));
        let ball = Primitive::Sphere(Sphere::new(Vec3::ZERO, 1.0));
        let holds = |prims: &[(&Primitive, u32)]| {
            Holds::of(
                prims
                    .iter()
                    .map(|&(p, id)| Holds::alone(TreeItem::Primitive(p), id)),
            )
        };
        let triangles = Holds::Triangles(TriangleTest::default());
        assert_eq!(holds(&[(&tri, 0), (&tri, MAX_BLOCK_ID)]), triangles);
        assert_eq!(holds(&[(&tri, MAX_BLOCK_ID + 1)]), Holds::Mixed);
        assert_eq!(holds(&[(&tri, 0), (&tri, u32::MAX)]), Holds::Mixed);
        assert_eq!(holds(&[(&ball, u32::MAX), (&ball, 0)]), Holds::Spheres);
        assert_eq!(holds(&[(&tri, 0), (&ball, 1)]), Holds::Mixed);
    }
}
