//! Building a [`Bvh`] over a scene's primitives: their boxes, the binned SAH
//! tree over them ([`build_sah`]), the leaves' primitive
//! store, and the two wide trees collapsed from the binary one.

use glam::Vec3;
use rayon::prelude::*;

use crate::accel::bvh::build_sah::{self, BuildOptions, LeafKind};
use crate::accel::bvh::leaf::LeafRef;
use crate::accel::bvh::leaf_store::{Holds, LeafStore, TreeItem};
use crate::accel::bvh::node::{Node, NodePair};
use crate::accel::bvh::tree::{Bvh, machine_cache_bytes};
use crate::accel::bvh::wide;
use crate::bounds::Aabb;
use crate::geometry::{Primitive, Triangle, TriangleTest};
use crate::simd::Isa;

impl Bvh {
    /// Build over `prims` with the [`BuildOptions`] for the items the tree
    /// holds and how its leaves are tested ([`BuildOptions::for_primitives`]):
    /// a polygon tested as watertight pieces counts as its pieces, as
    /// [`Bvh::len`] counts it (an SPD gears scene's 9,345 polygons are 36,610
    /// triangles in the tree), and a scene whose items (all but one in 100)
    /// go into blocks of one kind is built for blocks ([`LeafKind::Blocks`]).
    pub fn new(prims: &[Primitive]) -> Self {
        Self::build(prims, None)
    }

    /// Build over `prims` with `options`; a hit's primitive index is the position in `prims`.
    pub fn with_options(prims: &[Primitive], options: &BuildOptions) -> Self {
        Self::build(prims, Some(options))
    }

    /// Build over `prims` with `options`, or with those for its items if none.
    fn build(prims: &[Primitive], options: Option<&BuildOptions>) -> Self {
        // The tree's items: the primitives, then the pieces of the polygons
        // tested as watertight pieces, which stand in for their polygon (tight
        // boxes, and triangle blocks in the leaves), each naming it.
        let pieces = watertight_pieces(prims);
        let item = |i: usize| match i.checked_sub(prims.len()) {
            None => (TreeItem::Primitive(&prims[i]), i as u32),
            Some(piece) => (TreeItem::Piece(pieces[piece].0), pieces[piece].1),
        };
        // The items' boxes, in parallel, the empty box for one the tree cannot
        // hold (not finite, or empty) or that its pieces stand in for; and
        // what each would hold in a leaf alone, while it is at hand.
        let usable = |b: Aabb| b.min.is_finite() && b.max.is_finite() && !b.is_empty();
        let (mut boxes, item_holds): (Vec<Aabb>, Vec<Holds>) = (0..prims.len() + pieces.len())
            .into_par_iter()
            .map(|i| {
                let (it, id) = item(i);
                let bounds = match it {
                    TreeItem::Primitive(p) if pieces_of(p).is_some() => None,
                    TreeItem::Primitive(p) => p.bounds(),
                    TreeItem::Piece(&vertices) => Some(Triangle::bounds_of(vertices)),
                };
                (
                    bounds.filter(|b| usable(*b)).unwrap_or(Aabb::EMPTY),
                    Holds::alone(it, id),
                )
            })
            .unzip();
        // The options for the items the tree holds, unless given.
        let options = options.copied().unwrap_or_else(|| {
            let (count, kind) = tree_items(&boxes, &item_holds);
            BuildOptions::for_primitives(count, kind)
        });
        // Where some cannot be held, sort the items into the tree's, the
        // unbounded and the skipped; the tree's then have ids of their own.
        // (Mostly all can: then a tree index is an input index.)
        let (mut bounded_ids, mut unbounded_ids, mut skipped) = (None, Vec::new(), 0);
        if boxes.par_iter().any(Aabb::is_empty) {
            let mut ids = Vec::with_capacity(boxes.len());
            let mut kept = 0;
            for i in 0..boxes.len() {
                let (b, (item, _)) = (boxes[i], item(i));
                if !b.is_empty() {
                    boxes[kept] = b;
                    kept += 1;
                    ids.push(i as u32);
                    continue;
                }
                match item {
                    TreeItem::Primitive(Primitive::Triangle(t)) if t.is_degenerate() => skipped += 1,
                    TreeItem::Primitive(p) => match pieces_of(p) {
                        // Its pieces stand in for it; one of zero area has none.
                        Some(pieces) => skipped += usize::from(pieces.is_empty()),
                        None => unbounded_ids.push(i as u32),
                    },
                    TreeItem::Piece(_) => unbounded_ids.push(i as u32),
                }
            }
            boxes.truncate(kept);
            bounded_ids = Some(ids);
        }
        let (mut pairs, order) = if boxes.is_empty() {
            (vec![NodePair([Node::EMPTY; 2])], Vec::new())
        } else {
            let built = build_sah::build(&boxes, &options);
            (built.pairs, built.order)
        };
        // Store each leaf's items; the leaf nodes then point there.
        let mut leaves: Vec<&mut Node> = pairs
            .iter_mut()
            .flat_map(|pair| &mut pair.0)
            .filter(|n| n.is_leaf() && n.meta != 0)
            .collect();
        leaves.sort_unstable_by_key(|n| n.first);
        let item_of = |k: u32| bounded_ids.as_ref().map_or(k, |ids| ids[k as usize]) as usize;
        let mut store = LeafStore::build(
            &mut leaves,
            &order,
            |k| item(item_of(k)),
            |k| item_holds[item_of(k)],
        );
        let unbounded = store.push_records(unbounded_ids.iter().map(|&i| item(i as usize)));
        let mut bvh = Self {
            pairs,
            ray_tree: Vec::new(),
            packet_tree: Vec::new(),
            leaves: store,
            unbounded,
            bounded: order.len(),
            skipped,
            isa: Isa::default_level(),
            cache_bytes: machine_cache_bytes(),
            walked_bytes: 0,
        };
        bvh.collapse();
        bvh
    }

