//! Building a [`Bvh`] over a scene's primitives: their boxes, the binned SAH
//! tree over them ([`build_sah`]), the leaves' primitive
//! store, and the two wide trees collapsed from the binary one.

use rayon::prelude::*;

use crate::accel::bvh::build_sah::{self, BuildOptions};
use crate::accel::bvh::leaf::LeafRef;
use crate::accel::bvh::leaf_store::LeafStore;
use crate::accel::bvh::node::{Node, NodePair};
use crate::accel::bvh::tree::Bvh;
use crate::accel::bvh::wide;
use crate::bounds::Aabb;
use crate::geometry::{Primitive, Triangle, TriangleTest};
use crate::simd::Isa;

impl Bvh {
    /// Build over `prims` with the [`BuildOptions`] for their number
    /// ([`BuildOptions::for_primitives`]).
    pub fn new(prims: &[Primitive]) -> Self {
        Self::with_options(prims, &BuildOptions::for_primitives(prims.len()))
    }

    /// Build over `prims`; a hit's primitive index is the position in `prims`.
    pub fn with_options(prims: &[Primitive], options: &BuildOptions) -> Self {
        // The tree's items: the primitives, then the pieces of the polygons
        // tested as watertight pieces, which stand in for their polygon (tight
        // boxes, and triangle blocks in the leaves), each naming it.
        let pieces = watertight_pieces(prims);
        let item = |i: usize| match i.checked_sub(prims.len()) {
            None => (&prims[i], i as u32),
            Some(piece) => (&pieces[piece].0, pieces[piece].1),
        };
        let is_split = |p: &Primitive| matches!(p, Primitive::Polygon(p) if p.watertight_pieces().is_some());
        // The items' boxes, in parallel, the empty box for one the tree cannot
        // hold (not finite, or empty) or that its pieces stand in for.
        let usable = |b: Aabb| b.min.is_finite() && b.max.is_finite() && !b.is_empty();
        let mut boxes: Vec<Aabb> = (0..prims.len() + pieces.len())
            .into_par_iter()
            .map(|i| {
                let (p, _) = item(i);
                let bounds = if is_split(p) { None } else { p.bounds() };
                bounds.filter(|b| usable(*b)).unwrap_or(Aabb::EMPTY)
            })
            .collect();
        // Where some cannot be held, sort the items into the tree's, the
        // unbounded and the skipped; the tree's then have ids of their own.
        // (Mostly all can: then a tree index is an input index.)
        let (mut bounded_ids, mut unbounded_ids, mut skipped) = (None, Vec::new(), 0);
        if boxes.par_iter().any(Aabb::is_empty) {
            let mut ids = Vec::with_capacity(boxes.len());
            let mut kept = 0;
            for i in 0..boxes.len() {
                let (b, (p, _)) = (boxes[i], item(i));
                if !b.is_empty() {
                    boxes[kept] = b;
                    kept += 1;
                    ids.push(i as u32);
                } else if matches!(p, Primitive::Triangle(t) if t.is_degenerate()) {
                    skipped += 1;
                } else if is_split(p) {
                    // Its pieces stand in for it; one of zero area has none.
                    skipped +=
                        usize::from(matches!(p, Primitive::Polygon(p) if p.watertight_pieces() == Some(&[])));
                } else {
                    unbounded_ids.push(i as u32);
                }
            }
            boxes.truncate(kept);
            bounded_ids = Some(ids);
        }
        let (mut pairs, order) = if boxes.is_empty() {
            (vec![NodePair([Node::EMPTY; 2])], Vec::new())
        } else {
            let built = build_sah::build(&boxes, options);
            (built.pairs, built.order)
        };
        // Store each leaf's items; the leaf nodes then point there.
        let mut leaves: Vec<&mut Node> = pairs
            .iter_mut()
            .flat_map(|pair| &mut pair.0)
            .filter(|n| n.is_leaf() && n.meta != 0)
            .collect();
        leaves.sort_unstable_by_key(|n| n.first);
        let input = |k: u32| item(bounded_ids.as_ref().map_or(k, |ids| ids[k as usize]) as usize);
        let mut store = LeafStore::build(&mut leaves, &order, input);
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
        };
        bvh.ray_tree = wide::collapse(&bvh.pairs, bvh.is_empty());
        bvh.packet_tree = wide::collapse(&bvh.pairs, bvh.is_empty());
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
        };
        bvh.ray_tree = wide::collapse(&bvh.pairs, bvh.is_empty());
        bvh.packet_tree = wide::collapse(&bvh.pairs, bvh.is_empty());
        (bvh, order)
    }
}

/// The watertight pieces of the polygons in `prims` tested so
/// ([`Polygon::watertight_pieces`](crate::geometry::Polygon::watertight_pieces)),
/// as watertight triangles, each with its polygon's index.
fn watertight_pieces(prims: &[Primitive]) -> Vec<(Primitive, u32)> {
    let mut pieces = Vec::new();
    for (i, p) in prims.iter().enumerate() {
        if let Primitive::Polygon(polygon) = p
            && let Some(triangles) = polygon.watertight_pieces()
        {
            pieces.extend(triangles.iter().map(|&[a, b, c]| {
                let piece = Triangle::new(a, b, c).with_test(TriangleTest::Watertight);
                (Primitive::Triangle(piece), i as u32)
            }));
        }
    }
    pieces
}
