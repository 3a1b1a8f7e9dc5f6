//! Where a BVH's leaves keep their primitives, apart from the trees that point
//! at them: triangle blocks, sphere blocks and [`LeafPrim`] records, each list
//! in leaf order (a leaf is a contiguous run of one list, named by a
//! [`LeafRef`]). The traversals never look inside: they hand a [`LeafRef`] to
//! a query, which asks the store to test it (as madmann91's `bvh` hands leaves
//! to a callback). The primitives without a box (planes) are one more leaf of
//! records, which every ray visits before the tree.

use rayon::prelude::*;

use crate::accel::bvh::leaf::{
    BLOCK_SIZE, LeafItem, LeafPrim, LeafRef, SphereBlock, TriangleBlock, intersect_blocks,
};
use crate::accel::bvh::node::Node;
use crate::accel::stats::Counter;
use crate::geometry::Primitive;
use crate::geometry::triangle::MAX_BLOCK_ID;
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::{Simd8, SimdFloat};

/// The leaves' primitives. 96 bytes plus the lists.
#[derive(Clone, Debug, Default)]
pub struct LeafStore {
    /// The records of leaves that are neither all triangles nor all spheres.
    records: Vec<LeafPrim>,
    /// The triangles of all-triangle leaves.
    triangle_blocks: Vec<TriangleBlock>,
    /// The spheres of all-sphere leaves.
    sphere_blocks: Vec<SphereBlock>,
    /// The primitives `records` refer to rather than hold (see [`LeafPrim`]).
    others: Vec<Primitive>,
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
    /// What the leaf of `prims` (not empty, each with its input index) holds:
    /// triangles go into blocks only if their indices fit one ([`MAX_BLOCK_ID`]).
    fn of<'a>(mut prims: impl Iterator<Item = (&'a Primitive, u32)>) -> Self {
        let first = match prims.next() {
            Some((Primitive::Triangle(_), id)) if id <= MAX_BLOCK_ID => Holds::Triangles,
            Some((Primitive::Sphere(_), _)) => Holds::Spheres,
            _ => return Holds::Mixed,
        };
        let same = |(p, id): (&Primitive, u32)| match first {
            Holds::Triangles => matches!(p, Primitive::Triangle(_)) && id <= MAX_BLOCK_ID,
            _ => matches!(p, Primitive::Sphere(_)),
        };
        if prims.all(same) { first } else { Holds::Mixed }
    }
}