    /// A tree over `boxes` with no primitives of its own, for the top level
    /// of [`TwoLevel`](crate::accel::TwoLevel): its leaves are ranges of
    /// items in leaf order (item `i` is box `order[i]`, `order` returned), and
    /// its unbounded leaf the `unbounded` items after them, which every ray
    /// visits first. Its queries' leaves are handed to the caller's
    /// [`RayQuery`](super::query::RayQuery) or [`PacketQuery`](super::query::PacketQuery).
    pub fn over_boxes(boxes: &[Aabb], unbounded: usize, options: &BuildOptions) -> (Self, Vec<u32>) {
        let (pairs, order) = if boxes.is_empty() {
            (vec![NodePair([Node::EMPTY; 2])], Vec::new())
        } else {
            let built = build_sah::build(boxes, options);
            (built.pairs, built.order)
        };
        let mut bvh = Self {
            pairs,
            ray_tree: Vec::new(),
            packet_tree: Vec::new(),
            leaves: LeafStore::default(),
            unbounded: LeafRef::Prims(order.len()..order.len() + unbounded),
            bounded: order.len(),
            skipped: 0,
            isa: Isa::default_level(),
            cache_bytes: machine_cache_bytes(),
            walked_bytes: 0,
        };
        bvh.collapse();
        (bvh, order)
    }

    /// Collapse the binary tree into the single rays' and the packets' wide
    /// trees, the two at once (each walks the binary tree on one thread),
    /// and sum the bytes single rays walk ([`Bvh::walked_bytes`]).
    fn collapse(&mut self) {
        let empty = self.is_empty();
        (self.ray_tree, self.packet_tree) = rayon::join(
            || wide::collapse(&self.pairs, empty),
            || wide::collapse(&self.pairs, empty),
        );
        self.walked_bytes = size_of_val(self.ray_tree.as_slice()) + self.leaves.bytes();
    }
}

/// How many of the items with `boxes` the tree holds (those with a box), and
/// how its leaves will be tested: in blocks if all of them but at most one
/// in [`BLOCK_SCENE_ODD_ITEM_IN`] would go into blocks of one kind (`holds`,
/// each item's alone). The few others make leaves of records where they fall.
fn tree_items(boxes: &[Aabb], holds: &[Holds]) -> (usize, LeafKind) {
    // Items per kind: watertight and barycentric triangles, spheres, records.
    let slot = |h: Holds| match h {
        Holds::Triangles(TriangleTest::Watertight) => 0,
        Holds::Triangles(TriangleTest::Barycentric) => 1,
        Holds::Spheres => 2,
        Holds::Mixed => 3,
    };
    let per_kind = boxes
        .par_iter()
        .zip(holds)
        .filter(|(b, _)| !b.is_empty())
        .fold(
            || [0usize; 4],
            |mut n, (_, &h)| {
                n[slot(h)] += 1;
                n
            },
        )
        .reduce(|| [0; 4], |a, b| std::array::from_fn(|k| a[k] + b[k]));
    let count = per_kind.iter().sum();
    let most_in_blocks = per_kind[..3].iter().copied().max().unwrap_or(0);
    let odd = count - most_in_blocks;
    let kind = if most_in_blocks > 0 && odd * BLOCK_SCENE_ODD_ITEM_IN <= count {
        LeafKind::Blocks
    } else {
        LeafKind::Records
    };
    (count, kind)
}

/// A scene is built for blocks ([`LeafKind::Blocks`]) if no more than one
/// item in this many would go into other leaves than blocks of its main
/// kind: SPD mount's 4 spheres beside 8,192 triangles, SPD balls' floor
/// beside 7,381 spheres. (SPD rings and tree are half records: cones.)
const BLOCK_SCENE_ODD_ITEM_IN: usize = 100;

/// The watertight pieces of the polygons in `prims` tested so, each with its
/// polygon's index.
fn watertight_pieces(prims: &[Primitive]) -> Vec<(&[Vec3; 3], u32)> {
    let split = || {
        prims
            .iter()
            .enumerate()
            .filter_map(|(i, p)| Some((pieces_of(p)?, i as u32)))
    };
    let mut pieces = Vec::with_capacity(split().map(|(pieces, _)| pieces.len()).sum());
    for (polygon, i) in split() {
        pieces.extend(polygon.iter().map(|piece| (piece, i)));
    }
    pieces
}

/// The pieces `p` is tested as, if it is a polygon tested so
/// ([`Polygon::watertight_pieces`](crate::geometry::Polygon::watertight_pieces)):
/// the tree holds these in its place.
fn pieces_of(p: &Primitive) -> Option<&[[Vec3; 3]]> {
    match p {
        Primitive::Polygon(polygon) => polygon.watertight_pieces(),
        _ => None,
    }
}