impl LeafStore {
    /// Store the primitives of the leaf nodes `leaves` (sorted by `first`),
    /// whose ranges index `order`, and point each node at its store: blocks if
    /// a leaf holds only triangles or only spheres, else records. `input(k)` is
    /// the primitive at `order` entry `k` and its input index.
    pub fn build<'p>(
        leaves: &mut [&mut Node],
        order: &[u32],
        input: impl Fn(u32) -> (&'p Primitive, u32) + Sync,
    ) -> Self {
        let range_of = |node: &Node| match node.contents() {
            LeafRef::Prims(range) => range,
            _ => unreachable!("the build makes leaves of primitive ranges"),
        };
        // What each leaf holds, in parallel: the primitives are read in leaf
        // order, far from their input order, so this mostly waits on memory.
        let holds: Vec<Holds> = leaves
            .par_iter()
            .map(|node| Holds::of(order[range_of(node)].iter().map(|&k| input(k))))
            .collect();
        // Lay the blocks out leaf by leaf, each block a run of leaf primitives.
        let mut store = Self::default();
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
                Holds::Mixed => store.push_records(order[range].iter().map(|&k| input(k))),
            };
            (node.first, node.meta) = leaf.encode();
        }
        // Fill the blocks in parallel, in place (an indexed collect); a block's
        // lanes go on the stack, the last repeated into unused slots.
        store.triangle_blocks = triangle_runs
            .par_iter()
            .map(|run| {
                let lanes: [_; BLOCK_SIZE] =
                    std::array::from_fn(|i| match input(order[run.start + i.min(run.len() - 1)]) {
                        (Primitive::Triangle(t), id) => (*t.projected(), id),
                        _ => unreachable!("a triangle leaf holds triangles"),
                    });
                TriangleBlock::new(&lanes[..run.len()])
            })
            .collect();
        store.sphere_blocks = sphere_runs
            .par_iter()
            .map(|run| {
                let lanes: [_; BLOCK_SIZE] =
                    std::array::from_fn(|i| match input(order[run.start + i.min(run.len() - 1)]) {
                        (Primitive::Sphere(s), id) => (*s, id),
                        _ => unreachable!("a sphere leaf holds spheres"),
                    });
                SphereBlock::new(&lanes[..run.len()])
            })
            .collect();
        store
    }

    /// Append a leaf of records for `prims` (primitive, input index).
    pub fn push_records<'p>(&mut self, prims: impl Iterator<Item = (&'p Primitive, u32)>) -> LeafRef {
        let at = self.records.len();
        for (prim, id) in prims {
            self.records.push(LeafPrim::new(prim, id, &mut self.others));
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
        ray: &Ray,
        hit: &mut Hit,
        any_hit: bool,
        stats: &mut S,
    ) -> bool {
        match leaf {
            LeafRef::Triangles { blocks, count } => {
                intersect_blocks::<_, N, S>(&self.triangle_blocks[blocks], count, ray, hit, any_hit, stats)
            }
            LeafRef::Spheres { blocks, count } => {
                intersect_blocks::<_, N, S>(&self.sphere_blocks[blocks], count, ray, hit, any_hit, stats)
            }
            LeafRef::Prims(range) => {
                let mut recorded = false;
                for prim in &self.records[range] {
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

    /// The primitives of `leaf`, one at a time. (An iterator rather than a
    /// callback: the loop body stays in the caller, compiled with the
    /// caller's instruction set, see `dispatch`.)
    #[inline(always)]
    pub fn items(&self, leaf: LeafRef) -> LeafItems<'_> {
        match leaf {
            LeafRef::Triangles { blocks, count } => LeafItems::Triangles {
                blocks: &self.triangle_blocks[blocks],
                next: 0,
                count,
            },
            LeafRef::Spheres { blocks, count } => LeafItems::Spheres {
                blocks: &self.sphere_blocks[blocks],
                next: 0,
                count,
            },
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

    /// Where `leaf`'s blocks start and how many bytes they span, for a
    /// prefetch; None for records, which are read one by one.
    #[inline(always)]
    pub fn block_bytes(&self, leaf: LeafRef) -> Option<(*const u8, usize)> {
        match leaf {
            LeafRef::Triangles { blocks, .. } => Some((
                self.triangle_blocks
                    .as_ptr()
                    .wrapping_add(blocks.start)
                    .cast::<u8>(),
                blocks.len() * size_of::<TriangleBlock>(),
            )),
            LeafRef::Spheres { blocks, .. } => Some((
                self.sphere_blocks
                    .as_ptr()
                    .wrapping_add(blocks.start)
                    .cast::<u8>(),
                blocks.len() * size_of::<SphereBlock>(),
            )),
            LeafRef::Prims(_) => None,
        }
    }

    /// Memory of the stored primitives, in bytes.
    pub fn bytes(&self) -> usize {
        self.records.len() * size_of::<LeafPrim>()
            + self.triangle_blocks.len() * size_of::<TriangleBlock>()
            + self.sphere_blocks.len() * size_of::<SphereBlock>()
            + self.others.len() * size_of::<Primitive>()
    }
}

/// The primitives of a leaf, one at a time ([`LeafStore::items`]).
pub enum LeafItems<'a> {
    /// Records.
    Records(std::slice::Iter<'a, LeafPrim>),
    /// The first `count` lanes of triangle blocks; `next` is the next lane.
    Triangles {
        /// The blocks.
        blocks: &'a [TriangleBlock],
        /// The next lane, counted over all blocks.
        next: usize,
        /// Triangles in the blocks.
        count: usize,
    },
    /// The first `count` lanes of sphere blocks; `next` is the next lane.
    Spheres {
        /// The blocks.
        blocks: &'a [SphereBlock],
        /// The next lane, counted over all blocks.
        next: usize,
        /// Spheres in the blocks.
        count: usize,
    },
}

impl<'a> Iterator for LeafItems<'a> {
    type Item = LeafItem<'a>;

    #[inline(always)]
    fn next(&mut self) -> Option<LeafItem<'a>> {
        match self {
            LeafItems::Records(records) => records.next().map(LeafItem::Record),
            LeafItems::Triangles { blocks, next, count } => {
                if *next == *count {
                    return None;
                }
                let lane = *next;
                *next += 1;
                Some(LeafItem::TriangleLane(
                    &blocks[lane / BLOCK_SIZE],
                    lane % BLOCK_SIZE,
                ))
            }
            LeafItems::Spheres { blocks, next, count } => {
                if *next == *count {
                    return None;
                }
                let lane = *next;
                *next += 1;
                Some(LeafItem::SphereLane(
                    &blocks[lane / BLOCK_SIZE],
                    lane % BLOCK_SIZE,
                ))
            }
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
        let holds = |prims: &[(&Primitive, u32)]| Holds::of(prims.iter().copied());
        assert_eq!(holds(&[(&tri, 0), (&tri, MAX_BLOCK_ID)]), Holds::Triangles);
        assert_eq!(holds(&[(&tri, MAX_BLOCK_ID + 1)]), Holds::Mixed);
        assert_eq!(holds(&[(&tri, 0), (&tri, u32::MAX)]), Holds::Mixed);
        assert_eq!(holds(&[(&ball, u32::MAX), (&ball, 0)]), Holds::Spheres);
        assert_eq!(holds(&[(&tri, 0), (&ball, 1)]), Holds::Mixed);
    }
}
